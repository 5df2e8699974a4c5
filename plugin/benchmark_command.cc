// raycarve benchmark: the seed paper's comparison (its Table 1 and Figure 6) on any project.
#include <cstdio>
#include <filesystem>
#include <sstream>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "carve/carver.h"
#include "export/carve_export.h"
#include "export/line_plot.h"
#include "export/point_cloud_compare.h"
#include "export/point_cloud_io.h"
#include "pipeline/carve_pipeline.h"
#include "plugin/carve_flags.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "pipeline/json_writer.h"
#include "pipeline/output_files.h"

namespace raycarve {
namespace {

struct MethodRun {
  CarveMethod method;
  std::unique_ptr<CarveResult> result;
  size_t cloud_points = 0;
  bool compared = false;
  exporter::CloudComparison comparison;
};

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
  std::string reference;
  double reference_threshold = 0.0;
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
  parser.AddDefault("reference", &reference,
                    "optional reference PLY (e.g. synth's truth.ply): accuracy and completeness "
                    "of each method's cloud");
  parser.AddDefault("reference_threshold", &reference_threshold,
                    "completeness distance for --reference (0: two voxels)");
  parser.SetBasicOptions({"workspace_path", "output_path", "methods", "reference", "resolution",
                          "num_threads"});
  parser.AddExample("raycarve benchmark --workspace_path P --reference P/truth.ply",
                    "the paper's Table 1 and Figure 6 on P, each cloud against a true surface");
  if (!parser.Parse(argc, argv)) return 0;
  ApplyCarveFlags(text, &request);
  const std::vector<CarveMethod> methods = ParseMethods(methods_text);

  // The carve pipeline's stages up to the carve, once; then a carve per method of the same views.
  PipelineScope scope;
  scope.command = "benchmark";
  CarvePipeline pipeline(request, scope);
  pipeline.LoadViews();
  pipeline.AgreeMasks();
  pipeline.CheckVolume();
  const LoadedProject& project = pipeline.project();
  const std::vector<CalibratedView>& views = pipeline.carved_views();
  std::vector<Eigen::Vector3f> reference_points;
  if (!reference.empty()) reference_points = exporter::ReadComparablePoints(reference, 200000);
  const std::filesystem::path out = std::filesystem::path(project.output_path) / "benchmark";
  std::error_code error;
  std::filesystem::create_directories(out, error);
  if (error) throw InputError(out.string() + ": cannot create: " + error.message());

  std::vector<MethodRun> runs;
  for (const CarveMethod method : methods) {
    CarveOptions options = request.options;
    options.method = method;
    LOG(INFO) << "benchmark: carving with " << CarveMethodToString(method);
    auto progress = [&](const CarveProgress& p) {
      LOG(INFO) << CarveMethodToString(method) << " " << p.seconds << " s: evaluated "
                << p.evaluated << ", carved " << p.carved << ", queue " << p.queued;
    };
    MethodRun run;
    run.method = method;
    run.result = std::make_unique<CarveResult>(pipeline.CarveWith(options, progress, 5.0));
    LOG(INFO) << run.result->statistics.Summary();
    const std::vector<exporter::ColouredPoint> points =
        exporter::SurfacePoints(*run.result, options.min_views);
    run.cloud_points = points.size();
    exporter::WritePointCloudPly(points,
                                 (out / ("cloud_" + CarveMethodToString(method) + ".ply")).string());
    if (!reference_points.empty()) {
      exporter::CompareOptions compare;
      compare.threshold = reference_threshold > 0.0 ? reference_threshold
                                                    : 2.0 * run.result->volume.grid().voxel_size();
      compare.num_threads = options.num_threads;
      std::vector<Eigen::Vector3f> cloud;
      for (const exporter::ColouredPoint& point : points) cloud.push_back(point.xyz);
      run.comparison = exporter::CompareClouds(reference_points, cloud, compare);
      run.compared = true;
    }
    runs.push_back(std::move(run));
  }

  // Table 1, as text and Markdown.
  const CarveStatistics& first = runs.front().result->statistics;
  std::ostringstream table;
  table << "| method | convergence s | set-up s | memory MiB | carved | evaluated | passes |"
        << (reference_points.empty() ? "" : " completeness | accuracy (90%) |") << "\n"
        << "|---|---:|---:|---:|---:|---:|---:|" << (reference_points.empty() ? "" : "---:|---:|")
        << "\n";
  for (const MethodRun& run : runs) {
    const CarveStatistics& s = run.result->statistics;
    char row[512];
    std::snprintf(row, sizeof(row), "| %s | %.2f | %.2f | %.1f | %lld | %lld | %d |",
                  s.visibility.c_str(), s.carve_seconds, s.setup_seconds,
                  s.peak_memory_bytes / (1024.0 * 1024.0), static_cast<long long>(s.carved),
                  static_cast<long long>(s.evaluated), s.passes);
    table << row;
    if (run.compared) {
      std::snprintf(row, sizeof(row), " %.1f%% | %.4g |", 100.0 * run.comparison.completeness,
                    run.comparison.accuracy);
      table << row;
    }
    table << "\n";
  }
  std::ostringstream agreement_table;
  agreement_table << "| volumes | voxel IoU | voxels differing | only first | only second |\n"
                  << "|---|---:|---:|---:|---:|\n";
  JsonWriter json;
  json.BeginObject()
      .Key("model_path").Value(project.model_path)
      .Key("num_views").Value(static_cast<int>(views.size()))
      .Key("resolution").Value(request.options.resolution)
      .Key("grid").Value(std::vector<double>{static_cast<double>(first.dimensions.x()),
                                              static_cast<double>(first.dimensions.y()),
                                              static_cast<double>(first.dimensions.z())})
      .Key("consistency").Value(ConsistencyMethodToString(request.options.consistency))
      .Key("threshold").Value(request.options.threshold);
  json.Key("methods").BeginArray();
  for (const MethodRun& run : runs) {
    const CarveStatistics& s = run.result->statistics;
    json.BeginObject()
        .Key("method").Value(CarveMethodToString(run.method))
        .Key("visibility").Value(s.visibility)
        .Key("convergence_seconds").Value(s.carve_seconds)
        .Key("setup_seconds").Value(s.setup_seconds)
        .Key("peak_memory_bytes").Value(static_cast<uint64_t>(s.peak_memory_bytes))
        .Key("carved").Value(s.carved)
        .Key("evaluated").Value(s.evaluated)
        .Key("passes").Value(s.passes)
        .Key("final_solid").Value(s.final_solid)
        .Key("final_surface").Value(s.final_surface)
        .Key("cloud_points").Value(static_cast<uint64_t>(run.cloud_points));
    if (run.compared) {
      json.Key("completeness").Value(run.comparison.completeness)
          .Key("accuracy").Value(run.comparison.accuracy)
          .Key("precision").Value(run.comparison.precision)
          .Key("reference_threshold").Value(run.comparison.threshold);
    }
    json.EndObject();
  }
  json.EndArray();
  json.Key("agreement").BeginArray();
  for (size_t i = 0; i < runs.size(); ++i) {
    for (size_t j = i + 1; j < runs.size(); ++j) {
      const VolumeAgreement a = CompareVolumes(runs[i].result->volume, runs[j].result->volume);
      const std::string pair =
          CarveMethodToString(runs[i].method) + " vs " + CarveMethodToString(runs[j].method);
      char row[256];
      std::snprintf(row, sizeof(row), "| %s | %.4f | %lld | %lld | %lld |\n", pair.c_str(),
                    a.iou(), static_cast<long long>(a.differing()),
                    static_cast<long long>(a.only_first), static_cast<long long>(a.only_second));
      agreement_table << row;
      json.BeginObject()
          .Key("first").Value(CarveMethodToString(runs[i].method))
          .Key("second").Value(CarveMethodToString(runs[j].method))
          .Key("iou").Value(a.iou())
          .Key("differing").Value(a.differing())
          .Key("only_first").Value(a.only_first)
          .Key("only_second").Value(a.only_second)
          .EndObject();
    }
  }
  json.EndArray();
  json.EndObject();

  // Figure 6: voxels carved against time.
  std::ostringstream csv;
  csv << "method,seconds,carved,evaluated\n";
  std::vector<exporter::PlotSeries> series;
  for (const MethodRun& run : runs) {
    exporter::PlotSeries line;
    line.name = CarveMethodToString(run.method);
    for (const CurveSample& sample : run.result->statistics.curve) {
      csv << line.name << "," << sample.seconds << "," << sample.carved << "," << sample.evaluated
          << "\n";
      line.x.push_back(sample.seconds);
      line.y.push_back(static_cast<double>(sample.carved));
    }
    series.push_back(std::move(line));
  }
  std::ostringstream title;
  title << "Voxels carved against time: " << views.size() << " views, "
        << first.dimensions.x() << "x" << first.dimensions.y() << "x" << first.dimensions.z()
        << " voxels";
  WriteImageAtomically((out / "figure6.png").string(),
           exporter::DrawLinePlot(series, {title.str(), "seconds", "voxels carved (colouring)"}));
  WriteTextFileAtomically((out / "figure6.csv").string(), csv.str());
  WriteTextFileAtomically((out / "table.md").string(),
                          table.str() + "\n" + agreement_table.str());
  WriteTextFileAtomically((out / "benchmark.json").string(), json.str());
  std::printf("\n%s\n%s\nwritten to %s/ (benchmark.json, table.md, figure6.csv, figure6.png)\n",
              table.str().c_str(), agreement_table.str().c_str(), out.string().c_str());
  return 0;
}

}  // namespace raycarve
