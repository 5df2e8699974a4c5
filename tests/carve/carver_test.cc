#include "carve/carver.h"
#include "carve/incremental_carver.h"

#include <algorithm>
#include <memory>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "carve/ray_cast_visibility.h"
#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

using testing::Options;
using testing::Scene;

TEST(IncrementalCarver, KeepsItsInvariantsWhileCarving) {
  const SyntheticScene scene = Scene(6, 120, 90);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  IncrementalCarver carver(views, scene.object_box, Options(24, 30.0));
  const Volume& volume = carver.volume();
  std::vector<bool> ever_empty(volume.grid().num_voxels(), false);
  std::vector<PixelRef> vis;
  int checks = 0;
  // Checked every 1500 evaluations (a step is one batch of voxels; CarveOptions::batch_voxels).
  for (int64_t next_check = 1500; carver.Step();) {
    if (carver.evaluated() < next_check) continue;
    next_check = carver.evaluated() + 1500;
    ++checks;
    for (int64_t i = 0; i < volume.grid().num_voxels(); ++i) {
      if (ever_empty[i]) {
        ASSERT_FALSE(volume.IsSolid(i)) << "carved voxel " << i << " came back";
      }
      if (!volume.IsSolid(i)) ever_empty[i] = true;
      ASSERT_EQ(volume.IsSurface(i), volume.IsExposed(i)) << i;
    }
    std::vector<std::vector<int>> owners(views.size());
    for (size_t v = 0; v < views.size(); ++v) {
      owners[v].assign(views[v].width * views[v].height, 0);
      for (int pixel = 0; pixel < views[v].width * views[v].height; ++pixel) {
        const int64_t voxel = carver.ray_visibility()->rays(v).CurrentVoxel(pixel);
        ASSERT_TRUE(voxel == RayImage::kNoVoxel || volume.IsSolid(voxel))
            << "view " << v << " pixel " << pixel << " ends in an empty voxel";
      }
    }
    for (int64_t voxel : volume.SurfaceVoxels()) {
      vis.clear();
      carver.visibility().ComputeVis(voxel, &vis);
      for (const PixelRef& ref : vis) ASSERT_EQ(++owners[ref.view][ref.pixel], 1);
    }
  }
  EXPECT_GE(checks, 3);
  EXPECT_GT(carver.carved(), 1000);
  EXPECT_EQ(carver.queue_size(), 0u);
}

// Carving outside the batches' pipeline (the removal of small components) while a batch is in
// flight: the batch goes back to the queue first, so that no stale Vis is judged.
TEST(IncrementalCarver, ABatchInFlightGoesBackToTheQueueWhenCarvingHappensOutsideThePipeline) {
  const SyntheticScene scene = Scene(6, 120, 90);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  CarveOptions options = Options(24, 30.0);
  options.num_threads = 2;
  IncrementalCarver untouched(views, scene.object_box, options);
  IncrementalCarver kept(views, scene.object_box, options);
  IncrementalCarver emptied(views, scene.object_box, options);
  for (int step = 0; step < 20; ++step) {
    ASSERT_TRUE(kept.Step());
    ASSERT_TRUE(emptied.Step());
  }
  const size_t queued = kept.queue_size();
  ASSERT_GT(queued, 0u);
  // Nothing smaller than 1 voxel: nothing carved, the batch stays in flight, the carving goes on
  // exactly as without the call.
  EXPECT_EQ(kept.RemoveSmallComponents(1), 0);
  EXPECT_EQ(kept.queue_size(), queued);
  while (kept.Step()) {
  }
  while (untouched.Step()) {
  }
  EXPECT_EQ(CompareVolumes(kept.volume(), untouched.volume()).differing(), 0);
  EXPECT_EQ(kept.evaluated(), untouched.evaluated());
  // Every piece is small: all carved, each voxel's rays stepped on, the batch back in the queue
  // and skipped there (its voxels are gone).
  const int64_t solid = emptied.volume().num_solid();
  ASSERT_GT(solid, 0);
  EXPECT_EQ(emptied.RemoveSmallComponents(int64_t{1} << 40), solid);
  EXPECT_EQ(emptied.volume().num_solid(), 0);
  while (emptied.Step()) {
  }
  EXPECT_EQ(emptied.queue_size(), 0u);
  for (size_t v = 0; v < views.size(); ++v) {
    for (int pixel = 0; pixel < views[v].width * views[v].height; ++pixel) {
      ASSERT_EQ(emptied.ray_visibility()->rays(v).CurrentVoxel(pixel), RayImage::kNoVoxel);
    }
  }
}

TEST(CarveVolume, AThresholdSoLooseThatEverythingIsConsistentCarvesNothing) {
  const SyntheticScene scene = Scene(4, 80, 60);
  const CarveResult result =
      CarveVolume(testing::SceneViews(scene), scene.object_box, Options(20, 1e9));
  EXPECT_EQ(result.statistics.carved, 0);
  EXPECT_EQ(result.statistics.evaluated, result.statistics.initial_surface);
  EXPECT_EQ(result.volume.num_solid(), result.volume.grid().num_voxels());
}

TEST(CarveVolume, AVoxelSeenByMoreThan65535PixelsOfAViewIsColouredAsOneAtATimeColoursIt) {
  // Batches keep a view's colour sums as 32-bit integers, split where a voxel has more pixels
  // in a view than a sum of squares holds; one voxel at a time keeps doubles. A coarse grid on
  // large photos: voxels hundreds of pixels wide. Nothing is carved (the threshold admits
  // everything), so both colour the same surface.
  const SyntheticScene scene = Scene(2, 1600, 1200);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  CarveOptions options = Options(3, 1e9);
  options.lod_levels = 1;
  const CarveResult batched = CarveVolume(views, scene.object_box, options);
  options.batch_voxels = 1;
  const CarveResult single = CarveVolume(views, scene.object_box, options);
  ASSERT_EQ(batched.surface.size(), single.surface.size());
  int most_pixels = 0;
  for (size_t i = 0; i < single.surface.size(); ++i) {
    const ColouredVoxel& a = batched.surface[i];
    const ColouredVoxel& b = single.surface[i];
    ASSERT_EQ(a.index, b.index);
    EXPECT_EQ(a.num_pixels, b.num_pixels) << "voxel " << a.index;
    EXPECT_EQ(a.num_views, b.num_views) << "voxel " << a.index;
    EXPECT_EQ(a.colour, b.colour) << "voxel " << a.index;
    most_pixels = std::max(most_pixels, b.num_pixels);
  }
  // Two views: some voxel has more than 65535 pixels in one of them.
  EXPECT_GT(most_pixels, 2 * 65535);
}

TEST(CarveVolume, AThresholdSoTightThatNothingIsConsistentCarvesEverythingSeenTwice) {
  const SyntheticScene scene = Scene(4, 80, 60);
  const CarveResult result =
      CarveVolume(testing::SceneViews(scene), scene.object_box, Options(20, -1.0));
  EXPECT_GT(result.statistics.carved, 0);
  for (const ColouredVoxel& voxel : result.surface) {
    EXPECT_LT(voxel.num_views, 2) << "voxel " << voxel.index << " survived, seen by "
                                  << voxel.num_views << " views";
  }
}

// CarveOptions::lod_carve_depth's held voxels (interior_held) are never carved by the test:
// nothing is consistent, everything else seen twice goes.
TEST(IncrementalCarver, HeldInteriorVoxelsSurviveATestThatFindsThemInconsistent) {
  const SyntheticScene scene = Scene(4, 80, 60);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  CarveOptions options = Options(20, -1.0);
  const VoxelGrid grid(scene.object_box, 20);
  const Eigen::Vector3d centre = (grid.dimensions().cast<double>() - Eigen::Vector3d::Ones()) / 2;
  for (int64_t i = 0; i < grid.num_voxels(); ++i) {
    if ((grid.Voxel(i).cast<double>() - centre).norm() <= 3.0) options.interior_held.push_back(i);
  }
  ASSERT_GT(options.interior_held.size(), 50u);
  for (const bool held : {false, true}) {
    CarveOptions run = options;
    if (!held) run.interior_held.clear();
    IncrementalCarver carver(views, scene.object_box, run);
    while (carver.Step()) {
    }
    int64_t solid = 0;
    for (int64_t i : options.interior_held) solid += carver.volume().IsSolid(i);
    if (held) {
      EXPECT_EQ(solid, static_cast<int64_t>(options.interior_held.size()));
      EXPECT_GT(carver.protected_kept(), 0);
    } else {
      EXPECT_EQ(solid, 0);  // without the hold the test carves them all
    }
    EXPECT_GT(carver.carved(), 1000);
  }
}

// Two carvings are the same: counts, every voxel, and every surface voxel's colour and pixels.
void ExpectSameCarving(const CarveResult& a, const CarveResult& b, const std::string& context) {
  EXPECT_EQ(a.statistics.carved, b.statistics.carved) << context;
  EXPECT_EQ(a.statistics.evaluated, b.statistics.evaluated) << context;
  ASSERT_EQ(a.volume.grid().num_voxels(), b.volume.grid().num_voxels()) << context;
  int64_t differing = 0;
  for (int64_t i = 0; i < a.volume.grid().num_voxels(); ++i) {
    differing += a.volume.IsSolid(i) != b.volume.IsSolid(i);
  }
  EXPECT_EQ(differing, 0) << context;
  ASSERT_EQ(a.surface.size(), b.surface.size()) << context;
  for (size_t i = 0; i < a.surface.size(); ++i) {
    EXPECT_EQ(a.surface[i].colour, b.surface[i].colour) << context;
    EXPECT_EQ(a.surface[i].num_pixels, b.surface[i].num_pixels) << context;
  }
}

TEST(CarveVolume, FootprintScansAndRayListsCarveIdentically) {
  const SyntheticScene scene = Scene(6, 160, 120);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  CarveOptions options = Options(48, 30.0);
  options.batch_voxels = 1;  // ray lists carve one voxel at a time
  const CarveResult footprint = CarveVolume(views, scene.object_box, options);
  options.vis_lookup = VisLookup::kRayLists;
  const CarveResult lists = CarveVolume(views, scene.object_box, options);
  EXPECT_GT(footprint.statistics.carved, 1000);
  ExpectSameCarving(lists, footprint, "ray lists against footprints");
}

TEST(CarveVolume, AnyNumberOfThreadsCarvesExactlyAsOneDoes) {
  const SyntheticScene scene = Scene(6, 160, 120);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  struct Variant {
    CarveDecision decision;
    int batch_voxels;  // 1: one voxel at a time, its views shared by the threads
    int lod_levels;
  };
  for (const Variant& variant : {Variant{CarveDecision::kThreshold, 64, 1},
                                 Variant{CarveDecision::kThreshold, 7, 2},
                                 Variant{CarveDecision::kThreshold, 1, 1},
                                 Variant{CarveDecision::kReprojection, 64, 1}}) {
    CarveOptions options = Options(48, 30.0);
    options.decision = variant.decision;
    options.batch_voxels = variant.batch_voxels;
    options.lod_levels = variant.lod_levels;
    options.num_threads = 1;
    const std::string name = CarveDecisionToString(variant.decision) + ", batches of " +
                             std::to_string(variant.batch_voxels) + ", " +
                             std::to_string(variant.lod_levels) + " levels, ";
    const CarveResult one = CarveVolume(views, scene.object_box, options);
    EXPECT_GT(one.statistics.carved, 1000) << name;
    EXPECT_EQ(one.statistics.threads, 1) << name;
    // 2 threads: views dealt 3 and 3; 4: dealt 2, 2, 1, 1; 9: more threads than views, capped
    // at one a view (more threads than this machine's cores is allowed, only slower).
    for (const int threads : {2, 4, 9}) {
      options.num_threads = threads;
      const CarveResult many = CarveVolume(views, scene.object_box, options);
      ExpectSameCarving(many, one, name + std::to_string(threads) + " threads");
      EXPECT_EQ(many.statistics.reprojection_error_after, one.statistics.reprojection_error_after)
          << name << threads << " threads";
      EXPECT_EQ(many.statistics.threads, std::min<int>(threads, views.size())) << name;
      // Every thread worked, and none worked longer than the parallel sections lasted.
      ASSERT_EQ(many.statistics.thread_work_seconds.size(), many.statistics.threads) << name;
      for (double work : many.statistics.thread_work_seconds) {
        EXPECT_LE(work, many.statistics.parallel_seconds + 1e-6) << name;
      }
      EXPECT_GT(many.statistics.parallel_runs, 0) << name;
    }
  }
}

TEST(CarveVolume, IncrementalStatisticsCarveExactlyAsGatheringDoes) {
  const SyntheticScene scene = Scene(6, 160, 120);
  const std::vector<CalibratedView> views = testing::SceneViews(scene);
  struct Variant {
    CarveDecision decision;
    CarveOrder order;
    int lod_levels;
    int threads;
  };
  for (const Variant& variant : {Variant{CarveDecision::kThreshold, CarveOrder::kFifo, 1, 1},
                                 Variant{CarveDecision::kThreshold, CarveOrder::kFifo, 1, 2},
                                 Variant{CarveDecision::kReprojection, CarveOrder::kFifo, 1, 2},
                                 Variant{CarveDecision::kThreshold, CarveOrder::kVisiblePixels, 1, 1},
                                 Variant{CarveDecision::kThreshold, CarveOrder::kFifo, 2, 1}}) {
    CarveOptions options = Options(48, 30.0);
    options.batch_voxels = 1;  // incremental statistics carve one voxel at a time
    options.decision = variant.decision;
    options.order = variant.order;
    options.lod_levels = variant.lod_levels;
    options.num_threads = variant.threads;
    const CarveResult gathered = CarveVolume(views, scene.object_box, options);
    options.incremental_statistics = true;
    const CarveResult incremental = CarveVolume(views, scene.object_box, options);
    const std::string name = CarveDecisionToString(variant.decision) + " " +
                             CarveOrderToString(variant.order) + " lod " +
                             std::to_string(variant.lod_levels) + " threads " +
                             std::to_string(variant.threads);
    EXPECT_GT(gathered.statistics.carved, 1000) << name;
    ExpectSameCarving(incremental, gathered, name);
  }
  CarveOptions gvc = Options(48, 30.0);
  gvc.method = CarveMethod::kGvc;
  gvc.incremental_statistics = true;
  std::string reason;
  EXPECT_FALSE(gvc.IsValid(&reason));
  EXPECT_NE(reason.find("ray casting"), std::string::npos) << reason;
}

}  // namespace
}  // namespace raycarve
