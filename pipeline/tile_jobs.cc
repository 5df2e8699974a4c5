#include "pipeline/tile_jobs.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "pipeline/output_files.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string Quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string SlurmTime(double minutes) {
  const int total = static_cast<int>(std::ceil(std::max(minutes, 1.0)));
  char text[32];
  std::snprintf(text, sizeof(text), "%d:%02d:00", total / 60, total % 60);
  return text;
}

int MemoryMiB(double gib) { return static_cast<int>(std::ceil(gib * 1024.0 / 256.0)) * 256; }

// The jobs' commands: a tile job (its index appended) and the merge.
struct JobCommands {
  std::string run;
  std::string merge;
  std::string logs;  // the folder of Slurm's logs
  double memory_gib = 0.0;  // the largest tile's estimate
  double minutes = 0.0;
};

void MakeExecutable(const fs::path& path) {
  fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
}

// tiles.sbatch (an array over the jobs), merge.sbatch and submit_slurm.sh (the merge after every
// task of the array succeeded).
void WriteSlurmJobs(const fs::path& folder, const TilePlan& plan, const JobCommands& jobs) {
  // One sbatch script: its comment lines, name, extra directives, request and command.
  const auto script = [&](const std::string& comment, const std::string& name,
                          const std::string& directives, double memory_gib, double minutes,
                          const std::string& log, const std::string& command) {
    std::ostringstream text;
    text << "#!/bin/bash\n" << comment << "#SBATCH --job-name=" << name << "\n" << directives
         << "#SBATCH --cpus-per-task=2\n"
         << "#SBATCH --mem=" << MemoryMiB(memory_gib) << "M\n"
         << "#SBATCH --time=" << SlurmTime(minutes) << "\n"
         << "#SBATCH --output=" << jobs.logs << "/" << log << "\n"
         << "cd " << Quoted(plan.working_directory) << "\n"
         << "exec " << command << "\n";
    return text.str();
  };
  WriteTextFileAtomically(
      (folder / "tiles.sbatch").string(),
      script("# raycarve tile jobs of plan " + plan.plan_id +
                 ": one array task per tile with work.\n"
                 "# Memory and time: the largest tile's estimate (plan.json lists each tile's).\n",
             "raycarve-tiles",
             "#SBATCH --array=0-" + std::to_string(std::max(0, plan.jobs - 1)) + "\n",
             jobs.memory_gib, jobs.minutes, "tile_%a.log",
             jobs.run + " --index \"$SLURM_ARRAY_TASK_ID\""));
  WriteTextFileAtomically(
      (folder / "merge.sbatch").string(),
      script("# raycarve: joins the tiles of plan " + plan.plan_id + " and writes the model.\n",
             "raycarve-merge", "", plan.merge_memory_gib, plan.merge_minutes, "merge.log",
             jobs.merge));
  std::ostringstream submit;
  submit << "#!/bin/bash\n"
         << "# Submits the tile array, then the merge once every task has succeeded.\n"
         << "set -euo pipefail\n"
         << "cd " << Quoted(folder.string()) << "\n"
         << "mkdir -p logs\n"
         << "array=$(sbatch --parsable tiles.sbatch)\n"
         << "merge=$(sbatch --parsable --dependency=afterok:\"${array%%;*}\" merge.sbatch)\n"
         << "echo \"tiles: job $array, merge: job $merge\"\n";
  WriteTextFileAtomically((folder / "submit_slurm.sh").string(), submit.str());
  MakeExecutable(folder / "submit_slurm.sh");
}

// One Kubernetes Job: `indexed`, one completion per tile job (the index in JOB_COMPLETION_INDEX).
// The workspace must be mounted at the same path in the pods (a volume the user names).
std::string KubernetesJob(const TilePlan& plan, const std::string& raycarve, const std::string& name,
                          bool indexed, double gib, double minutes, const std::string& command) {
  std::ostringstream y;
  y << "# raycarve plan " << plan.plan_id << ". The image must hold raycarve at " << raycarve
    << ",\n# and the workspace must be mounted at " << plan.working_directory
    << " (edit the volume below).\n"
    << "apiVersion: batch/v1\nkind: Job\nmetadata:\n  name: " << name << "\nspec:\n";
  if (indexed) {
    y << "  completionMode: Indexed\n  completions: " << plan.jobs << "\n  parallelism: " << plan.jobs
      << "\n";
  }
  y << "  backoffLimit: 2\n  activeDeadlineSeconds: "
    << static_cast<int>(std::ceil(std::max(minutes, 1.0) * 60.0) * (indexed ? 2 : 1)) << "\n"
    << "  template:\n    spec:\n      restartPolicy: Never\n      containers:\n"
    << "        - name: raycarve\n          image: raycarve:latest\n"
    << "          workingDir: " << plan.working_directory << "\n"
    << "          command: [\"/bin/sh\", \"-c\", " << json(command).dump() << "]\n"
    << "          resources:\n            requests:\n              cpu: \"2\"\n"
    << "              memory: " << MemoryMiB(gib) << "Mi\n            limits:\n"
    << "              memory: " << MemoryMiB(gib) << "Mi\n"
    << "          volumeMounts:\n            - name: workspace\n              mountPath: "
    << plan.working_directory << "\n      volumes:\n        - name: workspace\n"
    << "          persistentVolumeClaim:\n            claimName: raycarve-workspace\n";
  return y.str();
}

}  // namespace

void WriteTileJobScripts(const std::string& folder, const TilePlan& plan,
                         const std::string& raycarve, const std::string& plan_path) {
  JobCommands jobs;
  for (const TilePlan::Tile& tile : plan.tiles) {
    if (tile.job < 0) continue;
    jobs.memory_gib = std::max(jobs.memory_gib, tile.memory_gib);
    jobs.minutes = std::max(jobs.minutes, tile.minutes);
  }
  jobs.logs = (fs::path(folder) / "logs").string();
  jobs.run = Quoted(raycarve) + " tile run --plan " + Quoted(plan_path);
  jobs.merge = Quoted(raycarve) + " tile merge --plan " + Quoted(plan_path);
  WriteSlurmJobs(folder, plan, jobs);
  WriteTextFileAtomically((fs::path(folder) / "tiles.k8s.yaml").string(),
                          KubernetesJob(plan, raycarve, "raycarve-tiles", true, jobs.memory_gib,
                                        jobs.minutes, jobs.run + " --index \"$JOB_COMPLETION_INDEX\""));
  WriteTextFileAtomically((fs::path(folder) / "merge.k8s.yaml").string(),
                          "# Apply once the tiles' Job has completed:\n"
                          "#   kubectl wait --for=condition=complete job/raycarve-tiles --timeout=24h\n" +
                              KubernetesJob(plan, raycarve, "raycarve-merge", false,
                                            plan.merge_memory_gib, plan.merge_minutes, jobs.merge));
  std::ostringstream local;
  local << "#!/bin/bash\n"
        << "# The tile jobs as processes on this machine, JOBS at a time (default 1), then the merge.\n"
        << "set -euo pipefail\n"
        << "cd " << Quoted(plan.working_directory) << "\n"
        << "seq 0 " << plan.jobs - 1 << " | xargs -P \"${JOBS:-1}\" -I{} " << jobs.run << " --index {}\n"
        << jobs.merge << "\n";
  WriteTextFileAtomically((fs::path(folder) / "run_local.sh").string(), local.str());
  MakeExecutable(fs::path(folder) / "run_local.sh");
}

}  // namespace raycarve
