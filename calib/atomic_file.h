#pragma once

#include <string>

namespace raycarve {

// Outputs are written under a temporary name beside their final path and renamed into place, so
// that a failed or interrupted write never leaves a partial file under the final name.

// The temporary name for `path`: same folder, ".tmp." prefixed to the file name, extension kept
// (writers that choose a format by extension, such as cv::imwrite, still work).
std::string TemporaryPathFor(const std::string& path);

// Renames `temporary` to `path`; throws InputError naming `path` on failure.
void RenameIntoPlace(const std::string& temporary, const std::string& path);

}  // namespace raycarve
