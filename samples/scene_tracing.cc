#include "samples/scene_tracing.h"

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
#include "samples/triangle_mesh.h"
#include "export/point_cloud_io.h"

namespace raycarve {
namespace scene_tracing {

void IntersectSphere(const SceneGeometry& g, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& direction, Hit* hit) {
  const Eigen::Vector3d offset = origin - g.sphere_centre;
  const double b = offset.dot(direction);
  const double c = offset.squaredNorm() - g.sphere_radius * g.sphere_radius;
  const double discriminant = b * b - c;
  if (discriminant < 0.0) return;
  const double t = -b - std::sqrt(discriminant);
  if (t > 1e-9 && t < hit->t) {
    hit->t = t;
    hit->surface = Surface::kSphere;
    hit->point = origin + t * direction;
    hit->normal = (hit->point - g.sphere_centre) / g.sphere_radius;
  }
}

// The nearest entry of a ray into the axis-aligned box [lo, hi] ahead of *hit, as `surface`.
void IntersectAlignedBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, Surface surface,
                         const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                         Hit* hit) {
  double t_near = -kInfinity, t_far = kInfinity;
  int near_axis = 0;
  for (int axis = 0; axis < 3; ++axis) {
    if (direction[axis] == 0.0) {
      if (origin[axis] < lo[axis] || origin[axis] > hi[axis]) return;
      continue;
    }
    double t0 = (lo[axis] - origin[axis]) / direction[axis];
    double t1 = (hi[axis] - origin[axis]) / direction[axis];
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_near) {
      t_near = t0;
      near_axis = axis;
    }
    t_far = std::min(t_far, t1);
  }
  if (t_near > t_far || t_near <= 1e-9 || t_near >= hit->t) return;
  hit->t = t_near;
  hit->surface = surface;
  hit->point = origin + t_near * direction;
  hit->normal = Eigen::Vector3d::Zero();
  hit->normal[near_axis] = direction[near_axis] > 0.0 ? -1.0 : 1.0;
}

void IntersectBox(const SceneGeometry& g, const Eigen::Vector3d& origin,
                  const Eigen::Vector3d& direction, Hit* hit) {
  IntersectAlignedBox(g.box_min, g.box_max, Surface::kBox, origin, direction, hit);
  for (const Eigen::AlignedBox3d& block : g.clutter) {
    IntersectAlignedBox(block.min(), block.max(), Surface::kClutter, origin, direction, hit);
  }
}

std::vector<Eigen::AlignedBox3d> ClutterBoxes() {
  const auto block = [](double x, double y, double size_x, double size_y, double height) {
    return Eigen::AlignedBox3d(Eigen::Vector3d(x - 0.5 * size_x, y - 0.5 * size_y, 0.0),
                               Eigen::Vector3d(x + 0.5 * size_x, y + 0.5 * size_y, height));
  };
  return {
      block(1.25, -1.2, 0.3, 0.3, 1.25),  // a post on the ground square's corner
      block(-1.2, 1.15, 0.6, 0.45, 0.35),  // a low crate on the opposite corner
      block(0.1, 2.25, 0.9, 0.35, 0.75),   // a bench in front of the arc's middle cameras
      block(1.9, 1.5, 0.4, 0.4, 0.95),     // a column towards the arc's first cameras
      block(-0.6, -2.3, 1.2, 0.4, 0.6),    // a chest behind the objects, seen from the arc
  };
}

void IntersectGround(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, Hit* hit) {
  if (direction.z() == 0.0) return;
  const double t = -origin.z() / direction.z();
  if (t <= 1e-9 || t >= hit->t) return;
  const Eigen::Vector3d point = origin + t * direction;
  if (std::abs(point.x()) > kGroundHalfSize || std::abs(point.y()) > kGroundHalfSize) return;
  hit->t = t;
  hit->surface = Surface::kGround;
  hit->point = point;
  hit->normal = Eigen::Vector3d::UnitZ();
}

void IntersectTeapot(const SceneGeometry& g, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d& direction, Hit* hit) {
  if (!g.teapot) return;
  TriangleMesh::RayHit mesh_hit;
  if (!g.teapot->Intersect(origin, direction, 1e-9, hit->t, &mesh_hit)) return;
  hit->t = mesh_hit.t;
  hit->surface = Surface::kTeapot;
  hit->point = origin + mesh_hit.t * direction;
  hit->normal = mesh_hit.normal;
}

Hit Trace(const SceneGeometry& g, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  Hit hit;
  IntersectSphere(g, origin, direction, &hit);
  IntersectBox(g, origin, direction, &hit);
  IntersectGround(origin, direction, &hit);
  IntersectTeapot(g, origin, direction, &hit);
  return hit;
}

// The sky: a patchwork over directions (cells of 9 degrees of azimuth by 7 of elevation, each a
// colour of its own). Empty space seen against it from different views shows different colours,
// as against a real background; a uniform sky would be photo-consistent everywhere and leave a
// shell of sky-coloured voxels.
Eigen::Vector3d SkyColour(const Eigen::Vector3d& direction) {
  const double azimuth = std::atan2(direction.y(), direction.x());
  const double elevation = std::asin(std::clamp(direction.z(), -1.0, 1.0));
  const int cell_a = static_cast<int>(std::floor(azimuth / (M_PI / 20.0)));
  const int cell_e = static_cast<int>(std::floor(elevation / (M_PI / 26.0)));
  uint32_t hash = static_cast<uint32_t>(cell_a * 73856093) ^ static_cast<uint32_t>(cell_e * 19349663);
  hash = (hash ^ (hash >> 13)) * 0x5bd1e995u;
  hash ^= hash >> 15;
  return Eigen::Vector3d(40 + (hash & 0x7f), 40 + ((hash >> 8) & 0x7f), 60 + ((hash >> 16) & 0x7f));
}

// Where a ray from inside the room meets its floor (z = 0, inside the wall) or its wall (the
// cylinder of kRoomRadius, up to kRoomHeight); false when it leaves through the open top.
bool RoomHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
             Eigen::Vector3d* point);
// The room's texture at a point of its floor or wall: boards on the floor, patches on the wall,
// with value noise over both so that every place looks different.
Eigen::Vector3d RoomColour(const Eigen::Vector3d& point);

// Value noise in [0, 1]; defined below.
double ValueNoise(const Eigen::Vector3d& point, double scale, uint32_t channel);

// Outdoors (Backdrop::kCloudy): above the horizon a sky at infinity, deep blue overhead and
// paler towards the horizon, with soft-edged white clouds (fractal value noise over directions);
// below it a field on the plane z = 0, grass and earth mottled at two scales.
Eigen::Vector3d CloudyColour(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  if (direction.z() < 0.0 && origin.z() > 0.0) {
    const Eigen::Vector3d on = origin - direction * (origin.z() / direction.z());
    const double grass = ValueNoise(on, 1.5, 31), fine = ValueNoise(on, 0.2, 32);
    return (1.0 - grass) * Eigen::Vector3d(70, 110, 45) + grass * Eigen::Vector3d(120, 100, 70) +
           (fine - 0.5) * Eigen::Vector3d(40, 40, 30);
  }
  const Eigen::Vector3d d = direction.normalized();
  const double up = std::clamp(d.z(), 0.0, 1.0);
  const Eigen::Vector3d sky = (1.0 - up) * Eigen::Vector3d(180, 205, 235) + up * Eigen::Vector3d(60, 110, 205);
  const double cloud = 0.6 * ValueNoise(d, 0.18, 33) + 0.3 * ValueNoise(d, 0.07, 34) +
                       0.1 * ValueNoise(d, 0.03, 35);
  const double t = std::clamp((cloud - 0.5) / 0.2, 0.0, 1.0);
  const double cover = t * t * (3.0 - 2.0 * t);
  return (1.0 - cover) * sky + cover * Eigen::Vector3d(240, 242, 246);
}

// What a ray that meets no part of the scene shows, for each backdrop. The table is the plane
// z = 0 around the ground square (out to a radius of 14), the wall everything beyond it.
Eigen::Vector3d BackdropColour(Backdrop backdrop, const Eigen::Vector3d& origin,
                               const Eigen::Vector3d& direction) {
  const bool meets_table = direction.z() < 0.0;
  const Eigen::Vector3d on_table = meets_table
                                       ? Eigen::Vector3d(origin - direction * (origin.z() /
                                                                               direction.z()))
                                       : Eigen::Vector3d::Zero();
  const bool table = meets_table && on_table.head<2>().norm() < 14.0;
  switch (backdrop) {
    case Backdrop::kPatchwork:
      return SkyColour(direction);
    case Backdrop::kUniform:
      return kBackdropColour;
    case Backdrop::kTwoTone:
      return table ? Eigen::Vector3d(150, 160, 205) : Eigen::Vector3d(85, 100, 160);
    case Backdrop::kGradient: {
      const double elevation = std::asin(std::clamp(direction.z(), -1.0, 1.0));
      const double t = std::clamp((elevation + 0.85) / 0.85, 0.0, 1.0);
      const double w = t * t * (3.0 - 2.0 * t);
      return (1.0 - w) * Eigen::Vector3d(150, 110, 80) + w * Eigen::Vector3d(235, 200, 170);
    }
    case Backdrop::kVignetted:
      return Eigen::Vector3d(140, 90, 150);
    case Backdrop::kRoom: {
      Eigen::Vector3d point;
      return RoomHit(origin, direction, &point) ? RoomColour(point) : SkyColour(direction);
    }
    case Backdrop::kCloudy:
      return CloudyColour(origin, direction);
    case Backdrop::kShadowedTable: {
      if (!table) return Eigen::Vector3d(225, 225, 230);
      // A soft shadow cast away from the light (see SurfaceColour), darkest near the objects.
      const double r = (on_table.head<2>() - Eigen::Vector2d(-0.2, -0.3)).norm();
      const double shade = 1.0 - 0.55 * std::exp(-(r / 1.9) * (r / 1.9));
      return shade * Eigen::Vector3d(190, 160, 120);
    }
  }
  return SkyColour(direction);
}

// Value noise in [0, 1] at a point: random values on a lattice of spacing `scale` (hashed from
// the lattice coordinates and `channel`), interpolated smoothly. Not periodic.
double ValueNoise(const Eigen::Vector3d& point, double scale, uint32_t channel) {
  const Eigen::Vector3d p = point / scale;
  const Eigen::Vector3d base = p.array().floor();
  const Eigen::Vector3d f = p - base;
  const Eigen::Vector3d w = f.array().square() * (3.0 - 2.0 * f.array());  // smoothstep
  const auto lattice = [&](int dx, int dy, int dz) {
    uint32_t hash = static_cast<uint32_t>(static_cast<int64_t>(base.x()) + dx) * 73856093u ^
                    static_cast<uint32_t>(static_cast<int64_t>(base.y()) + dy) * 19349663u ^
                    static_cast<uint32_t>(static_cast<int64_t>(base.z()) + dz) * 83492791u ^
                    channel * 2654435761u;
    hash = (hash ^ (hash >> 13)) * 0x5bd1e995u;
    hash ^= hash >> 15;
    return (hash & 0xffff) / 65535.0;
  };
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
    value += lattice(dx, dy, dz) * (dx ? w.x() : 1.0 - w.x()) * (dy ? w.y() : 1.0 - w.y()) *
             (dz ? w.z() : 1.0 - w.z());
  }
  return value;
}

bool RoomHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
             Eigen::Vector3d* point) {
  if (direction.z() < 0.0) {
    const Eigen::Vector3d floor = origin - direction * (origin.z() / direction.z());
    if (floor.head<2>().norm() < kRoomRadius) {
      *point = floor;
      return true;
    }
  }
  // |origin.xy + t direction.xy| = kRoomRadius, the root ahead (the origin is inside).
  const Eigen::Vector2d o = origin.head<2>(), d = direction.head<2>();
  const double a = d.squaredNorm(), b = o.dot(d), c = o.squaredNorm() - kRoomRadius * kRoomRadius;
  if (a <= 0.0 || c >= 0.0) return false;
  const double t = (-b + std::sqrt(b * b - a * c)) / a;
  *point = origin + t * direction;
  return point->z() >= 0.0 && point->z() <= kRoomHeight;
}

double FirstSolidDistance(const SceneGeometry& g, Backdrop backdrop, const Eigen::Vector3d& origin,
                          const Eigen::Vector3d& direction) {
  const Hit hit = Trace(g, origin, direction);
  if (hit.surface != Surface::kNone) return hit.t;
  const bool down = direction.z() < 0.0 && origin.z() > 0.0;
  const double to_plane = down ? -origin.z() / direction.z() : kInfinity;
  const double plane_radius =
      down ? (origin + to_plane * direction).head<2>().norm() : kInfinity;
  switch (backdrop) {
    case Backdrop::kRoom: {
      Eigen::Vector3d point;
      return RoomHit(origin, direction, &point) ? (point - origin).norm() : kInfinity;
    }
    case Backdrop::kCloudy:
      return to_plane;
    case Backdrop::kTwoTone:
    case Backdrop::kShadowedTable:
      return plane_radius < 14.0 ? to_plane : kInfinity;
    case Backdrop::kPatchwork:
    case Backdrop::kUniform:
    case Backdrop::kGradient:
    case Backdrop::kVignetted:
      return kInfinity;
  }
  return kInfinity;
}

Eigen::Vector3d RoomColour(const Eigen::Vector3d& point) {
  const Eigen::Vector3d noise(ValueNoise(point, 0.15, 11), ValueNoise(point, 0.15, 12),
                              ValueNoise(point, 0.15, 13));
  if (point.z() < 1e-9) {
    // Floor boards 0.4 wide along x, each its own shade of wood.
    const double board = ValueNoise(Eigen::Vector3d(std::floor(point.x() / 0.4), 0.0, 0.0), 1.0, 14);
    return Eigen::Vector3d(120, 85, 55) * (0.7 + 0.5 * board) + 50.0 * (noise - Eigen::Vector3d::Constant(0.5));
  }
  const double angle = std::atan2(point.y(), point.x());
  const Eigen::Vector3d patch(ValueNoise(Eigen::Vector3d(angle * 3.0, point.z(), 0.0), 0.5, 15),
                              ValueNoise(Eigen::Vector3d(angle * 3.0, point.z(), 0.0), 0.5, 16),
                              ValueNoise(Eigen::Vector3d(angle * 3.0, point.z(), 0.0), 0.5, 17));
  return (Eigen::Vector3d::Constant(40.0) + 170.0 * patch + 40.0 * noise).cwiseMin(255.0);
}

// Texture colour (RGB, 0-255) of a surface point, with a fixed directional shading. With
// `detail`, a non-repeating multi-scale noise modulates each channel: blobs of a few to a few
// tens of pixels that feature detectors find and match unambiguously, where the checks and
// stripes alone repeat.
Eigen::Vector3d SurfaceColour(const Hit& hit, bool detail) {
  Eigen::Vector3d albedo = Eigen::Vector3d::Zero();
  switch (hit.surface) {
    case Surface::kGround: {
      const int cx = static_cast<int>(std::floor(hit.point.x() / 0.25));
      const int cy = static_cast<int>(std::floor(hit.point.y() / 0.25));
      albedo = ((cx + cy) & 1) ? Eigen::Vector3d(230, 225, 210) : Eigen::Vector3d(60, 70, 90);
      break;
    }
    case Surface::kSphere: {
      const Eigen::Vector3d d = hit.normal;
      const double longitude = std::atan2(d.y(), d.x());
      const double latitude = std::asin(std::clamp(d.z(), -1.0, 1.0));
      const int band = static_cast<int>(std::floor(longitude / (M_PI / 6.0))) +
                       static_cast<int>(std::floor(latitude / (M_PI / 8.0)));
      albedo = (band & 1) ? Eigen::Vector3d(200, 60, 50) : Eigen::Vector3d(250, 200, 60);
      albedo += Eigen::Vector3d(0, 40, 80) * (0.5 + 0.5 * std::sin(3.0 * longitude));
      break;
    }
    case Surface::kBox: {
      const double s = hit.point.x() + hit.point.y() + 1.7 * hit.point.z();
      const bool stripe = static_cast<int>(std::floor(s / 0.24)) & 1;
      albedo = stripe ? Eigen::Vector3d(40, 150, 80) : Eigen::Vector3d(170, 230, 240);
      break;
    }
    case Surface::kTeapot: {
      // Porcelain with a blue 3D check of 0.1 and a soft band: texture at every scale.
      const Eigen::Vector3d& p = hit.point;
      const int check = static_cast<int>(std::floor(p.x() / 0.1)) +
                        static_cast<int>(std::floor(p.y() / 0.1)) +
                        static_cast<int>(std::floor(p.z() / 0.1));
      albedo = (check & 1) ? Eigen::Vector3d(45, 70, 170) : Eigen::Vector3d(235, 232, 215);
      albedo += Eigen::Vector3d(10, -20, -40) * (0.5 + 0.5 * std::sin(9.0 * p.z()));
      albedo = albedo.cwiseMax(0.0);
      break;
    }
    case Surface::kClutter: {
      // Blocks of mottled paint in big checks of 0.2: each place its own mix of three colours.
      const Eigen::Vector3d& p = hit.point;
      const int check = static_cast<int>(std::floor(p.x() / 0.2)) +
                        static_cast<int>(std::floor(p.y() / 0.2)) +
                        static_cast<int>(std::floor(p.z() / 0.2));
      const Eigen::Vector3d mottle(ValueNoise(p, 0.35, 21), ValueNoise(p, 0.35, 22),
                                   ValueNoise(p, 0.35, 23));
      albedo = ((check & 1) ? Eigen::Vector3d(70, 40, 110) : Eigen::Vector3d(150, 120, 40)) +
               110.0 * mottle;
      break;
    }
    case Surface::kNone:
      LOG(FATAL) << "no surface: use SkyColour";
  }
  if (detail) {
    for (int k = 0; k < 3; ++k) {
      const double noise = 0.5 * ValueNoise(hit.point, 0.012, k) +
                           0.3 * ValueNoise(hit.point, 0.03, k + 3) +
                           0.2 * ValueNoise(hit.point, 0.08, k + 6);
      albedo[k] *= 0.35 + 1.1 * noise;
    }
  }
  const double shade = 0.55 + 0.45 * std::max(0.0, hit.normal.dot(kLight));
  return (albedo * shade).cwiseMin(255.0);
}

Rigid3d LookAt(const Eigen::Vector3d& centre, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - centre).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x;
  R.row(1) = y;
  R.row(2) = z;
  Rigid3d cam_from_world;
  cam_from_world.rotation = Eigen::Quaterniond(R);
  cam_from_world.translation = -(R * centre);
  return cam_from_world;
}

// Renders the photo and the object mask (pixels where most rays hit the scene).
cv::Mat Render(const SceneGeometry& geometry, const Camera& camera, const Rigid3d& cam_from_world,
               const SyntheticSceneOptions& options, cv::Mat* mask) {
  const int supersampling = options.supersampling;
  const Backdrop backdrop = options.backdrop;
  const bool detail = options.detail_texture;
  const double specular = options.specular;
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  cv::Mat photo(static_cast<int>(camera.height), static_cast<int>(camera.width), CV_8UC3);
  mask->create(photo.size(), CV_8UC1);
  for (int row = 0; row < photo.rows; ++row) {
    for (int col = 0; col < photo.cols; ++col) {
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      int hits = 0;
      for (int sy = 0; sy < supersampling; ++sy) {
        for (int sx = 0; sx < supersampling; ++sx) {
          const Eigen::Vector2d pixel(col + (sx + 0.5) / supersampling,
                                      row + (sy + 0.5) / supersampling);
          const Eigen::Vector2d normalized = camera.CamFromImg(pixel);
          if (!normalized.allFinite()) continue;
          const Eigen::Vector3d direction =
              (world_from_cam.rotation * normalized.homogeneous()).normalized();
          const Hit hit = Trace(geometry, world_from_cam.translation, direction);
          hits += hit.surface != Surface::kNone;
          if (hit.surface == Surface::kNone) {
            sum += BackdropColour(backdrop, world_from_cam.translation, direction);
            continue;
          }
          Eigen::Vector3d colour = SurfaceColour(hit, detail);
          if (specular > 0.0) {
            // A white highlight where the light's mirror direction meets the camera (Phong,
            // exponent 30): it moves over the surface from view to view.
            const Eigen::Vector3d mirror = 2.0 * hit.normal.dot(kLight) * hit.normal - kLight;
            const double facing = std::max(0.0, mirror.dot(-direction));
            colour = (colour + Eigen::Vector3d::Constant(specular * 255.0 * std::pow(facing, 30.0)))
                         .cwiseMin(255.0);
          }
          sum += colour;
        }
      }
      const Eigen::Vector3d rgb = sum / (supersampling * supersampling);
      mask->at<uint8_t>(row, col) = 2 * hits >= supersampling * supersampling ? 255 : 0;
      photo.at<cv::Vec3b>(row, col) = cv::Vec3b(static_cast<uint8_t>(std::lround(rgb[0])),
                                                static_cast<uint8_t>(std::lround(rgb[1])),
                                                static_cast<uint8_t>(std::lround(rgb[2])));
    }
  }
  if (backdrop == Backdrop::kVignetted) {
    // Natural vignetting: the photo darkens with the squared distance from its centre.
    const Eigen::Vector2d centre(0.5 * photo.cols, 0.5 * photo.rows);
    const double corner2 = centre.squaredNorm();
    for (int row = 0; row < photo.rows; ++row) {
      for (int col = 0; col < photo.cols; ++col) {
        const double r2 = (Eigen::Vector2d(col + 0.5, row + 0.5) - centre).squaredNorm();
        const double gain = 1.0 - 0.45 * r2 / corner2;
        cv::Vec3b& p = photo.at<cv::Vec3b>(row, col);
        for (int k = 0; k < 3; ++k) p[k] = static_cast<uint8_t>(std::lround(p[k] * gain));
      }
    }
  }
  if (backdrop == Backdrop::kTwoTone) {
    // A near-black frame of 3 pixels, as a lens hood or a scanner leaves.
    const int frame = 3;
    for (int row = 0; row < photo.rows; ++row) {
      for (int col = 0; col < photo.cols; ++col) {
        if (row < frame || col < frame || row >= photo.rows - frame || col >= photo.cols - frame) {
          photo.at<cv::Vec3b>(row, col) = cv::Vec3b(18, 16, 14);
          mask->at<uint8_t>(row, col) = 0;
        }
      }
    }
  }
  return photo;
}

// The area of the axis-aligned box [lo, hi]'s six faces.
double BoxArea(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Vector3d size = hi - lo;
  return 2.0 * (size.x() * size.y() + size.y() * size.z() + size.x() * size.z());
}

// A point uniform over the faces of the axis-aligned box [lo, hi], as `surface`.
Hit SampleBoxSurface(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, Surface surface,
                     std::mt19937_64* random) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const Eigen::Vector3d size = hi - lo;
  // A face picked in proportion to its area (faces normal to x, y, z), then a uniform point.
  const double face_areas[3] = {size.y() * size.z(), size.x() * size.z(), size.x() * size.y()};
  const double face_pick = uniform(*random) * (face_areas[0] + face_areas[1] + face_areas[2]);
  const int axis = face_pick < face_areas[0]                   ? 0
                   : face_pick < face_areas[0] + face_areas[1] ? 1
                                                               : 2;
  Hit hit;
  hit.point = lo + size.cwiseProduct(
                       Eigen::Vector3d(uniform(*random), uniform(*random), uniform(*random)));
  const bool upper = uniform(*random) < 0.5;
  hit.point[axis] = upper ? hi[axis] : lo[axis];
  hit.normal = Eigen::Vector3d::Zero();
  hit.normal[axis] = upper ? 1.0 : -1.0;
  hit.surface = surface;
  return hit;
}

// A uniformly distributed point on the scene's surfaces, by area. (A clutter block's bottom
// face stands on the ground and is sampled too: no view sees it, so the visibility filters drop
// it.)
Hit SampleSurface(const SceneGeometry& g, std::mt19937_64* random) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const double sphere_area = 4.0 * M_PI * g.sphere_radius * g.sphere_radius;
  const double box_area = BoxArea(g.box_min, g.box_max);
  const double ground_area = 4.0 * kGroundHalfSize * kGroundHalfSize;
  const double teapot_area = g.teapot_area_cdf.empty() ? 0.0 : g.teapot_area_cdf.back();
  std::vector<double> clutter_cdf;
  double clutter_area = 0.0;
  for (const Eigen::AlignedBox3d& block : g.clutter) {
    clutter_area += BoxArea(block.min(), block.max());
    clutter_cdf.push_back(clutter_area);
  }
  const double pick =
      uniform(*random) * (sphere_area + box_area + ground_area + teapot_area + clutter_area);
  Hit hit;
  if (pick >= sphere_area + box_area + ground_area + teapot_area) {
    const double at = pick - (sphere_area + box_area + ground_area + teapot_area);
    const size_t block = std::min<size_t>(
        std::upper_bound(clutter_cdf.begin(), clutter_cdf.end(), at) - clutter_cdf.begin(),
        g.clutter.size() - 1);
    hit = SampleBoxSurface(g.clutter[block].min(), g.clutter[block].max(), Surface::kClutter,
                           random);
  } else if (pick >= sphere_area + box_area + ground_area) {
    const double at = pick - (sphere_area + box_area + ground_area);
    const int triangle = static_cast<int>(
        std::upper_bound(g.teapot_area_cdf.begin(), g.teapot_area_cdf.end(), at) -
        g.teapot_area_cdf.begin());
    const double r1 = uniform(*random), r2 = uniform(*random);
    hit.surface = Surface::kTeapot;
    hit.point = g.teapot->PointOn(std::min(triangle, g.teapot->num_triangles() - 1), r1, r2,
                                  &hit.normal);
  } else if (pick < sphere_area) {
    const double z = 2.0 * uniform(*random) - 1.0;
    const double phi = 2.0 * M_PI * uniform(*random);
    const double s = std::sqrt(1.0 - z * z);
    hit.surface = Surface::kSphere;
    hit.normal = Eigen::Vector3d(s * std::cos(phi), s * std::sin(phi), z);
    hit.point = g.sphere_centre + g.sphere_radius * hit.normal;
  } else if (pick < sphere_area + box_area) {
    hit = SampleBoxSurface(g.box_min, g.box_max, Surface::kBox, random);
  } else {
    hit.surface = Surface::kGround;
    hit.point = Eigen::Vector3d((2.0 * uniform(*random) - 1.0) * kGroundHalfSize,
                                (2.0 * uniform(*random) - 1.0) * kGroundHalfSize,
                                0.0);
    hit.normal = Eigen::Vector3d::UnitZ();
  }
  return hit;
}

// The pixel of `point` in `image` when it is inside the frame and not occluded.
bool SeenBy(const SceneGeometry& geometry,
            const Eigen::Vector3d& point,
            const Image& image,
            const Camera& camera,
            Eigen::Vector2d* pixel) {
  const Eigen::Vector3d in_camera = image.cam_from_world * point;
  if (in_camera.z() <= 0.0) return false;
  *pixel = camera.ImgFromCam(in_camera.hnormalized());
  if (!(pixel->x() >= 0.0 && pixel->y() >= 0.0 && pixel->x() < camera.width &&
        pixel->y() < camera.height)) {
    return false;
  }
  const Eigen::Vector3d centre = image.ProjectionCenter();
  const Eigen::Vector3d offset = point - centre;
  const Hit hit = Trace(geometry, centre, offset.normalized());
  return std::abs(hit.t - offset.norm()) <= 1e-6 * offset.norm();
}


}  // namespace scene_tracing

double TrueSurfaceDistance(const Eigen::Vector3d& point) {
  using namespace scene_tracing;
  const double sphere = std::abs((point - kSphereCentre).norm() - kSphereRadius);
  // Box: outside, the distance to the box; inside, to the nearest face.
  const Eigen::Vector3d below = (kBoxMin - point).cwiseMax(0.0);
  const Eigen::Vector3d above = (point - kBoxMax).cwiseMax(0.0);
  const Eigen::Vector3d outside = below.cwiseMax(above);
  double box = outside.norm();
  if (box == 0.0) {
    box = std::min((point - kBoxMin).minCoeff(), (kBoxMax - point).minCoeff());
  }
  const double dx = std::max(std::abs(point.x()) - kGroundHalfSize, 0.0);
  const double dy = std::max(std::abs(point.y()) - kGroundHalfSize, 0.0);
  const double ground = std::sqrt(dx * dx + dy * dy + point.z() * point.z());
  return std::min({sphere, box, ground});
}

}  // namespace raycarve
