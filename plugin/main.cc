#include <cstring>
#include <exception>
#include <filesystem>
#include <iostream>
#include <new>
#include <cstdlib>
#include <string>
#include <vector>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "plugin/commands.h"
#include "pipeline/run_info.h"

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
    {"tile", raycarve::RunTile,
     "a carve split into tiles for separate processes or a cluster: plan, run, merge"},
    {"synth", raycarve::RunSynth, "generate a synthetic COLMAP project with ground truth"},
};

void PrintUsage() {
  std::cout << raycarve::VersionLine() << ": voxel colouring of COLMAP projects on the CPU\n\n"
               "Usage: raycarve <command> [options]   (raycarve <command> --help)\n\nCommands:\n";
  for (const Command& command : kCommands) {
    std::cout << "  " << command.name << std::string(20 - std::strlen(command.name), ' ')
              << command.summary << "\n";
  }
}

// Takes glog's flags as COLMAP does (--log_to_stderr, --log_level, --v; "--name value" or
// "--name=value") out of argv, applies them and returns the rest. Throws InputError on a value
// that is not a number.
std::vector<char*> TakeLoggingFlags(int argc, char** argv) {
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    const std::string argument = argv[i];
    std::string name, value;
    bool matched = false;
    for (const char* flag : {"log_to_stderr", "log_level", "v"}) {
      const std::string prefix = std::string("--") + flag;
      if (argument == prefix) {
        name = flag;
        matched = true;
        const bool has_next = i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0;
        value = has_next ? argv[++i] : (name == "log_to_stderr" ? "1" : "");
      } else if (argument.rfind(prefix + "=", 0) == 0) {
        name = flag;
        matched = true;
        value = argument.substr(prefix.size() + 1);
      }
      if (matched) break;
    }
    if (!matched) {
      rest.push_back(argv[i]);
      continue;
    }
    char* end = nullptr;
    const long number = std::strtol(value.c_str(), &end, 10);
    if (value.empty() || end == nullptr || *end != '\0' || number < 0 || number > 1000) {
      throw raycarve::InputError("--" + name + ": expected a number from 0 to 1000, got '" +
                                 value + "'");
    }
    if (name == "log_to_stderr") {
      FLAGS_logtostderr = number != 0;
    } else {
      FLAGS_v = static_cast<int>(number);  // COLMAP's --log_level is glog's verbosity
    }
  }
  rest.push_back(nullptr);
  return rest;
}

// A message that already names the command ("raycarve carve: ...") without the name, so that
// it is printed once.
std::string WithoutPrefix(const std::string& message, const std::string& name) {
  const std::string prefix = "raycarve " + name + ": ";
  return message.rfind(prefix, 0) == 0 ? message.substr(prefix.size()) : message;
}

// A filesystem failure as the user reads it: the path, what was being done, the reason.
std::string FilesystemMessage(const std::filesystem::filesystem_error& error) {
  std::string path = error.path1().string();
  if (path.empty()) path = "(a path)";
  std::string what = error.what();
  // libstdc++: "filesystem error: <operation>: <reason> [<path>]"; keep the operation.
  const std::string prefix = "filesystem error: ";
  std::string operation;
  if (what.rfind(prefix, 0) == 0) {
    const size_t colon = what.find(':', prefix.size());
    if (colon != std::string::npos) operation = what.substr(prefix.size(), colon - prefix.size());
  }
  return path + ": " + error.code().message() +
         (operation.empty() ? std::string() : " (while trying to " + operation + " it)");
}

}  // namespace

int main(int original_argc, char** original_argv) {
  google::InitGoogleLogging(original_argv[0]);
  raycarve::RecordRun(original_argc, original_argv);
  FLAGS_logtostderr = true;
  std::vector<char*> arguments;
  try {
    arguments = TakeLoggingFlags(original_argc, original_argv);
  } catch (const raycarve::InputError& error) {
    std::cerr << "raycarve: error: " << error.what() << std::endl;
    return 1;
  }
  const int argc = static_cast<int>(arguments.size()) - 1;
  char** argv = arguments.data();
  if (argc < 2 || std::string(argv[1]) == "help" || std::string(argv[1]) == "--help" ||
      std::string(argv[1]) == "-h") {
    PrintUsage();  // no arguments: the usage, as COLMAP prints it, and success
    return 0;
  }
  if (std::string(argv[1]) == "--version" || std::string(argv[1]) == "version") {
    std::cout << raycarve::VersionLine() << "\n";
    return 0;
  }
  const std::string command_name = argv[1];
  for (const Command& command : kCommands) {
    if (command_name != command.name) continue;
    // Messages name a command with steps by its step too ("raycarve tile plan: ...").
    const std::string name = command_name == "tile" && argc > 2 && argv[2][0] != '-'
                                 ? command_name + " " + argv[2]
                                 : command_name;
    try {
      return command.run(argc, argv);
    } catch (const raycarve::InputError& error) {
      std::cerr << "raycarve " << name << ": error: " << WithoutPrefix(error.what(), name)
                << std::endl;
      return 1;
    } catch (const std::filesystem::filesystem_error& error) {
      // A path the user gave or made (permissions, a name too long, a link loop, a full or
      // read-only disk): one line naming it and the reason.
      std::cerr << "raycarve " << name << ": error: " << FilesystemMessage(error) << std::endl;
      return 1;
    } catch (const std::bad_alloc&) {
      std::cerr << "raycarve " << name << ": error: out of memory: a size that an option or an "
                << "input file chose is too large for this machine (see --help for the limits)"
                << std::endl;
      return 1;
    } catch (const std::exception& error) {
      std::cerr << "raycarve " << name << ": unexpected error: " << WithoutPrefix(error.what(), name)
                << std::endl;
      return 2;
    }
  }
  std::cerr << "raycarve: unknown command '" << command_name << "' (raycarve help lists them)"
            << std::endl;
  return 1;
}
