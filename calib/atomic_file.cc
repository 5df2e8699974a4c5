#include "calib/atomic_file.h"

#include <filesystem>

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

}  // namespace raycarve
