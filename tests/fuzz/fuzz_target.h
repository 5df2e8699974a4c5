#pragma once

// A fuzz target is one function, LLVMFuzzerTestOneInput, as libFuzzer calls it. Built with
// RAYCARVE_FUZZ_ENABLED (clang, -fsanitize=fuzzer), it is a libFuzzer program; otherwise
// replay_main.cc turns it into a program that runs every file of a corpus once, which the test
// suite does for the committed corpora (tests/fuzz/corpus/<target>/).
//
// A target may only end by returning: bad input must come back as InputError (caught here, as
// main() does), never as a crash, an abort, a sanitizer report or an allocation beyond what the
// input holds.
#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
