#pragma once

#include <functional>
#include <string>

namespace raycarve {

// Outputs are written under a temporary name beside their final path and renamed into place, so
// that a failed or interrupted write never leaves a partial file under the final name.

// The temporary name for `path`: same folder, ".tmp." prefixed to the file name, extension kept
// (writers that choose a format by extension, such as cv::imwrite, still work).
std::string TemporaryPathFor(const std::string& path);

// Renames `temporary` to `path`; throws InputError naming `path` on failure.
void RenameIntoPlace(const std::string& temporary, const std::string& path);

// Why writing `path` failed: the system's reason `saved_errno` (errno just after the failure)
// when it is one, else what the file system holding `path` says (full, read-only), else "" (no
// reason known).
std::string WriteFailureReason(const std::string& path, int saved_errno);

// Removes `temporary` (a partial write) and throws InputError "<temporary>: cannot write <what>:
// <reason>". Call it with errno as it was just after the failed write.
[[noreturn]] void ThrowWriteFailure(const std::string& temporary, const std::string& what,
                                    int saved_errno);

// Throws InputError when a write of `relative` (a path relative to the output folder `folder`)
// would go through or onto a symbolic link inside `folder`: raycarve does not follow links in
// its output folders that it did not make, since one can point at an input (the photos, the
// masks). The message names the link and its target. `folder` itself may be a link.
void CheckNoLinkInside(const std::string& folder, const std::string& relative);

// A set of outputs that should be replaced together (a cloud, its mesh and the report that
// describes them). The constructor makes `<folder>/.raycarve-partial-<pid>`, empty, after
// removing staging folders that earlier, interrupted runs left in `folder`; the outputs are
// written under path(). MoveIntoPlace then syncs each file to disk and renames it into `folder`
// (same relative path), `last` after all the others, and syncs the folder. An interrupted run
// leaves the previous set whole; a run that fails before MoveIntoPlace leaves no staging folder
// (the destructor removes it). Throws InputError naming the file on failure.
//
// One run at a time writes into a folder: the constructor takes an advisory lock on
// `<folder>/.raycarve.lock` (flock, held until the destructor; the kernel drops it when a run is
// killed, so a stale lock never blocks) before it touches anything there. When another run holds
// it, the constructor throws InputError naming that run's process, or with `wait` waits for it.
// Every file is checked with CheckNoLinkInside before any is moved.
class StagedOutputs {
 public:
  explicit StagedOutputs(const std::string& folder, bool wait = false);
  ~StagedOutputs();
  StagedOutputs(const StagedOutputs&) = delete;
  StagedOutputs& operator=(const StagedOutputs&) = delete;

  const std::string& path() const { return staging_; }
  // Runs `write`, which writes the outputs under path(); an InputError from it (a disk that
  // fills, a file system that turns read-only) is thrown again saying that the outputs already in
  // the folder were left as they were.
  void Write(const std::function<void()>& write) const;
  void MoveIntoPlace(const std::string& last);

 private:
  std::string folder_;
  std::string staging_;
  int lock_fd_ = -1;
};

}  // namespace raycarve
