// The commands that make and measure models, run as a user runs them on a generated project:
// calibrate, import, carve (with and without masks), compare, holdout and benchmark.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>
#include <opencv2/imgcodecs.hpp>

#include <gtest/gtest.h>

#include "tests/plugin/project_fixture.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;
using testing::ExpectUserError;
using testing::JsonNumber;

class CarveCommands : public testing::SmallRadialProject {};

TEST_F(CarveCommands, CalibrateWritesViewsAndAReportWithExactReprojection) {
  const std::string out = *root_ + "/calibration";
  std::string output;
  ASSERT_EQ(Run("calibrate --workspace_path " + Project() + " --output_path " + out, &output), 0)
      << output;
  const std::string report = testing::ReadFileBytes(out + "/report.json");
  EXPECT_EQ(JsonNumber(report, "num_views"), 4);
  EXPECT_GT(JsonNumber(report, "num_observations"), 100);
  EXPECT_LT(JsonNumber(report, "max_reprojection_error_px"), 1e-6);
  for (int i = 1; i <= 4; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "view%03d.png", i);
    EXPECT_TRUE(fs::is_regular_file(out + "/undistorted/" + name)) << name;
    EXPECT_TRUE(fs::is_regular_file(out + "/masks/" + name + ".png")) << name;
  }
  // The outputs arrive as a set: no staging folder or temporary file is left, and a second run
  // into the same folder (report.json beside its folders) replaces them.
  for (const auto& entry : fs::recursive_directory_iterator(out)) {
    const std::string name = entry.path().filename().string();
    EXPECT_EQ(name.find(".raycarve-partial"), std::string::npos) << entry.path();
    EXPECT_EQ(name.find(".tmp."), std::string::npos) << entry.path();
  }
  ASSERT_EQ(Run("calibrate --workspace_path " + Project() + " --output_path " + out, &output), 0)
      << output;
  // A folder whose masks/ a user put there (no report.json beside it) is not written into.
  const std::string user = *root_ + "/calibration_user";
  fs::create_directories(user + "/masks");
  testing::WriteFile(user + "/masks/view001.png.png", "the user's mask");
  ExpectUserError("calibrate --workspace_path " + Project() + " --output_path " + user,
                  {user + "/masks", "did not write"});
  EXPECT_EQ(testing::ReadFileBytes(user + "/masks/view001.png.png"), "the user's mask");
  EXPECT_FALSE(fs::exists(user + "/undistorted"));
  ASSERT_EQ(Run("model_info --input_path " + Project() + "/sparse/0 --format json", &output), 0);
  EXPECT_NE(output.find("\"bounds\""), std::string::npos) << output;
  EXPECT_EQ(JsonNumber(output, "num_points"), JsonNumber(output, "count"));
}

TEST_F(CarveCommands, ImportsTheRealMiddleburyCalibrationAndDescribesIt) {
  RAYCARVE_REQUIRE_DATA("middlebury/templeSparseRing");
  const std::string model = *root_ + "/temple_model";
  std::string output;
  ASSERT_EQ(Run("import_middlebury --input_path " + data_path + "/templeSR_par.txt --image_path " +
                    data_path + " --output_path " + model,
                &output),
            0)
      << output;
  EXPECT_TRUE(fs::is_regular_file(model + "/cameras.txt"));
  // No 3D points in an imported calibration: bounds must come from --bbox.
  ASSERT_EQ(Run("model_info --input_path " + model, &output), 0) << output;
  EXPECT_NE(output.find("no 3D points"), std::string::npos) << output;
  ASSERT_EQ(Run("model_info --input_path " + model + " --format json --bbox " +
                    "-0.073568,0.021728,-0.012445,0.028855,0.181892,0.062736",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("templeSR0016.png"), std::string::npos);
  EXPECT_NE(output.find("\"explicit\": true"), std::string::npos);
}

TEST_F(CarveCommands, CarveWritesCloudMeshReportAndCurve) {
  const std::string out = *root_ + "/carved";
  std::string output;
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + out + " --resolution 40",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("carving a 40x"), std::string::npos) << output;
  EXPECT_NE(output.find("report.html in a browser"), std::string::npos) << output;
  for (const char* file : {"cloud.ply", "mesh.ply", "mesh.glb", "mesh.obj", "mesh.mtl",
                           "mesh_texture.png", "preview.png", "report.json", "report.html",
                           "convergence.csv"}) {
    EXPECT_TRUE(fs::is_regular_file(out + "/" + file)) << file;
  }
  // The preview: three rows of photo | mesh, each pair at the undistorted photos' size (the
  // project's 96x72, or as near as undistortion leaves it), then a row of views from outside.
  const cv::Mat preview = cv::imread(out + "/preview.png", cv::IMREAD_COLOR);
  ASSERT_FALSE(preview.empty());
  EXPECT_EQ(preview.rows % 4, 0);
  EXPECT_NEAR(preview.cols / 2.0, 96.0, 8.0);
  EXPECT_NEAR(preview.rows / 4.0, 72.0, 8.0);
  const std::string report = testing::ReadFileBytes(out + "/report.json");
  EXPECT_GT(JsonNumber(report, "textured_triangles"), 0);
  EXPECT_NE(report.find("\"lengths\": \"the model's world units (COLMAP's frame)\""),
            std::string::npos);
  const double carved = JsonNumber(report, "carved");
  EXPECT_GT(carved, 0);
  EXPECT_EQ(carved + JsonNumber(report, "final_solid"), JsonNumber(report, "num_voxels"));
  EXPECT_GT(JsonNumber(report, "evaluated"), carved);
  EXPECT_GT(JsonNumber(report, "peak_memory_bytes"), 0);
  EXPECT_EQ(JsonNumber(report, "resolution"), 40);
  EXPECT_EQ(JsonNumber(report, "schema_version"), 1);
  EXPECT_NE(report.find("\"carve\":"), std::string::npos);  // a stage timing
  const std::string csv = testing::ReadFileBytes(out + "/convergence.csv");
  EXPECT_EQ(csv.rfind("seconds,carved,evaluated\n", 0), 0u);
  // The last row of the curve is the final count.
  const std::string last = csv.substr(csv.rfind('\n', csv.size() - 2) + 1);
  EXPECT_EQ(std::stod(last.substr(last.find(',') + 1)), carved) << last;
  // The mesh is the smooth one, coloured from the photos; the box cuts this unmasked scene's
  // ground, and the mesh is open there only (no edge shared by more than two triangles).
  EXPECT_NE(report.find("\"mesh_kind\": \"smooth\""), std::string::npos) << report;
  EXPECT_GT(JsonNumber(report, "box_wall_triangles_removed"), 0) << report;
  EXPECT_GT(JsonNumber(report, "boundary_edges"), 0) << report;
  EXPECT_EQ(JsonNumber(report, "non_manifold_edges"), 0) << report;
  EXPECT_GT(JsonNumber(report, "vertices_coloured_from_photos"), 0);
  EXPECT_GT(JsonNumber(report, "mesh_triangles"), 0);
  const std::string mesh = testing::ReadFileBytes(out + "/mesh.ply");
  for (const char* property : {"property float nx", "property uchar red", "element face "}) {
    EXPECT_NE(mesh.find(property), std::string::npos) << property;
  }
}

TEST_F(CarveCommands, ACarveThatKeepsNothingWritesValidEmptyFilesAndSaysWhatToTry) {
  const std::string out = *root_ + "/carved_empty";
  std::string output;
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + out +
                    " --resolution 16 --threshold 0 --protect_surface_points 0 "
                    "--min_component_voxels 100000",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("kept nothing"), std::string::npos) << output;
  EXPECT_EQ(output.find("PCL"), std::string::npos) << output;
  const std::string report = testing::ReadFileBytes(out + "/report.json");
  EXPECT_EQ(JsonNumber(report, "final_solid"), 0);
  EXPECT_EQ(JsonNumber(report, "mesh_triangles"), 0);
  for (const char* file : {"cloud.ply", "mesh.ply"}) {
    const std::string bytes = testing::ReadFileBytes(out + "/" + file);
    EXPECT_EQ(bytes.rfind("ply\n", 0), 0u) << file;
    EXPECT_NE(bytes.find("element vertex 0\n"), std::string::npos) << file;
  }
  // The empty files are read back as empty, not as errors.
  ASSERT_EQ(Run("render --input " + out + "/cloud.ply --input_path " + Project() +
                    "/sparse/0 --output_path " + out + "/render",
                &output),
            0)
      << output;
}

TEST_F(CarveCommands, CompareMeasuresTheCarvedCloudAgainstTheGroundTruth) {
  const std::string out = *root_ + "/carved_for_compare";
  std::string output;
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + out + " --resolution 40",
                &output),
            0)
      << output;
  ASSERT_TRUE(fs::is_regular_file(Project() + "/truth.ply"));
  ASSERT_EQ(Run("compare --reference_path " + Project() + "/truth.ply --input_path " + out +
                    "/cloud.ply --threshold 0.2 --output_path " + out + "/compare.json",
                &output),
            0)
      << output;
  const std::string report = testing::ReadFileBytes(out + "/compare.json");
  // The old names still work, and say they are deprecated.
  ASSERT_EQ(Run("compare --reference " + Project() + "/truth.ply --input " + out +
                    "/cloud.ply --threshold 0.2 --output_path " + out + "/compare_old.json",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("--reference is deprecated; use --reference_path"), std::string::npos)
      << output;
  EXPECT_EQ(testing::ReadFileBytes(out + "/compare_old.json"), report);
  EXPECT_GT(JsonNumber(report, "num_reference_points"), 1000);
  // The metrics themselves are tested in export/point_cloud_compare_test; on this tiny project
  // (4 views of 96x72, 40 voxels) completeness at 0.2 measured 0.227.
  EXPECT_GT(JsonNumber(report, "completeness"), 0.1);
  EXPECT_LE(JsonNumber(report, "completeness"), 1.0);
  EXPECT_GT(JsonNumber(report, "f_score"), 0.0);
  // The mesh is read by sampling its surface.
  ASSERT_EQ(Run("compare --reference " + Project() + "/truth.ply --input " + out +
                    "/mesh.ply --mesh_samples 20000",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("\"num_input_points\": 20000"), std::string::npos) << output;
  ExpectUserError("compare --reference " + out + "/nothing.ply --input " + out + "/cloud.ply",
                  {out + "/nothing.ply", "not found"});
  ExpectUserError("compare --reference " + Project() + "/truth.ply --input " + out +
                      "/cloud.ply --threshold -1",
                  {"threshold must be a positive distance"});
  // --bbox cuts both clouds to a box: the carve's own volume keeps nearly all the cloud (the
  // refined mesh it is sampled on may stand up to a voxel beyond the volume: 4 of 1,416 points
  // measured) and leaves out the truth beyond it; the box is said in the report; a box that is
  // not one is refused.
  const std::string carve_report = testing::ReadFileBytes(out + "/report.json");
  ASSERT_EQ(Run("compare --reference_path " + Project() + "/truth.ply --input_path " + out +
                    "/cloud.ply --threshold 0.2 --bbox " + testing::ReportBoxText(carve_report) +
                    " --output_path " + out + "/compare_box.json",
                &output),
            0)
      << output;
  const std::string boxed = testing::ReadFileBytes(out + "/compare_box.json");
  EXPECT_GE(JsonNumber(boxed, "num_input_points"), 0.98 * JsonNumber(report, "num_input_points"));
  EXPECT_LE(JsonNumber(boxed, "num_reference_points"), JsonNumber(report, "num_reference_points"));
  EXPECT_NE(boxed.find("\"bbox\": \"" + testing::ReportBoxText(carve_report) + "\""),
            std::string::npos);
  ExpectUserError("compare --reference_path " + Project() + "/truth.ply --input_path " + out +
                      "/cloud.ply --bbox 0,0,0,1,1",
                  {"--bbox", "expected 6 comma-separated numbers, found 5"});
  ExpectUserError("compare --reference_path " + Project() + "/truth.ply --input_path " + out +
                      "/cloud.ply --bbox 100,100,100,101,101,101",
                  {"--bbox 100,100,100,101,101,101 holds 0 reference and 0 input points"});
}

TEST_F(CarveCommands, CarveWithMasksPreCarvesTheVisualHullAndSaysSo) {
  const std::string out = *root_ + "/carved_masked";
  std::string output;
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + out +
                    " --resolution 40 --mask_path " + Project() + "/masks",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("masks from " + Project() + "/masks, with the visual hull"), std::string::npos)
      << output;
  const std::string report = testing::ReadFileBytes(out + "/report.json");
  EXPECT_EQ(JsonNumber(report, "views_with_masks"), 4);
  EXPECT_GT(JsonNumber(report, "visual_hull_carved"), 0);
  EXPECT_LE(JsonNumber(report, "visual_hull_carved"), JsonNumber(report, "carved"));
  ExpectUserError("carve --workspace_path " + Project() + " --output_path " + out +
                      " --mask_path " + *root_ + "/no_masks",
                  {*root_ + "/no_masks/view001.png.png", "mask of image 1", "not found"});
}

TEST_F(CarveCommands, ByDefaultAPlainBackdropGivesMasksAndANaturalSceneNone) {
  const std::string studio = *root_ + "/studio";
  std::string output;
  ASSERT_EQ(Run("synth --output_path " + studio +
                    " --views 4 --width 96 --height 72 --points 300 --backdrop uniform",
                &output),
            0)
      << output;
  ASSERT_EQ(Run("carve --workspace_path " + studio + " --output_path " + studio + "/out --resolution 32",
                &output),
            0)
      << output;
  std::string report = testing::ReadFileBytes(studio + "/out/report.json");
  EXPECT_EQ(JsonNumber(report, "masks_from_backdrop"), 4);
  EXPECT_GT(JsonNumber(report, "visual_hull_carved"), 0);
  EXPECT_TRUE(fs::is_regular_file(studio + "/out/masks/view001.png.png"));  // for the user to check
  ASSERT_EQ(Run("carve --workspace_path " + studio + " --output_path " + studio +
                    "/plain --resolution 32 --background_colour none",
                &output),
            0)
      << output;
  report = testing::ReadFileBytes(studio + "/plain/report.json");
  EXPECT_EQ(JsonNumber(report, "masks_from_backdrop"), 0);
  EXPECT_EQ(JsonNumber(report, "visual_hull_carved"), 0);
  // The patchwork project has no plain backdrop: carved as without masks.
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + *root_ +
                    "/natural --resolution 32",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("no plain backdrop found"), std::string::npos) << output;
  EXPECT_EQ(JsonNumber(testing::ReadFileBytes(*root_ + "/natural/report.json"), "masks_from_backdrop"), 0);
  ExpectUserError("carve --workspace_path " + Project() + " --output_path " + *root_ +
                      "/natural --background_colour black",
                  {"--background_colour 'black'"});
}

TEST_F(CarveCommands, ABackdropOfTwoColoursBehindAFrameGivesMasksAndSaysWhatItFound) {
  const std::string studio = *root_ + "/two_tone";
  std::string output;
  ASSERT_EQ(Run("synth --output_path " + studio +
                    " --views 4 --width 160 --height 120 --points 300 --backdrop two_tone",
                &output),
            0)
      << output;
  ASSERT_EQ(Run("carve --workspace_path " + studio + " --output_path " + studio +
                    "/out --resolution 32",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("4 from the backdrop; backdrop of the first: 2 colours"), std::string::npos)
      << output;
  EXPECT_NE(output.find("4 photos with a frame"), std::string::npos) << output;
  const std::string report = testing::ReadFileBytes(studio + "/out/report.json");
  EXPECT_EQ(JsonNumber(report, "masks_from_backdrop"), 4);
  EXPECT_NE(report.find("\"source\": \"backdrop\""), std::string::npos) << report;
  EXPECT_NE(report.find("\"frame_px\": [3, 3, 3, 3]"), std::string::npos) << report;
  EXPECT_GT(JsonNumber(report, "visual_hull_carved"), 0);
}

TEST_F(CarveCommands, AGridFinerThanThePhotosResolveIsRefusedWithWhatTheySupport) {
  // The project's photos are 96x72: at 40 voxels a voxel spans pixels (the carve above), at 400
  // a tenth of that.
  const std::string out = *root_ + "/too_fine";
  ExpectUserError("carve --workspace_path " + Project() + " --output_path " + out +
                      " --resolution 400",
                  {"--resolution 400: a voxel would span 0.", "pixels of the photos",
                   "they support about --resolution", "--min_voxel_pixels 0"});
  EXPECT_FALSE(fs::exists(out + "/report.json"));
  // The figures behind the refusal, in a carve's report: the supported resolution is the
  // resolution times the pixels a voxel spans.
  std::string output;
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + out +
                    " --resolution 24", &output), 0) << output;
  const std::string report = testing::ReadFileBytes(out + "/report.json");
  const double pixels = JsonNumber(report, "voxel_pixels");
  EXPECT_GT(pixels, 0.5);
  EXPECT_NEAR(JsonNumber(report, "supported_resolution"), std::floor(24 * pixels), 0.5);
  EXPECT_LT(JsonNumber(report, "supported_resolution"), 400 * 0.5);
  EXPECT_EQ(JsonNumber(report, "default_lowered_from"), 0);  // given: never lowered
  // The default (128) is lowered to what the photos resolve, and says so.
  const std::string lowered = *root_ + "/default_resolution";
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + lowered, &output), 0)
      << output;
  EXPECT_NE(output.find("the default 128 lowered to"), std::string::npos) << output;
  const std::string lowered_report = testing::ReadFileBytes(lowered + "/report.json");
  EXPECT_EQ(JsonNumber(lowered_report, "default_lowered_from"), 128);
  const int supported = static_cast<int>(JsonNumber(lowered_report, "supported_resolution"));
  EXPECT_LT(supported, 128);
  EXPECT_NEAR(JsonNumber(lowered_report, "voxel_pixels"), 1.0, 0.1);
  EXPECT_EQ(JsonNumber(lowered_report, "resolution"), supported);
  // A voxel of about a pixel is under 1.5 rays: the final level's rays are supersampled from the
  // photos enlarged twice, and its threshold measured at half the resolution on the photos as
  // they are. At 24 voxels (several pixels each) nothing is enlarged.
  const auto last_number = [](const std::string& json, const std::string& key) {
    const size_t at = json.rfind("\"" + key + "\": ");
    return at == std::string::npos ? -1.0 : std::stod(json.substr(at + key.size() + 4));
  };
  EXPECT_EQ(last_number(lowered_report, "image_enlargement"), 2);
  EXPECT_EQ(last_number(lowered_report, "threshold_resolution"), supported / 2);
  EXPECT_NE(output.find("(photos enlarged 2x)"), std::string::npos) << output;
  EXPECT_EQ(last_number(report, "image_enlargement"), 1);
  ExpectUserError("carve --workspace_path " + Project() + " --output_path " + *root_ +
                      "/supersample3 --supersample 3",
                  {"supersample must be 0 (automatic), 1, 2 or 4, got 3"});
}

TEST_F(CarveCommands, AVolumeNoPhotoSeesIsRefusedWithWhatEachPhotoSees) {
  // A --bbox far from where the cameras look (as in another frame or unit).
  ExpectUserError("carve --workspace_path " + Project() + " --output_path " + *root_ +
                      "/unseen --resolution 16 --bbox 100,100,100,101,101,101",
                  {"the volume (100, 100, 100) - (101, 101, 101) (--bbox)",
                   "seen by fewer than 2 photos", "view001.png 0%", "view004.png 0%",
                   "The sparse points' own box is"});
  EXPECT_FALSE(fs::exists(*root_ + "/unseen/report.json"));
  ExpectUserError("holdout --workspace_path " + Project() + " --output_path " + *root_ +
                      "/unseen --resolution 16 --every 4 --bbox 100,100,100,101,101,101",
                  {"seen by fewer than 2 photos"});
}

TEST_F(CarveCommands, HoldoutScoresRendersOfLeftOutViews) {
  // Its own project: held-out scoring needs enough training views for a model to show.
  const std::string project = *root_ + "/holdout_project";
  const std::string out = project + "/out";
  std::string output;
  ASSERT_EQ(Run("synth --output_path " + project + " --views 8 --width 160 --height 120 --points 300",
                &output),
            0)
      << output;
  // Vertex colours only (--mesh_texture 0): mesh.ply holds them, so --model can score it again
  // below. (mesh.ply cannot hold a texture.)
  ASSERT_EQ(Run("holdout --workspace_path " + project + " --output_path " + out +
                    " --resolution 48 --every 4 --mesh_texture 0 --mask_path " + project + "/masks",
                &output),
            0)
      << output;
  const std::string report = testing::ReadFileBytes(out + "/holdout/holdout.json");
  EXPECT_EQ(JsonNumber(report, "training_views"), 6);
  // Measured: silhouette IoU 0.663 and PSNR 9.8 dB over the two held-out views (a 48-voxel
  // model of 160x120 photos seen from new directions).
  EXPECT_GT(JsonNumber(report, "mean_silhouette_iou"), 0.5);
  EXPECT_LE(JsonNumber(report, "mean_silhouette_iou"), 1.0);
  EXPECT_GT(JsonNumber(report, "mean_psnr_db"), 5.0);
  EXPECT_TRUE(fs::is_regular_file(out + "/holdout/view001.png"));
  EXPECT_TRUE(fs::is_regular_file(out + "/holdout/view005.png"));
  // The mesh is scored beside the voxel volume of the same carve, and written out.
  EXPECT_GT(JsonNumber(report, "mean_volume_psnr_db"), 5.0);
  EXPECT_GT(JsonNumber(report, "mean_volume_silhouette_iou"), 0.5);
  ASSERT_TRUE(fs::is_regular_file(out + "/holdout/mesh.ply"));
  // --model scores a given PLY on the same held-out views: the mesh it wrote scores as it did.
  const std::string again = project + "/out_model";
  ASSERT_EQ(Run("holdout --workspace_path " + project + " --output_path " + again +
                    " --resolution 48 --every 4 --mask_path " + project + "/masks --model " + out +
                    "/holdout/mesh.ply",
                &output),
            0)
      << output;
  const std::string scored = testing::ReadFileBytes(again + "/holdout/holdout.json");
  EXPECT_NEAR(JsonNumber(scored, "mean_psnr_db"), JsonNumber(report, "mean_psnr_db"), 0.01);
  EXPECT_NEAR(JsonNumber(scored, "mean_silhouette_iou"), JsonNumber(report, "mean_silhouette_iou"),
              0.001);
  ExpectUserError("holdout --workspace_path " + project + " --output_path " + again +
                      " --model " + project + "/missing.ply",
                  {"missing.ply", "not found"});
  ExpectUserError("holdout --workspace_path " + project + " --output_path " + out + " --every 1",
                  {"--every must be at least 2"});
}

TEST_F(CarveCommands, BenchmarkComparesTheThreeMethodsInATableAPlotAndJson) {
  const std::string out = *root_ + "/benchmark";
  std::string output;
  ASSERT_EQ(Run("benchmark --workspace_path " + Project() + " --output_path " + out +
                    " --resolution 32 --reference " + Project() + "/truth.ply",
                &output),
            0)
      << output;
  for (const char* method : {"| ray (footprint) |", "| gvc_ldi |", "| gvc |", "ray vs gvc_ldi"}) {
    EXPECT_NE(output.find(method), std::string::npos) << method << " not in:\n" << output;
  }
  const std::string report = testing::ReadFileBytes(out + "/benchmark/benchmark.json");
  // The first agreement listed is ray casting against GVC-LDI: the same carving here.
  EXPECT_EQ(JsonNumber(report, "iou"), 1.0) << report;
  EXPECT_EQ(JsonNumber(report, "differing"), 0.0) << report;
  // Measured 0.299 for ray casting: 4 views of 96x72 see little of a 32-voxel scene.
  EXPECT_GT(JsonNumber(report, "completeness"), 0.2) << report;
  const cv::Mat plot = cv::imread(out + "/benchmark/figure6.png");
  ASSERT_FALSE(plot.empty());
  EXPECT_EQ(plot.cols, 960);
  EXPECT_EQ(plot.rows, 600);
  for (const char* file : {"figure6.csv", "table.md", "cloud_ray.ply", "cloud_gvc.ply",
                           "cloud_gvc_ldi.ply"}) {
    EXPECT_TRUE(fs::is_regular_file(out + "/benchmark/" + file)) << file;
  }
  const std::string csv = testing::ReadFileBytes(out + "/benchmark/figure6.csv");
  EXPECT_EQ(csv.rfind("method,seconds,carved,evaluated\n", 0), 0u);
  EXPECT_NE(csv.find("\ngvc_ldi,"), std::string::npos);
  ExpectUserError("benchmark --workspace_path " + Project() + " --output_path " + out +
                      " --methods ray,zbuffer",
                  {"--methods", "zbuffer"});
  // carve takes the method too, and says which it used.
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + out +
                    "/gvc --resolution 24 --method gvc",
                &output),
            0)
      << output;
  const std::string carve_report = testing::ReadFileBytes(out + "/gvc/report.json");
  EXPECT_NE(carve_report.find("\"visibility\": \"gvc\""), std::string::npos) << carve_report;
  EXPECT_GE(JsonNumber(carve_report, "passes"), 2.0);

  // render draws a cloud into chosen cameras of the model.
  ASSERT_EQ(Run("render --input " + out + "/benchmark/cloud_ray.ply --input_path " + Project() +
                    "/sparse/0 --image_path " + Project() + "/images --output_path " + out +
                    "/render --image_names view002.png --point_size 0.1",
                &output),
            0)
      << output;
  const cv::Mat silhouette = cv::imread(out + "/render/view002.png.silhouette.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(silhouette.empty());
  EXPECT_EQ(silhouette.cols, 96);
  EXPECT_GT(cv::countNonZero(silhouette), 200);  // the carved scene covers much of the view
  EXPECT_TRUE(fs::is_regular_file(out + "/render/view002.png.side.png"));
  EXPECT_FALSE(fs::exists(out + "/render/view001.png.render.png"));
  EXPECT_FALSE(fs::exists(out + "/render/view004.png.render.png"));
  EXPECT_NE(output.find("into 1 cameras"), std::string::npos) << output;
  // Exactly the named images, also where image ids are not in name order: the first and the
  // last image's names swapped in a text copy of the model.
  const std::string swapped = CopyModel("swapped_names", "TXT");
  std::string images = testing::ReadFileBytes(swapped + "/images.txt");
  const size_t first = images.find("view001.png"), last = images.find("view004.png");
  ASSERT_NE(first, std::string::npos);
  ASSERT_NE(last, std::string::npos);
  images.replace(last, 11, "view001.png");
  images.replace(first, 11, "view004.png");
  testing::WriteFile(swapped + "/images.txt", images);
  ASSERT_EQ(Run("render --input " + out + "/benchmark/cloud_ray.ply --input_path " + swapped +
                    " --output_path " + out + "/render_swapped --image_names view004.png,view002.png",
                &output),
            0)
      << output;
  EXPECT_NE(output.find("into 2 cameras"), std::string::npos) << output;
  for (const char* name : {"view001.png", "view003.png"}) {
    EXPECT_FALSE(fs::exists(out + "/render_swapped/" + name + ".render.png")) << name;
  }
  for (const char* name : {"view002.png", "view004.png"}) {
    EXPECT_TRUE(fs::exists(out + "/render_swapped/" + name + ".render.png")) << name;
  }
  ExpectUserError("render --input " + out + "/benchmark/cloud_ray.ply --input_path " + Project() +
                      "/sparse/0 --output_path " + out + "/render --image_names nope.png",
                  {"no image named 'nope.png'"});
}

}  // namespace
}  // namespace raycarve
