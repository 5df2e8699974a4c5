// The tile planner on a generated city that no machine here could carve (issue 46, item 5):
// 10,000 photos of 12 MP along the streets of a 400 m x 400 m block grid, carved at 4096 voxels.
// The tiles and each tile's photos come from the planner's own code (SplitIntoTiles, BoxInView);
// no photo is made or carved. Prints a table per tile group and a JSON summary (--json).
//
// The city: streets 16 m wide every 80 m along x and along y (centres at 40, 120, ... 360 m), the
// blocks between them built up to 20 m. The cameras: every 1.6 m along each street's centre line,
// 1.6 m up, four photos per stop (each facade, 20 degrees either side of square on, tilted up 10
// degrees), 4000 x 3000 pixels, a focal length of 3000 pixels. Buildings hide everything off the
// street a photo is taken from, so a photo counts for a tile where the tile meets its street's
// corridor (the street between its facades, up to the roofs) inside the photo's view.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "calib/calibrated_view.h"
#include "carve/tiling.h"
#include "carve/voxel_grid.h"

namespace {

using raycarve::CalibratedView;

constexpr double kExtent = 400.0;     // metres, along x and y
constexpr double kHeight = 24.0;      // the volume's height (buildings 20 m)
constexpr double kBuildings = 20.0;
constexpr double kStreetSpacing = 80.0;
constexpr double kHalfStreet = 8.0;
constexpr double kStop = 1.6;         // metres between camera stops
constexpr int kWidth = 4000, kHeightPixels = 3000;
constexpr double kFocal = 3000.0;
constexpr int kResolution = 4096;
constexpr int kTileVoxels = 512;
constexpr int kOverlap = 8;
constexpr double kBytesPerPhotoPixel = 19.0;  // the photo as loaded (14), its rays (4), validity (1)
constexpr double kBytesPerVoxel = 3.0;
constexpr double kGiB = 1024.0 * 1024.0 * 1024.0;

// A camera at `centre` looking along the horizontal direction `yaw` (radians from +x), tilted up.
CalibratedView Camera(const Eigen::Vector3d& centre, double yaw, double pitch) {
  CalibratedView view;
  view.width = kWidth;
  view.height = kHeightPixels;
  view.K << kFocal, 0, kWidth / 2.0, 0, kFocal, kHeightPixels / 2.0, 0, 0, 1;
  const Eigen::Vector3d forward(std::cos(yaw) * std::cos(pitch), std::sin(yaw) * std::cos(pitch),
                                std::sin(pitch));
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d rotation;  // rows: camera x (right), y (down), z (forward) in world
  rotation.row(0) = right;
  rotation.row(1) = down;
  rotation.row(2) = forward;
  view.cam_from_world.rotation = Eigen::Quaterniond(rotation);
  view.cam_from_world.translation = -(rotation * centre);
  view.centre = centre;
  view.P.leftCols<3>() = view.K * rotation;
  view.P.col(3) = view.K * view.cam_from_world.translation;
  return view;
}

struct Street {
  int axis;         // 0: runs along x, 1: along y
  double position;  // its centre line's other coordinate
  Eigen::AlignedBox3d Corridor() const {
    Eigen::Vector3d lo(0, 0, 0), hi(kExtent, kExtent, kBuildings);
    lo[1 - axis] = position - kHalfStreet;
    hi[1 - axis] = position + kHalfStreet;
    return Eigen::AlignedBox3d(lo, hi);
  }
};

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(q * (values.size() - 1) + 0.5)];
}

}  // namespace

int main(int argc, char** argv) {
  const bool json = argc > 1 && std::strcmp(argv[1], "--json") == 0;
  std::vector<Street> streets;
  for (int axis = 0; axis < 2; ++axis) {
    for (double p = kStreetSpacing / 2; p < kExtent; p += kStreetSpacing) streets.push_back({axis, p});
  }
  std::vector<CalibratedView> views;
  std::vector<int> street_of;
  const double yaws[2] = {-20.0 * M_PI / 180.0, 20.0 * M_PI / 180.0};
  for (size_t s = 0; s < streets.size(); ++s) {
    const Street& street = streets[s];
    const double along = street.axis == 0 ? 0.0 : M_PI / 2;  // the street's direction
    for (double t = kStop / 2; t < kExtent; t += kStop) {
      Eigen::Vector3d centre(0, 0, 1.6);
      centre[street.axis] = t;
      centre[1 - street.axis] = street.position;
      for (double side : {-M_PI / 2, M_PI / 2}) {  // each facade, square on is along +- 90 degrees
        for (double yaw : yaws) {
          views.push_back(Camera(centre, along + side + yaw, 10.0 * M_PI / 180.0));
          street_of.push_back(static_cast<int>(s));
        }
      }
    }
  }
  const Eigen::AlignedBox3d box(Eigen::Vector3d::Zero(), Eigen::Vector3d(kExtent, kExtent, kHeight));
  const raycarve::VoxelGrid grid(box, kResolution);
  const Eigen::Vector3i n = grid.dimensions();
  const Eigen::Vector3i tiles((n.x() + kTileVoxels - 1) / kTileVoxels,
                              (n.y() + kTileVoxels - 1) / kTileVoxels,
                              (n.z() + kTileVoxels - 1) / kTileVoxels);
  const std::vector<raycarve::TileRegion> regions = raycarve::SplitIntoTiles(n, tiles, kOverlap);

  std::vector<double> photos_per_job, memory_2400, memory_1600;
  for (const raycarve::TileRegion& region : regions) {
    const Eigen::AlignedBox3d tile_box = grid.Region(region.lo, region.hi).Box();
    int photos = 0;
    for (size_t v = 0; v < views.size(); ++v) {
      const Eigen::AlignedBox3d seen = tile_box.intersection(streets[street_of[v]].Corridor());
      photos += !seen.isEmpty() && raycarve::BoxInView(views[v], seen);
    }
    if (photos == 0) continue;  // no photo sees it: no job (the coarse volume is empty there)
    const Eigen::Vector3i m = region.hi - region.lo;
    const double voxels = static_cast<double>(m.x()) * m.y() * m.z();
    photos_per_job.push_back(photos);
    memory_2400.push_back(0.5 + (photos * 2400.0 * 1800.0 * kBytesPerPhotoPixel + voxels * kBytesPerVoxel) / kGiB);
    memory_1600.push_back(0.5 + (photos * 1600.0 * 1200.0 * kBytesPerPhotoPixel + voxels * kBytesPerVoxel) / kGiB);
  }
  // The plan's coarse pass (levels up to 512) on photos reduced 8 times from 1600 x 1200, and the
  // merge's grid (a dense grid of 3 bytes a voxel) without its photos.
  const double plan_gib = 0.5 + (views.size() * 200.0 * 150.0 * kBytesPerPhotoPixel +
                                 raycarve::VoxelGrid(box, kResolution / 8).num_voxels() * kBytesPerVoxel) / kGiB;
  const double merge_grid_gib = grid.num_voxels() * kBytesPerVoxel / kGiB;
  int over_16 = 0;
  for (double gib : memory_1600) over_16 += gib > 16.0;
  if (json) {
    std::printf("{\"photos\": %zu, \"grid\": [%d, %d, %d], \"voxel_m\": %.4f, \"tiles\": [%d, %d, %d], "
                "\"jobs\": %zu, \"photos_per_job\": {\"min\": %.0f, \"median\": %.0f, \"max\": %.0f}, "
                "\"job_memory_gib_2400\": {\"median\": %.1f, \"max\": %.1f}, "
                "\"job_memory_gib_1600\": {\"median\": %.1f, \"max\": %.1f, \"over_16\": %d}, "
                "\"plan_memory_gib\": %.1f, \"merge_grid_gib\": %.1f}\n",
                views.size(), n.x(), n.y(), n.z(), grid.voxel_size(), tiles.x(), tiles.y(), tiles.z(),
                photos_per_job.size(), Quantile(photos_per_job, 0), Quantile(photos_per_job, 0.5),
                Quantile(photos_per_job, 1), Quantile(memory_2400, 0.5), Quantile(memory_2400, 1),
                Quantile(memory_1600, 0.5), Quantile(memory_1600, 1), over_16, plan_gib, merge_grid_gib);
    return 0;
  }
  std::printf("%zu photos of %dx%d along %zu streets; grid %dx%dx%d (voxel %.3f m) in %dx%dx%d tiles "
              "of %d voxels, overlap %d: %zu jobs (tiles no photo sees have none)\n",
              views.size(), kWidth, kHeightPixels, streets.size(), n.x(), n.y(), n.z(),
              grid.voxel_size(), tiles.x(), tiles.y(), tiles.z(), kTileVoxels, kOverlap,
              photos_per_job.size());
  std::printf("%-28s %8s %8s %8s\n", "per job", "min", "median", "max");
  std::printf("%-28s %8.0f %8.0f %8.0f\n", "photos", Quantile(photos_per_job, 0),
              Quantile(photos_per_job, 0.5), Quantile(photos_per_job, 1));
  std::printf("%-28s %8.1f %8.1f %8.1f\n", "memory GiB, photos at 2400", Quantile(memory_2400, 0),
              Quantile(memory_2400, 0.5), Quantile(memory_2400, 1));
  std::printf("%-28s %8.1f %8.1f %8.1f\n", "memory GiB, photos at 1600", Quantile(memory_1600, 0),
              Quantile(memory_1600, 0.5), Quantile(memory_1600, 1));
  std::printf("jobs over 16 GiB at 1600: %d; the plan's coarse pass (photos at 200x150): %.1f GiB; "
              "the merge's dense grid alone: %.1f GiB\n", over_16, plan_gib, merge_grid_gib);
  return 0;
}
