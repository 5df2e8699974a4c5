#!/usr/bin/env bash
# Shared set-up for both README commands: installs the Debian 12 packages raycarve needs (only
# those missing, so a second run is quick), then configures and builds in Release in build/.
# Usage: scripts/setup.sh [cmake targets...]   (no target: everything, tests included)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake pkg-config libeigen3-dev libopencv-dev libceres-dev libpcl-dev
          libvtk9-dev libgoogle-glog-dev libgflags-dev libjpeg-dev libgtest-dev libgmock-dev libbenchmark-dev libcgal-dev libtinygltf-dev colmap)
missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "[setup] installing: ${missing[*]}" >&2
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
else
  echo "[setup] all Debian packages present" >&2
fi

if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DRAYCARVE_TESTS_ENABLED=ON >&2
fi
jobs=$(nproc 2>/dev/null || echo 2)
if [ $# -gt 0 ]; then
  cmake --build build -j"$jobs" --target "$@" >&2
else
  cmake --build build -j"$jobs" >&2
fi
