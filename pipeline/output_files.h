#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace raycarve {

// The output folder's rules: every file is written under a temporary name and renamed
// (calib/atomic_file.h's StagedOutputs writes a whole set), and no output lands in an input.

// Writes `text` to `path` through a temporary file and a rename; throws InputError on failure.
void WriteTextFileAtomically(const std::string& path, const std::string& text);

// Writes an image in the format of the path's extension (cv::imwrite: BGR or grey), through a
// temporary name and a rename; throws InputError naming the file on failure.
void WriteImageAtomically(const std::string& path, const cv::Mat& image);

// Declares a file that was read as input outside a model or photo folder (an option file read
// through --project_path): every check below refuses an output onto it, naming `what`.
void ProtectInputFile(const std::string& path, const std::string& what);

// Throws InputError when `output_path` is `input_path` (after resolving links and dots), or a
// protected input file: the writers would replace the input's files.
void CheckOutputDoesNotOverwrite(const std::string& output_path,
                                 const std::string& input_path,
                                 const std::string& what);
// Throws InputError when the output file or folder `output_file` is `input_path` or lies inside
// it (a folder), after resolving links, dots and trailing slashes, or is a protected input file.
void CheckOutputFileOutside(const std::string& output_file,
                            const std::string& input_path,
                            const std::string& what);
// The path of an output named after an image (`relative_name`, e.g. "<name>.png") under
// `folder`. Throws InputError when the name is absolute or escapes `folder` through "..", or
// when the path lies inside one of `inputs` (path, what it is).
std::filesystem::path OutputFileInside(const std::string& folder,
                                       const std::string& relative_name,
                                       const std::vector<std::pair<std::string, std::string>>& inputs);

}  // namespace raycarve
