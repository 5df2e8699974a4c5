#pragma once

#include <cstdint>
#include <string>

#include "calib/bounds.h"
#include "calib/colour_calibration.h"
#include "calib/view_reader.h"
#include "carve/carver.h"
#include "export/carve_export.h"

namespace raycarve {

// The defaults of `raycarve carve` that differ from the libraries' own, each written once here;
// the command line's help and CarveRequest's constructor read them.

// --threshold auto's threshold where too few sparse points can be judged.
constexpr double kFallbackThreshold = kDefaultThreshold;
// --pattern_threshold auto's where too few textured sparse points can be judged.
constexpr double kFallbackPatternThreshold = 0.5;
// --max_image_size: 200 photos of 4:3 at 2400 pixels hold ~12 GB while carving
// (kBytesPerPhotoPixel), within a 24 GiB machine.
constexpr int kDefaultMaxImageSize = 2400;
// --free_space_margin (voxels short of the point where a sight line stops).
constexpr double kDefaultFreeSpaceMarginVoxels = 2.0;
// --spread_floor auto on an object capture without masks: the threshold is at least one
// within-view spread (CarveOptions::spread_floor). Measured:
// docs/studies/2026-12-06-spread-floor.md.
constexpr double kAutoSpreadFloor = 1.0;
// --floater_expected_points: a piece with no sparse point goes where three were expected (a
// Poisson count of mean 3 is 0 one time in 20).
constexpr double kDefaultFloaterExpectedPoints = 3.0;
// --min_component_voxels: specks smaller than this are carved.
constexpr int kDefaultMinComponentVoxels = 8;

// Options of the volume's bounds: from the sparse points (BoundsOptions) unless a box is given.
struct BoundsRequest {
  BoundsOptions options;
  std::string bbox;  // "min_x,min_y,min_z,max_x,max_y,max_z"; empty: from the sparse points
  // What the capture is, for the box: "object" (the box around the cameras' common focus,
  // CaptureLayout::focus_box), "scene" (every sparse point the filters keep), or "auto": object
  // when the cameras stand around a point and the photos have no masks (masks already bound an
  // object), else scene. With masks, unless "scene", the box is narrowed to the masks' visual
  // hull where the sparse points are (NarrowToMaskedHull).
  std::string capture = "auto";
};

// Everything the carve pipeline takes: where the project is, and each stage's options.
struct CarveRequest {
  // The command line's defaults: every core, automatic levels of detail, specks removed, the
  // threshold from the data, known surface kept, the sparse points' sight lines carved and
  // silhouettes repaired.
  CarveRequest();

  // Where: the workspace (or model and photos), the output folder.
  std::string workspace_path;
  std::string input_path;
  std::string image_path;
  std::string output_path;  // default <workspace>/raycarve
  int model_index = -1;     // sparse/<index> among several models; -1: the largest
  // When another run is writing into the output folder: wait for it (else refuse at once).
  bool wait_for_output = false;

  // Load views and masks.
  ViewReaderOptions view_options;
  // Per-photo gains and offsets from the sparse points: "auto", "1" or "0" (ColourCalibrationMode).
  std::string colour_calibration = "auto";
  std::string background = "auto";  // as given on the command line, for the report
  // Masks made from the backdrop are made to agree across the views (AgreeMasks) before the
  // carve; masks from files are the user's and are left as they are.
  bool agree_masks = true;

  // Bounds.
  BoundsRequest bounds;

  // Carve.
  CarveOptions options;
  // Without masks, when the sparse points show a supporting plane (a floor, a table top): what
  // lies under it, where its points are, is held solid (CarveOptions::ground): colour carving
  // through a plain or repeating floor would open it and show the photos the volume under it.
  bool hold_ground = true;
  // Smooth mesh: where the sparse points show a supporting plane, masked or not, the mesh
  // near it is levelled onto it where its points are (ModelMeshOptions::support).
  bool level_support = true;
  // Without masks: photo pixels whose pattern moves between the photos as something beyond the
  // volume would (sky, clouds, far hills; calib/distant_pixels.h) saw across the volume, and
  // their rays are carved before colouring (CarveOptions::distant_rays).
  bool distant_free_space = true;
  // Without masks, where the ground is held (hold_ground): photo pixels whose pattern moves
  // between the photos as the ground's plane does (carve/ground_pixels.h) saw the floor across
  // empty space, and their rays are carved before colouring down to the plane's tolerance (or
  // as far as the photos tell the ray from the plane, where that is less).
  bool ground_free_space = true;
  // options.spread_floor chosen for the capture (--spread_floor auto): with --threshold auto, an
  // object capture without masks (cameras around it) holds each voxel to at least
  // kAutoSpreadFloor times its within-view colour spread (CarvePipeline::DecideObjectRules).
  bool auto_spread_floor = true;
  // options.threshold_seen_views chosen for the capture (--threshold_views auto): on where the
  // spread floor applies (an object without masks, --threshold auto).
  bool auto_threshold_views = true;
  // A grid whose voxels span fewer pixels of the photos than this (median at the volume's
  // centre) is refused before the work: there the photos cannot tell a voxel from its
  // neighbours, rays pass between voxels that are never judged, and the carve degrades (the
  // paper scene at 0.93 px: F-score 88% against 94% at 1.85 px; at 0.46 px it collapses to 20%).
  // 0: never refused. A resolution the user did not give (the default) is instead lowered to
  // the one whose voxel spans a pixel, whenever its voxels would span less than one.
  double min_voxel_pixels = 0.5;
  bool resolution_given = true;  // false: options.resolution is the default, and may be lowered
  double progress_seconds = 2.0;  // between progress reports

  // Surface and colour. mesh.ply: "smooth" (welded, coloured from the photos) or "voxels" (the
  // voxel faces, each voxel's mean colour).
  std::string mesh_kind = "smooth";
  exporter::ModelMeshOptions mesh;
  uint64_t mesh_max_faces = 0;  // as given; copied into mesh.max_triangles
  // With the smooth mesh: cloud.ply keeps the surface that at least this many photos see. Two
  // photos always find a colour they agree on somewhere; a third is the first check of it.
  int cloud_min_views = 3;
};

// The request's --colour_calibration (checked by the parser: "auto", "1", "0", "true", "false").
ColourCalibrationMode ColourCalibrationModeOf(const CarveRequest& request);

// Derives the options that follow from others (the thread count of every stage, the mesh's
// smallest piece from the carve's, its face budget) and checks the whole request; throws
// InputError naming the option on a bad value.
void FinishCarveRequest(CarveRequest* request);

}  // namespace raycarve
