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
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace raycarve {
namespace fuzzing {

// For readers that take a file: `data` written to one temporary file per process and per `name`
// (raycarve_<name>_fuzz_<pid><extension>), rewritten for every input; returns its path.
inline std::string WriteInputFile(const std::string& name, const std::string& extension,
                                  const uint8_t* data, size_t size) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("raycarve_" + name + "_fuzz_" + std::to_string(getpid()) + extension))
                               .string();
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace fuzzing
}  // namespace raycarve
