#include "carve/ray_image.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

namespace raycarve {
namespace {

// Brute force: the voxels whose (open) interior the segment of the ray inside the box crosses,
// ordered by entry parameter. A voxel that the ray only touches along an edge or at a corner
// (zero length inside) is not included.
std::vector<int64_t> BruteForceVoxels(const VoxelGrid& grid,
                                      const Eigen::Vector3d& origin,
                                      const Eigen::Vector3d& direction) {
  std::vector<std::pair<double, int64_t>> hits;
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    const Eigen::Vector3i voxel = grid.Voxel(index);
    const Eigen::Vector3d lo = grid.Corner(voxel, 0), hi = grid.Corner(voxel, 7);
    double t0 = 0.0, t1 = 1e300;
    bool miss = false;
    for (int axis = 0; axis < 3 && !miss; ++axis) {
      if (direction[axis] == 0.0) {
        if (origin[axis] <= lo[axis] || origin[axis] >= hi[axis]) miss = true;
        continue;
      }
      double a = (lo[axis] - origin[axis]) / direction[axis];
      double b = (hi[axis] - origin[axis]) / direction[axis];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
    }
    if (!miss && t1 - t0 > 1e-9) hits.emplace_back(t0, index);
  }
  std::sort(hits.begin(), hits.end());
  std::vector<int64_t> voxels;
  for (const auto& [t, index] : hits) voxels.push_back(index);
  return voxels;
}

// Walks one ray through an empty volume by carving each voxel it reaches, recording the visits.
std::vector<int64_t> TraversedVoxels(const VoxelGrid& grid,
                                     const Eigen::Vector3d& origin,
                                     const Eigen::Vector3d& direction) {
  Volume volume(grid);
  // A 1x1 "image" whose only pixel centre (0.5, 0.5) maps to `direction`.
  Eigen::Matrix3d world_from_pixel = Eigen::Matrix3d::Zero();
  world_from_pixel.col(2) = direction;
  RayImage rays(grid, world_from_pixel, origin, 1, 1);
  rays.Initialise(volume);
  std::vector<int64_t> visited;
  for (int64_t voxel = rays.CurrentVoxel(0); voxel != RayImage::kNoVoxel;
       voxel = rays.Advance(0, volume)) {
    visited.push_back(voxel);
    volume.Carve(voxel, nullptr);
    if (visited.size() > 1000) break;
  }
  return visited;
}

const VoxelGrid kGrid(Eigen::AlignedBox3d(Eigen::Vector3d(-1, -0.5, 0), Eigen::Vector3d(1, 0.5, 1)), 8);

TEST(RayImage, TraversalVisitsExactlyTheVoxelsARandomRayCrosses) {
  // kGrid (8x4x4) and one whose dimensions are not powers of two, so that the packed keys have
  // unused values.
  const VoxelGrid odd_grid(
      Eigen::AlignedBox3d(Eigen::Vector3d(-1, -0.5, 0), Eigen::Vector3d(1, 0.2, 1.05)), 11);
  ASSERT_EQ(odd_grid.dimensions(), Eigen::Vector3i(11, 4, 6));
  for (const VoxelGrid& grid : {kGrid, odd_grid}) {
    std::mt19937_64 random(42);
    std::uniform_real_distribution<double> uniform(-1.0, 1.0);
    int rays_hitting = 0;
    for (int trial = 0; trial < 300; ++trial) {
      const Eigen::Vector3d origin(3 * uniform(random), 3 * uniform(random), 3 * uniform(random));
      const Eigen::Vector3d target(uniform(random), -0.15 + 0.35 * uniform(random),
                                   0.5 + 0.5 * uniform(random));
      const Eigen::Vector3d direction = target - origin;
      const std::vector<int64_t> expected = BruteForceVoxels(grid, origin, direction);
      EXPECT_EQ(TraversedVoxels(grid, origin, direction), expected) << "trial " << trial;
      rays_hitting += !expected.empty();
    }
    EXPECT_GT(rays_hitting, 250);
  }
}

TEST(RayImage, KeysHoldGridsWhoseCoordinatesNeedAtMost31Bits) {
  EXPECT_TRUE(RayImage::KeyBitsFit(Eigen::Vector3i(1, 1, 1)));
  EXPECT_TRUE(RayImage::KeyBitsFit(Eigen::Vector3i(1024, 1024, 1024)));   // 30 bits
  EXPECT_TRUE(RayImage::KeyBitsFit(Eigen::Vector3i(2048, 1024, 1000)));   // 31
  EXPECT_FALSE(RayImage::KeyBitsFit(Eigen::Vector3i(2048, 2048, 1024)));  // 32
  EXPECT_FALSE(RayImage::KeyBitsFit(Eigen::Vector3i(4096, 4096, 129)));   // 32
  EXPECT_FALSE(RayImage::KeyBitsFit(Eigen::Vector3i(0, 4, 4)));
}

TEST(RayImage, RaysAlongGridPlanesEdgesAndCornersStayOnAConnectedPathOfTouchedVoxels) {
  const double s = kGrid.voxel_size();  // 0.25: planes at exact binary fractions
  ASSERT_EQ(s, 0.25);
  const struct {
    Eigen::Vector3d origin, direction;
  } cases[] = {
      {{-3, 0.0, 0.5}, {1, 0, 0}},            // along the plane y = 0 and z = 0.5: an edge line
      {{-3, 0.125, 0.5}, {1, 0, 0}},          // along the plane z = 0.5
      {{-3, -3.5, -3}, {1, 1, 1}},            // through voxel corners (diagonal)
      {{-1.5, 0.125, -0.5}, {1, 0, 1}},       // through edges in the xz plane
      {{-1, -0.5, 0}, {1, 1, 1}},             // starting exactly on the box's corner
      {{0.0, 0.0, 3.0}, {0, 0, -1}},          // straight down an edge line
  };
  for (const auto& c : cases) {
    const std::vector<int64_t> visited = TraversedVoxels(kGrid, c.origin, c.direction);
    const std::vector<int64_t> crossed = BruteForceVoxels(kGrid, c.origin, c.direction);
    ASSERT_FALSE(visited.empty()) << c.origin.transpose();
    // Every voxel with a segment inside is visited, in order.
    size_t next = 0;
    for (int64_t voxel : visited) {
      if (next < crossed.size() && crossed[next] == voxel) ++next;
    }
    EXPECT_EQ(next, crossed.size()) << "missed a crossed voxel, ray from " << c.origin.transpose();
    // Consecutive visits are face neighbours, and each visited voxel's closed box touches the ray.
    for (size_t i = 0; i < visited.size(); ++i) {
      const Eigen::Vector3i voxel = kGrid.Voxel(visited[i]);
      if (i > 0) {
        EXPECT_EQ((voxel - kGrid.Voxel(visited[i - 1])).cwiseAbs().sum(), 1);
      }
      const Eigen::Vector3d lo = kGrid.Corner(voxel, 0), hi = kGrid.Corner(voxel, 7);
      double t0 = -1e300, t1 = 1e300;
      for (int axis = 0; axis < 3; ++axis) {
        if (c.direction[axis] == 0.0) {
          EXPECT_TRUE(c.origin[axis] >= lo[axis] - 1e-12 && c.origin[axis] <= hi[axis] + 1e-12);
          continue;
        }
        double a = (lo[axis] - c.origin[axis]) / c.direction[axis];
        double b = (hi[axis] - c.origin[axis]) / c.direction[axis];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
      }
      EXPECT_LE(t0, t1 + 1e-9) << "visited a voxel the ray does not touch";
    }
  }
}

// A volume of a few random solid balls on a grid whose dimensions are not multiples of the
// block size, so that most blocks are empty and the edge blocks are partial.
Volume RandomBalls(const VoxelGrid& grid, int balls, std::mt19937_64* random) {
  const Eigen::Vector3i& n = grid.dimensions();
  std::vector<uint64_t> solid((grid.num_voxels() + 63) / 64, 0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int ball = 0; ball < balls; ++ball) {
    const Eigen::Vector3d centre(n.x() * unit(*random), n.y() * unit(*random), n.z() * unit(*random));
    const double radius = 1.5 + 3.5 * unit(*random);
    for (int64_t index = 0; index < grid.num_voxels(); ++index) {
      const Eigen::Vector3d at = grid.Voxel(index).cast<double>().array() + 0.5;
      if ((at - centre).norm() <= radius) solid[index >> 6] |= uint64_t{1} << (index & 63);
    }
  }
  return Volume(grid, std::move(solid));
}

// A 40x30 camera `distance` from the origin in a random direction, looking at a random point of
// the box (-0.8, -0.5, -0.4) .. (0.8, 0.5, 0.4): its world_from_pixel (pixel (u, v, 1) ->
// forward + (u - 20) right + (v - 15) down, right and down 1/25 long) and its `centre`.
Eigen::Matrix3d RandomLookAt(double distance, std::mt19937_64* random, Eigen::Vector3d* centre) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  *centre = Eigen::Vector3d(uniform(*random), uniform(*random), uniform(*random));
  *centre = distance * centre->normalized();
  const Eigen::Vector3d target(0.8 * uniform(*random), 0.5 * uniform(*random),
                               0.4 * uniform(*random));
  const Eigen::Vector3d forward = (target - *centre).normalized();
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d(0.3, 0.1, 1)).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d world_from_pixel;
  world_from_pixel.col(0) = right / 25.0;
  world_from_pixel.col(1) = down / 25.0;
  world_from_pixel.col(2) = forward - 20.0 * right / 25.0 - 15.0 * down / 25.0;
  return world_from_pixel;
}

TEST(RayImage, CrossingEmptyBlocksReachesTheSameFirstSolidVoxelsAsSteppingEveryVoxel) {
  const VoxelGrid grid(
      Eigen::AlignedBox3d(Eigen::Vector3d(-1, -0.7, -0.5), Eigen::Vector3d(1, 0.7, 0.6)), 23);
  ASSERT_EQ(grid.dimensions(), Eigen::Vector3i(23, 17, 13));
  std::mt19937_64 random(7);
  int64_t hits = 0, rays_compared = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const Volume volume = RandomBalls(grid, trial % 5 == 0 ? 0 : 2 + trial % 7, &random);
    const BlockOccupancy blocks(volume);
    // A camera somewhere around the box; every fourth inside it, where blocks reach behind the
    // camera (pixels are then traced everywhere, not only under the blocks' projections).
    Eigen::Vector3d centre;
    const Eigen::Matrix3d world_from_pixel =
        RandomLookAt(trial % 4 == 3 ? 0.4 : 3.0, &random, &centre);
    RayImage every_voxel(grid, world_from_pixel, centre, 40, 30);
    RayImage by_blocks(grid, world_from_pixel, centre, 40, 30);
    RayImage threaded(grid, world_from_pixel, centre, 40, 30);
    every_voxel.Initialise(volume);
    by_blocks.Initialise(volume, &blocks);
    threaded.Initialise(volume, &blocks, 1 + trial % 4);  // the pixels split among threads
    for (int pixel = 0; pixel < 40 * 30; ++pixel) {
      ASSERT_EQ(by_blocks.CurrentVoxel(pixel), every_voxel.CurrentVoxel(pixel))
          << "trial " << trial << " pixel " << pixel;
      ASSERT_EQ(threaded.CurrentVoxel(pixel), by_blocks.CurrentVoxel(pixel))
          << "trial " << trial << " pixel " << pixel;
      hits += every_voxel.CurrentVoxel(pixel) != RayImage::kNoVoxel;
      ++rays_compared;
    }
  }
  // The comparison covers both rays that hit and rays that cross the whole grid.
  EXPECT_GT(hits, rays_compared / 20);
  EXPECT_LT(hits, rays_compared / 2);
}

TEST(RayImage, ArrivalBitsSayExactlyWhichSolidVoxelsSomeRayEndsIn) {
  const VoxelGrid grid(
      Eigen::AlignedBox3d(Eigen::Vector3d(-1, -0.7, -0.5), Eigen::Vector3d(1, 0.7, 0.6)), 23);
  std::mt19937_64 random(11);
  for (int trial = 0; trial < 6; ++trial) {
    Volume volume = trial % 2 == 0 ? Volume(grid) : RandomBalls(grid, 4, &random);
    const BlockOccupancy blocks(volume);
    Eigen::Matrix3d world_from_pixel;  // a 40x30 camera looking down the -x axis at the box
    world_from_pixel.col(0) = Eigen::Vector3d(0, 1, 0) / 25.0;
    world_from_pixel.col(1) = Eigen::Vector3d(0, 0, -1) / 25.0;
    world_from_pixel.col(2) = Eigen::Vector3d(-1, 0.05 * trial, 0.1) -
                              20.0 * world_from_pixel.col(0) - 15.0 * world_from_pixel.col(1);
    RayImage rays(grid, world_from_pixel, Eigen::Vector3d(3, 0.1, 0.2), 40, 30);
    ASSERT_TRUE(rays.HasArrivalBits());  // 5,083 voxels, 1,200 pixels
    rays.Initialise(volume, trial < 3 ? nullptr : &blocks, trial == 5 ? 2 : 1);
    // Carve the voxel of a random ray, step every ray that ended there, and compare the bits of
    // every solid voxel with the rays.
    for (int carving = 0; carving < 300; ++carving) {
      if (carving % 50 == 0) {
        std::vector<bool> ends(grid.num_voxels(), false);
        for (int pixel = 0; pixel < 40 * 30; ++pixel) {
          if (rays.CurrentVoxel(pixel) != RayImage::kNoVoxel) ends[rays.CurrentVoxel(pixel)] = true;
        }
        int64_t ended = 0;
        for (int64_t voxel = 0; voxel < grid.num_voxels(); ++voxel) {
          if (!volume.IsSolid(voxel)) continue;
          ASSERT_EQ(rays.MayEndIn(voxel), ends[voxel]) << "trial " << trial << " voxel " << voxel;
          ended += ends[voxel];
        }
        EXPECT_GT(ended, 0);
      }
      const int pixel = static_cast<int>(random() % (40 * 30));
      const int64_t voxel = rays.CurrentVoxel(pixel);
      if (voxel == RayImage::kNoVoxel) continue;
      volume.Carve(voxel, nullptr);
      for (int other = 0; other < 40 * 30; ++other) {
        if (rays.CurrentVoxel(other) == voxel) rays.Advance(other, volume);
      }
    }
  }
}

TEST(RayImage, AdvancingACarvedVoxelsRaysTogetherReachesWhatAdvancingEachOneDoes) {
  const VoxelGrid grid(
      Eigen::AlignedBox3d(Eigen::Vector3d(-1, -0.7, -0.5), Eigen::Vector3d(1, 0.7, 0.6)), 23);
  std::mt19937_64 random(5);
  int64_t rays_stepped = 0, rays_gone = 0;
  for (int trial = 0; trial < 12; ++trial) {
    Volume volume = RandomBalls(grid, 2 + trial % 5, &random);
    // A camera around the box (every third inside it).
    Eigen::Vector3d centre;
    const Eigen::Matrix3d world_from_pixel =
        RandomLookAt(trial % 3 == 2 ? 0.4 : 3.0, &random, &centre);
    RayImage one_by_one(grid, world_from_pixel, centre, 40, 30);
    RayImage together(grid, world_from_pixel, centre, 40, 30);
    one_by_one.Initialise(volume);
    together.Initialise(volume);
    for (int carving = 0; carving < 200; ++carving) {
      const int pixel = static_cast<int>(random() % (40 * 30));
      const int64_t voxel = one_by_one.CurrentVoxel(pixel);
      if (voxel == RayImage::kNoVoxel) continue;
      volume.Carve(voxel, nullptr);
      std::vector<PixelRef> refs;
      std::vector<int64_t> expected, reached;
      for (int other = 0; other < 40 * 30; ++other) {
        if (one_by_one.CurrentVoxel(other) != voxel) continue;
        refs.emplace_back(0, other);
        const int64_t next = one_by_one.Advance(other, volume);
        if (next != RayImage::kNoVoxel) expected.push_back(next);
        rays_gone += next == RayImage::kNoVoxel;
      }
      together.AdvanceFromCarved(grid.Voxel(voxel), refs.data(), refs.data() + refs.size(),
                                 volume, &reached);
      rays_stepped += static_cast<int64_t>(refs.size());
      ASSERT_EQ(reached, expected) << "trial " << trial << " carving " << carving;
      for (int other = 0; other < 40 * 30; ++other) {
        ASSERT_EQ(together.CurrentVoxel(other), one_by_one.CurrentVoxel(other))
            << "trial " << trial << " carving " << carving << " pixel " << other;
      }
    }
    for (int64_t voxel = 0; voxel < grid.num_voxels(); ++voxel) {
      ASSERT_EQ(together.MayEndIn(voxel), one_by_one.MayEndIn(voxel)) << "voxel " << voxel;
    }
  }
  // Many rays stepped, some of them out of the box.
  EXPECT_GT(rays_stepped, 2000);
  EXPECT_GT(rays_gone, 0);
}

TEST(RayImage, RaysMissingTheBoxOrMaskedOutHaveNoVoxel) {
  Volume volume(kGrid);
  Eigen::Matrix3d away = Eigen::Matrix3d::Zero();
  away.col(2) = Eigen::Vector3d(0, 0, 1);  // upwards from above the box
  RayImage rays(kGrid, away, Eigen::Vector3d(0, 0, 2), 1, 1);
  rays.Initialise(volume);
  EXPECT_EQ(rays.CurrentVoxel(0), RayImage::kNoVoxel);
  Eigen::Matrix3d down = Eigen::Matrix3d::Zero();
  down.col(2) = Eigen::Vector3d(0.01, 0.02, -1);
  cv::Mat masked(1, 1, CV_8UC1, cv::Scalar(0));
  RayImage masked_rays(kGrid, down, Eigen::Vector3d(0, 0, 2), 1, 1, masked);
  masked_rays.Initialise(volume);
  EXPECT_EQ(masked_rays.CurrentVoxel(0), RayImage::kNoVoxel);
  RayImage open_rays(kGrid, down, Eigen::Vector3d(0, 0, 2), 1, 1);
  open_rays.Initialise(volume);
  EXPECT_EQ(kGrid.Voxel(open_rays.CurrentVoxel(0)).z(), 3);  // the top layer
  EXPECT_EQ(open_rays.MemoryBytes(), 4u);  // one packed key a pixel
}

// One pixel whose ray falls straight down through the grid at (0.1, 0.1), initialised on `volume`.
RayImage OnePixelLookingDown(const Volume& volume) {
  Eigen::Matrix3d down = Eigen::Matrix3d::Zero();
  down.col(2) = Eigen::Vector3d(0, 0, -1);
  RayImage rays(kGrid, down, Eigen::Vector3d(0.1, 0.1, 2), 1, 1);
  rays.Initialise(volume);
  return rays;
}

TEST(RayImage, StepsToTheNextSolidVoxelAfterCarving) {
  Volume volume(kGrid);
  RayImage rays = OnePixelLookingDown(volume);
  const int64_t top = rays.CurrentVoxel(0);
  // Carve the top two voxels of the column: the ray skips both in one Advance.
  volume.Carve(top, nullptr);
  const int64_t below = kGrid.Index(kGrid.Voxel(top) - Eigen::Vector3i(0, 0, 1));
  volume.Carve(below, nullptr);
  const int64_t next = rays.Advance(0, volume);
  EXPECT_EQ(kGrid.Voxel(next), kGrid.Voxel(top) - Eigen::Vector3i(0, 0, 2));
  EXPECT_EQ(rays.Advance(0, volume), next);  // already solid: stays
}

TEST(RayImage, PeekingBeyondTheCurrentVoxelChangesNothingAndFindsWhatAdvanceWouldReach) {
  Volume volume(kGrid);
  RayImage rays = OnePixelLookingDown(volume);
  const int64_t top = rays.CurrentVoxel(0);
  const int64_t below = kGrid.Index(kGrid.Voxel(top) - Eigen::Vector3i(0, 0, 1));
  EXPECT_EQ(rays.PeekBeyondCurrent(0, volume), below);
  volume.Carve(below, nullptr);  // then the one after it
  const int64_t two_below = kGrid.Index(kGrid.Voxel(top) - Eigen::Vector3i(0, 0, 2));
  EXPECT_EQ(rays.PeekBeyondCurrent(0, volume), two_below);
  EXPECT_EQ(rays.CurrentVoxel(0), top);  // unchanged
  volume.Carve(top, nullptr);
  EXPECT_EQ(rays.Advance(0, volume), two_below);
  // The last voxel of the column: nothing beyond it.
  for (int64_t voxel = rays.CurrentVoxel(0); voxel != RayImage::kNoVoxel;
       voxel = rays.Advance(0, volume)) {
    if (rays.PeekBeyondCurrent(0, volume) == RayImage::kNoVoxel) {
      EXPECT_EQ(kGrid.Voxel(voxel).z(), 0);
      return;
    }
    volume.Carve(voxel, nullptr);
  }
  FAIL() << "the column ended without a voxel with nothing beyond it";
}

}  // namespace
}  // namespace raycarve
