#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "calib/bounds.h"
#include "export/supporting_plane.h"
#include "calib/calibrated_view.h"
#include "calib/colour_calibration.h"
#include "calib/reconstruction.h"
#include "calib/view_reader.h"
#include "carve/surface_evidence.h"
#include "pipeline/carve_request.h"
#include "pipeline/workspace.h"

namespace raycarve {

// The pipeline's first stage: a COLMAP project's paths, model, bounds and calibrated views.
constexpr double kPlaneTolerance = 0.01;

struct LoadedProject {
  std::string model_path;
  std::string image_path;
  std::string output_path;
  Reconstruction reconstruction;
  Bounds bounds;
  CaptureLayout layout;  // how the cameras stand (DescribeCapture), after any hold-out
  // The plane the subject stands on, from the sparse points in the volume that three or more
  // photos saw (CheckedPoints; FitSupportingPlane, tolerance kPlaneTolerance of the volume's
  // largest extent). Without masks the carve holds the ground under it (DecideGround).
  exporter::SupportingPlane plane;
  std::vector<CalibratedView> views;
  ViewReaderSummary view_summary;
  ColourCalibration colour;  // estimated unless off (points_used 0 otherwise); see its `applied`
  // The reliable sparse points (SurfacePointsOf) with the indices of the views that saw them.
  std::vector<SurfacePoint> surface_points;
  // With hold_out_every: the names of the held-out images (their observations were removed from
  // the sparse points before anything used them).
  std::vector<std::string> held_out;
  // Per held-out name, the sparse points it saw that two or more other images keep.
  std::map<std::string, std::vector<Eigen::Vector3d>> held_out_points;
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

// Sparse points inside `box` that three or more photos saw (a third photo checks the match), or,
// where fewer than kMinCheckedPoints are, those that two or more saw. The supporting plane is fit
// to these.
constexpr int kCheckedTrack = 3;  // photos that make a point checked
constexpr int kMinCheckedPoints = 20;
std::vector<Eigen::Vector3d> CheckedPoints(const Reconstruction& reconstruction,
                                          const Eigen::AlignedBox3d& box);

// Holds out every `every`-th image in name order (the first, then every k-th after it): their
// observations leave the sparse points' tracks, and points left with fewer than two go. Returns
// the held-out names, in name order. `seen_points` (when given) gets, per held-out name, the
// points that image saw which two or more other images keep (triangulated without it).
std::vector<std::string> HoldOutImages(
    int every, Reconstruction* reconstruction,
    std::map<std::string, std::vector<Eigen::Vector3d>>* seen_points = nullptr);

// The box "min_x,min_y,min_z,max_x,max_y,max_z" of `text`; throws InputError naming `flag`
// when it is not six numbers or not a box (ExplicitBounds).
Bounds ParseBoxText(const std::string& text, const std::string& flag);

// The explicit box when request.bbox is given, else ComputeBounds; throws InputError on bad
// options. `source` names the model in messages.
Bounds ResolveBounds(const Reconstruction& reconstruction,
                     const BoundsRequest& request,
                     const std::string& source);

// What LoadProject reads, and how.
struct ProjectRequest {
  std::string command;  // for messages: "raycarve <command>: ..."
  std::string workspace_path;
  std::string input_path;
  std::string image_path;
  std::string output_path;  // default <workspace>/raycarve
  BoundsRequest bounds;
  ViewReaderOptions view_options;
  int min_images = 2;
  int model_index = -1;
  ColourCalibrationMode colour_calibration = ColourCalibrationMode::kOff;
  int hold_out_every = 0;  // > 0: HoldOutImages before anything reads the sparse points
  // The carve's --resolution, for a scene's box (ChooseCaptureBox); 0: not narrowed in depth.
  int resolution = 0;
  // The workspace when already resolved (CarvePipeline::LockOutputs); else ResolveWorkspace.
  std::optional<WorkspacePaths> paths;
};
// The ProjectRequest of a carve request, for `command`.
ProjectRequest ProjectRequestOf(const CarveRequest& request, const std::string& command);

// The project's model and photo folders (ResolveWorkspace) and in *output_path its output folder
// (default <workspace>/raycarve); throws InputError when the output is the model or photo folder.
WorkspacePaths ResolveProjectPaths(const ProjectRequest& request, std::string* output_path);

// Resolves the workspace (see workspace.h) and the output folder (default <workspace>/raycarve,
// refused when it is the model or photo folder), reads the model (it must have at least
// `min_images` registered images), bounds it and loads its views, logging each stage. With
// `hold_out_every` > 0, HoldOutImages runs first, so that neither the bounds, the colour
// calibration nor the surface points see the held-out views (which are still loaded). Throws
// InputError naming the command or the file on bad input.
LoadedProject LoadProject(const ProjectRequest& request);

// Masks are decided for the capture, not per photo: automatic backdrop masks found in fewer
// than half of the photos (a beige forest floor in one photo of an unmasked capture, sky and
// ground in some photos of a facade) are not the capture's backdrop. The number of such masks
// to drop (0 when there are mask files, masks from a given colour, or the backdrop holds in half
// of the photos or more).
int MinorityBackdropMasks(const ViewReaderSummary& summary);
// Whether the capture is carved with masks once MinorityBackdropMasks are dropped.
bool CaptureIsMasked(const ViewReaderSummary& summary);

// Masked captures: the box narrowed to the masks' visual hull (VisualHullBox on a grid of
// kHullBoxResolution, a voxel carved where kHullBoxBackgroundViews views show it on background,
// as AgreeMasks does), marked Bounds::around_hull. The sparse points of the surroundings (a
// field, a floor, a wall, which the masks call background) otherwise widen the box and coarsen
// the object's voxels. Narrowed only where the hull's box is at most kHullBoxMaxSide of the
// box's longest side (its voxels a third finer or more): a box the points already fit to the
// object is kept as it is.
constexpr int kHullBoxResolution = 96;
constexpr double kHullBoxMaxSide = 0.75;
constexpr int kHullBoxBackgroundViews = 2;
void NarrowToMaskedHull(LoadedProject* project);

// The capture's box (BoundsRequest::capture): for an object, the computed box narrowed to the
// one around the cameras' focus (CaptureLayout::focus_box), marked Bounds::around_focus; for a
// scene found by --capture auto without masks, narrowed to the sparse points its photos place in
// depth to two voxels at `resolution` (ResolveSceneDepth; 0: not). An explicit box, --capture
// scene, or too few points there leave it as it is.
void ChooseCaptureBox(const BoundsRequest& request, int resolution, LoadedProject* project);

// Memory held per photo pixel while carving (the photo, its undistorted view, validity and mask,
// rays and their statistics): 13.6 bytes measured as the peak resident memory of carving 100
// photos of 2400x1800 at 128 voxels (scripts/run_large_project.sh), and the share of the
// machine's memory the photos may take.
constexpr double kBytesPerPhotoPixel = 14.0;
constexpr double kUsableMemoryShare = 0.75;
// This machine's memory in bytes (0 when unknown).
double PhysicalMemoryBytes();

// Refuses, before it is allocated, work that needs about `bytes` when that is more than
// kUsableMemoryShare of this machine's memory: InputError "<what> needs about X GiB (<how>), more
// than 75% of this machine's Y GiB: <remedy>". Unknown memory: accepted.
void CheckFitsInMemory(double bytes, const std::string& what, const std::string& how,
                       const std::string& remedy);

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
                     const BoundsRequest& bounds);

}  // namespace raycarve
