#include "calib/atomic_file.h"

#include <algorithm>
#include <filesystem>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include "calib/input_error.h"

namespace raycarve {

std::string TemporaryPathFor(const std::string& path) {
  const std::filesystem::path final_path(path);
  return (final_path.parent_path() / (".tmp." + final_path.filename().string())).string();
}

void RenameIntoPlace(const std::string& temporary, const std::string& path) {
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary, error);
    throw InputError(path + ": cannot move the written file into place: " + error.message());
  }
}

namespace {

// fsync of a file or folder; a failure to sync is reported (the data may not be on disk).
void Sync(const std::filesystem::path& path, bool folder) {
  const int fd = open(path.c_str(), folder ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0) throw InputError(path.string() + ": cannot open to sync it to disk");
  const int status = fsync(fd);
  close(fd);
  if (status != 0) throw InputError(path.string() + ": cannot sync it to disk");
}

}  // namespace

StagedOutputs::StagedOutputs(const std::string& folder) : folder_(folder) {
  const std::filesystem::path root(folder);
  std::error_code error;
  std::filesystem::create_directories(root, error);
  if (error) throw InputError(folder + ": cannot create: " + error.message());
  for (const auto& entry : std::filesystem::directory_iterator(root, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_directory() && name.rfind(".raycarve-partial-", 0) == 0) {
      std::filesystem::remove_all(entry.path(), error);
    }
  }
  const std::filesystem::path staging = root / (".raycarve-partial-" + std::to_string(getpid()));
  std::filesystem::create_directory(staging, error);
  if (error) throw InputError(staging.string() + ": cannot create: " + error.message());
  staging_ = staging.string();
}

StagedOutputs::~StagedOutputs() {
  std::error_code ignored;
  std::filesystem::remove_all(staging_, ignored);
}

void StagedOutputs::MoveIntoPlace(const std::string& last) {
  const std::filesystem::path from(staging_), to(folder_);
  std::vector<std::filesystem::path> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(from, error)) {
    if (entry.is_regular_file()) files.push_back(std::filesystem::relative(entry.path(), from));
  }
  if (error) throw InputError(staging_ + ": cannot list the outputs: " + error.message());
  std::sort(files.begin(), files.end());
  std::stable_partition(files.begin(), files.end(),
                        [&](const std::filesystem::path& file) { return file != last; });
  for (const std::filesystem::path& file : files) Sync(from / file, false);
  for (const std::filesystem::path& file : files) {
    std::filesystem::create_directories((to / file).parent_path(), error);
    if (error) throw InputError((to / file).parent_path().string() + ": cannot create: " + error.message());
    RenameIntoPlace((from / file).string(), (to / file).string());
  }
  Sync(to, true);
  std::filesystem::remove_all(from, error);
}

}  // namespace raycarve
