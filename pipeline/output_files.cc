#include "pipeline/output_files.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "calib/atomic_file.h"
#include "calib/input_error.h"

namespace raycarve {
namespace {

std::vector<std::pair<std::string, std::string>>& ProtectedFiles() {
  static std::vector<std::pair<std::string, std::string>> files;
  return files;
}

// No output replaces a protected input file (an option file read through --project_path).
void CheckNotAProtectedFile(const std::string& output_path) {
  if (output_path.empty()) return;
  for (const auto& [file, what] : ProtectedFiles()) {
    if (std::filesystem::weakly_canonical(output_path) == std::filesystem::weakly_canonical(file)) {
      throw InputError(output_path + ": the output is the " + what +
                       "; raycarve never overwrites its input, choose another --output_path");
    }
  }
}

}  // namespace

void WriteTextFileAtomically(const std::string& path, const std::string& text) {
  const std::string temporary = TemporaryPathFor(path);
  {
    errno = 0;
    std::ofstream stream(temporary);
    if (!stream) throw InputError(temporary + ": cannot open for writing: " + std::strerror(errno));
    stream << text;
    stream.close();
    if (!stream) ThrowWriteFailure(temporary, "the file (" + path + " is unchanged)", errno);
  }
  RenameIntoPlace(temporary, path);
}

void WriteImageAtomically(const std::string& path, const cv::Mat& image) {
  const std::string temporary = TemporaryPathFor(path);
  bool written = false;
  errno = 0;
  try {
    written = cv::imwrite(temporary, image);
  } catch (const cv::Exception& error) {
    throw InputError(temporary + ": cannot write the image (" + error.err + ")");
  }
  if (!written) {
    // imwrite says no more: errno or the file system says why, unless the encoder refused.
    const std::string reason = WriteFailureReason(temporary, errno);
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw InputError(temporary + ": cannot write the image: " +
                     (reason.empty() ? std::string("the encoder failed") : reason));
  }
  RenameIntoPlace(temporary, path);
}


void ProtectInputFile(const std::string& path, const std::string& what) {
  ProtectedFiles().emplace_back(path, what);
}

void CheckOutputDoesNotOverwrite(const std::string& output_path,
                                 const std::string& input_path,
                                 const std::string& what) {
  CheckNotAProtectedFile(output_path);
  if (output_path.empty() || input_path.empty()) return;
  if (std::filesystem::weakly_canonical(output_path) ==
      std::filesystem::weakly_canonical(input_path)) {
    throw InputError(output_path + ": the output is the " + what + " (" + input_path +
                     "); raycarve never overwrites its input, choose another --output_path");
  }
}

void CheckOutputFileOutside(const std::string& output_file,
                            const std::string& input_path,
                            const std::string& what) {
  CheckNotAProtectedFile(output_file);
  if (output_file.empty() || input_path.empty()) return;
  namespace fs = std::filesystem;
  const fs::path output = fs::weakly_canonical(output_file);
  const fs::path input = fs::weakly_canonical(input_path);
  // The output is the input, or lies inside it (a folder), through links, dots and slashes.
  const auto [input_end, output_at] = std::mismatch(input.begin(), input.end(), output.begin(), output.end());
  if (input_end == input.end()) {
    throw InputError(output_file + ": the output " +
                     (output == input ? std::string("is the ") : std::string("lies inside the ")) +
                     what + " (" + input_path +
                     "); raycarve never overwrites its input, choose another --output_path");
  }
}

std::filesystem::path OutputFileInside(const std::string& folder,
                                       const std::string& relative_name,
                                       const std::vector<std::pair<std::string, std::string>>& inputs) {
  namespace fs = std::filesystem;
  const fs::path name(relative_name);
  const fs::path root = fs::weakly_canonical(folder);
  const fs::path path = fs::weakly_canonical(root / name);
  const auto [root_end, path_at] = std::mismatch(root.begin(), root.end(), path.begin(), path.end());
  if (name.is_absolute() || root_end != root.end() || path == root) {
    throw InputError(folder + ": the image name '" + relative_name +
                     "' would write outside this output folder; raycarve refuses it");
  }
  for (const auto& [input, what] : inputs) CheckOutputFileOutside(path.string(), input, what);
  return path;
}

}  // namespace raycarve
