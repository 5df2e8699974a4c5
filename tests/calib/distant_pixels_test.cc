#include "calib/distant_pixels.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "calib/pixel.h"
#include "calib/ray_box.h"
#include "tests/test_support.h"

namespace raycarve {
namespace {

using testing::CellColour;

// The sky: plain cells of 5 degrees over directions, each a colour of its own.
Eigen::Vector3d SkyColour(const Eigen::Vector3d& d) {
  const double cell = 5.0 * M_PI / 180.0;
  return CellColour(static_cast<int>(std::floor(std::atan2(d.x(), d.z()) / cell)),
                    static_cast<int>(std::floor(std::asin(std::clamp(d.y(), -1.0, 1.0)) / cell)), 1);
}

constexpr double kSphereRadius = 0.5;
// A wall across the volume behind the sphere (seen from the cameras), at z = -kWallDepth.
constexpr double kWallDepth = 0.9;

// Distance along the unit ray to the sphere at the origin; < 0 when it misses.
double HitSphere(const Eigen::Vector3d& origin, const Eigen::Vector3d& d) {
  const double b = origin.dot(d);
  const double c = origin.squaredNorm() - kSphereRadius * kSphereRadius;
  const double disc = b * b - c;
  return disc < 0.0 ? -1.0 : -b - std::sqrt(disc);
}

// What a pixel shows: the sphere (cells of 15 degrees), else the wall (cells of 0.15) when there
// is one, else the sky. *near is false only for the sky.
Eigen::Vector3d Trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& d, bool wall, bool* near) {
  *near = true;
  const double t = HitSphere(origin, d);
  if (t > 0.0) {
    const Eigen::Vector3d x = origin + t * d;
    const double cell = 15.0 * M_PI / 180.0;
    return CellColour(static_cast<int>(std::floor(std::atan2(x.x(), x.z()) / cell)),
                      static_cast<int>(std::floor(std::asin(x.y() / kSphereRadius) / cell)), 2);
  }
  if (wall && d.z() < 0.0) {
    const Eigen::Vector3d x = origin + ((-kWallDepth - origin.z()) / d.z()) * d;
    return CellColour(static_cast<int>(std::floor(x.x() / 0.15)), static_cast<int>(std::floor(x.y() / 0.15)), 3);
  }
  *near = false;
  return SkyColour(d);
}

struct Rendered {
  std::vector<CalibratedView> views;
  std::vector<cv::Mat> sky;  // per view, 255 where the pixel's centre ray meets nothing near
};

// Eight cameras on an arc of 70 degrees, 4 from the origin, looking at it.
Rendered Render(bool wall) {
  Rendered rendered;
  for (int k = 0; k < 8; ++k) {
    const double a = (-35.0 + 10.0 * k) * M_PI / 180.0;
    const Eigen::Vector3d centre(4.0 * std::sin(a), 0.6 + 0.1 * (k % 3), 4.0 * std::cos(a));
    CalibratedView view = testing::PinholeViewLookingAtOrigin(centre, 200, 150, 170.0);
    view.name = "view" + std::to_string(k);
    const cv::Mat near = testing::TraceViewImage(
        &view, [&](const Eigen::Vector3d& origin, const Eigen::Vector3d& d, bool* is_near) {
          return Trace(origin, d, wall, is_near);
        });
    const cv::Mat sky = 255 - near;
    rendered.views.push_back(std::move(view));
    rendered.sky.push_back(sky);
  }
  return rendered;
}

const Eigen::AlignedBox3d kBox(Eigen::Vector3d::Constant(-1.0), Eigen::Vector3d::Constant(1.0));

TEST(DistantPixels, SkyBehindATexturedSphereIsFoundAndTheSphereNever) {
  const Rendered scene = Render(/*wall=*/false);
  DistantOptions options;
  options.num_threads = 2;
  const DistantPixels found = FindDistantPixels(scene.views, kBox, options);
  ASSERT_EQ(found.masks.size(), scene.views.size());
  // No ray of a distant pixel meets the sphere.
  int64_t on_sphere = 0;
  for (const DistantRay& ray : found.rays) {
    on_sphere += HitSphere(scene.views[ray.view].centre, ray.direction) > 0.0;
  }
  EXPECT_EQ(on_sphere, 0) << found.Summary();
  // Much of the sky that the volume lies in front of is found. Measured: 45% of those pixels (the
  // rest: sky that no other photo frames, and patches whose rim is not found).
  int64_t sky = 0, sky_found = 0;
  for (size_t v = 0; v < scene.views.size(); ++v) {
    const CalibratedView& view = scene.views[v];
    const Eigen::Matrix3d world_from_pixel = view.WorldFromPixel();
    for (int row = 0; row < view.height; ++row) {
      for (int col = 0; col < view.width; ++col) {
        const Eigen::Vector3d d = world_from_pixel * PixelCentre(row, col).homogeneous();
        double t0 = 0.0, t1 = 0.0;
        if (!ClipRayToBox(view.centre, d, kBox, &t0, &t1) || !scene.sky[v].at<uint8_t>(row, col)) continue;
        ++sky;
        const uint8_t verdict = found.masks[v].at<uint8_t>(row, col);
        sky_found += verdict == 255 || verdict == 200;
      }
    }
  }
  ASSERT_GT(sky, 0);
  EXPECT_GT(static_cast<double>(sky_found) / sky, 0.4) << sky_found << " of " << sky;
  EXPECT_GT(found.distant, 0);
  EXPECT_GT(found.grown, 0);
  // A sparse point seen inside a plain region found distant: the region is not distant then.
  int row = -1, col = -1;
  for (int r = 0; r < found.masks[0].rows && row < 0; ++r) {
    for (int c = 0; c < found.masks[0].cols; ++c) {
      if (found.masks[0].at<uint8_t>(r, c) == 200) {
        row = r;
        col = c;
        break;
      }
    }
  }
  ASSERT_GE(row, 0);
  std::vector<std::vector<Eigen::Vector2d>> observations(scene.views.size());
  observations[0].push_back(PixelCentre(row, col));
  const DistantPixels held = FindDistantPixels(scene.views, kBox, options, observations);
  EXPECT_NE(held.masks[0].at<uint8_t>(row, col), 200);
  EXPECT_LT(held.grown, found.grown);
}

// A sky of plain cells in two colours (a light and a dark one, checkered), and the sphere of
// the first test with its upper half plain in the sky's light colour: where the cap's
// outline meets a light cell, the cap and the cell are one plain region, whose rim (the cell's
// edges) moves as the sky does.
const Eigen::Vector3d kLightSky(150.0, 185.0, 225.0);
Eigen::Vector3d TraceCappedSphere(const Eigen::Vector3d& origin, const Eigen::Vector3d& d, bool* near) {
  *near = true;
  const double t = HitSphere(origin, d);
  if (t > 0.0) {
    const Eigen::Vector3d x = origin + t * d;
    if (x.y() > 0.0) return kLightSky;
    const double cell = 15.0 * M_PI / 180.0;
    return CellColour(static_cast<int>(std::floor(std::atan2(x.x(), x.z()) / cell)),
                      static_cast<int>(std::floor(std::asin(x.y() / kSphereRadius) / cell)), 2);
  }
  *near = false;
  const double cell = 4.0 * M_PI / 180.0;
  const int a = static_cast<int>(std::floor(std::atan2(d.x(), d.z()) / cell));
  const int b = static_cast<int>(std::floor(std::asin(std::clamp(d.y(), -1.0, 1.0)) / cell));
  return (a + b) % 2 == 0 ? kLightSky : Eigen::Vector3d(60.0, 80.0, 120.0);
}

TEST(DistantPixels, APlainHalfOfTheSkysColourIsMostlyNotSeenThrough) {
  std::vector<CalibratedView> views;
  for (int k = 0; k < 8; ++k) {
    const double a = (-35.0 + 10.0 * k) * M_PI / 180.0;
    const Eigen::Vector3d centre(4.0 * std::sin(a), 0.6 + 0.1 * (k % 3), 4.0 * std::cos(a));
    CalibratedView view = testing::PinholeViewLookingAtOrigin(centre, 200, 150, 170.0);
    testing::TraceViewImage(&view, TraceCappedSphere);
    views.push_back(std::move(view));
  }
  // Grown rays that meet the sphere, and those of sky pixels, with the colour check and without.
  const auto count = [&](bool check, int64_t* sky) {
    DistantOptions options;
    options.num_threads = 2;
    options.check_grown_colour = check;
    const DistantPixels found = FindDistantPixels(views, kBox, options);
    int64_t on_sphere = 0;
    *sky = 0;
    for (const DistantRay& ray : found.rays) {
      // Through the sphere, not grazing it: within 0.9 of its radius of its centre.
      const Eigen::Vector3d& c = views[ray.view].centre;
      const bool hit = (c - c.dot(ray.direction) * ray.direction).norm() < 0.9 * kSphereRadius;
      on_sphere += hit;
      *sky += !hit;
    }
    return on_sphere;
  };
  int64_t sky_unchecked = 0, sky_checked = 0;
  const int64_t unchecked = count(false, &sky_unchecked);
  const int64_t checked = count(true, &sky_checked);
  // Without the check the merged regions' rays pass through the cap; with it most are left out.
  // Measured: 255 rays without, 80 with (the other photos see the cap again where its pixels'
  // sky would be: it is wider than its parallax between them), of 12,980 and 12,979 in the sky.
  EXPECT_GT(unchecked, 100);
  EXPECT_LT(checked, unchecked / 2) << checked << " of " << unchecked;
  EXPECT_GT(sky_checked, 0.99 * sky_unchecked) << sky_checked << " of " << sky_unchecked;
}

TEST(DistantPixels, ATexturedWallInsideTheVolumeIsNeverDistant) {
  // The same cameras, a wall of plain cells behind the sphere inside the volume: every pixel
  // shows something near, textured edges and plain cells alike.
  const Rendered scene = Render(/*wall=*/true);
  DistantOptions options;
  const DistantPixels found = FindDistantPixels(scene.views, kBox, options);
  int64_t sky = 0;
  for (const cv::Mat& mask : scene.sky) sky += cv::countNonZero(mask);
  // The wall fills the photos but for the corners of some (sky beyond its edge).
  int64_t wrong = 0;
  for (const DistantRay& ray : found.rays) {
    bool near = false;
    Trace(scene.views[ray.view].centre, ray.direction, true, &near);
    wrong += near;
  }
  EXPECT_EQ(wrong, 0) << found.Summary() << " (" << sky << " sky pixels)";
  EXPECT_GT(found.textured, 1000);
}

TEST(DistantPixels, OptionsAreChecked) {
  std::string reason;
  DistantOptions options;
  EXPECT_TRUE(options.IsValid(&reason));
  options.max_partners = 1;
  EXPECT_FALSE(options.IsValid(&reason));
  EXPECT_NE(reason.find("min_agreeing_views"), std::string::npos);
}

TEST(DistantPixels, NoiseOfAPlainImageIsItsNoise) {
  cv::Mat grey(200, 200, CV_32F);
  cv::randn(grey, 100.0, 3.0);
  EXPECT_NEAR(ImageNoiseSigma(grey), 3.0, 0.3);
  EXPECT_EQ(ImageNoiseSigma(cv::Mat(2, 2, CV_32F, cv::Scalar(0))), 0.0);
}

// A photo mostly filled by texture (gravel, grass, a patterned floor seen from above): the
// noise is that of its plain fifth, not the texture's.
TEST(DistantPixels, NoiseOfAPhotoFilledByTextureIsItsPlainPartsNoise) {
  cv::Mat grey(200, 200, CV_32F);
  cv::randn(grey, 100.0, 3.0);
  for (int row = 0; row < grey.rows; ++row) {
    for (int col = 0; col < 160; ++col) {
      grey.at<float>(row, col) += static_cast<float>(CellColour(col / 3, row / 3, 7).x() - 135.0);
    }
  }
  EXPECT_NEAR(ImageNoiseSigma(grey), 3.0, 0.3);
}

}  // namespace
}  // namespace raycarve
