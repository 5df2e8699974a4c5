#pragma once

#include <filesystem>
#include <string>

#include <memory>
#include <utility>
#include <vector>

#include "calib/bounds.h"
#include "calib/calibrated_view.h"
#include "calib/colour_calibration.h"
#include "calib/reconstruction.h"
#include "calib/view_reader.h"
#include "carve/carver.h"
#include "carve/mask_agreement.h"
#include "export/carve_export.h"
#include "export/point_cloud_compare.h"
#include "plugin/option_parser.h"

namespace raycarve {

// Subcommands of the `raycarve` program. Each parses its options and calls a typed function
// that tests call too; bad input throws InputError, which main() prints as one line before
// exiting non-zero.
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

// Options shared by every command that bounds the volume.
struct BoundsFlags {
  BoundsOptions options;
  std::string bbox;  // "min_x,min_y,min_z,max_x,max_y,max_z"; empty: from the sparse points
};
void AddBoundsFlags(OptionParser* parser, BoundsFlags* flags);
// The explicit box when --bbox was given, else ComputeBounds; throws InputError on bad flags.
Bounds ResolveBounds(const Reconstruction& reconstruction,
                     const BoundsFlags& flags,
                     const std::string& source);

// model_info: a text and a JSON description of a model and the bounds it would carve.
std::string DescribeModelText(const Reconstruction& reconstruction,
                              const std::string& model_path,
                              const Bounds& bounds);
std::string DescribeModelJson(const Reconstruction& reconstruction,
                              const std::string& model_path,
                              const Bounds& bounds);

// What calibrate and carve start from: the project's paths, model, bounds and calibrated views.
struct LoadedProject {
  std::string model_path;
  std::string image_path;
  std::string output_path;
  Reconstruction reconstruction;
  Bounds bounds;
  std::vector<CalibratedView> views;
  ViewReaderSummary view_summary;
  ColourCalibration colour;  // estimated unless off (points_used 0 otherwise); see its `applied`
  // The reliable sparse points (SurfacePointsOf) with the indices of the views that saw them.
  std::vector<SurfacePoint> surface_points;
  // With hold_out_every: the names of the held-out images (their observations were removed from
  // the sparse points before anything used them).
  std::vector<std::string> held_out;
};

// Reliable sparse points as surface evidence for carving: points inside `box` seen by at least
// kMinSurfaceTrack of `views` with a mean reprojection error of at most kMaxSurfaceError pixels.
// (Measured on the Middlebury sets' held-out views at 128 voxels: tracks of 2 or more gave +1.58
// dB over silhouettes only on average, 3 or more +1.40; the generated scenes gained too.)
constexpr int kMinSurfaceTrack = 2;
constexpr double kMaxSurfaceError = 1.0;
std::vector<SurfacePoint> SurfacePointsOf(const Reconstruction& reconstruction,
                                          const std::vector<CalibratedView>& views,
                                          const Eigen::AlignedBox3d& box);

// Holds out every `every`-th image in name order (the first, then every k-th after it): their
// observations leave the sparse points' tracks, and points left with fewer than two go. Returns
// the held-out names, in name order.
std::vector<std::string> HoldOutImages(int every, Reconstruction* reconstruction);

// Resolves the workspace (see workspace.h) and the output folder (default <workspace>/raycarve,
// refused when it is the model or photo folder), reads the model (it must have at least
// `min_images` registered images), bounds it and loads its views, logging each stage. With
// `hold_out_every` > 0, HoldOutImages runs first, so that neither the bounds, the colour
// calibration nor the surface points see the held-out views (which are still loaded). Throws
// InputError naming `command` or the file on bad input.
LoadedProject LoadProject(const std::string& command,
                          const std::string& workspace_path,
                          const std::string& input_path,
                          const std::string& image_path,
                          const std::string& output_path,
                          const BoundsFlags& bounds_flags,
                          const ViewReaderOptions& view_options,
                          int min_images,
                          int model_index = -1,
                          ColourCalibrationMode colour_calibration = ColourCalibrationMode::kOff,
                          int hold_out_every = 0);

// sfm --colmap_options: "Section.name=value,..." split into the arguments of the COLMAP step
// that takes each section. Throws InputError on a malformed item or an unknown section.
struct ColmapPassThrough {
  std::vector<std::string> extractor, matcher, mapper;
};
ColmapPassThrough SplitColmapOptions(const std::string& text);

// Memory held per photo pixel while carving (the photo, its undistorted view, validity and mask,
// rays and their statistics): 13.6 bytes measured as the peak resident memory of carving 100
// photos of 2400x1800 at 128 voxels (scripts/run_large_project.sh), and the share of the
// machine's memory the photos may take.
constexpr double kBytesPerPhotoPixel = 14.0;
constexpr double kUsableMemoryShare = 0.75;
// Refuses, before any photo is read, a project whose photos (reduced to `max_image_size`) would
// need more than kUsableMemoryShare of `physical_bytes` (0: this machine's memory): the
// message gives the estimate and a --max_image_size that fits.
void CheckPhotosFitInMemory(const Reconstruction& reconstruction, int max_image_size,
                            double physical_bytes = 0.0);

// Throws InputError when no part of the project's volume is seen by `min_views` of `views`
// (a --bbox in another frame or unit, bounds from points far from every camera's view): the
// message names the box, how much of it each photo sees and, for a --bbox, the sparse points'
// own box.
void CheckVolumeSeen(const std::string& command,
                     const LoadedProject& project,
                     const std::vector<CalibratedView>& views,
                     int min_views,
                     const BoundsFlags& bounds_flags);

// carve: everything `raycarve carve` takes, and what it produced.
// --threshold auto's threshold where too few sparse points can be judged.
constexpr double kFallbackThreshold = 30.0;
// --pattern_threshold auto's where too few textured sparse points can be judged.
constexpr double kFallbackPatternThreshold = 0.5;

// carve's --max_image_size default: 200 photos of 4:3 at 2400 pixels hold ~12 GB while carving
// (kBytesPerPhotoPixel), within a 24 GiB machine.
constexpr int kDefaultMaxImageSize = 2400;

// carve's --free_space_margin default (voxels short of the point where a sight line stops).
constexpr double kDefaultFreeSpaceMarginVoxels = 2.0;
// carve's --floater_expected_points default: a piece with no sparse point goes where three were
// expected (a Poisson count of mean 3 is 0 one time in 20).
constexpr double kDefaultFloaterExpectedPoints = 3.0;

struct CarveRequest {
  // The command line uses every core, automatic levels of detail, removes specks, takes the
  // threshold from the data, keeps known surface, carves the sparse points' sight lines and
  // repairs what the masks say by default.
  CarveRequest() {
    view_options.max_image_size = kDefaultMaxImageSize;
    options.num_threads = -1;
    options.lod_levels = kAutomaticLevels;
    options.min_component_voxels = 8;
    options.auto_threshold = true;
    options.protect_surface_points = true;
    options.free_space_margin_voxels = kDefaultFreeSpaceMarginVoxels;
    options.unsupported_component_points = kDefaultFloaterExpectedPoints;
    options.repair_silhouettes = true;
  }
  std::string workspace_path;
  std::string input_path;
  std::string image_path;
  std::string output_path;  // default <workspace>/raycarve
  CarveOptions options;
  BoundsFlags bounds;
  ViewReaderOptions view_options;
  int model_index = -1;              // sparse/<index> among several models; -1: the largest
  // Per-photo gains and offsets from the sparse points: "auto", "1" or "0" (ColourCalibrationMode).
  std::string colour_calibration = "auto";
  std::string background = "auto";  // as given on the command line, for the report
  double progress_seconds = 2.0;     // between progress lines
  // mesh.ply: "smooth" (welded, coloured from the photos) or "voxels" (the voxel faces, each
  // voxel's mean colour).
  std::string mesh_kind = "smooth";
  exporter::ModelMeshOptions mesh;
  uint64_t mesh_max_faces = 0;  // as given; copied into mesh.max_triangles
  // With the smooth mesh: cloud.ply keeps the surface that at least this many photos see. Two
  // photos always find a colour they agree on somewhere; a third is the first check of it.
  int cloud_min_views = 3;
  // Masks made from the backdrop are made to agree across the views (AgreeMasks) before the
  // carve; masks from files are the user's and are left as they are.
  bool agree_masks = true;
};

// The request's --colour_calibration (checked by the parser: "auto", "1", "0", "true", "false").
inline ColourCalibrationMode ColourCalibrationModeOf(const CarveRequest& request) {
  ColourCalibrationMode mode = ColourCalibrationMode::kAuto;
  ColourCalibrationModeFromString(request.colour_calibration, &mode);
  return mode;
}

// AgreeMasks over `views` when `request` asks for it and their masks came from the backdrop;
// logs its summary. Returns what it changed (views 0 when it did not run).
MaskAgreementStatistics AgreeBackdropMasks(const CarveRequest& request,
                                           const ViewReaderSummary& summary,
                                           const Eigen::AlignedBox3d& box,
                                           std::vector<CalibratedView>* views);

struct CarveRun {
  std::string model_path;
  std::string image_path;
  std::string output_path;
  Bounds bounds;
  int num_views = 0;
  int num_missing_images = 0;
  int masks_from_files = 0;
  int masks_from_backdrop = 0;
  std::vector<PhotoMaskInfo> mask_photos;  // per view: where its mask came from, what was found
  MaskAgreementStatistics mask_agreement;
  std::vector<std::string> view_names;
  ColourCalibration colour;
  std::unique_ptr<CarveResult> result;
  std::vector<std::pair<std::string, double>> stage_seconds;
  size_t num_cloud_points = 0;
  size_t num_mesh_triangles = 0;
  size_t num_mesh_vertices = 0;
  exporter::MeshTopology mesh_topology;
  exporter::MeshColouringSummary mesh_colouring;  // the smooth mesh's (vertices 0 otherwise)
  exporter::MeshRefinementSummary mesh_refinement;
  exporter::MeshPartsSummary mesh_parts;
  exporter::SilhouetteFitSummary mesh_silhouettes;
  double mesh_final_smoothing_mean_move = 0.0;  // world units
  int64_t mesh_small_components_removed = 0;
  int64_t mesh_grid_wall_vertices = 0;  // on the grid's wall: left out of the cloud
  // The output folder as a COLMAP dense workspace: fused.ply and fused.ply.vis (links to
  // cloud.ply and cloud.ply.vis) and the sparse model in sparse/. Empty when sparse/ was written;
  // otherwise why it was not (an input there, or a folder raycarve did not write).
  std::string dense_sparse_skipped;
  // The model's sparse points inside the grid against the cloud (accuracy: their 90% distance).
  bool has_sparse = false;
  exporter::CloudComparison sparse;
};

// The carve flags shared by `carve` and `holdout`: AddCarveFlags declares them (the enum-valued
// ones as text), ApplyCarveFlags converts and checks them (InputError on bad values).
struct CarveFlagText {
  std::string threshold = "auto";
  std::string pattern_threshold = "auto";
  std::string consistency;
  std::string vis_lookup;
  std::string method;
  std::string order;
  std::string decision;
  std::string background = "auto";
};
void AddCarveFlags(OptionParser* parser, CarveRequest* request, CarveFlagText* text);
void ApplyCarveFlags(const CarveFlagText& text, CarveRequest* request);

// Reads the project, carves, and writes cloud.ply, mesh.ply, report.json and convergence.csv
// into the output folder. Throws InputError on bad input or options.
CarveRun CarveProject(const CarveRequest& request);
std::string CarveReportJson(const CarveRequest& request, const CarveRun& run);

// Throws InputError when `output_path` is `input_path` (after resolving links and dots): the
// writers would replace the input's files.
void CheckOutputDoesNotOverwrite(const std::string& output_path,
                                 const std::string& input_path,
                                 const std::string& what);
// Throws InputError when the output file or folder `output_file` is `input_path` or lies inside
// it (a folder), after resolving links, dots and trailing slashes.
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
