// The command-line parser: the input, split at NUL bytes, is the argument list; an input that
// starts with "INI\n" is instead an option file (COLMAP's INI format) given as --project_path.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "calib/input_error.h"
#include "plugin/option_parser.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> words = {"raycarve", "fuzz"};
  static const std::string ini_path = (std::filesystem::temp_directory_path() /
                                       ("raycarve_ini_fuzz_" + std::to_string(getpid()) + ".ini"))
                                          .string();
  if (size >= 4 && std::string(reinterpret_cast<const char*>(data), 4) == "INI\n") {
    {
      std::ofstream file(ini_path, std::ios::binary | std::ios::trunc);
      file.write(reinterpret_cast<const char*>(data) + 4, static_cast<std::streamsize>(size - 4));
    }
    words.push_back("--project_path");
    words.push_back(ini_path);
  } else {
    std::string word;
    for (size_t i = 0; i < size && words.size() < 64; ++i) {
      if (data[i] == 0) {
        words.push_back(word);
        word.clear();
      } else {
        word += static_cast<char>(data[i]);
      }
    }
    words.push_back(word);
  }
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  std::string text = "x", required;
  int count = 1;
  uint64_t big = 0;
  double value = 0.5;
  bool flag = false;
  raycarve::OptionParser parser("fuzz", "fuzzed options");
  parser.AddDefault("text", &text, "a string", {"x", "y"});
  parser.AddDefault("count", &count, "an int");
  parser.AddDefault("big", &big, "a uint64");
  parser.AddDefault("value", &value, "a double");
  parser.AddDefault("flag", &flag, "a bool");
  try {
    parser.Parse(static_cast<int>(argv.size()), argv.data());
  } catch (const raycarve::InputError&) {
  }
  return 0;
}
