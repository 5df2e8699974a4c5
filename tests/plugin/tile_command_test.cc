// raycarve tile plan | run | merge, run as a user runs them: every tile job is its own process.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "tests/plugin/project_fixture.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;
using testing::ExpectUserError;
using testing::JsonNumber;
using testing::ReadFileBytes;

// 8 photos of 240 x 180 around the generated scene, carved at 128 voxels (levels 64 and 128).
class TileCommand : public testing::GeneratedProject {
 protected:
  static void SetUpTestSuite() {
    MakeProject("tile_command", "--views 8 --width 240 --height 180 --points 1500");
  }
  static std::string Carve() { return "--workspace_path " + Project() + " --resolution 128 "; }
  // Plans into `tiles` with `extra` options and runs every job; returns the number of jobs.
  static int PlanAndRun(const std::string& tiles, const std::string& extra) {
    std::string output;
    EXPECT_EQ(Run("tile plan " + Carve() + "--output_path " + *root_ + "/tiled --tiles 2 " +
                      "--tile_path " + tiles + " " + extra,
                  &output),
              0)
        << output;
    const int jobs = static_cast<int>(JsonNumber(ReadFileBytes(tiles + "/plan.json"), "jobs"));
    for (int job = 0; job < jobs; ++job) {
      EXPECT_EQ(Run("tile run --plan " + tiles + "/plan.json --index " + std::to_string(job), &output),
                0)
          << output;
    }
    return jobs;
  }
};

TEST_F(TileCommand, JobsInSeparateProcessesMergeToWhatOneCarveGives) {
  std::string output;
  const std::string single = *root_ + "/single";
  ASSERT_EQ(Run("carve " + Carve() + "--output_path " + single, &output), 0) << output;
  const std::string tiles = *root_ + "/tiles";
  const int jobs = PlanAndRun(tiles, "");
  ASSERT_GE(jobs, 4);
  ASSERT_LE(jobs, 8);
  // The jobs for a cluster: a Slurm array over the jobs with the merge after it, a Kubernetes
  // indexed Job, and the same as local processes.
  const std::string sbatch = ReadFileBytes(tiles + "/tiles.sbatch");
  EXPECT_NE(sbatch.find("#SBATCH --array=0-" + std::to_string(jobs - 1) + "\n"), std::string::npos)
      << sbatch;
  EXPECT_NE(sbatch.find("--index \"$SLURM_ARRAY_TASK_ID\""), std::string::npos) << sbatch;
  EXPECT_NE(sbatch.find("#SBATCH --mem="), std::string::npos);
  EXPECT_NE(ReadFileBytes(tiles + "/submit_slurm.sh").find("--dependency=afterok"), std::string::npos);
  const std::string k8s = ReadFileBytes(tiles + "/tiles.k8s.yaml");
  EXPECT_NE(k8s.find("completionMode: Indexed"), std::string::npos) << k8s;
  EXPECT_NE(k8s.find("completions: " + std::to_string(jobs) + "\n"), std::string::npos) << k8s;
  EXPECT_NE(k8s.find("JOB_COMPLETION_INDEX"), std::string::npos) << k8s;
  EXPECT_TRUE(fs::is_regular_file(tiles + "/run_local.sh"));
  // The manifests are YAML that Kubernetes reads as an indexed Job and a plain one.
  std::string parsed;
  ASSERT_EQ(testing::RunShell(
                "/usr/bin/python3 -c \"import sys, yaml\n"
                "for path in sys.argv[1:]:\n"
                "  job = yaml.safe_load(open(path))\n"
                "  spec = job['spec']; pod = spec['template']['spec']; c = pod['containers'][0]\n"
                "  print(job['kind'], spec.get('completionMode', '-'), spec.get('completions', 0), "
                "pod['restartPolicy'], c['resources']['requests']['memory'], "
                "'INDEX' if 'JOB_COMPLETION_INDEX' in c['command'][2] else 'noindex')\" " +
                    tiles + "/tiles.k8s.yaml " + tiles + "/merge.k8s.yaml",
                &parsed),
            0)
      << parsed;
  EXPECT_NE(parsed.find("Job Indexed " + std::to_string(jobs) + " Never "), std::string::npos) << parsed;
  EXPECT_NE(parsed.find("Mi INDEX\nJob - 0 Never "), std::string::npos) << parsed;
  EXPECT_NE(parsed.find("Mi noindex"), std::string::npos) << parsed;

  ASSERT_EQ(Run("tile merge --plan " + tiles + "/plan.json", &output), 0) << output;
  const std::string tiled = *root_ + "/tiled";
  for (const char* name : {"cloud.ply", "mesh.ply", "mesh.glb", "report.json", "fused.ply"}) {
    EXPECT_TRUE(fs::is_regular_file(tiled + "/" + name)) << name;
  }
  const std::string tiled_report = ReadFileBytes(tiled + "/report.json");
  EXPECT_EQ(JsonNumber(tiled_report, "jobs"), jobs);
  // One mesh from the joined volume: no seam along the cuts. The scene's ground runs out of the
  // box, so both meshes are open there; a seam would add its edges along every cut.
  const double single_edges = JsonNumber(ReadFileBytes(single + "/report.json"), "boundary_edges");
  const double tiled_edges = JsonNumber(tiled_report, "boundary_edges");
  std::printf("boundary edges: single %.0f, tiled %.0f\n", single_edges, tiled_edges);
  EXPECT_LE(tiled_edges, 1.1 * single_edges + 20);
  EXPECT_EQ(JsonNumber(tiled_report, "self_intersecting_pairs"), 0);
  EXPECT_GT(JsonNumber(tiled_report, "merge_evaluated"), 0);
  EXPECT_NE(output.find("joined from " + std::to_string(jobs) + " jobs"), std::string::npos) << output;
  // Against the truth as good as the single carve, and the two models within a voxel.
  const std::string report = ReadFileBytes(single + "/report.json");
  const double voxel = JsonNumber(report, "voxel_size");
  double f[2];
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(Run("compare --input_path " + (i == 0 ? single : tiled) + "/cloud.ply --reference_path " +
                      Project() + "/truth.ply --threshold " + std::to_string(2 * voxel),
                  &output),
              0)
        << output;
    f[i] = JsonNumber(output, "f_score");
  }
  std::printf("F-score at 2 voxels: single %.4f, tiled %.4f\n", f[0], f[1]);
  EXPECT_GT(f[1], f[0] - 0.01);
  ASSERT_EQ(Run("compare --input_path " + tiled + "/cloud.ply --reference_path " + single +
                    "/cloud.ply --threshold " + std::to_string(voxel),
                &output),
            0)
      << output;
  std::printf("tiled against single within one voxel: F-score %.4f\n", JsonNumber(output, "f_score"));
  EXPECT_GT(JsonNumber(output, "f_score"), 0.97);
}

TEST_F(TileCommand, TheMergeRefusesMissingOrForeignPartsAndAJobRunAgainRestoresItsPart) {
  const std::string tiles = *root_ + "/tiles_refuse";
  ASSERT_GE(PlanAndRun(tiles, ""), 2);
  const std::string part = tiles + "/tile_1.bin";
  const std::string bytes = ReadFileBytes(part);
  // A job killed before its part was renamed into place leaves no part: the merge names it.
  fs::remove(part);
  testing::WriteFile(tiles + "/.tmp.tile_1.bin", bytes.substr(0, bytes.size() / 2));
  ExpectUserError("tile merge --plan " + tiles + "/plan.json", {part, "missing", "jobs 1"});
  std::string output;
  ASSERT_EQ(Run("tile run --plan " + tiles + "/plan.json --index 1", &output), 0) << output;
  EXPECT_EQ(ReadFileBytes(part), bytes);  // the same part again
  // A cut part, and a part of another plan (another threshold: another plan id).
  testing::WriteFile(part, bytes.substr(0, bytes.size() - 8));
  ExpectUserError("tile merge --plan " + tiles + "/plan.json", {part, "shorter"});
  const std::string other = *root_ + "/tiles_other";
  ASSERT_EQ(Run("tile plan " + Carve() + "--tiles 2 --tile_path " + other + " --threshold 25", &output), 0)
      << output;
  ASSERT_EQ(Run("tile run --plan " + other + "/plan.json --index 1", &output), 0) << output;
  fs::copy_file(other + "/tile_1.bin", part, fs::copy_options::overwrite_existing);
  ExpectUserError("tile merge --plan " + tiles + "/plan.json", {part, "plan_id", "another plan"});
  // The plan's distant pixels, which every job takes instead of searching the photos again.
  fs::rename(tiles + "/distant.bin", tiles + "/distant.saved");
  ExpectUserError("tile run --plan " + tiles + "/plan.json --index 0", {"distant.bin", "missing"});
  fs::rename(tiles + "/distant.saved", tiles + "/distant.bin");
  // Jobs and plans that do not exist.
  ExpectUserError("tile run --plan " + tiles + "/plan.json --index 99", {"--index 99", "jobs 0 to"});
  ExpectUserError("tile run --plan " + *root_ + "/nowhere/plan.json --index 0", {"nowhere/plan.json", "missing"});
  testing::WriteFile(*root_ + "/bad_plan.json", "{\"schema\": 1, \"plan_id\": \"0123456789abcdef\"}");
  ExpectUserError("tile merge --plan " + *root_ + "/bad_plan.json", {"bad_plan.json", "working_directory"});
  ExpectUserError("tile plan " + Carve() + "--tiles 2 --tile_overlap 3 --tile_path " + other,
                  {"overlap", "even"});
  ExpectUserError("tile plan --workspace_path " + Project() + " --resolution 64 --tiles 2 --tile_path " + other,
                  {"levels of detail"});
  ExpectUserError("tile fly", {"unknown step", "plan, run or merge"});
}

}  // namespace
}  // namespace raycarve
