#pragma once

#include <string>
#include <vector>

#include "calib/bounds.h"
#include "calib/reconstruction.h"

namespace raycarve {

// The subcommands of the `raycarve` program, one file each (<name>_command.cc). Each parses its
// options and calls the library (the carve pipeline in pipeline/, or a stage's own library);
// bad input throws InputError, which main() prints as one line before exiting non-zero.
int RunModelInfo(int argc, char** argv);
int RunModelConverter(int argc, char** argv);
int RunImportMiddlebury(int argc, char** argv);
int RunSynth(int argc, char** argv);
int RunCalibrate(int argc, char** argv);
int RunCarve(int argc, char** argv);
int RunCompare(int argc, char** argv);
int RunCheckBackground(int argc, char** argv);
int RunHoldout(int argc, char** argv);
int RunBenchmark(int argc, char** argv);
int RunSfm(int argc, char** argv);
int RunRender(int argc, char** argv);
int RunTile(int argc, char** argv);

// model_info: a text and a JSON description of a model and the bounds it would carve; with
// `bounds_error`, why its points bound no volume instead.
std::string DescribeModelText(const Reconstruction& reconstruction,
                              const std::string& model_path,
                              const Bounds& bounds,
                              const std::string& bounds_error = "");
std::string DescribeModelJson(const Reconstruction& reconstruction,
                              const std::string& model_path,
                              const Bounds& bounds,
                              const std::string& bounds_error = "");

// sfm --colmap_options: "Section.name=value,..." split into the arguments of the COLMAP step
// that takes each section. Throws InputError on a malformed item or an unknown section.
struct ColmapPassThrough {
  std::vector<std::string> extractor, matcher, mapper;
};
ColmapPassThrough SplitColmapOptions(const std::string& text);

}  // namespace raycarve
