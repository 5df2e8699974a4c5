// The `raycarve` program as a user runs it: usage, options and project files, outputs that a killed
// run or a link cannot damage, photos missing, options refused. Bad input ends with one line
// naming the file and the field and exit status 1, never a crash.
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

class CommandLine : public testing::SmallRadialProject {};

TEST_F(CommandLine, UsageHelpAndUnknownCommands) {
  std::string output;
  EXPECT_EQ(Run("help", &output), 0);
  EXPECT_NE(output.find("model_info"), std::string::npos);
  // No arguments: the usage and success, as COLMAP does.
  EXPECT_EQ(Run("", &output), 0);
  EXPECT_NE(output.find("model_info"), std::string::npos);
  EXPECT_EQ(Run("carve_everything", &output), 1);
  EXPECT_NE(output.find("unknown command 'carve_everything'"), std::string::npos);
  EXPECT_EQ(Run("calibrate --help", &output), 0);
  EXPECT_NE(output.find("--workspace_path"), std::string::npos);
  ExpectUserError("model_info --input_path x --bogus 1", {"unknown option --bogus"});
  ExpectUserError("synth --output_path x --views many", {"--views", "'many'"});
}

TEST_F(CommandLine, SaysItsVersionAndRecordsTheRunInTheReport) {
  std::string output;
  ASSERT_EQ(Run("--version", &output), 0);
  EXPECT_EQ(output.rfind("raycarve 0.1.0 (commit ", 0), 0u) << output;
  EXPECT_EQ(Run("version", &output), 0);
  EXPECT_EQ(output.rfind("raycarve 0.1.0 (commit ", 0), 0u) << output;
  const std::string out = *root_ + "/identity";
  ASSERT_EQ(Run("carve --workspace_path " + Project() + " --output_path " + out + " --resolution 16",
                &output),
            0)
      << output;
  const std::string report = testing::ReadFileBytes(out + "/report.json");
  EXPECT_NE(report.find("\"raycarve_version\": \"0.1.0\""), std::string::npos) << report;
  EXPECT_NE(report.find("--resolution 16\""), std::string::npos) << report;  // the command line
  EXPECT_NE(report.find("\"start_time\": \"20"), std::string::npos) << report;
}

TEST_F(CommandLine, ErrorsNameTheCommandOnce) {
  std::string output;
  EXPECT_EQ(Run("carve --bogus 1", &output), 1);
  EXPECT_NE(output.find("raycarve carve: error: unknown option --bogus"), std::string::npos)
      << output;
  EXPECT_EQ(output.find("raycarve carve: error: raycarve carve:"), std::string::npos) << output;
  EXPECT_EQ(Run("holdout --workspace_path " + Project() + " --every 1", &output), 1);
  EXPECT_EQ(output.find("raycarve holdout: error: raycarve holdout:"), std::string::npos) << output;
}

TEST_F(CommandLine, TakesGlogsFlagsAsColmapDoes) {
  const std::string model = Project() + "/sparse/0";
  std::string output;
  for (const std::string flags : {"--log_to_stderr 1 --log_level 2", "--v=1", "--log_to_stderr"}) {
    EXPECT_EQ(Run("model_info --input_path " + model + " " + flags, &output), 0) << flags << output;
    EXPECT_NE(output.find("images: 4"), std::string::npos) << flags << output;
  }
  ExpectUserError("model_info --input_path " + model + " --log_level loud", {"--log_level", "'loud'"});
}

TEST_F(CommandLine, ReadsOptionsFromAColmapIniFileThatTheCommandLineOverrides) {
  const std::string ini = *root_ + "/project.ini";
  // COLMAP's own sections and keys raycarve does not take are left alone.
  testing::WriteFile(ini,
                     "# options\nlog_to_stderr=1\nworkspace_path=" + Project() + "\nresolution=24\n"
                     "database_path=" + Project() + "/database.db\n"
                     "[SiftExtraction]\nuse_gpu=0\n[carve]\nmesh=voxels\n");
  std::string output;
  ASSERT_EQ(Run("carve --project_path " + ini + " --output_path " + *root_ + "/from_ini", &output), 0)
      << output;
  std::string report = testing::ReadFileBytes(*root_ + "/from_ini/report.json");
  EXPECT_EQ(JsonNumber(report, "resolution"), 24);
  EXPECT_NE(report.find("\"mesh_kind\": \"voxels\""), std::string::npos) << report;
  ASSERT_EQ(Run("carve --project_path=" + ini + " --output_path " + *root_ + "/from_ini_16 --resolution 16",
                &output),
            0)
      << output;
  report = testing::ReadFileBytes(*root_ + "/from_ini_16/report.json");
  EXPECT_EQ(JsonNumber(report, "resolution"), 16);
  testing::WriteFile(ini, "resolution=many\n");
  ExpectUserError("carve --project_path " + ini + " --workspace_path " + Project(),
                  {ini + ":1:", "--resolution"});
  ExpectUserError("carve --project_path " + *root_ + "/no.ini", {*root_ + "/no.ini", "--project_path"});
}

TEST_F(CommandLine, ARunKilledWhileWritingLeavesThePreviousOutputsWhole) {
  const std::string out = *root_ + "/killed";
  std::string output;
  const std::string carve = "'" + testing::RaycarveBinary() + "' carve --workspace_path " +
                            Project() + " --output_path " + out;
  ASSERT_EQ(testing::RunShell(carve + " --resolution 24", &output), 0) << output;
  const std::string report = testing::ReadFileBytes(out + "/report.json");
  const std::string cloud = testing::ReadFileBytes(out + "/cloud.ply");
  // A second run with other options, killed as soon as it starts writing its outputs (the
  // staging folder appears before the mesh is made, well before anything moves into place).
  const std::string script =
      "(" + carve + " --resolution 96 --mesh_refine_passes 4 > /dev/null 2>&1 & echo $! > " + out +
      ".pid); "
      "for i in $(seq 1 3000); do ls -d " + out + "/.raycarve-partial-* > /dev/null 2>&1 && break; "
      "sleep 0.01; done; kill -9 $(cat " + out + ".pid); sleep 0.2";
  testing::WriteFile(out + ".sh", script + "\n");
  ASSERT_EQ(testing::RunShell("bash " + out + ".sh", &output), 0) << output;
  bool interrupted = false;
  for (const auto& entry : fs::directory_iterator(out)) {
    interrupted |= entry.path().filename().string().rfind(".raycarve-partial-", 0) == 0;
  }
  EXPECT_TRUE(interrupted) << "the second run was not caught while writing";
  EXPECT_EQ(testing::ReadFileBytes(out + "/report.json"), report);
  EXPECT_EQ(testing::ReadFileBytes(out + "/cloud.ply"), cloud);
  // The next run clears the interrupted run's staging folder and replaces the set.
  ASSERT_EQ(testing::RunShell(carve + " --resolution 32", &output), 0) << output;
  EXPECT_NE(testing::ReadFileBytes(out + "/report.json"), report);
  for (const auto& entry : fs::directory_iterator(out)) {
    EXPECT_EQ(entry.path().filename().string().rfind(".raycarve-partial-", 0), std::string::npos)
        << entry.path();
    EXPECT_EQ(entry.path().filename().string().rfind(".tmp.", 0), std::string::npos) << entry.path();
  }
}

TEST_F(CommandLine, AMasksFolderThatCarveDidNotWriteIsNeverWrittenInto) {
  // A studio project whose own folder holds the user's masks, carved into that folder.
  const std::string studio = *root_ + "/own_masks";
  std::string output;
  ASSERT_EQ(Run("synth --output_path " + studio +
                    " --views 4 --width 96 --height 72 --points 300 --backdrop uniform",
                &output),
            0)
      << output;
  const std::string mask = studio + "/masks/view001.png.png";
  const std::string before = testing::ReadFileBytes(mask);
  ExpectUserError("carve --workspace_path " + studio + " --output_path " + studio +
                      " --resolution 16",
                  {studio + "/masks", "raycarve did not write", "--mask_path"});
  EXPECT_EQ(testing::ReadFileBytes(mask), before);
  // An earlier carve's own output folder is written again.
  const std::string out = studio + "/out";
  for (int run = 0; run < 2; ++run) {
    ASSERT_EQ(Run("carve --workspace_path " + studio + " --output_path " + out + " --resolution 16",
                  &output),
              0)
        << output;
  }
}

TEST_F(CommandLine, NoOutputLandsInAnInputOrOutsideItsFolder) {
  // model_info's JSON inside the model it describes (it replaced images.bin).
  const std::string model = CopyModel("write_into_model");
  const std::string images_bin = testing::ReadFileBytes(model + "/images.bin");
  ExpectUserError("model_info --input_path " + model + " --output_path " + model + "/images.bin",
                  {model + "/images.bin", "lies inside the input model", "never overwrites"});
  ExpectUserError("model_info --input_path " + model + " --output_path " + model + "/../" +
                      fs::path(model).filename().string() + "/info.json",
                  {"lies inside the input model"});
  EXPECT_EQ(testing::ReadFileBytes(model + "/images.bin"), images_bin);

  // A carve's masks over the user's masks: refused before the carve starts.
  const std::string project = *root_ + "/masks_project";
  fs::remove_all(project);
  fs::copy(Project(), project, fs::copy_options::recursive);
  ASSERT_TRUE(fs::is_directory(project + "/masks"));
  ExpectUserError("carve --workspace_path " + project + " --output_path " + project +
                      " --mask_path " + project + "/masks --resolution 16",
                  {"lies inside the mask folder", project + "/masks"});

  // check_background's JSON over the cloud it checks.
  std::string output;
  ASSERT_EQ(Run("carve --workspace_path " + project + " --output_path " + project +
                    "/carved --resolution 16",
                &output),
            0)
      << output;
  const std::string cloud = project + "/carved/cloud.ply";
  ExpectUserError("check_background --input " + cloud + " --workspace_path " + project +
                      " --mask_path " + project + "/masks --output_path " + cloud,
                  {"is the input cloud"});
  // An option file given as --project_path is an input too.
  const std::string ini = project + "/options.ini";
  testing::WriteFile(ini, "[raycarve]\n");
  ExpectUserError("model_info --input_path " + project + "/sparse/0 --project_path " + ini +
                      " --output_path " + ini,
                  {"is the option file"});
  ExpectUserError("check_background --input " + cloud + " --workspace_path " + project +
                      " --mask_path " + project + "/masks --project_path " + ini +
                      " --output_path " + ini,
                  {"is the option file"});
  EXPECT_EQ(testing::ReadFileBytes(ini), "[raycarve]\n");

  // calibrate writing undistorted photos into the photo folder they come from.
  fs::copy(project + "/images", project + "/undistorted", fs::copy_options::recursive);
  ExpectUserError("calibrate --input_path " + project + "/sparse/0 --image_path " + project +
                      "/undistorted --output_path " + project + " --skip_missing_images 1",
                  {"lies inside the photo folder"});

  // An image name that climbs out of the folder its outputs go to.
  const std::string escape = CopyModel("escaping_name", "TXT");
  std::string text = testing::ReadFileBytes(escape + "/images.txt");
  const size_t at = text.find("view001.png");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, 11, "../escaped.png");
  testing::WriteFile(escape + "/images.txt", text);
  fs::copy_file(project + "/images/view001.png", project + "/escaped.png",
                fs::copy_options::overwrite_existing);
  ExpectUserError("calibrate --input_path " + escape + " --image_path " + project +
                      "/images --output_path " + *root_ + "/escaping_out",
                  {"'../escaped.png'", "would write outside"});
  EXPECT_FALSE(fs::exists(*root_ + "/escaping_out/escaped.png"));
}

TEST_F(CommandLine, MissingOrWrongPhotosAreNamedAndCanBeSkipped) {
  const std::string images = *root_ + "/images_missing";
  fs::remove_all(images);
  fs::copy(Project() + "/images", images);
  fs::remove(images + "/view003.png");
  const std::string base = "calibrate --input_path " + Project() + "/sparse/0 --output_path " +
                           *root_ + "/out_missing --image_path " + images;
  ExpectUserError(base, {images + "/view003.png", "image 3", "not found"});
  std::string output;
  EXPECT_EQ(Run(base + " --skip_missing_images 1", &output), 0) << output;
  EXPECT_NE(output.find("3 of 4 registered images loaded, 1 skipped"), std::string::npos) << output;

  cv::imwrite(images + "/view003.png", cv::Mat(10, 12, CV_8UC3, cv::Scalar::all(0)));
  ExpectUserError(base, {images + "/view003.png", "12x10", "96x72"});
}

TEST_F(CommandLine, ConverterNeverOverwritesItsInput) {
  const std::string model = CopyModel("no_overwrite");
  ExpectUserError("model_converter --input_path " + model + " --output_path " + model + "/. --output_type TXT",
                  {"never overwrites"});
}

TEST_F(CommandLine, CarveRefusesNonsenseOptionsAndVolumesTooLargeForMemory) {
  const std::string base = "carve --workspace_path " + Project() + " --output_path " + *root_ + "/refused";
  ExpectUserError(base + " --resolution 0", {"resolution must be in [1, 4096]"});
  ExpectUserError(base + " --resolution 4000 --max_memory_gib 1", {"GiB", "lower the resolution"});
  ExpectUserError(base + " --threshold nan", {"threshold must be a finite number"});
  ExpectUserError(base + " --threshold auto7", {"--threshold", "auto7"});
  ExpectUserError(base + " --threshold -5", {"threshold must be a finite number >= 0", "-5"});
  ExpectUserError(base + " --num_threads 0", {"--num_threads", "-1 (every core) or 1 to 1024", "got 0"});
  ExpectUserError(base + " --num_threads 100000", {"--num_threads", "got 100000"});
  ExpectUserError(base + " --mesh_max_faces 2", {"--mesh_", "face budget"});
  ExpectUserError(base + " --cloud_min_views 0", {"--cloud_min_views", "must be >= 1", "got 0"});
  ExpectUserError(base + " --pattern_threshold 3", {"--pattern_threshold", "[0, 2]", "'3'"});
  ExpectUserError(base + " --spread_floor -1", {"--spread_floor", "number >= 0 or auto", "'-1'"});
  ExpectUserError(base + " --spread_floor inf", {"--spread_floor", "'inf'"});
  ExpectUserError(base + " --threshold_views all", {"--threshold_views", "auto, seen or tracks", "'all'"});
  ExpectUserError(base + " --consistency median", {"not one of: mean_colour, standard_deviation"});
  ExpectUserError(base + " --method zbuffer", {"not one of: ray, gvc, gvc_ldi"});

  // A model with very few points asks for an explicit box, and carves with one.
  const std::string few = *root_ + "/few_points";
  std::string output;
  ASSERT_EQ(Run("synth --output_path " + few + " --views 3 --width 64 --height 48 --points 6",
                &output),
            0)
      << output;
  ExpectUserError("carve --workspace_path " + few + " --output_path " + few + "/out",
                  {"few_points/sparse/0: only", "too few to bound the volume", "--bbox"});
  EXPECT_EQ(Run("carve --workspace_path " + few + " --output_path " + few +
                    "/out --resolution 16 --bbox=-1.5,-1.5,0,1.5,1.5,1.1",
                &output),
            0)
      << output;
  EXPECT_TRUE(fs::is_regular_file(few + "/out/cloud.ply"));
}

TEST_F(CommandLine, SizesThatAnOptionChoosesAreEstimatedBeforeAllocation) {
  // Far more than any machine holds: refused with the estimate before anything is made.
  ExpectUserError("synth --output_path " + *root_ + "/huge --views 100000000 --width 64 --height 48",
                  {"this scene needs about", "GiB", "--views"});
  EXPECT_FALSE(fs::exists(*root_ + "/huge"));
  ExpectUserError("compare --reference_path " + *root_ + "/a.ply --input_path " + *root_ +
                      "/b.ply --mesh_samples 2000000000",
                  {"--mesh_samples 2000000000", "GiB", "give at most"});
}

}  // namespace
}  // namespace raycarve
