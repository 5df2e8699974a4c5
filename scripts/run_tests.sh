#!/usr/bin/env bash
# README command 2: set-up, build everything, and run every test (CTest, 2 at a time); then the
# tests that feed raycarve bad input, and the fuzz targets' corpora, again under AddressSanitizer +
# UndefinedBehaviorSanitizer.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc 2>/dev/null || echo 2)
(cd build && ctest --output-on-failure --timeout 900 -j"$jobs")

echo "[tests] bad-input tests under AddressSanitizer + UBSan (build-asan/)" >&2
# Configured every time (quick when cached): make does not know a target added since the last
# configuration until CMake has run again.
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRAYCARVE_ASAN_ENABLED=ON \
  -DRAYCARVE_TESTS_ENABLED=ON >&2
cmake --build build-asan -j"$jobs" --target raycarve calib_model_reader_test calib_middlebury_test \
  calib_colmap_program_test export_point_cloud_io_test plugin_option_parser_test \
  plugin_command_line_test plugin_model_input_test plugin_carve_commands_test \
  fuzz_model_reader fuzz_middlebury fuzz_ply fuzz_option_parser fuzz_image fuzz_gltf fuzz_obj >&2
(cd build-asan && ctest --output-on-failure --timeout 900 -j"$jobs" \
  -R 'calib/(model_reader|middlebury|colmap_program)_test|export/point_cloud_io_test|'\
'plugin/(option_parser|command_line|model_input|carve_commands)_test|fuzz/')
