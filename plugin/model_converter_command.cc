// raycarve model_converter: a COLMAP model between BIN and TXT, as colmap model_converter.
#include <cstdio>
#include <string>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "calib/model_writer.h"
#include "pipeline/output_files.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"

namespace raycarve {

int RunModelConverter(int argc, char** argv) {
  std::string input_path, output_path, output_type = "BIN";
  OptionParser parser("model_converter",
                      "Reads a COLMAP model (binary or text) and writes it in the other form, "
                      "as `colmap model_converter` does.");
  parser.AddRequired("input_path", &input_path, "COLMAP model folder to read");
  parser.AddRequired("output_path", &output_path, "folder to write (created; must differ from input)");
  parser.AddDefault("output_type", &output_type, "format to write", {"BIN", "TXT"});
  if (!parser.Parse(argc, argv)) return 0;
  CheckOutputDoesNotOverwrite(output_path, input_path, "input model");
  const Reconstruction reconstruction = ReadModel(input_path);
  WriteModel(reconstruction, output_path, ModelFormatFromString(output_type));
  LOG(INFO) << "wrote " << reconstruction.cameras.size() << " cameras, "
            << reconstruction.images.size() << " images, " << reconstruction.points3D.size()
            << " points to " << output_path << " (" << output_type << ")";
  return 0;
}

}  // namespace raycarve
