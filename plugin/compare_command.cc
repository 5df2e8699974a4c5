#include <algorithm>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <map>
#include <memory>

#include "calib/input_error.h"
#include "pipeline/project.h"
#include "calib/model_reader.h"
#include "export/point_cloud_compare.h"
#include "export/similarity_alignment.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "pipeline/json_writer.h"
#include "pipeline/output_files.h"

namespace raycarve {
namespace {

// Memory a mesh sample costs while comparing, both clouds counted (the points, their k-d trees
// and distances): 75 bytes measured as the peak resident memory of comparing the demo's mesh
// with itself at 1 and 4 million samples.
constexpr double kBytesPerMeshSample = 80.0;

// Refuses, before anything is allocated, a --mesh_samples whose clouds would not fit in
// kUsableMemoryShare of this machine's memory, with the count that fits.
void CheckSamplesFitInMemory(int mesh_samples) {
  const double fits = kUsableMemoryShare * PhysicalMemoryBytes() / kBytesPerMeshSample;
  CheckFitsInMemory(kBytesPerMeshSample * mesh_samples,
                    "--mesh_samples " + std::to_string(mesh_samples) + ": comparing",
                    std::to_string(static_cast<int>(kBytesPerMeshSample)) + " bytes a sample",
                    "give at most " + std::to_string(static_cast<long long>(fits)));
}

}  // namespace


namespace {

// The similarity from `input_model`'s frame to `reference_model`'s, from the camera centres of
// the images both hold (matched by name).
exporter::Alignment AlignModels(const std::string& input_model, const std::string& reference_model) {
  const Reconstruction input = ReadModel(input_model);
  const Reconstruction reference = ReadModel(reference_model);
  std::map<std::string, Eigen::Vector3d> reference_centres;
  for (const auto& [id, image] : reference.images) {
    reference_centres[image.name] = image.ProjectionCenter();
  }
  std::vector<Eigen::Vector3d> source, target;
  for (const auto& [id, image] : input.images) {
    const auto match = reference_centres.find(image.name);
    if (match == reference_centres.end()) continue;
    source.push_back(image.ProjectionCenter());
    target.push_back(match->second);
  }
  if (source.size() < 3) {
    throw InputError("raycarve compare: " + input_model + " and " + reference_model + " share " +
                     std::to_string(source.size()) +
                     " image names; aligning their frames needs at least 3");
  }
  return exporter::AlignPoints(source, target);
}

}  // namespace

std::string ComparisonJson(const std::string& reference,
                           const std::string& input,
                           const exporter::CloudComparison& c,
                           const exporter::Alignment* alignment,
                           const std::string& bbox) {
  JsonWriter json;
  json.BeginObject()
      .Key("reference").Value(reference)
      .Key("input").Value(input)
      .Key("num_reference_points").Value(static_cast<uint64_t>(c.num_reference))
      .Key("num_input_points").Value(static_cast<uint64_t>(c.num_reconstruction))
      .Key("bbox").Value(bbox)
      .Key("threshold").Value(c.threshold)
      .Key("accuracy").Value(c.accuracy)
      .Key("completeness").Value(c.completeness)
      .Key("precision").Value(c.precision)
      .Key("f_score").Value(c.f_score)
      .Key("mean_input_to_reference").Value(c.mean_reconstruction_to_reference)
      .Key("mean_reference_to_input").Value(c.mean_reference_to_reconstruction)
      .Key("chamfer").Value(c.chamfer);
  if (alignment != nullptr) {
    const exporter::Similarity3& t = alignment->transform;
    std::vector<double> rotation;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) rotation.push_back(t.rotation(row, col));
    }
    json.Key("alignment").BeginObject()
        .Key("scale").Value(t.scale)
        .Key("rotation_row_major").Value(rotation)
        .Key("translation").Value(JsonArray(t.translation))
        .Key("pairs").Value(alignment->num_pairs)
        .Key("inliers").Value(alignment->num_inliers)
        .Key("rms").Value(alignment->rms)
        .Key("rms_closed_form").Value(alignment->rms_before_refinement)
        .EndObject();
  }
  json.EndObject();
  return json.str();
}

int RunCompare(int argc, char** argv) {
  std::string reference, input, output_path, input_model, reference_model, bbox;
  int mesh_samples = 500000;
  exporter::CompareOptions options;
  OptionParser parser(
      "compare",
      "Measures a reconstruction against a reference (ground truth, or COLMAP's dense fused.ply), "
      "both PLY point clouds or meshes (meshes are sampled over their surface): accuracy (the "
      "distance within which 90% of the input lies from the reference), completeness (share of "
      "the reference within --threshold of the input), precision, F-score and chamfer distance. "
      "Both must be in the same frame, or give --input_model and --reference_model: the input is "
      "then moved by the similarity that takes the input model's camera centres onto the "
      "reference model's (images matched by name; robust, refined with Ceres).");
  parser.AddRequired("reference_path", &reference, "reference PLY (points or mesh)");
  parser.AddRequired("input_path", &input, "reconstruction PLY (points or mesh)");
  parser.AddDeprecatedName("reference", "reference_path");
  parser.AddDeprecatedName("input", "input_path");
  parser.AddDefault("threshold", &options.threshold,
                    "match distance for completeness, precision and F-score (world units)");
  parser.AddDefault("accuracy_quantile", &options.accuracy_quantile,
                    "share of the input that the accuracy distance covers");
  parser.AddDefault("mesh_samples", &mesh_samples, "points sampled on each mesh");
  parser.AddDefault("output_path", &output_path, "also write the JSON report to this file");
  parser.AddDefault("input_model", &input_model,
                    "COLMAP model the input was made from (e.g. COLMAP SfM's sparse/0)");
  parser.AddDefault("reference_model", &reference_model,
                    "COLMAP model in the reference's frame (e.g. the given calibration)");
  parser.AddDefault("bbox", &bbox,
                    "compare only inside this box, min_x,min_y,min_z,max_x,max_y,max_z in the "
                    "reference's frame (e.g. the volume a carve covered, report.json's bounds): "
                    "both clouds are cut to it");
  if (!parser.Parse(argc, argv)) return 0;
  const std::unique_ptr<Bounds> crop =
      bbox.empty() ? nullptr : std::make_unique<Bounds>(ParseBoxText(bbox, "--bbox"));
  if (input_model.empty() != reference_model.empty()) {
    throw InputError("raycarve compare: give both --input_model and --reference_model, or neither");
  }
  std::string reason;
  if (!options.IsValid(&reason)) throw InputError("raycarve compare: " + reason);
  if (mesh_samples < 1) throw InputError("raycarve compare: --mesh_samples must be >= 1");
  CheckSamplesFitInMemory(mesh_samples);
  std::vector<Eigen::Vector3f> input_points = exporter::ReadComparablePoints(input, mesh_samples);
  std::unique_ptr<exporter::Alignment> alignment;
  if (!input_model.empty()) {
    alignment = std::make_unique<exporter::Alignment>(AlignModels(input_model, reference_model));
    for (Eigen::Vector3f& point : input_points) {
      point = alignment->transform(point.cast<double>()).cast<float>();
    }
  }
  std::vector<Eigen::Vector3f> reference_points =
      exporter::ReadComparablePoints(reference, mesh_samples);
  if (crop) {
    const auto outside = [&](const Eigen::Vector3f& point) {
      return !crop->box.contains(point.cast<double>());
    };
    reference_points.erase(
        std::remove_if(reference_points.begin(), reference_points.end(), outside),
        reference_points.end());
    input_points.erase(std::remove_if(input_points.begin(), input_points.end(), outside),
                       input_points.end());
    if (reference_points.empty() || input_points.empty()) {
      throw InputError("raycarve compare: --bbox " + bbox + " holds " +
                       std::to_string(reference_points.size()) + " reference and " +
                       std::to_string(input_points.size()) +
                       " input points; is it in the reference's frame?");
    }
  }
  const exporter::CloudComparison comparison =
      exporter::CompareClouds(reference_points, input_points, options);
  const std::string json = ComparisonJson(reference, input, comparison, alignment.get(), bbox);
  std::cout << "compare " << input << " against " << reference << "\n";
  if (alignment) std::cout << "  aligned: " << alignment->Summary() << "\n";
  std::cout << "  " << comparison.Summary() << "\n" << json;
  if (!output_path.empty()) {
    CheckOutputDoesNotOverwrite(output_path, reference, "reference");
    CheckOutputDoesNotOverwrite(output_path, input, "input");
    WriteTextFileAtomically(output_path, json);
  }
  return 0;
}

}  // namespace raycarve
