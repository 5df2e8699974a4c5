#include "carve/mask_agreement.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "carve/block_occupancy.h"
#include "carve/ray_image.h"
#include "carve/view_workers.h"
#include "carve/visual_hull.h"
#include "carve/volume.h"

namespace raycarve {
namespace {

// Points sampled along a ray inside the hull, half a voxel apart (see AgreeMasks).
constexpr int kDepthSamples = 6;
// The other views whose colours a pixel is compared with: its nearest.
constexpr size_t kNeighbourViews = 8;

int64_t Sum(const std::vector<int64_t>& values) {
  int64_t total = 0;
  for (int64_t value : values) total += value;
  return total;
}

}  // namespace

int64_t MaskAgreementStatistics::TotalAdded() const { return Sum(added); }
int64_t MaskAgreementStatistics::TotalObjectBefore() const { return Sum(object_before); }

std::string MaskAgreementStatistics::Summary(const std::vector<std::string>& names) const {
  if (views == 0) return "masks not compared across views (fewer than 3 masked views)";
  int most = -1;
  double most_share = 0.0;
  for (size_t v = 0; v < added.size(); ++v) {
    const double share = static_cast<double>(added[v]) / std::max<int64_t>(1, object_before[v]);
    if (added[v] > 0 && (most < 0 || share > most_share)) {
      most = static_cast<int>(v);
      most_share = share;
    }
  }
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << "masks agreed across " << views << " views: "
       << 100.0 * TotalAdded() / std::max<int64_t>(1, TotalObjectBefore())
       << "% more object pixels (background pixels inside the hull that 2+ views leave, in the "
          "colour the others see there); most in "
       << (most >= 0 && most < static_cast<int>(names.size()) ? names[most] : std::string("none"))
       << " (+" << std::setprecision(1) << 100.0 * most_share << "%); " << std::setprecision(2)
       << seconds << " s";
  return text.str();
}

namespace {

// Per masked view, the other masked views nearest to it (by camera centre), at most
// kNeighbourViews: they see most of what it sees from the same side.
std::vector<std::vector<size_t>> NearestMaskedViews(const std::vector<CalibratedView>& views) {
  const size_t num_views = views.size();
  std::vector<std::vector<size_t>> neighbours(num_views);
  for (size_t v = 0; v < num_views; ++v) {
    if (views[v].mask.empty()) continue;
    for (size_t u = 0; u < num_views; ++u) {
      if (u != v && !views[u].mask.empty()) neighbours[v].push_back(u);
    }
    const Eigen::Vector3d& at = views[v].centre;
    std::stable_sort(neighbours[v].begin(), neighbours[v].end(), [&](size_t a, size_t b) {
      return (views[a].centre - at).squaredNorm() < (views[b].centre - at).squaredNorm();
    });
    if (neighbours[v].size() > kNeighbourViews) neighbours[v].resize(kNeighbourViews);
  }
  return neighbours;
}

// The median colour the `neighbours` (masked views) show on their object at `point`, judged on
// their masks as made (`original`); false where fewer than two do, or where
// `min_background_views` of them show the point on background. (Occlusion is not asked: well
// inside the object's outline in every view, the photos agree on little else.)
bool OthersSee(const std::vector<CalibratedView>& views,
               const std::vector<cv::Mat>& original,
               const std::vector<size_t>& neighbours,
               int min_background_views,
               const Eigen::Vector3d& point,
               Eigen::Vector3d* colour) {
  std::array<double, kNeighbourViews> channel[3];
  size_t seen = 0;
  int background = 0;
  for (size_t u : neighbours) {
    const CalibratedView& other = views[u];
    const Eigen::Vector3d image = other.P * point.homogeneous();
    if (!(image.z() > 0.0)) continue;
    const int col = static_cast<int>(std::floor(image.x() / image.z()));
    const int row = static_cast<int>(std::floor(image.y() / image.z()));
    if (col < 0 || row < 0 || col >= other.width || row >= other.height) continue;
    if (!other.valid.empty() && other.valid.at<uint8_t>(row, col) == 0) continue;
    // Two neighbours showing the point on background say it is not the object's, as two
    // views carve a voxel from the voting hull.
    if (original[u].at<uint8_t>(row, col) == 0) {
      if (++background >= min_background_views) return false;
      continue;
    }
    const cv::Vec3b rgb = other.image.at<cv::Vec3b>(row, col);
    for (int c = 0; c < 3; ++c) channel[c][seen] = rgb[c];
    ++seen;
  }
  if (seen < 2) return false;
  for (int c = 0; c < 3; ++c) {
    const auto middle = channel[c].begin() + static_cast<std::ptrdiff_t>(seen / 2);
    std::nth_element(channel[c].begin(), middle, channel[c].begin() + static_cast<std::ptrdiff_t>(seen));
    (*colour)[c] = *middle;
  }
  return true;
}

// The pixels of `view` whose rays meet the voting hull at least a voxel's width inside its
// outline (in the view, at the volume's centre `centre`).
cv::Mat InsideHullOutline(const CalibratedView& view,
                          const VoxelGrid& grid,
                          const Volume& hull,
                          const BlockOccupancy& blocks,
                          const Eigen::Vector3d& centre) {
  const int threads = 1;  // per view: the views themselves share the cores
  // The pixels whose rays meet the voting hull, and those a voxel's width inside its outline:
  // from rays through every other pixel along each axis (the pixel (c, r) of the half-size
  // image is the point (2c + 1, 2r + 1) of the photo), a quarter of the work, then at full
  // size for the pixels that may change.
  const int half_width = (view.width + 1) / 2, half_height = (view.height + 1) / 2;
  const Eigen::Matrix3d world_from_half = view.WorldFromPixel() * Eigen::Vector3d(2, 2, 1).asDiagonal();
  cv::Mat half_valid;
  if (!view.valid.empty()) {
    cv::resize(view.valid, half_valid, cv::Size(half_width, half_height), 0, 0, cv::INTER_NEAREST);
  }
  RayImage coarse(grid, world_from_half, view.centre, half_width, half_height, half_valid);
  coarse.Initialise(hull, &blocks, threads);
  cv::Mat half_meets(half_height, half_width, CV_8UC1, cv::Scalar(0));
  for (int pixel = 0; pixel < coarse.num_pixels(); ++pixel) {
    if (coarse.CurrentVoxel(pixel) != RayImage::kNoVoxel) half_meets.data[pixel] = 255;
  }
  cv::Mat meets;
  cv::resize(half_meets, meets, cv::Size(view.width, view.height), 0, 0, cv::INTER_NEAREST);
  const double depth = view.Depth(centre);
  const double focal = 0.5 * (view.K(0, 0) + view.K(1, 1));
  const int radius =
      depth > 0.0 ? std::max(1, static_cast<int>(std::ceil(focal * grid.voxel_size() / depth))) : 1;
  cv::Mat inside;
  cv::erode(meets, inside,
            cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1)));
  return inside;
}

}  // namespace

MaskAgreementStatistics AgreeMasks(const Eigen::AlignedBox3d& box,
                                   const MaskAgreementOptions& options,
                                   std::vector<CalibratedView>* views) {
  const auto start = std::chrono::steady_clock::now();
  MaskAgreementStatistics statistics;
  const size_t num_views = views->size();
  statistics.added.assign(num_views, 0);
  statistics.object_before.assign(num_views, 0);
  int masked = 0;
  for (const CalibratedView& view : *views) masked += !view.mask.empty();
  if (masked < 3) return statistics;
  statistics.views = masked;
  const VoxelGrid grid(box, options.resolution);
  Volume hull(grid);
  CarveVisualHull(*views, &hull, options.num_threads, options.min_background_views);
  statistics.hull_voxels = hull.num_solid();
  const BlockOccupancy blocks(hull);
  // The masks as made: each view's change is judged against the others' own masks.
  std::vector<cv::Mat> original(num_views);
  for (size_t v = 0; v < num_views; ++v) original[v] = (*views)[v].mask;
  const std::vector<std::vector<size_t>> neighbours = NearestMaskedViews(*views);
  const Eigen::Vector3d centre = box.center();
  // The views one at a time on every core: each judges its pixels against the others' masks as
  // made (original) and writes only its own mask and counts, so the order does not matter.
  ViewWorkers workers(static_cast<int>(num_views), options.num_threads);
  const int threads = 1;  // per view: the views themselves share the cores
  auto agree = [&](size_t v) {
    CalibratedView& view = (*views)[v];
    if (view.mask.empty()) return;
    statistics.object_before[v] = cv::countNonZero(view.mask);
    const cv::Mat inside = InsideHullOutline(view, grid, hull, blocks, centre);
    const cv::Mat candidates = inside & (view.mask == 0);
    if (cv::countNonZero(candidates) == 0) return;
    cv::Mat agreed = view.mask.clone();
    RayImage rays(grid, view.WorldFromPixel(), view.centre, view.width, view.height, candidates);
    rays.Initialise(hull, &blocks, threads);
    for (int pixel = 0; pixel < rays.num_pixels(); ++pixel) {
      if (candidates.data[pixel] == 0 || rays.CurrentVoxel(pixel) == RayImage::kNoVoxel) continue;
      // The surface lies within the hull's first voxels along the ray (the hull is fat by about
      // a voxel): points every half voxel over the first three, the pixel's colour against what
      // the others see at each.
      const Eigen::Vector3d pixel_colour(view.image.data[3 * static_cast<size_t>(pixel)],
                                         view.image.data[3 * static_cast<size_t>(pixel) + 1],
                                         view.image.data[3 * static_cast<size_t>(pixel) + 2]);
      const Eigen::Vector3d direction = rays.Direction(pixel);  // a unit step of camera depth
      const double entry = view.Depth(grid.Centre(grid.Voxel(rays.CurrentVoxel(pixel))));
      bool agrees = false;
      for (int k = 0; k <= kDepthSamples && !agrees; ++k) {
        const double t = entry + (0.5 * k - 0.5) * grid.voxel_size();
        Eigen::Vector3d seen;
        agrees = OthersSee(*views, original, neighbours[v], options.min_background_views,
                           view.centre + t * direction, &seen) &&
                 (pixel_colour - seen).norm() <= options.colour_tolerance;
      }
      if (!agrees) continue;
      agreed.data[pixel] = 255;
      ++statistics.added[v];
    }
    view.mask = agreed;
  };
  ClaimItems(workers, static_cast<int>(num_views), 1, [&](int v, int /*group*/) { agree(v); });
  statistics.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return statistics;
}

}  // namespace raycarve
