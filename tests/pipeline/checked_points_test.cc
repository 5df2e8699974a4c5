// CheckedPoints: the supporting plane is fit to the points three or more photos saw, so that
// two-view wrong matches under the floor (as COLMAP's points of a chequered floor hold) do not rule
// the floor out; with too few such points, every point two photos saw counts.
#include "pipeline/project.h"

#include <random>

#include <gtest/gtest.h>

#include "export/supporting_plane.h"

namespace raycarve {
namespace {

class Model {
 public:
  Model() {
    for (image_t id = 1; id <= 4; ++id) {
      Image image;
      image.image_id = id;
      image.camera_id = 1;
      // Cameras above the floor z = 0, looking down at it.
      image.cam_from_world.translation = Eigen::Vector3d(0.0, 0.0, -3.0 - id);
      model_.images.emplace(id, image);
    }
  }
  void Add(const Eigen::Vector3d& xyz, std::initializer_list<image_t> images) {
    Point3D point;
    point.xyz = xyz;
    point.error = 0.5;
    for (image_t id : images) point.track.push_back({id, 0});
    model_.points3D.emplace(next_id_++, point);
  }
  std::vector<Eigen::Vector3d> Cameras() const {
    std::vector<Eigen::Vector3d> cameras;
    for (const auto& [id, image] : model_.images) cameras.push_back(image.ProjectionCenter());
    return cameras;
  }
  const Reconstruction& model() const { return model_; }

 private:
  Reconstruction model_;
  point3D_t next_id_ = 1;
};

const Eigen::AlignedBox3d kBox(Eigen::Vector3d(-10, -10, -10), Eigen::Vector3d(10, 10, 10));

TEST(CheckedPoints, APlaneUnderWhichOnlyTwoViewPointsLieIsFound) {
  Model model;
  std::mt19937 random(3);
  std::uniform_real_distribution<double> across(-1.0, 1.0), below(-3.0, -0.5);
  for (int i = 0; i < 200; ++i) model.Add({across(random), across(random), 0.0}, {1, 2, 3});
  // Wrong matches: as many two-view points under the floor as on it.
  for (int i = 0; i < 200; ++i) model.Add({across(random), across(random), below(random)}, {2, 4});
  const std::vector<Eigen::Vector3d> checked = CheckedPoints(model.model(), kBox);
  EXPECT_EQ(checked.size(), 200u);
  const exporter::SupportingPlane from_checked =
      exporter::FitSupportingPlane(checked, model.Cameras(), PhotosUp(), 0.02);
  EXPECT_TRUE(from_checked.found) << from_checked.Summary();
  EXPECT_NEAR(std::abs(from_checked.normal.z()), 1.0, 1e-6);

  // The same plane fit to every point two photos saw: half of them lie below it.
  std::vector<Eigen::Vector3d> all;
  for (const auto& [id, point] : model.model().points3D) all.push_back(point.xyz);
  const exporter::SupportingPlane from_all =
      exporter::FitSupportingPlane(all, model.Cameras(), PhotosUp(), 0.02);
  EXPECT_FALSE(from_all.found) << from_all.Summary();
}

TEST(CheckedPoints, TooFewCheckedPointsTakeEveryPointTwoPhotosSaw) {
  Model model;
  for (int i = 0; i < kMinCheckedPoints - 1; ++i) model.Add({0.1 * i, 0.0, 0.0}, {1, 2, 3});
  for (int i = 0; i < 30; ++i) model.Add({0.1 * i, 1.0, 0.0}, {1, 2});
  model.Add({50.0, 0.0, 0.0}, {1, 2, 3});  // outside the box
  model.Add({0.0, 0.0, 0.0}, {1});         // one photo
  EXPECT_EQ(CheckedPoints(model.model(), kBox).size(), static_cast<size_t>(kMinCheckedPoints - 1 + 30));
}

TEST(CheckedPoints, APhotoSeenTwiceInATrackCountsOnce) {
  Model model;
  for (int i = 0; i < kMinCheckedPoints; ++i) model.Add({0.1 * i, 0.0, 0.0}, {1, 2, 3});
  model.Add({0.0, 1.0, 0.0}, {1, 1, 2});  // two photos
  EXPECT_EQ(CheckedPoints(model.model(), kBox).size(), static_cast<size_t>(kMinCheckedPoints));
}

}  // namespace
}  // namespace raycarve
