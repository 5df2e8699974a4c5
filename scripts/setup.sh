#!/usr/bin/env bash
# Shared set-up for both README commands: installs the Debian 12 packages raycarve needs (only
# those missing, so a second run is quick), then configures and builds in Release in build/.
# Usage: scripts/setup.sh [cmake targets...]   (no target: everything, tests included)
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake pkg-config libeigen3-dev libopencv-dev libceres-dev libpcl-dev
          libvtk9-dev libgoogle-glog-dev libgflags-dev libjpeg-dev libgtest-dev libgmock-dev libbenchmark-dev libcgal-dev libtinygltf-dev libtinyobjloader-dev nlohmann-json3-dev python3-yaml colmap chromium)
# Node.js and npm for report.html's viewer (three.js) and its browser test (playwright-core):
# from Debian unless the machine already has them.
if ! command -v npm > /dev/null 2>&1; then packages+=(nodejs npm); fi
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

# The 3D view's scripts (embedded in raycarve at build time) and the page test's browser driver,
# at the versions pipeline/viewer/package-lock.json pins.
viewer=pipeline/viewer
if ! cmp -s "$viewer/package-lock.json" "$viewer/node_modules/.raycarve-installed-lock"; then
  echo "[setup] npm ci in $viewer" >&2
  (cd "$viewer" && npm ci --no-audit --no-fund --loglevel=error >&2)
  cp "$viewer/package-lock.json" "$viewer/node_modules/.raycarve-installed-lock"
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
