#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "calib/reconstruction.h"

namespace raycarve {

// A deterministic synthetic scene with exact ground truth: a textured sphere and a striped box
// standing on a checkered ground square, under a patchwork sky, seen by cameras on a ring around
// and above it. Rendered by ray tracing (unlit textures with fixed, view-independent shading, so
// every surface point has one colour in every view), through any COLMAP 3.8 camera model, so the
// photos carry that model's distortion.
//
// World frame: z up, ground at z = 0, the scene inside [-1.5, 1.5]^2 x [0, 1.1]; units arbitrary.
// Which objects: the simple scene (a sphere and a striped box), the seed paper's scene (a
// textured Utah teapot, a sphere and a cube), both on the checkered ground square, or the simple
// scene amid clutter (kClutterBoxes: blocks of other textures standing around it, on the ground
// square's edge and beyond, some between the cameras and the objects).
enum class SceneKind { kSimple, kPaper, kClutter };
std::string SceneKindToString(SceneKind kind);
bool SceneKindFromString(const std::string& text, SceneKind* kind);

// What the photos show around the scene. The scene (objects and the checkered ground square) is
// the object in the exact masks; everything a backdrop adds is background.
enum class Backdrop {
  kPatchwork,  // a sky of many coloured patches: a natural scene, no backdrop to mask
  kUniform,    // one dark colour (kBackdropColour), as a studio backdrop
  kTwoTone,    // a blue wall and a paler table plane (z = 0 around the ground square), and a
               // 3-pixel near-black frame at the photo's edge
  kGradient,   // a studio sweep: the colour goes from dark slate below to pale grey above
  kVignetted,  // a uniform grey backdrop, the whole photo darkened towards its corners
  kShadowedTable,  // a pale table plane with a soft shadow of the objects on it, a pale wall
  kRoom,           // a room: a textured floor (z = 0) and a textured round wall (radius kRoomRadius,
                   // up to kRoomHeight) with sky above; it holds sparse points of its own, as a
                   // room behind an object does in a real capture (kRoomPointShare of them)
  kCloudy,         // outdoors: a blue sky, paler towards the horizon, with soft white clouds
                   // (both at infinity), over a field of grass and earth (the plane z = 0)
};
constexpr double kRoomRadius = 9.0;
constexpr double kRoomHeight = 5.0;
// The room's share of the sparse points tried (its floor and wall, uniform by area).
constexpr double kRoomPointShare = 0.5;
std::string BackdropToString(Backdrop backdrop);
bool BackdropFromString(const std::string& text, Backdrop* backdrop);
std::vector<std::string> BackdropNames();

// Where the cameras stand, all looking at the scene's centre from outside it.
enum class CameraLayout {
  kRing,        // around the scene, 27 degrees up on average (heights vary so not all share a plane)
  kHemisphere,  // over a dome from 12 to 72 degrees up, area-uniform, on a golden-angle spiral
  kArc,         // the ring's front 150 degrees only, as where a wall stops the photographer
  kClose,       // a ring at 0.6 of the distance: the ground square leaves the frames
  kForward,     // forward-facing: a grid 2 wide and 0.8 high, 5 in front, all looking at the scene
  kEyeLevel,    // the arc's 150 degrees at the objects' height (0.7 to 1.1 up): what stands
                // behind their tops from there is the sky, as for a statue photographed on foot
};
std::string CameraLayoutToString(CameraLayout layout);
bool CameraLayoutFromString(const std::string& text, CameraLayout* layout);
std::vector<std::string> CameraLayoutNames();

// The camera centres of `layout` for `num_views` cameras (world frame), in image order.
std::vector<Eigen::Vector3d> CameraCentres(CameraLayout layout, int num_views);

// Where the paper's scene reads the teapot's Bezier patches: teapot/teapot_bezier.txt in
// $RAYCARVE_DATA_DIR, else in the first ../shared/data found beside the working folder or beside
// a folder holding the program.
std::string DefaultTeapotPath();

struct SceneGeometry;

struct SyntheticSceneOptions {
  SceneKind scene = SceneKind::kSimple;
  std::string teapot_path;      // the paper's scene: empty for DefaultTeapotPath()
  int teapot_tessellation = 12;  // quads per patch side
  int num_views = 8;           // cameras
  CameraLayout layout = CameraLayout::kRing;
  int width = 320;             // photo width in pixels
  int height = 240;            // photo height in pixels
  uint64_t seed = 1;           // seeds the surface points' sampling and the pixel noise
  CameraModelId camera_model = CameraModelId::kPinhole;  // distortion from ExampleCameraParams
  std::vector<double> camera_params;  // overrides ExampleCameraParams when not empty
  int num_surface_samples = 3000;  // candidate sparse points before the visibility filter
  double pixel_noise = 0.0;        // std. dev. of Gaussian noise on the 2D observations (px)
  int supersampling = 2;           // rays per pixel along each axis when rendering
  // Behind the scene: a patchwork sky (empty space is photo-inconsistent) or one of the studio
  // backdrops (empty space is consistent unless masks are used).
  Backdrop backdrop = Backdrop::kPatchwork;
  // A non-repeating noise texture over every surface, on top of the checks and stripes, so that
  // structure-from-motion (SIFT matching) can tell places apart; off, the photos are plain.
  bool detail_texture = false;
  // Each photo's brightness scaled by a gain in [1 - exposure_spread, 1 + exposure_spread] that
  // differs from photo to photo (an automatic exposure); the points' colours stay the surfaces'.
  double exposure_spread = 0.0;
  // A white highlight of this strength (0-1 of full white) where the light mirrors into the
  // camera, so that the surfaces' colours change with the view, as glazed or varnished ones do;
  // the points' colours stay the surfaces' own. 0: every surface looks the same from everywhere.
  double specular = 0.0;

  bool IsValid(std::string* reason) const;
};

struct SyntheticScene {
  // Cameras, registered images with their observations, and true surface points each seen (not
  // occluded, inside the frame) by at least two views; observations are exact projections
  // (plus pixel_noise).
  Reconstruction reconstruction;
  std::map<image_t, cv::Mat> photos;  // CV_8UC3 RGB, as the camera model sees them
  std::map<image_t, cv::Mat> masks;   // CV_8UC1, 255 where most of a pixel's rays hit the scene
  Eigen::AlignedBox3d object_box;     // smallest box holding the ground square and the objects
  std::shared_ptr<const SceneGeometry> geometry;  // what the photos show
  Backdrop backdrop = Backdrop::kPatchwork;        // what the photos show around it
};

// The uniform backdrop's colour (RGB).
const Eigen::Vector3d kBackdropColour(12, 10, 14);

// Parameters of `model` for a camera of the given size and focal length: principal point near
// the image centre and a mild distortion typical of that model (none for pinhole models).
std::vector<double> ExampleCameraParams(CameraModelId model, int width, int height, double focal);

// Distance from a world point to the simple scene's true surface (sphere, box, ground square),
// exact. (The paper's and the clutter scene are measured against their truth.ply.)
double TrueSurfaceDistance(const Eigen::Vector3d& point);

// A dense sample of the true surface for measuring reconstructions: `count` candidate points
// uniform over the surface's area (fixed `seed`), of which those seen (inside the frame, not
// occluded) by at least `min_views` of the scene's cameras are kept, since no method can recover
// what the photos do not show.
std::vector<Eigen::Vector3d> SampleTrueSurface(const SyntheticScene& scene,
                                               int count,
                                               uint64_t seed,
                                               int min_views);

// The room's floor (outside the ground square) and wall (Backdrop::kRoom) sampled likewise: they
// are surfaces the photos show, which a scene's model keeps. Uniform over their area, at about a
// seventh of the truth's density on the scene (kRoomTruthSamples over about 537 square units
// against 200,000 over about 16), which is still far denser than a voxel at the thresholds used.
constexpr int kRoomTruthSamples = 1000000;
std::vector<Eigen::Vector3d> SampleRoomSurface(const SyntheticScene& scene,
                                               int count,
                                               uint64_t seed,
                                               int min_views);

// The objects of options.scene (the photos are not rendered).
std::shared_ptr<const SceneGeometry> MakeSceneGeometry(const SyntheticSceneOptions& options);

// Generates the scene; the same options always give the same scene, bit for bit.
SyntheticScene GenerateSyntheticScene(const SyntheticSceneOptions& options);

// Writes a COLMAP project into `path`: images/<name>.png, masks/<name>.png (COLMAP's naming:
// the photo's name plus .png), sparse/0/ (binary) and truth.ply (the ground truth:
// SampleTrueSurface with 200,000 candidates, seen by 2 views; with the room backdrop also
// SampleRoomSurface with kRoomTruthSamples). Throws InputError when a file
// cannot be written.
void WriteSyntheticProject(const SyntheticScene& scene, const std::string& path);

}  // namespace raycarve
