#include "plugin/colmap_runner.h"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "calib/input_error.h"

namespace raycarve {
namespace {

// The longest a running COLMAP step goes without a line on the screen.
constexpr int kQuietSeconds = 10;

}  // namespace

std::string ShellQuote(const std::string& word) {
  std::string quoted = "'";
  for (const char c : word) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

std::string FindColmap(const std::string& colmap_path) {
  const std::string hint =
      " (install Debian's colmap package: apt-get install colmap, or give --colmap_path)";
  if (colmap_path.find('/') != std::string::npos) {
    if (access(colmap_path.c_str(), X_OK) == 0 && std::filesystem::is_regular_file(colmap_path)) {
      return colmap_path;
    }
    throw InputError(colmap_path + ": no such program" + hint);
  }
  const char* path = std::getenv("PATH");
  std::stringstream folders(path == nullptr ? "" : path);
  std::string folder;
  while (std::getline(folders, folder, ':')) {
    if (folder.empty()) continue;
    const std::filesystem::path candidate = std::filesystem::path(folder) / colmap_path;
    if (access(candidate.c_str(), X_OK) == 0 && std::filesystem::is_regular_file(candidate)) {
      return candidate.string();
    }
  }
  throw InputError("'" + colmap_path + "' not found on PATH" + hint);
}

int RunColmap(const std::string& colmap,
              const std::vector<std::string>& arguments,
              std::vector<std::string>* tail) {
  // COLMAP writes its progress (a line per photo, per block of matches) to stdout, which a pipe
  // would buffer until the step ends: stdbuf (coreutils) makes it line-buffered.
  std::string command;
  if (access("/usr/bin/stdbuf", X_OK) == 0) command = "/usr/bin/stdbuf -oL -eL ";
  command += ShellQuote(colmap);
  for (const std::string& argument : arguments) command += " " + ShellQuote(argument);
  command += " 2>&1";
  std::cout << "$ colmap";
  for (const std::string& argument : arguments) std::cout << " " << argument;
  std::cout << std::endl;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) throw InputError("cannot start " + colmap);
  std::deque<std::string> last;
  std::string line;
  char buffer[4096];
  const auto start = std::chrono::steady_clock::now();
  const auto seconds = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  pollfd descriptor = {fileno(pipe), POLLIN, 0};
  for (;;) {
    // A line at least every kQuietSeconds: a step that prints nothing for long still shows it runs.
    const int ready = poll(&descriptor, 1, kQuietSeconds * 1000);
    if (ready == 0) {
      std::cout << "  colmap| (still running, " << static_cast<int>(seconds()) << " s)" << std::endl;
      continue;
    }
    if (ready < 0 && errno == EINTR) continue;
    const ssize_t count = read(descriptor.fd, buffer, sizeof(buffer));
    if (count <= 0) break;
    line.append(buffer, static_cast<size_t>(count));
    for (size_t end; (end = line.find('\n')) != std::string::npos; line.erase(0, end + 1)) {
      const std::string text = line.substr(0, end);
      std::cout << "  colmap| " << text << std::endl;
      last.push_back(text);
      if (last.size() > 12) last.pop_front();
    }
  }
  if (!line.empty()) {
    std::cout << "  colmap| " << line << std::endl;
    last.push_back(line);
  }
  const int status = pclose(pipe);
  if (tail != nullptr) tail->assign(last.begin(), last.end());
  if (status == -1) throw InputError("cannot run " + colmap);
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

}  // namespace raycarve
