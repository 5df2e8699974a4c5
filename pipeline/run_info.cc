#include "pipeline/run_info.h"

#include <ctime>

#include "raycarve_version.h"  // generated: RAYCARVE_VERSION, RAYCARVE_COMMIT

namespace raycarve {
namespace {
std::string& CommandLineText() {
  static std::string text;
  return text;
}
std::string& StartTimeText() {
  static std::string text;
  return text;
}
}  // namespace

void RecordRun(int argc, char** argv) {
  std::string line;
  for (int i = 0; i < argc; ++i) {
    const std::string argument = argv[i];
    const bool plain = !argument.empty() &&
                       argument.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTU"
                                                  "VWXYZ0123456789-_=./,:+@%") == std::string::npos;
    std::string quoted = "'";
    for (char c : argument) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    line += (i > 0 ? " " : "") + (plain ? argument : quoted + "'");
  }
  CommandLineText() = line;
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &utc);
  StartTimeText() = text;
}

std::string RunCommandLine() { return CommandLineText(); }

std::string RunStartTime() { return StartTimeText(); }

std::string Version() { return RAYCARVE_VERSION; }

std::string BuildCommit() { return RAYCARVE_COMMIT; }

std::string VersionLine() { return "raycarve " + Version() + " (commit " + BuildCommit() + ")"; }

}  // namespace raycarve
