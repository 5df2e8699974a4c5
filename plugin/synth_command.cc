#include <iostream>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "calib/view_reader.h"
#include "pipeline/project.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "samples/synthetic_scene.h"

namespace raycarve {

namespace {

// The options given as names, before they are turned into the scene's.
struct SynthFlagText {
  std::string camera_model = "PINHOLE";
  std::string layout = "ring";
  std::string scene = "simple";
  std::string backdrop = "patchwork";
  std::string texture = "plain";
};

void AddSynthFlags(OptionParser* parser, std::string* output_path, SyntheticSceneOptions* options,
                   SynthFlagText* text) {
  parser->AddRequired("output_path", output_path, "project folder to write (created)");
  parser->AddDefault("views", &options->num_views, "number of cameras");
  parser->AddDefault("layout", &text->layout,
                     "where the cameras stand: a ring around the scene, a hemisphere (12 to 72 "
                     "degrees up), an arc (the ring's front 150 degrees), close (a ring at 0.6 "
                     "of the distance, the ground leaving the frames), forward (forward-facing: "
                     "a grid of positions on one side, as in front of a facade), or eye_level "
                     "(the arc at the objects' height, the sky behind their tops)",
                     CameraLayoutNames());
  parser->AddDefault("width", &options->width, "photo width in pixels");
  parser->AddDefault("height", &options->height, "photo height in pixels");
  parser->AddDefault("seed", &options->seed, "random seed of the sparse points and noise");
  parser->AddDefault("points", &options->num_surface_samples,
                     "surface samples tried as sparse points (kept when seen by >= 2 views)");
  parser->AddDefault("pixel_noise", &options->pixel_noise,
                     "std. dev. of noise on the 2D observations (px)");
  parser->AddDefault("scene", &text->scene,
                     "simple (sphere and box), paper (teapot, sphere and cube; reads the "
                     "teapot's patches from --teapot_path) or clutter (the simple scene amid "
                     "five blocks of other textures, some between the cameras and the objects)",
                     {"simple", "paper", "clutter"});
  parser->AddDefault("teapot_path", &options->teapot_path,
                     "the Utah teapot's Bezier patches (default: $RAYCARVE_DATA_DIR or "
                     "../shared/data, then teapot/teapot_bezier.txt)");
  parser->AddDefault("backdrop", &text->backdrop,
                     "behind the scene: a patchwork sky (a natural scene), or a studio backdrop "
                     "that needs masks: uniform (dark), two_tone (wall and table, with a dark "
                     "frame), gradient, vignetted, shadowed_table; a textured room (floor and "
                     "wall) holding sparse points of its own; or outdoors: a cloudy sky over a "
                     "field",
                     BackdropNames());
  parser->AddDefault("texture", &text->texture,
                     "the surfaces' texture: plain checks and stripes, or with a non-repeating "
                     "noise added (detailed) so that COLMAP's structure-from-motion can match the "
                     "photos",
                     {"plain", "detailed"});
  parser->AddDefault("exposure_spread", &options->exposure_spread,
                     "each photo brighter or darker by a gain within 1 +- this, differing from "
                     "photo to photo, as an automatic exposure makes them (0: all alike)");
  parser->AddDefault("specular", &options->specular,
                     "a white highlight of this strength (0-1) where the light mirrors into the "
                     "camera: colours that change with the view, as on a glazed surface (0: none)");
  std::vector<std::string> models;
  for (CameraModelId model : SupportedCameraModels()) models.push_back(CameraModelName(model));
  parser->AddDefault("camera_model", &text->camera_model,
                     "camera model of the photos (with a typical distortion)", models);
}

}  // namespace

int RunSynth(int argc, char** argv) {
  std::string output_path;
  SyntheticSceneOptions options;
  OptionParser parser("synth",
                      "Generates a synthetic COLMAP project with ground truth: a textured sphere "
                      "and box (--scene simple) or the seed paper's textured teapot, sphere and "
                      "cube (--scene paper) on a checkered ground, ray traced from cameras around "
                      "it (images/, masks/, sparse/0, truth.ply).");
  SynthFlagText text;
  AddSynthFlags(&parser, &output_path, &options, &text);
  if (!parser.Parse(argc, argv)) return 0;
  options.camera_model = CameraModelIdFromName(text.camera_model, "--camera_model");
  BackdropFromString(text.backdrop, &options.backdrop);
  CameraLayoutFromString(text.layout, &options.layout);
  options.detail_texture = text.texture == "detailed";
  SceneKindFromString(text.scene, &options.scene);
  std::string reason;
  if (!options.IsValid(&reason)) throw InputError("raycarve synth: " + reason);
  // Measured peak memory: about 4 bytes a photo pixel (photo and mask) and 36 bytes a sparse
  // point's observation (its track and the image's point), counted here with room to spare.
  const double pixels = static_cast<double>(options.num_views) * options.width * options.height;
  const double observations = static_cast<double>(options.num_surface_samples) * options.num_views;
  CheckFitsInMemory(8.0 * pixels + 48.0 * observations, "this scene",
                    "8 bytes a photo pixel, 48 bytes a point in each view",
                    "give fewer --views, --points or smaller --width and --height");

  LOG(INFO) << "rendering " << options.num_views << " views of " << options.width << "x"
            << options.height << " (" << text.camera_model << ")";
  const SyntheticScene scene = GenerateSyntheticScene(options);
  WriteSyntheticProject(scene, output_path);
  std::cout << "synth: wrote " << scene.photos.size() << " photos and a model with "
            << scene.reconstruction.points3D.size() << " points to " << output_path
            << " (images/, sparse/0)\n";
  return 0;
}

}  // namespace raycarve
