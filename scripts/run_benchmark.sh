#!/usr/bin/env bash
# Carving benchmark (not a test): set-up, build with benchmarks, and carve the generated scene at
# 14 views of 800x600 at 128 and 256 voxels (arguments are passed on, e.g. --resolutions 128).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh raycarve
cmake -S . -B build -DRAYCARVE_BENCHMARKS_ENABLED=ON >&2
cmake --build build -j"$(nproc 2>/dev/null || echo 2)" --target carve_benchmark calib_benchmark >&2
build/benchmarks/carve_benchmark "$@"
