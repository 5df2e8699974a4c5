#include <cstring>
#include <exception>
#include <iostream>
#include <string>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "plugin/commands.h"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* summary;
};

const Command kCommands[] = {
    {"model_info", raycarve::RunModelInfo,
     "print a COLMAP model's cameras, images, points and carving bounds (text or JSON)"},
    {"model_converter", raycarve::RunModelConverter, "convert a COLMAP model between BIN and TXT"},
    {"import_middlebury", raycarve::RunImportMiddlebury,
     "turn a Middlebury *_par.txt calibration into a COLMAP model"},
    {"calibrate", raycarve::RunCalibrate,
     "build calibrated, undistorted views of a COLMAP project and check them"},
    {"sfm", raycarve::RunSfm,
     "run COLMAP structure-from-motion on the CPU: photos to a COLMAP project"},
    {"carve", raycarve::RunCarve,
     "carve a coloured voxel model (cloud.ply, mesh.ply) from a COLMAP project"},
    {"compare", raycarve::RunCompare,
     "accuracy, completeness and F-score of a PLY cloud or mesh against a reference"},
    {"check_background", raycarve::RunCheckBackground,
     "share of a point cloud that projects onto background in the photos"},
    {"holdout", raycarve::RunHoldout,
     "carve without every k-th view and score renders of the left-out views (PSNR, IoU)"},
    {"benchmark", raycarve::RunBenchmark,
     "the seed paper's Table 1 and Figure 6: ray casting against GVC and GVC-LDI"},
    {"render", raycarve::RunRender,
     "draw a coloured cloud into the cameras of a COLMAP model (render and silhouette)"},
    {"synth", raycarve::RunSynth, "generate a synthetic COLMAP project with ground truth"},
};

void PrintUsage() {
  std::cout << "raycarve: voxel colouring of COLMAP projects on the CPU\n\n"
               "Usage: raycarve <command> [options]   (raycarve <command> --help)\n\nCommands:\n";
  for (const Command& command : kCommands) {
    std::cout << "  " << command.name << std::string(20 - std::strlen(command.name), ' ')
              << command.summary << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  if (argc < 2 || std::string(argv[1]) == "help" || std::string(argv[1]) == "--help" ||
      std::string(argv[1]) == "-h") {
    PrintUsage();
    return argc < 2 ? 1 : 0;
  }
  const std::string name = argv[1];
  for (const Command& command : kCommands) {
    if (name != command.name) continue;
    try {
      return command.run(argc, argv);
    } catch (const raycarve::InputError& error) {
      std::cerr << "raycarve " << name << ": error: " << error.what() << std::endl;
      return 1;
    } catch (const std::exception& error) {
      std::cerr << "raycarve " << name << ": unexpected error: " << error.what() << std::endl;
      return 2;
    }
  }
  std::cerr << "raycarve: unknown command '" << name << "' (raycarve help lists them)"
            << std::endl;
  return 1;
}
