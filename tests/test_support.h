#pragma once

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <map>
#include <string>

#include <gtest/gtest.h>

namespace raycarve {
namespace testing {

// A fresh, empty folder for one test under the system's temporary folder; removed when the test
// program exits unless RAYCARVE_KEEP_TEST_FILES is set.
std::string MakeTemporaryDirectory(const std::string& name);

// The shared data folder ($RAYCARVE_DATA_DIR, else <source>/../shared/data), or "" when absent.
std::string DataDirectory();

// Runs `command` through the shell; returns its exit status and stores stdout+stderr.
int RunShell(const std::string& command, std::string* output);

// The built `raycarve` program (set by CTest in $RAYCARVE_BINARY).
std::string RaycarveBinary();

// Runs the built `raycarve` program with `arguments` (a shell command line's words).
int RunRaycarve(const std::string& arguments, std::string* output);

// Runs raycarve and expects exit status 1 with a message "error: ..." holding every part, and no
// sign of a crash or a failed internal check.
void ExpectUserError(const std::string& arguments, std::initializer_list<std::string> parts);

// The number after "key": in a JSON text written by raycarve (fails the test when absent).
double JsonNumber(const std::string& json, const std::string& key);
// The carve's volume as raycarve compare's --bbox takes it, "min_x,...,max_z", from report.json's
// "bounds" (its "min" and "max" arrays).
std::string ReportBoxText(const std::string& report);

// Every regular file under `folder` with its bytes.
std::map<std::string, std::string> FolderSnapshot(const std::string& folder);

// True when a `colmap` program is on the PATH.
bool ColmapAvailable();

// Writes bytes to a file (CHECK-fails on error).
void WriteFile(const std::string& path, const std::string& bytes);
std::string ReadFileBytes(const std::string& path);

}  // namespace testing
}  // namespace raycarve

// Skips the test with a message naming what is missing.
#define RAYCARVE_REQUIRE_DATA(relative_path)                                                \
  const std::string data_path = ::raycarve::testing::DataDirectory().empty()                 \
                                    ? std::string()                                          \
                                    : ::raycarve::testing::DataDirectory() + "/" + relative_path; \
  if (data_path.empty() || !std::filesystem::exists(data_path)) {                            \
    GTEST_SKIP() << "shared data not found (" << relative_path                               \
                 << "): set RAYCARVE_DATA_DIR or place ../shared/data beside the source";    \
  }

#define RAYCARVE_REQUIRE_COLMAP()                                                 \
  if (!::raycarve::testing::ColmapAvailable()) {                                  \
    GTEST_SKIP() << "the colmap program is not installed (apt-get install colmap)"; \
  }

#include "calib/reconstruction.h"

namespace raycarve {
namespace testing {

// A camera of the given id, model, size and parameters (COLMAP's order).
Camera MakeCamera(camera_t id, CameraModelId model, int width, int height,
                  std::vector<double> params);

// A random, consistent model: one camera of every COLMAP 3.8 model, `num_images` images with
// random poses and points2D, and 3D points whose tracks refer to those points2D. Values use the
// full double range of digits so that text round trips are really tested.
Reconstruction RandomReconstruction(uint64_t seed, int num_images = 5, int num_points3D = 40);

// Equality of every field (GoogleTest failures name the differing field): exact, except that
// quaternion coefficients may differ by `rotation_tolerance` (COLMAP renormalises quaternions
// when it reads a model, which moves their last bits).
void ExpectSameReconstruction(const Reconstruction& a,
                              const Reconstruction& b,
                              double rotation_tolerance = 0.0);

}  // namespace testing
}  // namespace raycarve

#include <Eigen/Geometry>

namespace raycarve {
namespace testing {

// The "(tight) bounding box" stated in a Middlebury set's README.txt: the two lines of three
// numbers in parentheses after the words "bounding box". Fails the test if absent.
Eigen::AlignedBox3d ReadMiddleburyReadmeBox(const std::string& readme_path);

}  // namespace testing
}  // namespace raycarve

#include "calib/calibrated_view.h"

namespace raycarve {
namespace testing {

// A pinhole view (no distortion; K, cam_from_world, centre and P set; no photo) of
// `width` x `height` pixels with focal length `focal` and the principal point at the centre,
// at `centre` looking at the origin, its image's up towards +y (about). `valid` is all 255.
CalibratedView PinholeViewLookingAtOrigin(const Eigen::Vector3d& centre, int width, int height,
                                          double focal);

// A pinhole view at the world's origin looking down +z (x right, y down: cam_from_world the
// identity), `width` x `height` pixels, focal length `focal`, the principal point at the
// centre; K, cam_from_world, centre and P set, no photo, `valid` all 255.
CalibratedView PinholeViewAtOrigin(int width, int height, double focal);

// A colour for cell (a, b) of a pattern, from a hash of the cell and `salt` (one pattern per
// salt): each channel in 40..231, neighbouring cells unrelated.
Eigen::Vector3d CellColour(int a, int b, int salt);

// Renders view->image (CV_8UC3 RGB, of the view's size) with `trace`, 3 x 3 rays a pixel (as a
// camera integrates its pixel's area): trace(origin, unit direction, &flag) gives a ray's colour
// and a flag of the caller's (what the ray meets). Returns the mask (CV_8UC1, 255) of the pixels
// whose centre ray was flagged.
cv::Mat TraceViewImage(
    CalibratedView* view,
    const std::function<Eigen::Vector3d(const Eigen::Vector3d&, const Eigen::Vector3d&, bool*)>& trace);

}  // namespace testing
}  // namespace raycarve
