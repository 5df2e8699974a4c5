#include <iostream>

#include "calib/input_error.h"
#include "export/point_cloud_compare.h"
#include "plugin/commands.h"
#include "plugin/json_writer.h"

namespace raycarve {

std::string ComparisonJson(const std::string& reference,
                           const std::string& input,
                           const exporter::CloudComparison& c) {
  JsonWriter json;
  json.BeginObject()
      .Key("reference").Value(reference)
      .Key("input").Value(input)
      .Key("num_reference_points").Value(static_cast<uint64_t>(c.num_reference))
      .Key("num_input_points").Value(static_cast<uint64_t>(c.num_reconstruction))
      .Key("threshold").Value(c.threshold)
      .Key("accuracy").Value(c.accuracy)
      .Key("completeness").Value(c.completeness)
      .Key("precision").Value(c.precision)
      .Key("f_score").Value(c.f_score)
      .Key("mean_input_to_reference").Value(c.mean_reconstruction_to_reference)
      .Key("mean_reference_to_input").Value(c.mean_reference_to_reconstruction)
      .Key("chamfer").Value(c.chamfer)
      .EndObject();
  return json.str();
}

int RunCompare(int argc, char** argv) {
  std::string reference, input, output_path;
  int mesh_samples = 500000;
  exporter::CompareOptions options;
  OptionParser parser(
      "compare",
      "Measures a reconstruction against a reference (ground truth, or COLMAP's dense fused.ply), "
      "both PLY point clouds or meshes (meshes are sampled over their surface): accuracy (the "
      "distance within which 90% of the input lies from the reference), completeness (share of "
      "the reference within --threshold of the input), precision, F-score and chamfer distance. "
      "Both must be in the same frame.");
  parser.AddRequired("reference", &reference, "reference PLY (points or mesh)");
  parser.AddRequired("input", &input, "reconstruction PLY (points or mesh)");
  parser.AddDefault("threshold", &options.threshold,
                    "match distance for completeness, precision and F-score (world units)");
  parser.AddDefault("accuracy_quantile", &options.accuracy_quantile,
                    "share of the input that the accuracy distance covers");
  parser.AddDefault("mesh_samples", &mesh_samples, "points sampled on each mesh");
  parser.AddDefault("output_path", &output_path, "also write the JSON report to this file");
  if (!parser.Parse(argc, argv)) return 0;
  std::string reason;
  if (!options.IsValid(&reason)) throw InputError("raycarve compare: " + reason);
  if (mesh_samples < 1) throw InputError("raycarve compare: --mesh_samples must be >= 1");
  const exporter::CloudComparison comparison =
      exporter::CompareClouds(exporter::ReadComparablePoints(reference, mesh_samples),
                              exporter::ReadComparablePoints(input, mesh_samples), options);
  const std::string json = ComparisonJson(reference, input, comparison);
  std::cout << "compare " << input << " against " << reference << "\n  " << comparison.Summary()
            << "\n"
            << json;
  if (!output_path.empty()) {
    CheckOutputDoesNotOverwrite(output_path, reference, "reference");
    CheckOutputDoesNotOverwrite(output_path, input, "input");
    WriteTextFileAtomically(output_path, json);
  }
  return 0;
}

}  // namespace raycarve
