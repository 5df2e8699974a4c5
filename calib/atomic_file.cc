#include "calib/atomic_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <glog/logging.h>

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

std::string WriteFailureReason(const std::string& path, int saved_errno) {
  if (saved_errno != 0) return std::strerror(saved_errno);
  // Streams and libraries do not always keep errno: ask the file system.
  struct statvfs info;
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (statvfs(folder.empty() ? "." : folder.c_str(), &info) == 0) {
    if ((info.f_flag & ST_RDONLY) != 0) return std::strerror(EROFS);
    if (info.f_bavail == 0 || info.f_favail == 0) return std::strerror(ENOSPC);
  }
  return "";
}

void ThrowWriteFailure(const std::string& temporary, const std::string& what, int saved_errno) {
  std::string reason = WriteFailureReason(temporary, saved_errno);
  if (reason.empty()) reason = "the write failed";
  std::error_code ignored;
  std::filesystem::remove(temporary, ignored);
  throw InputError(temporary + ": cannot write " + what + ": " + reason);
}

void CheckNoLinkInside(const std::string& folder, const std::string& relative) {
  std::filesystem::path at(folder);
  for (const std::filesystem::path& part : std::filesystem::path(relative)) {
    at /= part;
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::symlink_status(at, error);
    if (error || status.type() != std::filesystem::file_type::symlink) continue;
    const std::filesystem::path target = std::filesystem::read_symlink(at, error);
    throw InputError(at.string() + ": is a symbolic link (to " + target.string() +
                     ") inside the output folder; raycarve does not write through links it did "
                     "not make (one may point at an input): remove it or give another --output_path");
  }
}

namespace {

// Takes the advisory lock on `folder`'s lock file; returns its descriptor. Throws InputError,
// naming the process that holds it, when another run does and `wait` is false.
int LockFolder(const std::filesystem::path& folder, bool wait) {
  const std::filesystem::path path = folder / ".raycarve.lock";
  const int fd = open(path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw InputError(path.string() + ": cannot open the output folder's lock file: " +
                     std::strerror(errno));
  }
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    char holder[32] = {0};
    const ssize_t read_bytes = pread(fd, holder, sizeof(holder) - 1, 0);
    const std::string process = read_bytes > 0 ? std::string(holder, read_bytes) : "unknown";
    if (!wait) {
      close(fd);
      throw InputError(folder.string() + ": another raycarve run (process " + process +
                       ") is writing into this output folder; wait for it to end, give --wait, "
                       "or choose another --output_path");
    }
    LOG(INFO) << folder.string() << ": waiting for raycarve process " << process
              << " to finish writing there";
    if (flock(fd, LOCK_EX) != 0) {
      close(fd);
      throw InputError(path.string() + ": cannot lock the output folder: " + std::strerror(errno));
    }
  }
  const std::string pid = std::to_string(getpid());
  if (ftruncate(fd, 0) != 0 || pwrite(fd, pid.data(), pid.size(), 0) < 0) {
    LOG(WARNING) << path.string() << ": cannot record this run's process id";
  }
  return fd;
}

// fsync of a file or folder; a failure to sync is reported (the data may not be on disk).
void Sync(const std::filesystem::path& path, bool folder) {
  const int fd = open(path.c_str(), folder ? O_RDONLY | O_DIRECTORY : O_RDONLY);
  if (fd < 0) throw InputError(path.string() + ": cannot open to sync it to disk");
  const int status = fsync(fd);
  close(fd);
  if (status != 0) throw InputError(path.string() + ": cannot sync it to disk");
}

}  // namespace

StagedOutputs::StagedOutputs(const std::string& folder, bool wait) : folder_(folder) {
  const std::filesystem::path root(folder);
  std::error_code error;
  std::filesystem::create_directories(root, error);
  if (error) throw InputError(folder + ": cannot create: " + error.message());
  lock_fd_ = LockFolder(root, wait);
  // With the lock held, staging folders here are those of runs that ended without cleaning up.
  for (const auto& entry : std::filesystem::directory_iterator(root, error)) {
    const std::string name = entry.path().filename().string();
    if (entry.symlink_status().type() == std::filesystem::file_type::directory &&
        name.rfind(".raycarve-partial-", 0) == 0) {
      std::filesystem::remove_all(entry.path(), error);
    }
  }
  const std::filesystem::path staging = root / (".raycarve-partial-" + std::to_string(getpid()));
  std::filesystem::create_directory(staging, error);
  if (error) {
    close(lock_fd_);
    throw InputError(staging.string() + ": cannot create: " + error.message());
  }
  staging_ = staging.string();
}

StagedOutputs::~StagedOutputs() {
  std::error_code ignored;
  if (!staging_.empty()) std::filesystem::remove_all(staging_, ignored);
  if (lock_fd_ >= 0) close(lock_fd_);  // releases the lock
}

void StagedOutputs::Write(const std::function<void()>& write) const {
  try {
    write();
  } catch (const InputError& error) {
    throw InputError(std::string(error.what()) + "; nothing was replaced in " + folder_ +
                     ": the outputs already there are as they were");
  }
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
  for (const std::filesystem::path& file : files) CheckNoLinkInside(folder_, file.string());
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
