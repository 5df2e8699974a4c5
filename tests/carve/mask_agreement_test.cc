#include "carve/mask_agreement.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "tests/carve/carve_fixture.h"

namespace raycarve {
namespace {

struct Damaged {
  std::vector<CalibratedView> views;
  Eigen::AlignedBox3d box;
  cv::Mat truth;  // view 0's exact mask
  cv::Mat hole;   // the object pixels taken out of view 0's mask
};

// The generated scene on a plain backdrop with exact masks, and a hole cut in view 0's mask
// where the photo shows the object: a colour rule's failure on one photo.
Damaged DamagedScene() {
  const SyntheticScene scene =
      GenerateSyntheticScene(testing::SceneOptions(8, 160, 120, /*uniform_backdrop=*/true));
  Damaged damaged;
  damaged.views = testing::SceneViews(scene, /*with_masks=*/true);
  damaged.box = scene.object_box;
  damaged.box.extend(damaged.box.max() + Eigen::Vector3d(0.3, 0.3, 0.6));
  damaged.box.extend(damaged.box.min() - Eigen::Vector3d(0.3, 0.3, 0.3));
  CalibratedView& first = damaged.views[0];
  damaged.truth = first.mask.clone();
  // A disc in the middle of the object's largest part.
  cv::Mat core;
  cv::erode(first.mask, core, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(9, 9)));
  const cv::Moments moments = cv::moments(core, /*binaryImage=*/true);
  const cv::Point middle(static_cast<int>(moments.m10 / moments.m00),
                         static_cast<int>(moments.m01 / moments.m00));
  cv::Mat disc(first.mask.size(), CV_8UC1, cv::Scalar(0));
  cv::circle(disc, middle, 14, cv::Scalar(255), cv::FILLED);
  damaged.hole = disc & core;
  first.mask = first.mask.clone();
  first.mask.setTo(0, damaged.hole);
  return damaged;
}

TEST(MaskAgreement, FillsAHoleOnePhotosMaskMadeAndLeavesTheOthers) {
  Damaged damaged = DamagedScene();
  const int hole = cv::countNonZero(damaged.hole);
  ASSERT_GT(hole, 200);
  std::vector<cv::Mat> before;
  for (const CalibratedView& view : damaged.views) before.push_back(view.mask.clone());
  MaskAgreementOptions options;
  options.resolution = 64;
  const MaskAgreementStatistics statistics = AgreeMasks(damaged.box, options, &damaged.views);
  EXPECT_EQ(statistics.views, 8);
  EXPECT_GT(statistics.hull_voxels, 0);
  // The hole: most of it is object again, and what was added lies on the true object.
  const cv::Mat& agreed = damaged.views[0].mask;
  const int restored = cv::countNonZero(agreed & damaged.hole);
  // The scene is checked and striped: the colour test holds back where the texture changes
  // within the hull's first voxels. More than a third comes back.
  EXPECT_GT(restored, hole / 3) << "of " << hole;
  const int added_off_object = cv::countNonZero(agreed & ~before[0] & ~damaged.truth);
  EXPECT_LE(added_off_object, statistics.added[0] / 20) << statistics.added[0] << " added";
  EXPECT_EQ(statistics.added[0], cv::countNonZero(agreed & ~before[0]));
  // Object pixels never become background.
  EXPECT_EQ(cv::countNonZero(before[0] & ~agreed), 0);
  // The exact masks of the other views: next to nothing added (the backdrop's colour is not the
  // object's).
  for (size_t v = 1; v < damaged.views.size(); ++v) {
    EXPECT_EQ(cv::countNonZero(before[v] & ~damaged.views[v].mask), 0) << v;
    EXPECT_LE(statistics.added[v], statistics.object_before[v] / 200) << v;
  }
  EXPECT_FALSE(statistics.Summary({}).empty());
}

TEST(MaskAgreement, GivesTheSameMasksOnAnyNumberOfThreads) {
  MaskAgreementOptions options;
  options.resolution = 64;
  options.num_threads = 1;
  Damaged one = DamagedScene();
  const MaskAgreementStatistics on_one = AgreeMasks(one.box, options, &one.views);
  ASSERT_GT(on_one.added[0], 0);
  options.num_threads = 3;
  Damaged three = DamagedScene();
  const MaskAgreementStatistics on_three = AgreeMasks(three.box, options, &three.views);
  EXPECT_EQ(on_three.added, on_one.added);
  EXPECT_EQ(on_three.object_before, on_one.object_before);
  for (size_t v = 0; v < one.views.size(); ++v) {
    EXPECT_EQ(cv::countNonZero(one.views[v].mask != three.views[v].mask), 0) << v;
  }
}

TEST(MaskAgreement, NeedsThreeMaskedViews) {
  Damaged damaged = DamagedScene();
  damaged.views.resize(2);
  const cv::Mat mask = damaged.views[0].mask.clone();
  const MaskAgreementStatistics statistics =
      AgreeMasks(damaged.box, MaskAgreementOptions(), &damaged.views);
  EXPECT_EQ(statistics.views, 0);
  EXPECT_EQ(cv::countNonZero(mask != damaged.views[0].mask), 0);
}

}  // namespace
}  // namespace raycarve
