#include "pipeline/method_comparison.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include <glog/logging.h>

#include "calib/atomic_file.h"
#include "calib/input_error.h"
#include "export/carve_export.h"
#include "export/line_plot.h"
#include "export/point_cloud_compare.h"
#include "export/point_cloud_io.h"
#include "pipeline/carve_pipeline.h"
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

// Each method's carve of the pipeline's views, its cloud written to `out`, compared with the
// reference when there is one.
std::vector<MethodRun> CarveEachMethod(const CarvePipeline& pipeline,
                                       const MethodComparisonOptions& comparison_options,
                                       const std::vector<Eigen::Vector3f>& reference_points,
                                       const std::filesystem::path& out) {
  std::vector<MethodRun> runs;
  for (const CarveMethod method : comparison_options.methods) {
    CarveOptions options = pipeline.request().options;
    options.method = method;
    LOG(INFO) << "benchmark: carving with " << CarveMethodToString(method);
    auto progress = [&](const CarveProgress& p) {
      if (p.setting_up) return;
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
      compare.threshold = comparison_options.reference_threshold > 0.0
                              ? comparison_options.reference_threshold
                              : 2.0 * run.result->volume.grid().voxel_size();
      compare.num_threads = options.num_threads;
      std::vector<Eigen::Vector3f> cloud;
      for (const exporter::ColouredPoint& point : points) cloud.push_back(point.xyz);
      run.comparison = exporter::CompareClouds(reference_points, cloud, compare);
      run.compared = true;
    }
    runs.push_back(std::move(run));
  }
  return runs;
}

// Table 1, as Markdown.
std::string Table1(const std::vector<MethodRun>& runs, bool has_reference) {
  std::ostringstream table;
  table << "| method | convergence s | set-up s | memory MiB | carved | evaluated | passes |"
        << (!has_reference ? "" : " completeness | accuracy (90%) |") << "\n"
        << "|---|---:|---:|---:|---:|---:|---:|" << (!has_reference ? "" : "---:|---:|")
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
  return table.str();
}

// benchmark.json, and the volumes' agreement as Markdown in *agreement.
std::string BenchmarkJson(const CarvePipeline& pipeline,
                          const std::vector<MethodRun>& runs,
                          std::string* agreement) {
  const CarveRequest& request = pipeline.request();
  const CarveStatistics& first = runs.front().result->statistics;
  std::ostringstream agreement_table;
  agreement_table << "| volumes | voxel IoU | voxels differing | only first | only second |\n"
                  << "|---|---:|---:|---:|---:|\n";
  JsonWriter json;
  json.BeginObject()
      .Key("model_path").Value(pipeline.project().model_path)
      .Key("num_views").Value(static_cast<int>(pipeline.carved_views().size()))
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

  *agreement = agreement_table.str();
  return json.str();
}

// Figure 6: voxels carved against time, as CSV and a plot.
void WriteFigure6(const std::vector<MethodRun>& runs,
                  size_t num_views,
                  const std::filesystem::path& out) {
  const CarveStatistics& first = runs.front().result->statistics;
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
  title << "Voxels carved against time: " << num_views << " views, "
        << first.dimensions.x() << "x" << first.dimensions.y() << "x" << first.dimensions.z()
        << " voxels";
  WriteImageAtomically((out / "figure6.png").string(),
           exporter::DrawLinePlot(series, {title.str(), "seconds", "voxels carved (colouring)"}));
  WriteTextFileAtomically((out / "figure6.csv").string(), csv.str());
}

}  // namespace

MethodComparison CompareCarveMethods(const CarveRequest& request,
                                     const MethodComparisonOptions& options) {
  // The carve pipeline's stages up to the carve, once; then a carve per method of the same views.
  PipelineScope scope;
  scope.command = "benchmark";
  CarvePipeline pipeline(request, scope);
  pipeline.LoadViews();
  pipeline.AgreeMasks();
  pipeline.CheckVolume();
  std::vector<Eigen::Vector3f> reference_points;
  if (!options.reference_path.empty()) {
    reference_points = exporter::ReadComparablePoints(options.reference_path, 200000);
  }
  CheckNoLinkInside(pipeline.project().output_path, "benchmark");
  const std::filesystem::path out = std::filesystem::path(pipeline.project().output_path) / "benchmark";
  std::error_code error;
  std::filesystem::create_directories(out, error);
  if (error) throw InputError(out.string() + ": cannot create: " + error.message());
  const std::vector<MethodRun> runs = CarveEachMethod(pipeline, options, reference_points, out);
  MethodComparison comparison;
  comparison.table = Table1(runs, !reference_points.empty());
  const std::string json = BenchmarkJson(pipeline, runs, &comparison.agreement_table);
  WriteFigure6(runs, pipeline.carved_views().size(), out);
  WriteTextFileAtomically((out / "table.md").string(),
                          comparison.table + "\n" + comparison.agreement_table);
  WriteTextFileAtomically((out / "benchmark.json").string(), json);
  comparison.output_folder = out.string();
  return comparison;
}

}  // namespace raycarve
