#pragma once

#include <string>

#include "pipeline/carve_pipeline.h"

namespace raycarve {

// The summary of a finished carve as `raycarve carve` prints it: the grid and what was carved,
// levels, times and memory, the surface, the sparse points' distances, the capture, the masks,
// the outputs, then warnings, COLMAP's mesher commands, the mesh's figures and, for a capture
// whose volume box cuts the scene, what to try next. Lines end in '\n'.
std::string CarveSummaryText(const CarveRequest& request, const CarveRun& run);

}  // namespace raycarve
