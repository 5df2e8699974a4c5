#pragma once

#include <string>
#include <vector>

#include "carve/carver.h"
#include "pipeline/carve_request.h"

namespace raycarve {

// `raycarve benchmark`: the seed paper's comparison (its Table 1 and Figure 6) on any project.
struct MethodComparisonOptions {
  std::vector<CarveMethod> methods = {CarveMethod::kRay, CarveMethod::kGvcLdi, CarveMethod::kGvc};
  std::string reference_path;        // optional PLY: each method's cloud against it
  double reference_threshold = 0.0;  // completeness distance (0: two voxels)
};

struct MethodComparison {
  std::string table;            // Table 1 (Markdown): time, memory, carved, evaluated per method
  std::string agreement_table;  // voxel IoU between the methods' volumes (Markdown)
  std::string output_folder;    // <output>/benchmark
};

// Runs the carve pipeline up to the volume check once, then carves the same views with each
// method (the same grid, test and options; only visibility differs), and writes to
// <output>/benchmark/: benchmark.json, table.md, figure6.csv, figure6.png (voxels carved against
// time) and cloud_<method>.ply. Throws InputError on bad input or options.
MethodComparison CompareCarveMethods(const CarveRequest& request,
                                     const MethodComparisonOptions& options);

}  // namespace raycarve
