#include "carve/ground_pixels.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "calib/pixel.h"
#include "calib/ray_box.h"
#include "tests/ground_fixture.h"
#include "tests/test_support.h"

namespace raycarve {
namespace {

using testing::CellColour;

// The floor y = 0 (cells of 0.07, each a colour of its own; about 3 pixels in the photos) under a
// box standing on it, plain red or in cells of its own; a grey sky beyond.
const Eigen::AlignedBox3d kObject(Eigen::Vector3d(-0.3, 0.0, -0.3), Eigen::Vector3d(0.3, 0.5, 0.3));
// The volume carved.
const Eigen::AlignedBox3d kVolume(Eigen::Vector3d(-1.2, -0.2, -1.2), Eigen::Vector3d(1.2, 1.2, 1.2));

Eigen::Vector3d Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& d, bool textured_box,
                      bool* floor) {
  *floor = false;
  double t0 = 0.0, t1 = 0.0;
  const double t_floor = d.y() < 0.0 ? -origin.y() / d.y() : HUGE_VAL;
  if (ClipRayToBox(origin, d, kObject, &t0, &t1) && t0 < t_floor) {
    if (!textured_box) return Eigen::Vector3d(200, 30, 30);
    const Eigen::Vector3d x = origin + t0 * d;
    return CellColour(static_cast<int>(std::floor((x.x() + x.z()) / 0.07)),
                      static_cast<int>(std::floor(x.y() / 0.07)), 5);
  }
  if (t_floor < HUGE_VAL) {
    *floor = true;
    const Eigen::Vector3d x = origin + t_floor * d;
    return CellColour(static_cast<int>(std::floor(x.x() / 0.07)), static_cast<int>(std::floor(x.z() / 0.07)), 4);
  }
  return Eigen::Vector3d(150, 160, 170);
}

struct Rendered {
  std::vector<CalibratedView> views;
  std::vector<cv::Mat> floor;  // per view, 255 where the pixel's centre ray meets the floor
};

// Eight cameras around, 3.5 out and 2 up, looking at the origin.
Rendered Render(bool textured_box) {
  Rendered rendered;
  for (int k = 0; k < 8; ++k) {
    const double a = 2.0 * M_PI * k / 8.0;
    const Eigen::Vector3d centre(3.5 * std::sin(a), 2.0, 3.5 * std::cos(a));
    CalibratedView view = testing::PinholeViewLookingAtOrigin(centre, 200, 150, 170.0);
    view.name = "view" + std::to_string(k);
    const cv::Mat floor = testing::TraceViewImage(
        &view, [&](const Eigen::Vector3d& origin, const Eigen::Vector3d& d, bool* on_floor) {
          return Trace(origin, d, textured_box, on_floor);
        });
    rendered.views.push_back(std::move(view));
    rendered.floor.push_back(floor);
  }
  return rendered;
}

// The floor as the sparse points would show it: points every 0.2 over [-2, 2]^2.
Ground FloorGround() {
  return testing::GridGround(/*axis=*/1, /*half=*/2.0, /*spacing=*/0.2, /*depth=*/0.02,
                             /*radius=*/0.3, /*outline=*/false);
}

constexpr double kClearance = 0.06;

// The ground pixels' rays that enter the object before their end (beyond a hair's width).
int64_t RaysIntoTheObject(const Rendered& scene, const DistantPixels& found) {
  const Eigen::AlignedBox3d inside(kObject.min().array() + 0.005, kObject.max().array() - 0.005);
  int64_t into = 0;
  for (const DistantRay& ray : found.rays) {
    double t0 = 0.0, t1 = 0.0;
    into += ClipRayToBox(scene.views[ray.view].centre, ray.direction, inside, &t0, &t1) && t0 < ray.length;
  }
  return into;
}

// The judged pixels (every second pixel, passing the patch's rules) whose centre ray meets the
// floor (`on_floor`) or not, and how many of those were found on the ground.
struct Judged {
  int64_t judged = 0, found = 0;
};
Judged JudgedPixels(const Rendered& scene, const DistantPixels& found, bool on_floor) {
  Judged count;
  for (size_t v = 0; v < scene.views.size(); ++v) {
    for (int row = 0; row < scene.floor[v].rows; ++row) {
      for (int col = 0; col < scene.floor[v].cols; ++col) {
        const uint8_t verdict = found.masks[v].at<uint8_t>(row, col);
        if ((scene.floor[v].at<uint8_t>(row, col) != 0) != on_floor || verdict == 0) continue;
        ++count.judged;
        count.found += verdict == 255;
      }
    }
  }
  return count;
}

// The options of both tests.
DistantOptions TestOptions() {
  DistantOptions options;
  options.num_threads = 2;
  // The renders are free of noise and the floor fills nearly all of them (ImageNoiseSigma, robust
  // to texture over four fifths of a photo, would take its texture for noise and judge a tenth of
  // the floor's pixels): textured from min_texture grey levels.
  options.texture_noise_factor = 0.0;
  options.grow_plain_regions = false;
  return options;
}

TEST(GroundPixels, TheFloorIsFoundAndNoRayEntersAPlainBoxStandingOnIt) {
  const Rendered scene = Render(/*textured_box=*/false);
  const DistantPixels found = FindGroundPixels(scene.views, kVolume, FloorGround(), kClearance, TestOptions());
  ASSERT_EQ(found.masks.size(), scene.views.size());
  EXPECT_EQ(RaysIntoTheObject(scene, found), 0) << found.Summary();
  // Every ray ends kClearance or more above the floor. Where it ends above that inside the volume,
  // two other photos (min_agreeing_views) see its end at least min_parallax from where the ray
  // meets the floor: the photos told the space up to there from the floor, no nearer to it.
  const DistantOptions options = TestOptions();
  int ended_at_clearance = 0, ended_resolved = 0;
  for (const DistantRay& ray : found.rays) {
    const Eigen::Vector3d& centre = scene.views[ray.view].centre;
    const Eigen::Vector3d end = centre + ray.length * ray.direction;
    double t0 = 0.0, t1 = 0.0;
    ASSERT_TRUE(ClipRayToBox(centre, ray.direction, kVolume, &t0, &t1));
    ASSERT_GE(end.y(), kClearance - 1e-9);
    if (!(ray.length < t1 - 1e-9)) continue;
    if (std::abs(end.y() - kClearance) < 1e-9) {
      ++ended_at_clearance;
      continue;
    }
    const Eigen::Vector3d foot = centre + (-centre.y() / ray.direction.y()) * ray.direction;
    int resolving = 0;
    for (size_t w = 0; w < scene.views.size(); ++w) {
      const CalibratedView& other = scene.views[w];
      if (static_cast<int>(w) == ray.view) continue;
      const Eigen::Vector2d a = (other.P * end.homogeneous()).hnormalized();
      const Eigen::Vector2d b = (other.P * foot.homogeneous()).hnormalized();
      resolving += (a - b).norm() >= options.min_parallax - 1e-6;
    }
    ASSERT_GE(resolving, options.min_agreeing_views) << "ray of view " << ray.view << " ends at " << end.transpose();
    ++ended_resolved;
  }
  EXPECT_GT(ended_at_clearance + ended_resolved, 1000);
  // Much of the floor the photos see is found. Measured: 23% of the judged pixels on it (the
  // partners asked first, those farthest, see the floor turned round and foreshortened, and the
  // box hides from them what the photo sees of the floor near it).
  const Judged floor = JudgedPixels(scene, found, /*on_floor=*/true);
  ASSERT_GT(floor.judged, 1000);
  EXPECT_GT(static_cast<double>(floor.found) / floor.judged, 0.15) << floor.found << " of " << floor.judged;
}

TEST(GroundPixels, NoRayEntersATexturedBox) {
  const Rendered scene = Render(/*textured_box=*/true);
  const DistantPixels found = FindGroundPixels(scene.views, kVolume, FloorGround(), kClearance, TestOptions());
  EXPECT_EQ(RaysIntoTheObject(scene, found), 0) << found.Summary();
  EXPECT_GT(found.distant, 1000) << found.Summary();
  // The box's own cells are judged and never found on the floor.
  const Judged box = JudgedPixels(scene, found, /*on_floor=*/false);
  EXPECT_GT(box.judged, 100);
  EXPECT_EQ(box.found, 0);
}

}  // namespace
}  // namespace raycarve
