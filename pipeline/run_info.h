#pragma once

#include <string>

namespace raycarve {

// raycarve's version (the CMake project's) and the git commit it was built from ("unknown"
// outside a git checkout; "-modified" when tracked files differed from the commit).
std::string Version();
std::string BuildCommit();
// "raycarve 0.1.0 (commit 0123456789ab)"
std::string VersionLine();

// The run's identity for reports: main records its command line (arguments quoted where they
// need it) and the time it started; before that, both are empty.
void RecordRun(int argc, char** argv);
std::string RunCommandLine();
std::string RunStartTime();  // UTC, ISO 8601: "2026-12-01T23:40:00Z"

}  // namespace raycarve
