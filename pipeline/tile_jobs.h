#pragma once
// The jobs of a tile plan (pipeline/tile_plan.h) for the engines that run them: a Slurm array
// job and the merge after it, a Kubernetes indexed Job and the merge Job, and a local script.

#include <string>

#include "pipeline/tile_plan.h"

namespace raycarve {

// The job scripts in `folder` (Slurm, Kubernetes, local processes) for `plan`, running
// `raycarve` (an absolute path) on `plan_path`; each job's memory and time from the plan.
void WriteTileJobScripts(const std::string& folder, const TilePlan& plan,
                         const std::string& raycarve, const std::string& plan_path);

}  // namespace raycarve
