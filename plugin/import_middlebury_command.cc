// raycarve import_middlebury: a Middlebury *_par.txt calibration as a COLMAP model.
#include <cstdio>
#include <string>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "calib/middlebury.h"
#include "calib/model_writer.h"
#include "pipeline/output_files.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"

namespace raycarve {

int RunImportMiddlebury(int argc, char** argv) {
  std::string input_path, image_path, output_path, output_type = "TXT";
  MiddleburyImportOptions options;
  OptionParser parser("import_middlebury",
                      "Converts a Middlebury multi-view calibration file (*_par.txt) into a "
                      "COLMAP model (PINHOLE cameras, no 3D points).");
  parser.AddRequired("input_path", &input_path, "the *_par.txt calibration file");
  parser.AddRequired("image_path", &image_path, "folder of the photos (their sizes are read)");
  parser.AddRequired("output_path", &output_path, "model folder to write (created)");
  parser.AddDefault("output_type", &output_type, "format to write", {"BIN", "TXT"});
  parser.AddDefault("principal_point_offset", &options.principal_point_offset,
                    "added to (k13, k23): 0.5 reads K with pixel centres at integers, 0 copies it");
  if (!parser.Parse(argc, argv)) return 0;
  std::string reason;
  if (!options.IsValid(&reason)) throw InputError("--principal_point_offset: " + reason);
  CheckOutputDoesNotOverwrite(output_path, image_path, "photo folder");
  const Reconstruction reconstruction = ImportMiddlebury(input_path, image_path, options);
  WriteModel(reconstruction, output_path, ModelFormatFromString(output_type));
  LOG(INFO) << "imported " << reconstruction.images.size() << " images ("
            << reconstruction.cameras.size() << " cameras) from " << input_path << " into "
            << output_path;
  return 0;
}

}  // namespace raycarve
