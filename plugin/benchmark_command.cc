// raycarve benchmark: the seed paper's comparison (its Table 1 and Figure 6) on any project.
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "calib/input_error.h"
#include "pipeline/method_comparison.h"
#include "plugin/carve_flags.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"

namespace raycarve {
namespace {

std::vector<CarveMethod> ParseMethods(const std::string& text) {
  std::vector<CarveMethod> methods;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    CarveMethod method;
    if (!CarveMethodFromString(item, &method)) {
      throw InputError("raycarve benchmark: --methods: unknown method '" + item +
                       "' (ray, gvc, gvc_ldi)");
    }
    methods.push_back(method);
  }
  if (methods.empty()) throw InputError("raycarve benchmark: --methods is empty");
  return methods;
}

}  // namespace

int RunBenchmark(int argc, char** argv) {
  CarveRequest request;
  CarveFlagText text;
  std::string methods_text = "ray,gvc_ldi,gvc";
  MethodComparisonOptions options;
  OptionParser parser(
      "benchmark",
      "The seed paper's comparison on one project: carves it with each method (same grid, "
      "consistency test and options; only visibility differs), prints Table 1 (convergence time, "
      "memory, voxels carved and evaluated), compares the final volumes with each other (voxel "
      "IoU, voxels that differ), and writes <output>/benchmark/: benchmark.json, table.md, "
      "figure6.csv and figure6.png (voxels carved against time), cloud_<method>.ply.");
  // One thread by default: the paper's comparison is of the methods, and only ray casting runs
  // on several.
  request.options.num_threads = 1;
  // The paper's order, one voxel at a time, as the baselines carve: GVC-LDI then makes the same
  // decisions as ray casting.
  request.options.batch_voxels = 1;
  request.options.lod_levels = 1;  // the paper's Table 1 carves in one level, as it ends
  request.options.min_component_voxels = 0;
  AddCarveFlags(&parser, &request, &text);
  parser.BeginGroup("Benchmark");
  parser.AddDefault("methods", &methods_text, "comma-separated: ray, gvc_ldi, gvc");
  parser.AddDefault("reference", &options.reference_path,
                    "optional reference PLY (e.g. synth's truth.ply): accuracy and completeness "
                    "of each method's cloud");
  parser.AddDefault("reference_threshold", &options.reference_threshold,
                    "completeness distance for --reference (0: two voxels)");
  parser.SetBasicOptions({"workspace_path", "output_path", "methods", "reference", "resolution",
                          "num_threads"});
  parser.AddExample("raycarve benchmark --workspace_path P --reference P/truth.ply",
                    "the paper's Table 1 and Figure 6 on P, each cloud against a true surface");
  if (!parser.Parse(argc, argv)) return 0;
  ApplyCarveFlags(parser, text, &request);
  options.methods = ParseMethods(methods_text);
  const MethodComparison comparison = CompareCarveMethods(request, options);
  std::printf("\n%s\n%s\nwritten to %s/ (benchmark.json, table.md, figure6.csv, figure6.png)\n",
              comparison.table.c_str(), comparison.agreement_table.c_str(),
              comparison.output_folder.c_str());
  return 0;
}

}  // namespace raycarve
