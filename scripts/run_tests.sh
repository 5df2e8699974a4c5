#!/usr/bin/env bash
# README command 2: set-up, build everything, and run every test (CTest, 2 at a time).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
cd build
ctest --output-on-failure --timeout 900 -j"$(nproc 2>/dev/null || echo 2)"
