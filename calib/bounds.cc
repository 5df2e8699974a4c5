#include "calib/bounds.h"

#include <algorithm>
#include <tuple>
#include <array>
#include <map>
#include <set>
#include <cmath>
#include <sstream>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <glog/logging.h>

#include "calib/input_error.h"

namespace raycarve {
namespace {

// Value at quantile q of `values` (0 <= q <= 1), nearest rank; `values` is reordered.
double Quantile(std::vector<double>* values, double q) {
  const size_t index = std::min(values->size() - 1,
                                static_cast<size_t>(std::floor(q * (values->size() - 1) + 0.5)));
  std::nth_element(values->begin(), values->begin() + index, values->end());
  return (*values)[index];
}

// Photos of an object are taken around it and aimed at it: every photo frames the object, while
// the room behind it (walls, furniture, a floor running on) is framed only by the photos that
// face that way. Points framed by fewer photos than min_framed_share of the best framed ones
// (the 90th percentile of the counts) are the room; they leave `points` when they are more than
// twice trim_fraction of them (a few stray ones are the trim's) and enough points stay. Where
// every photo frames everything (a forward-facing capture, a wall seen from in front) nothing
// is dropped: the photos do not tell an object from its background there.
void DropTheRoom(const Reconstruction& reconstruction, const BoundsOptions& options,
                 std::vector<Eigen::Vector3d>* points, Bounds* bounds) {
  if (options.min_framed_share <= 0.0 || points->empty() || reconstruction.images.empty()) return;
  // Each image with its camera, looked up once.
  std::vector<std::pair<const Image*, const Camera*>> photos;
  for (const auto& [image_id, image] : reconstruction.images) {
    const auto camera = reconstruction.cameras.find(image.camera_id);
    if (camera != reconstruction.cameras.end()) photos.emplace_back(&image, &camera->second);
  }
  // How many photos show each point inside their frame.
  std::vector<double> counts(points->size(), 0.0);
  Eigen::Vector2d pixel;
  for (size_t i = 0; i < points->size(); ++i) {
    for (const auto& [image, camera] : photos) {
      counts[i] += ProjectIntoFrame(*camera, image->cam_from_world, (*points)[i], &pixel);
    }
  }
  std::vector<double> sorted = counts;
  const double best = Quantile(&sorted, 0.9);
  std::vector<Eigen::Vector3d> framed;
  for (size_t i = 0; i < points->size(); ++i) {
    if (counts[i] >= options.min_framed_share * best) framed.push_back((*points)[i]);
  }
  const size_t room = points->size() - framed.size();
  if (room <= 2.0 * options.trim_fraction * points->size() ||
      static_cast<int>(framed.size()) < options.min_points) {
    return;
  }
  bounds->num_unframed = static_cast<int>(room);
  points->swap(framed);
}

}  // namespace

bool BoundsOptions::IsValid(std::string* reason) const {
  if (min_track_length < 0) {
    *reason = "min_track_length must be >= 0";
    return false;
  }
  if (!(min_framed_share >= 0.0 && min_framed_share <= 1.0)) {
    *reason = "min_framed_share must be in [0, 1]";
    return false;
  }
  if (min_points < 1) {
    *reason = "min_points must be >= 1";
    return false;
  }
  if (!(trim_fraction >= 0.0 && trim_fraction < 0.5)) {
    *reason = "trim_fraction must be in [0, 0.5)";
    return false;
  }
  if (!(margin >= 0.0 && margin <= kMaxMargin)) {
    *reason = "margin must be in [0, " + std::to_string(static_cast<int>(kMaxMargin)) +
              "] (a fraction of the volume's largest extent added on every side: 0.1 is 10%)";
    return false;
  }
  if (std::isnan(max_reprojection_error)) {
    *reason = "max_reprojection_error must be a number";
    return false;
  }
  return true;
}

std::string Bounds::Summary() const {
  std::ostringstream text;
  text.precision(6);
  text << "bounds: min (" << box.min().transpose() << ") max (" << box.max().transpose()
       << ") extent (" << box.sizes().transpose() << ")";
  if (is_explicit) {
    text << ", given explicitly";
  } else {
    text << ", from " << num_used << " of " << num_points << " sparse points (" << num_short_track
         << " short tracks, " << num_high_error << " high error";
    if (num_unframed > 0) text << ", " << num_unframed << " of the room around (framed by few photos)";
    text << " dropped; " << num_trimmed_outside << " trimmed as outliers)";
    if (around_focus) text << ", narrowed to the points framed around the cameras' focus";
    if (around_hull) text << ", narrowed to the masks' visual hull";
    if (depth_tried_points > 0) {
      text << ", narrowed to the " << depth_resolved_points << " of " << depth_tried_points
           << " points the photos place in depth to two voxels";
    }
  }
  return text.str();
}

Bounds ComputeBounds(const Reconstruction& reconstruction,
                     const BoundsOptions& options,
                     const std::string& source) {
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  Bounds bounds;
  bounds.num_points = static_cast<int>(reconstruction.points3D.size());
  if (reconstruction.points3D.empty()) {
    throw InputError(source +
                     ": the model has no 3D points, so they cannot bound the volume; give an "
                     "explicit box (--bbox)");
  }
  std::vector<Eigen::Vector3d> used;
  for (const auto& [point3D_id, point3D] : reconstruction.points3D) {
    if (static_cast<int>(point3D.track.size()) < options.min_track_length) {
      ++bounds.num_short_track;
    } else if (options.max_reprojection_error > 0.0 &&
               point3D.error > options.max_reprojection_error) {
      ++bounds.num_high_error;
    } else {
      used.push_back(point3D.xyz);
    }
  }
  DropTheRoom(reconstruction, options, &used, &bounds);
  bounds.num_used = static_cast<int>(used.size());
  if (used.empty()) {
    std::ostringstream message;
    message << source << ": all " << bounds.num_points << " 3D points were filtered out ("
            << bounds.num_short_track << " with track length < " << options.min_track_length
            << ", " << bounds.num_high_error << " with error > " << options.max_reprojection_error
            << " px); relax the filters or give an explicit box (--bbox)";
    throw InputError(message.str());
  }
  if (bounds.num_used < options.min_points) {
    throw InputError(source + ": only " + std::to_string(bounds.num_used) + " usable 3D points (of " +
                     std::to_string(bounds.num_points) + "), fewer than " +
                     std::to_string(options.min_points) +
                     ": too few to bound the volume reliably; give an explicit box (--bbox "
                     "x0,y0,z0,x1,y1,z1) or lower --min_points");
  }
  Eigen::Vector3d min, max;
  std::vector<double> values(used.size());
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < used.size(); ++i) values[i] = used[i][axis];
    min[axis] = Quantile(&values, options.trim_fraction);
    max[axis] = Quantile(&values, 1.0 - options.trim_fraction);
  }
  bounds.box = Eigen::AlignedBox3d(min, max);
  for (const Eigen::Vector3d& point : used) {
    if (!bounds.box.contains(point)) ++bounds.num_trimmed_outside;
  }
  const double extent = bounds.box.sizes().maxCoeff();
  if (!(extent > 0.0)) {
    throw InputError(source + ": the " + std::to_string(bounds.num_used) +
                     " usable 3D points span no volume; give an explicit box (--bbox)");
  }
  // A flat axis (all points on a plane) still gets the margin, so the box has volume.
  const Eigen::Vector3d pad = Eigen::Vector3d::Constant(options.margin * extent);
  bounds.box = Eigen::AlignedBox3d(min - pad, max + pad);
  if (!(bounds.box.sizes().minCoeff() > 0.0)) {
    throw InputError(source + ": the 3D points are flat along an axis and margin is 0; give a "
                              "margin or an explicit box (--bbox)");
  }
  return bounds;
}

Bounds ExplicitBounds(const Eigen::Vector3d& min, const Eigen::Vector3d& max) {
  if (!min.allFinite() || !max.allFinite()) {
    throw InputError("--bbox: coordinates must be finite numbers");
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (!(min[axis] < max[axis])) {
      throw InputError("--bbox: min must be below max on every axis (axis " +
                       std::to_string(axis) + ": " + std::to_string(min[axis]) +
                       " >= " + std::to_string(max[axis]) + ")");
    }
  }
  Bounds bounds;
  bounds.box = Eigen::AlignedBox3d(min, max);
  bounds.is_explicit = true;
  return bounds;
}

std::string CaptureLayout::Summary() const {
  std::ostringstream text;
  text.precision(3);
  text << (object_centred ? "cameras around a point (object-centred)"
                          : "cameras facing one way (a scene)")
       << ": seen from their common focus they fill a cone of " << cone_half_angle_degrees
       << " degrees, widest gap around it " << largest_gap_degrees << " degrees; the focus in front of "
       << focus_in_front << " of " << cameras;
  return text.str();
}

namespace {

// The values' range with a fiftieth left out at each end; sorts them.
std::pair<double, double> TrimmedRange(std::vector<double>* values) {
  std::sort(values->begin(), values->end());
  const size_t trim = values->size() / 50;
  return {(*values)[trim], (*values)[values->size() - 1 - trim]};
}

// The point nearest every optical axis (least squares: the sum over cameras of
// (I - a a^T) (x - c) = 0); false where the axes are all parallel.
bool NearestToAxes(const std::vector<Eigen::Vector3d>& centres,
                   const std::vector<Eigen::Vector3d>& axes, Eigen::Vector3d* focus) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d right = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < centres.size(); ++i) {
    const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - axes[i] * axes[i].transpose();
    normal += across;
    right += across * centres[i];
  }
  // Symmetric and positive semi-definite: singular only when every axis is parallel.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(normal);
  if (!(eigen.eigenvalues()(0) > 1e-6 * eigen.eigenvalues()(2))) return false;
  *focus = normal.ldlt().solve(right);
  return true;
}

// The cameras as seen from the focus: their median distance, the cone their directions fill
// and the widest gap between their azimuths around its axis, how many have the focus in front;
// from these whether the capture is object-centred.
void DescribeDirections(const std::vector<Eigen::Vector3d>& centres,
                        const std::vector<Eigen::Vector3d>& axes, CaptureLayout* layout) {
  std::vector<double> distances;
  std::vector<Eigen::Vector3d> directions;
  Eigen::Vector3d direction_sum = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < centres.size(); ++i) {
    const Eigen::Vector3d to_camera = centres[i] - layout->focus;
    distances.push_back(to_camera.norm());
    if (to_camera.norm() > 0.0) {
      directions.push_back(to_camera.normalized());
      direction_sum += directions.back();
    }
    layout->focus_in_front += axes[i].dot(layout->focus - centres[i]) > 0.0;
  }
  std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
  layout->camera_distance = distances[distances.size() / 2];
  // The directions about their mean: the cone's half angle, and their azimuths around it.
  const double kDegrees = 180.0 / M_PI;
  const Eigen::Vector3d mean =
      direction_sum.norm() > 1e-9 ? direction_sum.normalized() : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d u = mean.unitOrthogonal(), v = mean.cross(u);
  std::vector<double> azimuths;
  for (const Eigen::Vector3d& d : directions) {
    layout->cone_half_angle_degrees = std::max(
        layout->cone_half_angle_degrees, std::acos(std::clamp(d.dot(mean), -1.0, 1.0)) * kDegrees);
    const Eigen::Vector3d across = d - d.dot(mean) * mean;
    if (across.norm() > 1e-9) azimuths.push_back(std::atan2(across.dot(v), across.dot(u)) * kDegrees);
  }
  std::sort(azimuths.begin(), azimuths.end());
  if (azimuths.size() >= 2) {
    layout->largest_gap_degrees = 360.0 - (azimuths.back() - azimuths.front());
    for (size_t i = 1; i < azimuths.size(); ++i) {
      layout->largest_gap_degrees = std::max(layout->largest_gap_degrees, azimuths[i] - azimuths[i - 1]);
    }
  }
  const bool ring = layout->largest_gap_degrees <= kMaxObjectGapDegrees &&
                    layout->cone_half_angle_degrees >= kMinRingConeDegrees;
  const bool arc = layout->cone_half_angle_degrees >= kMinArcConeDegrees;
  layout->object_centred = layout->focus_in_front == layout->cameras && (ring || arc);
}

// The box of the sparse points (seen twice or more) that a photo centred on the focus frames
// (`half_fields`: the photos' half fields of view), grown to hold the points that stand in front
// of the subject.
void FindFocusBox(const Reconstruction& reconstruction, std::vector<double> half_fields,
                  CaptureLayout* layout) {
  double half_field = 0.5;
  if (!half_fields.empty()) {
    std::nth_element(half_fields.begin(), half_fields.begin() + half_fields.size() / 2,
                     half_fields.end());
    half_field = half_fields[half_fields.size() / 2];
  }
  const double radius = layout->camera_distance * std::tan(half_field);
  std::array<std::vector<double>, 3> coordinates;
  for (const auto& [id, point] : reconstruction.points3D) {
    if (point.track.size() < 2 || (point.xyz - layout->focus).norm() > radius) continue;
    for (int axis = 0; axis < 3; ++axis) coordinates[axis].push_back(point.xyz[axis]);
  }
  layout->focus_box_points = static_cast<int>(coordinates[0].size());
  if (layout->focus_box_points < 20) return;
  Eigen::Vector3d low, high;
  for (int axis = 0; axis < 3; ++axis) {
    std::tie(low[axis], high[axis]) = TrimmedRange(&coordinates[axis]);
  }
  const double margin = 0.1 * (high - low).maxCoeff();
  layout->focus_box = Eigen::AlignedBox3d(low.array() - margin, high.array() + margin);
  const std::vector<Eigen::Vector3d> occluders = FindOccluders(reconstruction, layout->focus_box);
  layout->occluder_points = static_cast<int>(occluders.size());
  if (layout->occluder_points < kMinOccluderPoints) return;
  // The box grows to hold them (trimmed as the focus points are), so that the carve sees what
  // stands in front of the subject instead of painting the subject with it.
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values;
    for (const Eigen::Vector3d& point : occluders) values.push_back(point[axis]);
    const auto [low_value, high_value] = TrimmedRange(&values);
    layout->focus_box.min()[axis] = std::min(layout->focus_box.min()[axis], low_value - margin);
    layout->focus_box.max()[axis] = std::max(layout->focus_box.max()[axis], high_value + margin);
  }
}

}  // namespace

CaptureLayout DescribeCapture(const Reconstruction& reconstruction) {
  CaptureLayout layout;
  std::vector<Eigen::Vector3d> centres, axes;
  std::vector<double> half_fields;
  for (const auto& [id, image] : reconstruction.images) {
    const Eigen::Vector3d centre = image.ProjectionCenter();
    // The optical axis: the camera's z axis in the world.
    const Eigen::Vector3d axis =
        image.cam_from_world.rotation.inverse() * Eigen::Vector3d::UnitZ();
    if (!centre.allFinite() || !axis.allFinite()) continue;
    centres.push_back(centre);
    axes.push_back(axis.normalized());
    const auto camera = reconstruction.cameras.find(image.camera_id);
    if (camera != reconstruction.cameras.end() && camera->second.FocalLengthX() > 0.0) {
      const double half_side = 0.5 * std::min(camera->second.width, camera->second.height);
      half_fields.push_back(std::atan(half_side / camera->second.FocalLengthX()));
    }
  }
  layout.cameras = static_cast<int>(centres.size());
  if (centres.size() < 2 || !NearestToAxes(centres, axes, &layout.focus)) return layout;
  DescribeDirections(centres, axes, &layout);
  FindFocusBox(reconstruction, std::move(half_fields), &layout);
  return layout;
}

std::vector<Eigen::Vector3d> FindOccluders(const Reconstruction& reconstruction,
                                           const Eigen::AlignedBox3d& box) {
  // Per image: the pixels and depths of the points inside the box that it does not observe
  // although they lie in its frame, in buckets of the neighbourhood's size.
  struct Hidden {
    Eigen::Vector2d pixel;
    double depth;
  };
  struct ImageBuckets {
    double cell = 1.0;
    int columns = 1;
    std::map<int64_t, std::vector<Hidden>> buckets;
  };
  std::map<image_t, ImageBuckets> hidden;
  std::map<image_t, std::set<point3D_t>> observed;
  for (const auto& [point_id, point] : reconstruction.points3D) {
    for (const TrackElement& element : point.track) observed[element.image_id].insert(point_id);
  }
  const auto project = [&](const Image& image, const Eigen::Vector3d& xyz, Eigen::Vector2d* pixel,
                           double* depth) {
    const auto camera = reconstruction.cameras.find(image.camera_id);
    if (camera == reconstruction.cameras.end()) return false;
    const Eigen::Vector3d local = image.cam_from_world * xyz;
    if (!(local.z() > 0.0)) return false;
    *pixel = camera->second.ImgFromCam(local.hnormalized());
    *depth = local.z();
    return pixel->allFinite() && pixel->x() >= 0.0 && pixel->y() >= 0.0 &&
           pixel->x() < camera->second.width && pixel->y() < camera->second.height;
  };
  for (const auto& [image_id, image] : reconstruction.images) {
    const auto camera = reconstruction.cameras.find(image.camera_id);
    if (camera == reconstruction.cameras.end()) continue;
    ImageBuckets& buckets = hidden[image_id];
    buckets.cell = std::max<double>(1.0, std::max(camera->second.width, camera->second.height) *
                                             kOccluderNeighbourhood);
    buckets.columns = static_cast<int>(camera->second.width / buckets.cell) + 1;
    const std::set<point3D_t>& seen = observed[image_id];
    for (const auto& [point_id, point] : reconstruction.points3D) {
      if (point.track.size() < 2 || !box.contains(point.xyz) || seen.count(point_id)) continue;
      Hidden entry;
      if (!project(image, point.xyz, &entry.pixel, &entry.depth)) continue;
      const int64_t key = static_cast<int64_t>(entry.pixel.y() / buckets.cell) * buckets.columns +
                          static_cast<int64_t>(entry.pixel.x() / buckets.cell);
      buckets.buckets[key].push_back(entry);
    }
  }
  std::vector<Eigen::Vector3d> occluders;
  for (const auto& [point_id, point] : reconstruction.points3D) {
    if (point.track.size() < 2 || box.contains(point.xyz)) continue;
    int hiding_views = 0;
    for (const TrackElement& element : point.track) {
      const auto image = reconstruction.images.find(element.image_id);
      if (image == reconstruction.images.end()) continue;
      Eigen::Vector2d pixel;
      double depth = 0.0;
      if (!project(image->second, point.xyz, &pixel, &depth)) continue;
      const ImageBuckets& buckets = hidden[element.image_id];
      const int column = static_cast<int>(pixel.x() / buckets.cell);
      const int row = static_cast<int>(pixel.y() / buckets.cell);
      int behind = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (column + dx < 0 || column + dx >= buckets.columns) continue;
          const auto bucket =
              buckets.buckets.find(static_cast<int64_t>(row + dy) * buckets.columns + column + dx);
          if (bucket == buckets.buckets.end()) continue;
          for (const Hidden& other : bucket->second) {
            behind += (other.pixel - pixel).norm() <= buckets.cell &&
                      other.depth > depth * (1.0 + kOccluderDepthGap);
          }
        }
      }
      hiding_views += behind >= kOccludedPointsPerView;
    }
    if (hiding_views >= kOccluderViews) occluders.push_back(point.xyz);
  }
  return occluders;
}

std::string DepthResolution::Summary() const {
  std::ostringstream text;
  text.precision(3);
  text << resolved << " of " << points << " sparse points placed in depth to "
       << kResolvedDepthVoxels << " voxels (of " << voxel << ") a pixel or better";
  if (!box.isEmpty()) {
    text << "; the box narrowed to them: (" << box.min().x() << ", " << box.min().y() << ", "
         << box.min().z() << ") - (" << box.max().x() << ", " << box.max().y() << ", "
         << box.max().z() << ")";
  }
  return text.str();
}

DepthResolution ResolveSceneDepth(const Reconstruction& reconstruction,
                                  const std::map<image_t, double>& focal_px,
                                  const Eigen::AlignedBox3d& box, int resolution) {
  DepthResolution result;
  if (box.isEmpty() || resolution <= 0) return result;
  result.voxel = box.sizes().maxCoeff() / resolution;
  std::map<image_t, Eigen::Vector3d> centres;
  for (const auto& [id, image] : reconstruction.images) centres[id] = image.ProjectionCenter();
  std::vector<Eigen::Vector3d> resolved;
  std::vector<Eigen::Vector3d> rays;
  std::vector<double> footprints;
  for (const auto& [id, point] : reconstruction.points3D) {
    if (!box.contains(point.xyz)) continue;
    rays.clear();
    footprints.clear();
    for (const TrackElement& element : point.track) {
      const auto focal = focal_px.find(element.image_id);
      const auto centre = centres.find(element.image_id);
      if (focal == focal_px.end() || centre == centres.end() || !(focal->second > 0.0)) continue;
      const Eigen::Vector3d ray = centre->second - point.xyz;
      const double distance = ray.norm();
      if (!(distance > 0.0)) continue;
      rays.push_back(ray / distance);
      footprints.push_back(distance / focal->second);
    }
    if (rays.size() < 2) continue;
    ++result.points;
    double min_cosine = 1.0;  // the widest angle between two of its rays
    for (size_t a = 0; a < rays.size(); ++a) {
      for (size_t b = a + 1; b < rays.size(); ++b) min_cosine = std::min(min_cosine, rays[a].dot(rays[b]));
    }
    const double sine = std::sqrt(std::max(0.0, 1.0 - min_cosine * min_cosine));
    std::nth_element(footprints.begin(), footprints.begin() + footprints.size() / 2,
                     footprints.end());
    const double footprint = footprints[footprints.size() / 2];
    if (footprint <= kResolvedDepthVoxels * result.voxel * sine) resolved.push_back(point.xyz);
  }
  result.resolved = static_cast<int>(resolved.size());
  if (result.resolved == result.points || result.resolved < 20 ||
      result.resolved < kMinResolvedShare * result.points) {
    return result;
  }
  Eigen::Vector3d low, high;
  std::vector<double> values(resolved.size());
  for (int axis = 0; axis < 3; ++axis) {
    for (size_t i = 0; i < resolved.size(); ++i) values[i] = resolved[i][axis];
    std::sort(values.begin(), values.end());
    const size_t trim = values.size() / 50;
    low[axis] = values[trim];
    high[axis] = values[values.size() - 1 - trim];
  }
  const double margin = 0.1 * (high - low).maxCoeff();
  const Eigen::AlignedBox3d narrowed =
      Eigen::AlignedBox3d(low.array() - margin, high.array() + margin).intersection(box);
  if (!narrowed.isEmpty() && narrowed.volume() < 0.95 * box.volume()) result.box = narrowed;
  return result;
}

}  // namespace raycarve
