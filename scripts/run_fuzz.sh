#!/usr/bin/env bash
# Fuzzes every reader (not a test): installs Debian's clang and libFuzzer if missing, builds the
# fuzz targets as libFuzzer programs with AddressSanitizer + UBSan (build-fuzz/), and runs each
# for SECONDS (default 600) from a scratch copy of its committed corpus, printing libFuzzer's
# figures (executions, coverage, corpus size). A crash fails and keeps its input in /tmp; add it
# to tests/fuzz/corpus/<target>/ with a unit test once fixed.
# Usage: scripts/run_fuzz.sh [SECONDS] [TARGETS]   (default: 600, "model_reader middlebury ply option_parser image")
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-600}
targets=${2:-"model_reader middlebury ply option_parser image"}
scripts/setup.sh raycarve >&2
if ! command -v clang++-16 > /dev/null || [ ! -d /usr/lib/llvm-16/lib/clang/16/lib/linux ] ||
   ! ls /usr/lib/llvm-16/lib/clang/16/lib/linux/libclang_rt.fuzzer-x86_64.a > /dev/null 2>&1; then
  sudo=""; [ "$(id -u)" -ne 0 ] && sudo=sudo
  $sudo apt-get install -y -q clang-16 libfuzzer-16-dev >&2
fi
if [ ! -f build-fuzz/CMakeCache.txt ]; then
  CC=clang-16 CXX=clang++-16 cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DRAYCARVE_FUZZ_ENABLED=ON -DRAYCARVE_TESTS_ENABLED=ON >&2
fi
for target in $targets; do
  cmake --build build-fuzz -j"$(nproc)" --target "fuzz_$target" >&2
done
for target in $targets; do
  echo "== fuzz_$target, $seconds s"
  tests/fuzz/run_fuzz.sh "build-fuzz/tests/fuzz/fuzz_$target" "tests/fuzz/corpus/$target" "$seconds"
done
