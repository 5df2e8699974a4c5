// A small program using raycarve's libraries: how many of the sparse points that `raycarve
// holdout` checks the model's depth against are themselves where the truth is, on a generated
// scene (raycarve synth). holdout writes each held-out view's points with the model's verdict
// (holdout/sparse_depth.csv); this program traces each point's ray in the true scene and says
// whether the truth would draw it at its depth, hide it behind something nearer (a wrong match,
// or a point triangulated off an occluding contour, inside the object), or lie behind it (a point
// floating in free space). A model that hides points the truth hides too is not at fault.
//   truth_sparse_depth PROJECT SPARSE_DEPTH_CSV TOLERANCE SCENE BACKDROP [OUT_CSV]
// PROJECT is the generated project (its sparse/0 gives the cameras' centres), TOLERANCE the
// holdout's (holdout.json: sparse_depth_tolerance), SCENE and BACKDROP synth's --scene and
// --backdrop. Prints a table of the model's verdicts against the truth's, then a JSON line;
// OUT_CSV, where given, receives the input's lines with the truth's verdict and depth added.
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "samples/scene_tracing.h"
#include "samples/synthetic_scene.h"

namespace raycarve {
namespace {

const char* const kModelVerdicts[] = {"at_depth", "hidden", "behind", "undrawn"};
const char* const kTruthVerdicts[] = {"at_depth", "hides_it", "behind_it"};

// The CSV's fields; a quoted first field (a name with a comma) is unquoted.
std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  return fields;
}

int Index(const char* const* names, int count, const std::string& name, const std::string& where) {
  for (int i = 0; i < count; ++i) {
    if (name == names[i]) return i;
  }
  throw InputError(where + ": unknown verdict '" + name + "'");
}

int Run(const std::string& project, const std::string& csv_path, double tolerance,
        const std::string& scene_name, const std::string& backdrop_name,
        const std::string& out_path) {
  SyntheticSceneOptions options;
  if (!SceneKindFromString(scene_name, &options.scene)) {
    throw InputError("unknown scene " + scene_name);
  }
  if (!BackdropFromString(backdrop_name, &options.backdrop)) {
    throw InputError("unknown backdrop " + backdrop_name);
  }
  if (!(tolerance > 0.0)) throw InputError("TOLERANCE must be positive");
  const std::shared_ptr<const SceneGeometry> geometry = MakeSceneGeometry(options);
  const Reconstruction model = ReadModel(project + "/sparse/0");
  std::map<std::string, Eigen::Vector3d> centre_of;
  for (const auto& [id, image] : model.images) {
    centre_of[image.name] = image.cam_from_world.Inverse().translation;
  }
  std::ifstream in(csv_path);
  if (!in) throw InputError(csv_path + ": cannot be read");
  std::string line;
  std::getline(in, line);  // the header
  std::ofstream out;
  if (!out_path.empty()) {
    out.open(out_path);
    if (!out) throw InputError(out_path + ": cannot be written");
    out << line << ",truth_verdict,truth_depth\n";
  }
  int counts[4][3] = {};
  int points = 0, line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    const std::string where = csv_path + ":" + std::to_string(line_number);
    const std::vector<std::string> f = SplitCsv(line);
    if (f.size() != 7) throw InputError(where + ": expected 7 fields");
    const auto centre = centre_of.find(f[0]);
    if (centre == centre_of.end()) throw InputError(where + ": no image named " + f[0]);
    const Eigen::Vector3d point(std::stod(f[1]), std::stod(f[2]), std::stod(f[3]));
    const double depth = std::stod(f[4]);
    const Eigen::Vector3d ray = point - centre->second;
    const double distance = ray.norm();
    // Depth along the view's axis scales with distance along the ray.
    const double truth_depth =
        depth * scene_tracing::FirstSolidDistance(*geometry, options.backdrop, centre->second,
                                                  ray / distance) / distance;
    const int truth = std::abs(truth_depth - depth) <= tolerance ? 0
                      : truth_depth < depth - tolerance          ? 1
                                                                 : 2;
    ++counts[Index(kModelVerdicts, 4, f[6], where)][truth];
    if (out.is_open()) out << line << "," << kTruthVerdicts[truth] << "," << truth_depth << "\n";
    ++points;
  }
  if (points == 0) throw InputError(csv_path + ": no points");
  std::printf("%-10s", "model\\truth");
  for (const char* truth : kTruthVerdicts) std::printf(" %10s", truth);
  std::printf("\n");
  for (int m = 0; m < 4; ++m) {
    std::printf("%-11s", kModelVerdicts[m]);
    for (int t = 0; t < 3; ++t) std::printf(" %10d", counts[m][t]);
    std::printf("\n");
  }
  const auto share = [&](int count) { return static_cast<double>(count) / points; };
  int truth_at_depth = 0, truth_hides = 0;
  for (int m = 0; m < 4; ++m) {
    truth_at_depth += counts[m][0];
    truth_hides += counts[m][1];
  }
  // The headline: of the points the truth draws at their depth, the shares the model draws there
  // and hides behind something nearer.
  const auto of_truth = [&](int count) {
    return truth_at_depth > 0 ? static_cast<double>(count) / truth_at_depth : 0.0;
  };
  std::printf("{\"points\": %d, \"truth_at_depth_share\": %.4f, \"truth_hidden_share\": %.4f, "
              "\"model_at_depth_share\": %.4f, \"model_hidden_share\": %.4f, "
              "\"truth_at_depth_points\": %d, \"truth_hidden_points\": %d, "
              "\"model_at_depth_of_truth_at_depth\": %.4f, "
              "\"model_hidden_of_truth_at_depth\": %.4f}\n",
              points, share(truth_at_depth), share(truth_hides),
              share(counts[0][0] + counts[0][1] + counts[0][2]),
              share(counts[1][0] + counts[1][1] + counts[1][2]), truth_at_depth, truth_hides,
              of_truth(counts[0][0]), of_truth(counts[1][0]));
  return 0;
}

}  // namespace
}  // namespace raycarve

int main(int argc, char** argv) {
  if (argc != 6 && argc != 7) {
    std::fprintf(stderr, "usage: %s PROJECT SPARSE_DEPTH_CSV TOLERANCE SCENE BACKDROP [OUT_CSV]\n",
                 argv[0]);
    return 1;
  }
  try {
    return raycarve::Run(argv[1], argv[2], std::stod(argv[3]), argv[4], argv[5],
                         argc == 7 ? argv[6] : "");
  } catch (const std::exception& error) {
    std::fprintf(stderr, "truth_sparse_depth: %s\n", error.what());
    return 1;
  }
}
