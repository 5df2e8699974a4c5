#!/usr/bin/env bash
# cmake --install of a built tree into a temporary prefix, then a consumer project
# (samples/consumer) configured against the installed package, built and run.
#   install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 source=$2
work=$(mktemp -d "${TMPDIR:-/tmp}/raycarve_install_XXXXXX")
trap 'rm -rf "$work"' EXIT
cmake --install "$build" --prefix "$work/prefix" > "$work/install.log"
prefix=$work/prefix
for path in bin/raycarve include/raycarve/calib/camera.h include/raycarve/export/point_cloud_io.h \
            lib/cmake/raycarve/raycarveConfig.cmake lib/cmake/raycarve/raycarveConfigVersion.cmake \
            lib/libraycarve_calib.a share/doc/raycarve/LICENSE; do
  [ -e "$prefix/$path" ] || { echo "not installed: $path"; cat "$work/install.log"; exit 1; }
done
version=$("$prefix/bin/raycarve" --version)
case "$version" in
  "raycarve 0.1.0 (commit "*")") echo "installed: $version" ;;
  *) echo "unexpected --version: $version"; exit 1 ;;
esac
cmake -S "$source/samples/consumer" -B "$work/consumer" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release > "$work/configure.log" 2>&1 || { cat "$work/configure.log"; exit 1; }
cmake --build "$work/consumer" -j2 > "$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
"$work/consumer/raycarve_consumer" "$work/consumer/cloud.ply"
[ -s "$work/consumer/cloud.ply" ] || { echo "the consumer wrote no cloud"; exit 1; }
head -c 3 "$work/consumer/cloud.ply" | grep -q ply
echo "consumer built against the installed package and ran"
