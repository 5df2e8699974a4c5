#include "samples/synthetic_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <limits>
#include <random>

#include <glog/logging.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/atomic_file.h"
#include "calib/input_error.h"
#include "calib/model_writer.h"
#include "calib/pixel.h"
#include "samples/scene_tracing.h"
#include "samples/triangle_mesh.h"
#include "export/point_cloud_io.h"

namespace raycarve {

using scene_tracing::Hit;
using scene_tracing::kCameraTarget;
using scene_tracing::kGroundHalfSize;
using scene_tracing::LookAt;
using scene_tracing::Render;
using scene_tracing::RoomColour;
using scene_tracing::SampleSurface;
using scene_tracing::SeenBy;
using scene_tracing::SurfaceColour;
using scene_tracing::Trace;

bool SyntheticSceneOptions::IsValid(std::string* reason) const {
  if (num_views < 2) {
    *reason = "num_views must be at least 2";
    return false;
  }
  if (width < 16 || height < 16 || width > 8192 || height > 8192) {
    *reason = "width and height must be in [16, 8192]";
    return false;
  }
  if (num_surface_samples < 0) {
    *reason = "num_surface_samples must be >= 0";
    return false;
  }
  if (!(pixel_noise >= 0.0)) {
    *reason = "pixel_noise must be >= 0";
    return false;
  }
  if (!camera_params.empty() &&
      static_cast<int>(camera_params.size()) != CameraModelNumParams(camera_model)) {
    *reason = "camera_params must hold " + std::to_string(CameraModelNumParams(camera_model)) +
              " values for " + CameraModelName(camera_model) + " (" +
              CameraModelParamsInfo(camera_model) + ")";
    return false;
  }
  if (teapot_tessellation < 1 || teapot_tessellation > 64) {
    *reason = "teapot_tessellation must be in [1, 64]";
    return false;
  }
  if (!(specular >= 0.0 && specular <= 1.0)) {
    *reason = "specular must be in [0, 1]";
    return false;
  }
  if (!(exposure_spread >= 0.0 && exposure_spread < 1.0)) {
    *reason = "exposure_spread must be in [0, 1)";
    return false;
  }
  if (supersampling < 1 || supersampling > 8) {
    *reason = "supersampling must be in [1, 8]";
    return false;
  }
  return true;
}

std::vector<double> ExampleCameraParams(CameraModelId model, int width, int height, double focal) {
  const double cx = 0.5 * width + 1.25;
  const double cy = 0.5 * height - 0.75;
  const double fy = focal * 1.01;
  switch (model) {
    case CameraModelId::kSimplePinhole:
      return {focal, cx, cy};
    case CameraModelId::kPinhole:
      return {focal, fy, cx, cy};
    case CameraModelId::kSimpleRadial:
      return {focal, cx, cy, -0.08};
    case CameraModelId::kRadial:
      return {focal, cx, cy, -0.1, 0.03};
    case CameraModelId::kOpenCv:
      return {focal, fy, cx, cy, -0.12, 0.04, 0.002, -0.001};
    case CameraModelId::kOpenCvFisheye:
      return {focal, fy, cx, cy, 0.05, -0.02, 0.01, -0.003};
    case CameraModelId::kFullOpenCv:
      return {focal, fy, cx, cy, -0.1, 0.02, 0.001, -0.002, 0.003, 0.05, 0.01, 0.002};
    case CameraModelId::kFov:
      return {focal, fy, cx, cy, 0.6};
    case CameraModelId::kSimpleRadialFisheye:
      return {focal, cx, cy, 0.06};
    case CameraModelId::kRadialFisheye:
      return {focal, cx, cy, 0.05, -0.01};
    case CameraModelId::kThinPrismFisheye:
      return {focal, fy, cx, cy, 0.04, -0.01, 0.001, -0.002, 0.003, -0.001, 0.002, -0.001};
  }
  LOG(FATAL) << "unhandled camera model";
  return {};
}

std::string SceneKindToString(SceneKind kind) {
  switch (kind) {
    case SceneKind::kSimple:
      return "simple";
    case SceneKind::kPaper:
      return "paper";
    case SceneKind::kClutter:
      return "clutter";
  }
  return "simple";
}

bool SceneKindFromString(const std::string& text, SceneKind* kind) {
  for (SceneKind candidate : {SceneKind::kSimple, SceneKind::kPaper, SceneKind::kClutter}) {
    if (text == SceneKindToString(candidate)) {
      *kind = candidate;
      return true;
    }
  }
  return false;
}

namespace {

// The enumerator whose position in `names` is that of `text`; false when it is none of them.
template <typename Enum>
bool EnumFromName(const std::vector<std::string>& names, const std::string& text, Enum* value) {
  const auto found = std::find(names.begin(), names.end(), text);
  if (found == names.end()) return false;
  *value = static_cast<Enum>(found - names.begin());
  return true;
}

}  // namespace

std::vector<std::string> CameraLayoutNames() {
  return {"ring", "hemisphere", "arc", "close", "forward", "eye_level"};
}

std::string CameraLayoutToString(CameraLayout layout) {
  return CameraLayoutNames()[static_cast<int>(layout)];
}

bool CameraLayoutFromString(const std::string& text, CameraLayout* layout) {
  return EnumFromName(CameraLayoutNames(), text, layout);
}

std::vector<Eigen::Vector3d> CameraCentres(CameraLayout layout, int num_views) {
  std::vector<Eigen::Vector3d> centres;
  const double ring_radius = 5.0;
  for (int i = 0; i < num_views; ++i) {
    double angle = 2.0 * M_PI * i / num_views + 0.3;
    switch (layout) {
      case CameraLayout::kRing:
      case CameraLayout::kClose: {
        const double scale = layout == CameraLayout::kClose ? 0.6 : 1.0;
        const double height = 2.6 + 0.6 * std::sin(3.0 * angle);  // not all on one plane
        centres.push_back(kCameraTarget + scale * (Eigen::Vector3d(ring_radius * std::cos(angle),
                                                                   ring_radius * std::sin(angle),
                                                                   height) -
                                                   kCameraTarget));
        break;
      }
      case CameraLayout::kArc:
      case CameraLayout::kEyeLevel: {
        angle = 0.3 + (num_views == 1 ? 0.0 : (150.0 / 180.0 * M_PI) * i / (num_views - 1));
        const double height = layout == CameraLayout::kArc ? 2.6 + 0.6 * std::sin(3.0 * angle)
                                                           : 0.9 + 0.2 * std::sin(3.0 * angle);
        centres.emplace_back(ring_radius * std::cos(angle), ring_radius * std::sin(angle),
                             height);
        break;
      }
      case CameraLayout::kForward: {
        // Rows of four (the last may be shorter) on a plane facing the scene from the side the
        // ring starts at, as a photographer steps sideways and up in front of a facade.
        const int column = i % 4, row = i / 4, rows = (num_views + 3) / 4;
        const Eigen::Vector3d front(std::cos(0.3), std::sin(0.3), 0.0);
        const Eigen::Vector3d side(-front.y(), front.x(), 0.0);
        centres.push_back(kCameraTarget + ring_radius * front + (column - 1.5) / 1.5 * side +
                          Eigen::Vector3d(0.0, 0.0, 1.2 + (rows > 1 ? 0.8 * row / (rows - 1) : 0.0)));
        break;
      }
      case CameraLayout::kHemisphere: {
        // Equal steps of sin(elevation) between 12 and 72 degrees: equal areas of the dome.
        const double low = std::sin(12.0 / 180.0 * M_PI), high = std::sin(72.0 / 180.0 * M_PI);
        const double elevation = std::asin(low + (high - low) * (i + 0.5) / num_views);
        const double azimuth = 0.3 + i * M_PI * (3.0 - std::sqrt(5.0));  // the golden angle
        const double distance = 5.6;
        centres.push_back(kCameraTarget +
                          distance * Eigen::Vector3d(std::cos(elevation) * std::cos(azimuth),
                                                     std::cos(elevation) * std::sin(azimuth),
                                                     std::sin(elevation)));
        break;
      }
    }
  }
  return centres;
}

std::vector<std::string> BackdropNames() {
  return {"patchwork", "uniform", "two_tone", "gradient", "vignetted", "shadowed_table", "room",
          "cloudy"};
}

std::string BackdropToString(Backdrop backdrop) {
  return BackdropNames()[static_cast<int>(backdrop)];
}

bool BackdropFromString(const std::string& text, Backdrop* backdrop) {
  return EnumFromName(BackdropNames(), text, backdrop);
}

std::string DefaultTeapotPath() {
  const std::string relative = "teapot/teapot_bezier.txt";
  const char* data = std::getenv("RAYCARVE_DATA_DIR");
  if (data != nullptr && *data != '\0') return std::string(data) + "/" + relative;
  // ../shared/data beside the working folder, or beside the source tree the program was built
  // in (build/plugin/raycarve: three folders up).
  std::vector<std::filesystem::path> candidates = {std::filesystem::path("../shared/data")};
  std::error_code error;
  const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    for (std::filesystem::path folder = program.parent_path(); folder.has_relative_path();
         folder = folder.parent_path()) {
      candidates.push_back(folder / "../shared/data");
    }
  }
  for (const std::filesystem::path& candidate : candidates) {
    if (std::filesystem::exists(candidate / relative, error)) {
      return (candidate / relative).lexically_normal().string();
    }
  }
  return (candidates.front() / relative).string();
}

std::shared_ptr<const SceneGeometry> MakeSceneGeometry(const SyntheticSceneOptions& options) {
  auto geometry = std::make_shared<SceneGeometry>();
  if (options.scene == SceneKind::kSimple) return geometry;
  if (options.scene == SceneKind::kClutter) {
    geometry->clutter = scene_tracing::ClutterBoxes();
    for (const Eigen::AlignedBox3d& block : geometry->clutter) {
      geometry->top = std::max(geometry->top, block.max().z());
    }
    return geometry;
  }
  // The seed paper's scene: a textured teapot, a sphere and a cube on the checkered ground.
  geometry->sphere_centre = Eigen::Vector3d(-0.75, 0.65, 0.35);
  geometry->sphere_radius = 0.35;
  geometry->box_min = Eigen::Vector3d(0.55, 0.55, 0.0);
  geometry->box_max = Eigen::Vector3d(1.15, 1.15, 0.6);
  const std::string path = options.teapot_path.empty() ? DefaultTeapotPath() : options.teapot_path;
  if (!std::filesystem::exists(path)) {
    throw InputError(path + ": the teapot's Bezier patches are not there; give --teapot_path or "
                            "set RAYCARVE_DATA_DIR to the shared data folder");
  }
  geometry->teapot = std::make_unique<TriangleMesh>(ReadBezierTeapot(
      path, options.teapot_tessellation, 0.3, Eigen::Vector3d(0.25, -0.35, 0.0)));
  double total = 0.0;
  for (int t = 0; t < geometry->teapot->num_triangles(); ++t) {
    total += geometry->teapot->Area(t);
    geometry->teapot_area_cdf.push_back(total);
  }
  geometry->top = std::max({geometry->sphere_centre.z() + geometry->sphere_radius,
                            geometry->box_max.z(), geometry->teapot->BoxMax().z()});
  return geometry;
}

namespace {

// Adds a sparse point at `xyz` of `colour` seen at `observations` (image, exact pixel), each
// pixel moved by Gaussian noise of `pixel_noise` (when > 0); its id follows the largest so far.
void AddObservedPoint(const Eigen::Vector3d& xyz, const Eigen::Vector3d& colour,
                      const std::vector<std::pair<image_t, Eigen::Vector2d>>& observations,
                      double pixel_noise, std::mt19937_64* random,
                      std::normal_distribution<double>* noise, Reconstruction* reconstruction) {
  Point3D point3D;
  point3D.xyz = xyz;
  for (int k = 0; k < 3; ++k) {
    point3D.color[k] = static_cast<uint8_t>(std::lround(std::clamp(colour[k], 0.0, 255.0)));
  }
  point3D.error = pixel_noise;
  const point3D_t id =
      reconstruction->points3D.empty() ? 1 : reconstruction->points3D.rbegin()->first + 1;
  for (const auto& [image_id, pixel] : observations) {
    Image& image = reconstruction->images.at(image_id);
    Point2D point2D;
    point2D.xy = pixel;
    if (pixel_noise > 0.0) point2D.xy += Eigen::Vector2d((*noise)(*random), (*noise)(*random));
    point2D.point3D_id = id;
    point3D.track.push_back({image_id, static_cast<point2D_t>(image.points2D.size())});
    image.points2D.push_back(point2D);
  }
  reconstruction->points3D.emplace(id, std::move(point3D));
}

// A point uniform by area over the room's floor outside the ground square and its wall
// (Backdrop::kRoom); false when the draw fell on the ground square (the caller draws again or
// skips it, which keeps the rest uniform).
bool SampleRoomPoint(std::mt19937_64* random, Eigen::Vector3d* point) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double floor_area = M_PI * kRoomRadius * kRoomRadius;
  const double wall_area = 2.0 * M_PI * kRoomRadius * kRoomHeight;
  const double angle = 2.0 * M_PI * unit(*random);
  if (unit(*random) * (floor_area + wall_area) < floor_area) {
    const double radius = kRoomRadius * std::sqrt(unit(*random));
    *point = Eigen::Vector3d(radius * std::cos(angle), radius * std::sin(angle), 0.0);
    return !(std::abs(point->x()) < kGroundHalfSize && std::abs(point->y()) < kGroundHalfSize);
  }
  *point = Eigen::Vector3d(kRoomRadius * std::cos(angle), kRoomRadius * std::sin(angle),
                           kRoomHeight * unit(*random));
  return true;
}

// The views that see a point of the room (inside the frame, nothing of the scene in front), and
// its pixel in each; stops once `enough` are found (0: all).
std::vector<std::pair<image_t, Eigen::Vector2d>> RoomPointViews(
    const Reconstruction& reconstruction, const SceneGeometry& geometry,
    const Eigen::Vector3d& point, size_t enough = 0) {
  std::vector<std::pair<image_t, Eigen::Vector2d>> observations;
  for (const auto& [image_id, image] : reconstruction.images) {
    const Camera& camera = reconstruction.cameras.at(image.camera_id);
    const Eigen::Vector3d local = image.cam_from_world * point;
    if (local.z() <= 0.0) continue;
    const Eigen::Vector2d pixel = camera.ImgFromCam(local.hnormalized());
    if (!(pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() < camera.width &&
          pixel.y() < camera.height)) {
      continue;
    }
    const Eigen::Vector3d centre = image.ProjectionCenter();
    const Eigen::Vector3d offset = point - centre;
    if (Trace(geometry, centre, offset.normalized()).t < offset.norm()) continue;  // hidden
    observations.emplace_back(image_id, pixel);
    if (enough > 0 && observations.size() >= enough) break;
  }
  return observations;
}

// The room's sparse points (Backdrop::kRoom): as many tried as the scene's, uniform by area over
// the floor outside the ground square and the wall, kept where two or more views see them.
void AddRoomPoints(const SyntheticSceneOptions& options, const SceneGeometry& geometry,
                   std::mt19937_64* random, std::normal_distribution<double>* noise,
                   SyntheticScene* scene) {
  Reconstruction& reconstruction = scene->reconstruction;
  const int tries = static_cast<int>(std::lround(options.num_surface_samples * kRoomPointShare /
                                                 (1.0 - kRoomPointShare)));
  for (int sample = 0; sample < tries; ++sample) {
    Eigen::Vector3d point;
    if (!SampleRoomPoint(random, &point)) continue;
    const auto observations = RoomPointViews(reconstruction, geometry, point);
    if (observations.size() < 2) continue;
    AddObservedPoint(point, RoomColour(point), observations, options.pixel_noise, random, noise,
                     &reconstruction);
  }
}

}  // namespace

SyntheticScene GenerateSyntheticScene(const SyntheticSceneOptions& options) {
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  SyntheticScene scene;
  scene.geometry = MakeSceneGeometry(options);
  const SceneGeometry& geometry = *scene.geometry;
  scene.object_box = Eigen::AlignedBox3d(Eigen::Vector3d(-kGroundHalfSize, -kGroundHalfSize, 0.0),
                                         Eigen::Vector3d(kGroundHalfSize, kGroundHalfSize,
                                                         geometry.top));
  for (const Eigen::AlignedBox3d& block : geometry.clutter) scene.object_box.extend(block);
  Reconstruction& reconstruction = scene.reconstruction;

  // One camera shared by all views; the focal length frames the ground square from the ring.
  Camera camera;
  camera.camera_id = 1;
  camera.model = options.camera_model;
  camera.width = options.width;
  camera.height = options.height;
  const double focal = 0.95 * options.width;
  camera.params = options.camera_params.empty()
                      ? ExampleCameraParams(
                            options.camera_model, options.width, options.height, focal)
                      : options.camera_params;
  reconstruction.cameras.emplace(camera.camera_id, camera);

  const std::vector<Eigen::Vector3d> centres = CameraCentres(options.layout, options.num_views);
  for (int i = 0; i < options.num_views; ++i) {
    const Eigen::Vector3d& centre = centres[i];
    Image image;
    image.image_id = static_cast<image_t>(i + 1);
    image.camera_id = camera.camera_id;
    char name[32];
    std::snprintf(name, sizeof(name), "view%03d.png", i + 1);
    image.name = name;
    image.cam_from_world = LookAt(centre, kCameraTarget);
    cv::Mat mask;
    cv::Mat photo = Render(geometry, camera, image.cam_from_world, options, &mask);
    if (options.exposure_spread > 0.0) {
      // An automatic exposure: the whole photo brighter or darker, by a gain that varies from
      // photo to photo over [1 - spread, 1 + spread].
      const double gain = 1.0 + options.exposure_spread * std::sin(2.3 * i + 0.7);
      photo.convertTo(photo, CV_8UC3, gain);
    }
    scene.photos.emplace(image.image_id, photo);
    scene.masks.emplace(image.image_id, mask);
    reconstruction.images.emplace(image.image_id, std::move(image));
  }

  std::mt19937_64 random(options.seed);
  std::normal_distribution<double> noise(0.0, options.pixel_noise);
  for (int sample = 0; sample < options.num_surface_samples; ++sample) {
    const Hit surface = SampleSurface(geometry, &random);
    std::vector<std::pair<image_t, Eigen::Vector2d>> observations;
    for (const auto& [image_id, image] : reconstruction.images) {
      Eigen::Vector2d pixel;
      if (SeenBy(geometry, surface.point, image, camera, &pixel)) {
        observations.emplace_back(image_id, pixel);
      }
    }
    if (observations.size() < 2) continue;
    AddObservedPoint(surface.point, SurfaceColour(surface, options.detail_texture), observations,
                     options.pixel_noise, &random, &noise, &reconstruction);
  }
  if (options.backdrop == Backdrop::kRoom) AddRoomPoints(options, geometry, &random, &noise, &scene);
  scene.backdrop = options.backdrop;
  return scene;
}

namespace {

// `count` draws of `draw(&random, &point)` (false: nothing drawn) from a generator seeded with
// `seed`, kept where `seen(point)`.
template <typename Draw, typename Seen>
std::vector<Eigen::Vector3d> KeepSeenDraws(int count, uint64_t seed, Draw draw, Seen seen) {
  std::mt19937_64 random(seed);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < count; ++i) {
    Eigen::Vector3d point;
    if (draw(&random, &point) && seen(point)) points.push_back(point);
  }
  return points;
}

}  // namespace

std::vector<Eigen::Vector3d> SampleTrueSurface(const SyntheticScene& scene,
                                               int count,
                                               uint64_t seed,
                                               int min_views) {
  const auto draw = [&scene](std::mt19937_64* random, Eigen::Vector3d* point) {
    *point = SampleSurface(*scene.geometry, random).point;
    return true;
  };
  const auto seen = [&scene, min_views](const Eigen::Vector3d& point) {
    if (min_views <= 0) return true;
    int views = 0;
    for (const auto& [image_id, image] : scene.reconstruction.images) {
      Eigen::Vector2d pixel;
      views += SeenBy(*scene.geometry, point, image,
                      scene.reconstruction.cameras.at(image.camera_id), &pixel);
      if (views >= min_views) return true;
    }
    return false;
  };
  return KeepSeenDraws(count, seed, draw, seen);
}

std::vector<Eigen::Vector3d> SampleRoomSurface(const SyntheticScene& scene,
                                               int count,
                                               uint64_t seed,
                                               int min_views) {
  const auto seen = [&scene, min_views](const Eigen::Vector3d& point) {
    return RoomPointViews(scene.reconstruction, *scene.geometry, point, min_views).size() >=
           static_cast<size_t>(min_views);
  };
  return KeepSeenDraws(count, seed, SampleRoomPoint, seen);
}

void WriteSyntheticProject(const SyntheticScene& scene, const std::string& path) {
  const std::filesystem::path root(path);
  std::error_code error;
  std::filesystem::create_directories(root / "images", error);
  std::filesystem::create_directories(root / "masks", error);
  if (error) throw InputError(path + ": cannot create the project folder: " + error.message());
  for (const auto& [image_id, photo] : scene.photos) {
    const std::string name = scene.reconstruction.images.at(image_id).name;
    const std::filesystem::path final_path = root / "images" / name;
    const std::string temporary = TemporaryPathFor(final_path.string());
    cv::Mat bgr;
    cv::cvtColor(photo, bgr, cv::COLOR_RGB2BGR);
    if (!cv::imwrite(temporary, bgr)) throw InputError(temporary + ": cannot write the photo");
    RenameIntoPlace(temporary, final_path.string());
    const std::string mask_path = (root / "masks" / (name + ".png")).string();
    const std::string mask_temporary = TemporaryPathFor(mask_path);
    if (!cv::imwrite(mask_temporary, scene.masks.at(image_id))) {
      throw InputError(mask_temporary + ": cannot write the mask");
    }
    RenameIntoPlace(mask_temporary, mask_path);
  }
  WriteModel(scene.reconstruction, (root / "sparse" / "0").string(), ModelFormat::kBinary);
  std::vector<exporter::ColouredPoint> truth;
  const auto add = [&truth](const std::vector<Eigen::Vector3d>& points) {
    for (const Eigen::Vector3d& point : points) {
      exporter::ColouredPoint coloured;
      coloured.xyz = point.cast<float>();
      truth.push_back(coloured);
    }
  };
  add(SampleTrueSurface(scene, 200000, 7, 2));
  if (scene.backdrop == Backdrop::kRoom) add(SampleRoomSurface(scene, kRoomTruthSamples, 8, 2));
  exporter::WritePointCloudPly(truth, (root / "truth.ply").string());
}

}  // namespace raycarve
