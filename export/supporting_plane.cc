#include "export/supporting_plane.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <utility>

#include <Eigen/Eigenvalues>
#include <glog/logging.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/msac.h>
#include <pcl/sample_consensus/sac_model_plane.h>

namespace raycarve {
namespace exporter {

namespace {

// `points` less `centre`, in single precision: centred, so that they keep their detail far from
// the origin.
pcl::PointCloud<pcl::PointXYZ>::Ptr CentredCloud(const std::vector<Eigen::Vector3d>& points,
                                                 const Eigen::Vector3d& centre) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d q = p - centre;
    cloud->push_back(pcl::PointXYZ(static_cast<float>(q.x()), static_cast<float>(q.y()),
                                   static_cast<float>(q.z())));
  }
  return cloud;
}

}  // namespace

std::string SupportingPlane::Summary() const {
  std::ostringstream text;
  text.precision(3);
  if (points < 20) return "no supporting plane (too few sparse points)";
  text << (found ? "a supporting plane" : "no supporting plane") << ": normal (" << normal.x()
       << ", " << normal.y() << ", " << normal.z() << "), " << 100.0 * on_plane_share
       << "% of " << points << " sparse points on it (within " << tolerance << "), "
       << 100.0 * below_share << "% below it, " << 100.0 * cameras_above_share
       << "% of the cameras above it";
  if (angle_to_photos_up >= 0.0) {
    text << ", " << angle_to_photos_up << " degrees from the photos' up";
  }
  if (spread_ratio >= 0.0) {
    text << ", its points spread " << spread_ratio << " x as wide as all the points"
         << (found_by_spread ? " (a floor around what stands on it)" : "");
  }
  if (densest_on_share >= 0.0) {
    text << " (passed over: the densest plane, " << 100.0 * densest_on_share << "% on it and "
         << 100.0 * densest_below_share << "% below it";
    if (densest_angle_to_photos_up >= 0.0) {
      text << ", " << densest_angle_to_photos_up << " degrees from the photos' up";
    }
    text << ")";
  }
  return text.str();
}

bool SupportingPlane::Level() const {
  return angle_to_photos_up < 0.0 || angle_to_photos_up <= kMaxLevelAngle;
}

namespace {

// Nothing much under the plane, the cameras above it: whether it could be a support, however many
// points it holds.
bool CouldSupport(const SupportingPlane& plane) {
  return plane.below_share <= kMaxBelowShare && plane.cameras_above_share >= kMinCamerasAbove;
}

// `coefficients` (a plane of the centred cloud) as a SupportingPlane in the world frame, oriented
// towards the majority of `cameras`, with its shares of `points` (false for a degenerate plane).
bool MeasurePlane(const Eigen::VectorXf& coefficients, const Eigen::Vector3d& centre,
                  const std::vector<Eigen::Vector3d>& points,
                  const std::vector<Eigen::Vector3d>& cameras, const PhotosUp& up,
                  SupportingPlane* plane) {
  Eigen::Vector3d normal(coefficients[0], coefficients[1], coefficients[2]);
  if (!(normal.norm() > 0.0)) return false;
  double offset = coefficients[3] / normal.norm();
  normal.normalize();
  offset -= normal.dot(centre);  // back to the world frame
  int above = 0;
  for (const Eigen::Vector3d& c : cameras) above += normal.dot(c) + offset > 0.0;
  if (2 * above < static_cast<int>(cameras.size())) {
    normal = -normal;
    offset = -offset;
    above = static_cast<int>(cameras.size()) - above;
  }
  int on = 0, below = 0;
  for (const Eigen::Vector3d& p : points) {
    const double distance = normal.dot(p) + offset;
    on += std::abs(distance) <= plane->tolerance;
    below += distance < -plane->tolerance;
  }
  plane->normal = normal;
  plane->offset = offset;
  plane->on_plane_share = static_cast<double>(on) / points.size();
  plane->below_share = static_cast<double>(below) / points.size();
  plane->cameras_above_share =
      cameras.empty() ? 0.0 : static_cast<double>(above) / cameras.size();
  plane->angle_to_photos_up =
      up.Known() ? std::acos(std::clamp(normal.dot(up.up), -1.0, 1.0)) * 180.0 / M_PI : -1.0;
  plane->found = plane->on_plane_share >= kMinSupportShare && CouldSupport(*plane);
  return true;
}

// How closely `plane` holds `points`: each point within the tolerance scores 1 - d / tolerance, d
// its distance (the truncated cost of MSAC, Torr and Zisserman 2000, as PCL's takes it), the sum
// over the points' number. Two planes that hold as many points within the tolerance differ here
// where one holds them close (a floor's points) and the other only crosses the band (a plane tilted
// through the floor's points and an object's).
double CloseHoldScore(const SupportingPlane& plane, const std::vector<Eigen::Vector3d>& points) {
  double score = 0.0;
  for (const Eigen::Vector3d& p : points) {
    const double d = std::abs(plane.normal.dot(p) + plane.offset) / plane.tolerance;
    if (d <= 1.0) score += 1.0 - d;
  }
  return points.empty() ? 0.0 : score / static_cast<double>(points.size());
}

// `coefficients` refined by least squares on the points of the centred cloud within `tolerance`.
Eigen::VectorXf Refined(pcl::SampleConsensusModelPlane<pcl::PointXYZ>& model,
                        const Eigen::VectorXf& coefficients, double tolerance) {
  pcl::Indices inliers;
  model.selectWithinDistance(coefficients, tolerance, inliers);
  Eigen::VectorXf refined = coefficients;
  if (inliers.size() >= 3) model.optimizeModelCoefficients(inliers, coefficients, refined);
  return refined;
}

// The planes that could be a support (at most kMaxBelowShare of the points below it,
// kMinCamerasAbove of the cameras above it) holding the most points closely (CloseHoldScore): of
// any direction, and level with the photos' up (Level: any where the photos do not know up). Planes
// through random triples of points (a fixed seed), scored on up to 1,000 of the points; empty
// coefficients where none could. Where wrong matches or an object's sides hold more points on
// another plane than the ground holds, the ground is still the densest plane with (nearly) nothing
// under it.
struct SupportCandidates {
  Eigen::VectorXf any, level;
};
SupportCandidates DrawSupportCandidates(pcl::SampleConsensusModelPlane<pcl::PointXYZ>& model,
                                        const Eigen::Vector3d& centre,
                                        const std::vector<Eigen::Vector3d>& points,
                                        const std::vector<Eigen::Vector3d>& cameras,
                                        const PhotosUp& up, const SupportingPlane& measure) {
  // A plane holding kMinSupportShareWithNothingBelow (0.1) of the points: a triple of them comes
  // up once in 1,000 draws, so 10,000 draws miss it with a chance of about 5e-5.
  constexpr int kDraws = 10000;
  constexpr size_t kScoredPoints = 1000;
  std::mt19937 random(7);
  std::vector<Eigen::Vector3d> scored = points;
  if (scored.size() > kScoredPoints) {
    std::shuffle(scored.begin(), scored.end(), random);
    scored.resize(kScoredPoints);
  }
  std::uniform_int_distribution<int> pick(0, static_cast<int>(points.size()) - 1);
  double best_any = -1.0, best_level = -1.0;
  SupportCandidates best;
  for (int draw = 0; draw < kDraws; ++draw) {
    const pcl::Indices sample = {pick(random), pick(random), pick(random)};
    Eigen::VectorXf coefficients;
    if (sample[0] == sample[1] || sample[1] == sample[2] || sample[0] == sample[2] ||
        !model.computeModelCoefficients(sample, coefficients)) {
      continue;
    }
    SupportingPlane candidate = measure;
    if (!MeasurePlane(coefficients, centre, scored, cameras, up, &candidate) ||
        !CouldSupport(candidate)) {
      continue;
    }
    const double score = CloseHoldScore(candidate, scored);
    if (score > best_any) {
      best_any = score;
      best.any = coefficients;
    }
    if (candidate.Level() && score > best_level) {
      best_level = score;
      best.level = coefficients;
    }
  }
  return best;
}

// The area over which a set of points spreads along a plane with axes u, v: the square root of
// the determinant of their 2-D covariance (0 for fewer than 3 points).
double SpreadAlong(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& u,
                   const Eigen::Vector3d& v) {
  if (points.size() < 3) return 0.0;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector3d& p : points) mean += Eigen::Vector2d(u.dot(p), v.dot(p));
  mean /= static_cast<double>(points.size());
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector2d q = Eigen::Vector2d(u.dot(p), v.dot(p)) - mean;
    covariance += q * q.transpose();
  }
  covariance /= static_cast<double>(points.size());
  return std::sqrt(std::max(0.0, covariance.determinant()));
}

// The spread of the points on `plane` along it against all the points' (SupportingPlane::
// spread_ratio), and their number.
double SpreadRatio(const SupportingPlane& plane, const std::vector<Eigen::Vector3d>& points,
                   int* on_count) {
  std::vector<Eigen::Vector3d> on;
  for (const Eigen::Vector3d& p : points) {
    if (std::abs(plane.normal.dot(p) + plane.offset) <= plane.tolerance) on.push_back(p);
  }
  *on_count = static_cast<int>(on.size());
  const Eigen::Vector3d u = plane.normal.unitOrthogonal(), v = plane.normal.cross(u);
  const double all = SpreadAlong(points, u, v);
  return all > 0.0 ? SpreadAlong(on, u, v) / all : 0.0;
}

// A candidate's plane refined on all the points and measured into *plane: whether it is a support
// with nothing below it (kMinSupportShareWithNothingBelow on it; level where `level_only`, and
// then also one whose points spread as widely as all the points: kMinWideSupportSpread).
bool AcceptCandidate(pcl::SampleConsensusModelPlane<pcl::PointXYZ>& model,
                     const Eigen::VectorXf& coefficients, const Eigen::Vector3d& centre,
                     const std::vector<Eigen::Vector3d>& points,
                     const std::vector<Eigen::Vector3d>& cameras, const PhotosUp& up,
                     bool level_only, SupportingPlane* plane) {
  if (coefficients.size() == 0 ||
      !MeasurePlane(Refined(model, coefficients, plane->tolerance), centre, points, cameras, up,
                    plane)) {
    return false;
  }
  // A support has nothing under it: the points just under the plane may be its own that a tilt
  // left out (SettleOnPoints). The settled plane is taken where it leaves fewer points under it
  // and holds as many on it or more.
  Eigen::Vector3d normal = plane->normal;
  double offset = plane->offset;
  if (SettleOnPoints(points, plane->tolerance, &normal, &offset)) {
    Eigen::VectorXf settled(4);
    settled << static_cast<float>(normal.x()), static_cast<float>(normal.y()),
        static_cast<float>(normal.z()), static_cast<float>(offset + normal.dot(centre));
    SupportingPlane measured = *plane;
    if (MeasurePlane(settled, centre, points, cameras, up, &measured) &&
        measured.below_share < plane->below_share &&
        measured.on_plane_share >= plane->on_plane_share) {
      *plane = measured;
    }
  }
  if (!CouldSupport(*plane) || (level_only && !plane->Level())) return false;
  if (plane->on_plane_share >= kMinSupportShareWithNothingBelow) {
    plane->found = true;
    return true;
  }
  if (!level_only || !up.Known() || plane->below_share > kMaxBelowShareWide) return false;
  int on = 0;
  plane->spread_ratio = SpreadRatio(*plane, points, &on);
  plane->found_by_spread =
      on >= kMinWideSupportPoints && plane->spread_ratio >= kMinWideSupportSpread;
  plane->found = plane->found_by_spread;
  return plane->found;
}

}  // namespace

bool SettleOnPoints(const std::vector<Eigen::Vector3d>& points, double tolerance,
                    Eigen::Vector3d* normal, double* offset) {
  std::vector<size_t> held;
  bool moved = false;
  for (int round = 0; round < kMaxSettleRounds; ++round) {
    std::vector<size_t> next;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (size_t i = 0; i < points.size(); ++i) {
      const double d = normal->dot(points[i]) + *offset;
      if (d <= tolerance && d >= -kUnderReach * tolerance) {
        next.push_back(i);
        mean += points[i];
      }
    }
    if (next == held || next.size() < 3) break;
    held = std::move(next);
    mean /= static_cast<double>(held.size());
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (size_t i : held) scatter += (points[i] - mean) * (points[i] - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
    Eigen::Vector3d fitted = eigen.eigenvectors().col(0);  // the least spread: the normal
    if (!(fitted.norm() > 0.0)) break;
    fitted.normalize();
    if (fitted.dot(*normal) < 0.0) fitted = -fitted;
    *normal = fitted;
    *offset = -fitted.dot(mean);
    moved = true;
  }
  return moved;
}

SupportingPlane FitSupportingPlane(const std::vector<Eigen::Vector3d>& points,
                                   const std::vector<Eigen::Vector3d>& cameras,
                                   const PhotosUp& up, double tolerance) {
  SupportingPlane plane;
  plane.points = static_cast<int>(points.size());
  plane.tolerance = tolerance;
  plane.photos_up = up;
  if (points.size() < 20 || !(tolerance > 0.0)) return plane;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) centre += p;
  centre /= static_cast<double>(points.size());
  const pcl::PointCloud<pcl::PointXYZ>::Ptr cloud = CentredCloud(points, centre);
  pcl::SampleConsensusModelPlane<pcl::PointXYZ>::Ptr model(
      new pcl::SampleConsensusModelPlane<pcl::PointXYZ>(cloud));  // fixed seed
  // MSAC: of the planes through random triples, the one holding the points most closely (the
  // sum of their distances, each at most the tolerance: CloseHoldScore), not merely the most
  // within the tolerance.
  pcl::MEstimatorSampleConsensus<pcl::PointXYZ> msac(model, tolerance);
  msac.setMaxIterations(1000);
  if (!msac.computeModel()) return plane;
  pcl::Indices inliers;
  msac.getInliers(inliers);
  Eigen::VectorXf coefficients;
  msac.getModelCoefficients(coefficients);
  Eigen::VectorXf refined = coefficients;
  if (inliers.size() >= 3) model->optimizeModelCoefficients(inliers, coefficients, refined);
  if (!MeasurePlane(refined, centre, points, cameras, up, &plane)) return plane;
  if (plane.found && plane.Level()) return plane;
  // The densest plane is no support (points under it, or cameras on both sides) or not level: the
  // densest level plane that could be one, then (where there is none) the densest support of any
  // direction.
  const auto passed_over = [&plane](SupportingPlane support) {
    support.densest_on_share = plane.on_plane_share;
    support.densest_below_share = plane.below_share;
    support.densest_angle_to_photos_up = plane.angle_to_photos_up;
    return support;
  };
  const SupportCandidates candidates =
      DrawSupportCandidates(*model, centre, points, cameras, up, plane);
  SupportingPlane support = plane;
  if (up.Known() && AcceptCandidate(*model, candidates.level, centre, points, cameras, up,
                                    /*level_only=*/true, &support)) {
    return passed_over(support);
  }
  if (plane.found) return plane;
  support = plane;
  if (AcceptCandidate(*model, candidates.any, centre, points, cameras, up, /*level_only=*/false,
                      &support)) {
    return passed_over(support);
  }
  return plane;
}

namespace {

// The convex hull of points on a plane (Andrew's monotone chain in the plane's coordinates),
// counter-clockwise about `normal`.
std::vector<Eigen::Vector3d> HullOnPlane(const std::vector<Eigen::Vector3d>& points,
                                         const Eigen::Vector3d& normal) {
  const Eigen::Vector3d helper =
      std::abs(normal.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = normal.cross(helper).normalized(), v = normal.cross(u);
  std::vector<std::pair<Eigen::Vector2d, size_t>> q;
  for (size_t i = 0; i < points.size(); ++i) q.push_back({{u.dot(points[i]), v.dot(points[i])}, i});
  std::sort(q.begin(), q.end(), [](const auto& a, const auto& b) {
    return a.first.x() < b.first.x() || (a.first.x() == b.first.x() && a.first.y() < b.first.y());
  });
  const auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<size_t> hull(2 * q.size());
  size_t k = 0;
  for (size_t i = 0; i < q.size(); ++i) {  // lower chain
    while (k >= 2 && cross(q[hull[k - 2]].first, q[hull[k - 1]].first, q[i].first) <= 0.0) --k;
    hull[k++] = i;
  }
  for (size_t i = q.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && cross(q[hull[k - 2]].first, q[hull[k - 1]].first, q[i].first) <= 0.0) --k;
    hull[k++] = i;
  }
  std::vector<Eigen::Vector3d> outline;
  for (size_t i = 0; i + 1 < k; ++i) outline.push_back(points[q[hull[i]].second]);
  return outline;
}

}  // namespace

Ground GroundUnder(const SupportingPlane& plane, const std::vector<Eigen::Vector3d>& points,
                   const std::vector<Eigen::Vector3d>& hole_points,
                   const std::vector<bool>& checked) {
  Ground ground;
  if (!plane.found) return ground;
  CHECK(checked.empty() || checked.size() == points.size());
  std::vector<Eigen::Vector3d> on, below;
  std::vector<bool> on_checked;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    const double distance = plane.normal.dot(p) + plane.offset;
    if (std::abs(distance) <= plane.tolerance) {
      on.push_back(p - distance * plane.normal);
      on_checked.push_back(checked.empty() || checked[i]);
    }
  }
  for (const Eigen::Vector3d& p : hole_points) {
    const double distance = plane.normal.dot(p) + plane.offset;
    if (distance < -plane.tolerance) below.push_back(p - distance * plane.normal);
  }
  if (on.size() < 3) return ground;
  const pcl::PointCloud<pcl::PointXYZ>::Ptr cloud = CentredCloud(on, on.front());
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(cloud);
  std::vector<double> spacing;
  pcl::Indices found;
  std::vector<float> distances;
  for (const pcl::PointXYZ& p : cloud->points) {
    // The nearest other point (past any at the same place: a point seen twice).
    const int count = tree.nearestKSearch(p, 4, found, distances);
    for (int k = 1; k < count; ++k) {
      if (distances[k] > 0.0f) {
        spacing.push_back(std::sqrt(distances[k]));
        break;
      }
    }
  }
  if (spacing.empty()) return ground;
  std::nth_element(spacing.begin(), spacing.begin() + spacing.size() / 2, spacing.end());
  const double radius = 2.0 * spacing[spacing.size() / 2];
  if (!(radius > 0.0)) return ground;
  // Lone unchecked points: no other place on the plane within the discs' diameter.
  std::vector<Eigen::Vector3d> kept;
  kept.reserve(on.size());
  for (size_t i = 0; i < on.size(); ++i) {
    bool keep = on_checked[i];
    if (!keep) {
      tree.radiusSearch(cloud->points[i], static_cast<float>(2.0 * radius), found, distances);
      for (float d : distances) keep = keep || d > 0.0f;
    }
    if (keep) {
      kept.push_back(on[i]);
    } else {
      ++ground.lone_points;
    }
  }
  if (kept.size() < 3) return Ground();
  ground.normal = plane.normal;
  ground.offset = plane.offset;
  ground.depth = plane.tolerance;
  ground.radius = radius;
  ground.outline = HullOnPlane(kept, plane.normal);
  ground.footprint = std::move(kept);
  ground.holes = std::move(below);
  return ground;
}

}  // namespace exporter
}  // namespace raycarve
