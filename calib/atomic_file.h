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

// A set of outputs that should be replaced together (a cloud, its mesh and the report that
// describes them): written under `staging`, then, once complete, each file synced to disk and
// renamed into `folder` (same relative path), `last` after all the others, and the folder synced.
// An interrupted run leaves the previous set whole beside the staging folder. Throws InputError
// naming the file on failure.
//
// StagingFolderFor(folder): `<folder>/.raycarve-partial-<pid>`, created empty; staging folders
// left by earlier, interrupted runs in `folder` are removed first.
std::string StagingFolderFor(const std::string& folder);
void MoveOutputSetIntoPlace(const std::string& staging, const std::string& folder,
                            const std::string& last);

}  // namespace raycarve
