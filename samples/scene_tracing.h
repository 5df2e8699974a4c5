#pragma once
// Internal to samples/: the generated scene's geometry and its ray tracer, which
// synthetic_scene.cc renders photos and samples sparse points with.

#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "calib/camera.h"
#include "calib/reconstruction.h"
#include "samples/synthetic_scene.h"
#include "samples/triangle_mesh.h"

namespace raycarve {
namespace scene_tracing {

constexpr double kGroundHalfSize = 1.5;
const Eigen::Vector3d kSphereCentre(0.45, 0.35, 0.55);
constexpr double kSphereRadius = 0.55;
const Eigen::Vector3d kBoxMin(-1.05, -0.75, 0.0);
const Eigen::Vector3d kBoxMax(-0.2, 0.05, 0.8);
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// What every camera looks at.
const Eigen::Vector3d kCameraTarget(0.0, 0.0, 0.35);
// Where the light comes from (a unit direction): the surfaces' shading and the highlights.
const Eigen::Vector3d kLight = Eigen::Vector3d(0.3, 0.5, 0.8).normalized();

enum class Surface { kNone, kGround, kSphere, kBox, kTeapot, kClutter };

// The clutter scene's blocks (SceneKind::kClutter), standing on z = 0 around the simple scene's
// objects: two on the ground square's edge, three beyond it, between the cameras of an arc
// (SceneKind::kArc looks from +y) and the objects or behind them.
std::vector<Eigen::AlignedBox3d> ClutterBoxes();

}  // namespace scene_tracing

// The objects of a scene: the simple scene's sphere and box, or the paper's teapot, sphere and
// cube; all on the same checkered ground square.
struct SceneGeometry {
  Eigen::Vector3d sphere_centre = scene_tracing::kSphereCentre;
  double sphere_radius = scene_tracing::kSphereRadius;
  Eigen::Vector3d box_min = scene_tracing::kBoxMin;
  Eigen::Vector3d box_max = scene_tracing::kBoxMax;
  std::unique_ptr<TriangleMesh> teapot;  // the paper's scene only
  std::vector<double> teapot_area_cdf;   // cumulative triangle areas, for sampling
  std::vector<Eigen::AlignedBox3d> clutter;  // the clutter scene's blocks
  double top = scene_tracing::kSphereCentre.z() + scene_tracing::kSphereRadius;  // highest point of the objects
};

namespace scene_tracing {

struct Hit {
  double t = kInfinity;
  Surface surface = Surface::kNone;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
};

// The first surface a ray from `origin` along `direction` (unit) meets.
Hit Trace(const SceneGeometry& g, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction);
// How far along a ray from `origin` (inside the room, above the ground) along `direction` (unit)
// the first solid surface lies: the objects and the ground square (Trace), or what the backdrop
// puts behind them that a model may hold (the room's floor and wall, the table plane out to a
// radius of 14, the field); infinity where the ray meets only sky or a backdrop at infinity.
double FirstSolidDistance(const SceneGeometry& g, Backdrop backdrop, const Eigen::Vector3d& origin,
                          const Eigen::Vector3d& direction);
// The room's wall or floor colour at `point` (--backdrop room).
Eigen::Vector3d RoomColour(const Eigen::Vector3d& point);
// A surface's colour at a hit; `detail` adds the non-repeating noise of --texture detailed.
Eigen::Vector3d SurfaceColour(const Hit& hit, bool detail = false);
// A camera at `centre` looking at `target`, y down in the photo.
Rigid3d LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target);
// A photo of the scene through `camera` (with its distortion), with the options' supersampling^2
// rays a pixel, backdrop, detail texture and specular highlights; *mask the exact object mask.
cv::Mat Render(const SceneGeometry& geometry, const Camera& camera, const Rigid3d& cam_from_world,
               const SyntheticSceneOptions& options, cv::Mat* mask);
// A point on the objects or the ground, uniform over their area.
Hit SampleSurface(const SceneGeometry& g, std::mt19937_64* random);
// Whether `point` is the first surface along its ray in `image`, and its pixel there.
bool SeenBy(const SceneGeometry& geometry,
            const Eigen::Vector3d& point,
            const Image& image,
            const Camera& camera,
            Eigen::Vector2d* pixel);

}  // namespace scene_tracing
}  // namespace raycarve
