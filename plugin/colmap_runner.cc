#include "plugin/colmap_runner.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "calib/input_error.h"

namespace raycarve {

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
  std::string command = ShellQuote(colmap);
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
  while (std::fgets(buffer, sizeof(buffer), pipe) != nullptr) {
    line += buffer;
    if (line.empty() || line.back() != '\n') continue;
    line.pop_back();
    std::cout << "  colmap| " << line << "\n";
    last.push_back(line);
    if (last.size() > 12) last.pop_front();
    line.clear();
  }
  std::cout.flush();
  const int status = pclose(pipe);
  if (tail != nullptr) tail->assign(last.begin(), last.end());
  if (status == -1) throw InputError("cannot run " + colmap);
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

}  // namespace raycarve
