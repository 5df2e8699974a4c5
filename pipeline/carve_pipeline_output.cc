// The carve pipeline's outputs: the cloud sampled from the mesh and measured against the sparse
// points, and the files written in the staging folder (cloud, mesh, COLMAP's dense workspace
// names, the masks used, convergence.csv, report.html and report.json), moved into place together.
#include "pipeline/carve_pipeline.h"

#include <chrono>
#include <filesystem>
#include <future>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "calib/input_error.h"
#include "calib/model_writer.h"
#include "export/mesh_colouring.h"
#include "export/mesh_formats.h"
#include "export/preview.h"
#include "pipeline/carve_report.h"
#include "pipeline/carve_summary.h"
#include "pipeline/output_files.h"
#include "pipeline/report_page.h"

namespace raycarve {

namespace fs = std::filesystem;

void CarvePipeline::SampleCloud() {
  CHECK(run_.result);
  const Clock::time_point start = Clock::now();
  if (request_.mesh_kind != "smooth") {
    points_ = exporter::SurfacePoints(*run_.result, request_.options.min_views);
    run_.num_cloud_points = points_.size();
    export_seconds_ += SecondsSince(start);
    return;
  }
  if (staged_) {
    // The mesh's checks and file on a second thread while the cloud is sampled and written: both
    // only read the mesh. (The future waits for its thread however the pipeline is left; the
    // mesh's own failure is thrown by get() in WriteOutputs.)
    const fs::path out(staged_->path());
    // The files of a fine grid's mesh take minutes: said as they start and end.
    LOG(INFO) << "writing the mesh (" << model_.mesh.triangles.size()
              << " triangles: its check, mesh.ply, mesh.glb"
              << (model_.mesh.texture.empty() ? "" : ", mesh.obj with its atlas")
              << ", preview.png) and sampling the cloud from it ...";
    auto mesh_file = [this, out] {
      const Clock::time_point file_start = Clock::now();
      // The undo left no pair, and since then only triangles were removed (the box's walls):
      // no new pair can have appeared, and the search (about half a second on 100k triangles)
      // need not run again.
      const bool none_left = request_.mesh.undo_self_intersections &&
                             model_.self_intersections.pairs_after == 0;
      run_.mesh_topology = exporter::AnalyseTopology(model_.mesh, none_left ? 0 : -1);
      exporter::WriteMeshPly(model_.mesh, (out / "mesh.ply").string());
      exporter::WriteMeshFormats(model_.mesh, out.string());
      // Something to look at: the mesh from three of the photos' cameras, beside the photos.
      cv::Mat preview = exporter::PreviewImage(model_.mesh, carved_);
      if (!preview.empty()) {
        cv::cvtColor(preview, preview, cv::COLOR_RGB2BGR);
        WriteImageAtomically((out / "preview.png").string(), preview);
      }
      LOG(INFO) << "mesh files written in " << SecondsSince(file_start) << " s";
    };
    if (ResolveNumThreads(request_.options.num_threads) > 1) {
      mesh_written_ = std::async(std::launch::async, mesh_file);
    } else {
      mesh_file();
    }
  }
  // The mesh's surface that --cloud_min_views or more photos see, and which ones, in COLMAP's
  // visibility format (image indices: positions among the model's images in id order).
  const double spacing =
      MedianPixelFootprint(carved_, run_.result->volume.grid().Box().center());
  if (!model_.mesh.empty() && spacing > 0.0) {
    points_ = exporter::SampleMeshPoints(model_, spacing, request_.cloud_min_views, /*seed=*/1,
                                         &visibility_);
  }
  std::vector<image_t> ids;
  for (const auto& [id, image] : project_.reconstruction.images) ids.push_back(id);
  std::sort(ids.begin(), ids.end());
  std::vector<uint32_t> index_of_view(carved_.size());
  for (size_t v = 0; v < carved_.size(); ++v) {
    index_of_view[v] = static_cast<uint32_t>(
        std::lower_bound(ids.begin(), ids.end(), carved_[v].image_id) - ids.begin());
  }
  for (std::vector<uint32_t>& seen : visibility_) {
    for (uint32_t& v : seen) v = index_of_view[v];
  }
  run_.num_cloud_points = points_.size();
  export_seconds_ += SecondsSince(start);
  LOG(INFO) << "cloud: " << points_.size() << " points sampled from the mesh in "
            << SecondsSince(start) << " s";
}

void CarvePipeline::MeasureCloud() {
  CHECK(run_.result);
  // COLMAP's sparse points lie on the true surface: how far they are from the carved one.
  const Eigen::AlignedBox3d grid_box = run_.result->volume.grid().Box();
  std::vector<Eigen::Vector3f> sparse, cloud;
  for (const auto& [id, point] : project_.reconstruction.points3D) {
    if (grid_box.contains(point.xyz)) sparse.push_back(point.xyz.cast<float>());
  }
  for (const exporter::ColouredPoint& point : points_) cloud.push_back(point.xyz);
  if (sparse.empty() || cloud.empty()) return;
  exporter::CompareOptions compare;
  compare.threshold = 2.0 * run_.result->volume.grid().voxel_size();
  compare.num_threads = request_.options.num_threads;
  run_.sparse = exporter::CompareClouds(cloud, sparse, compare);
  run_.has_sparse = true;
}

void CarvePipeline::WriteDenseWorkspace(const fs::path& staging) {
  // COLMAP's dense workspace names, for its meshers: the same files under a second name (hard
  // links; copies where the file system has none), and the sparse model they index.
  for (const char* name : {"cloud.ply", "cloud.ply.vis"}) {
    const fs::path from = staging / name;
    const fs::path to = staging / (std::string("fused") + (name + 5));
    std::error_code error;
    fs::create_hard_link(from, to, error);
    if (error) {
      error.clear();
      fs::copy_file(from, to, fs::copy_options::overwrite_existing, error);
      if (error) throw InputError(to.string() + ": cannot write: " + error.message());
    }
  }
  if (run_.dense_sparse_skipped.empty()) {
    WriteModel(project_.reconstruction, (staging / "sparse").string(), ModelFormat::kBinary);
  }
}

void CarvePipeline::WriteMasks(const fs::path& staging) const {
  // The masks used, so that a user can check them: undistorted, as the carving saw them.
  const fs::path final_out(run_.output_path);
  for (size_t v = 0; v < carved_.size(); ++v) {
    if (carved_[v].mask.empty()) continue;
    // Checked before carving; written to the same place under the staging folder.
    const fs::path mask_path = staging / fs::relative(mask_targets_[v], final_out);
    std::error_code error;
    fs::create_directories(mask_path.parent_path(), error);
    if (error) throw InputError(mask_path.parent_path().string() + ": cannot create: " + error.message());
    WriteImageAtomically(mask_path.string(), carved_[v].mask);
  }
}

void CarvePipeline::WriteReportPage(const fs::path& staging) const {
  ReportPageContent page;
  page.title = run_.model_path;
  page.summary = CarveSummaryText(request_, run_);
  if (fs::exists(staging / "preview.png")) page.preview_image = "preview.png";
  page.convergence = run_.result->statistics.curve;
  // The 3D view starts as the photos saw the model: their mean up (-y of the camera), from the
  // camera nearest the cameras' mean direction from the volume's centre (a photo's viewpoint: a
  // ring's mean direction points straight up).
  const Eigen::Vector3d centre = project_.bounds.box.center();
  page.view_up = exporter::UpOfPhotos(carved_);
  Eigen::Vector3d mean_direction = Eigen::Vector3d::Zero();
  for (const CalibratedView& view : carved_) mean_direction += (view.centre - centre).normalized();
  double best = -2.0;
  for (const CalibratedView& view : carved_) {
    const Eigen::Vector3d direction = (view.centre - centre).normalized();
    if (direction.dot(mean_direction) > best) {
      best = direction.dot(mean_direction);
      page.view_from = direction;
    }
  }
  const fs::path glb = staging / "mesh.glb";
  if (fs::exists(glb) && fs::file_size(glb) > kMaxEmbeddedGlbBytes) {
    page.glb_name = "mesh.glb";
    page.glb_bytes_not_embedded = fs::file_size(glb);
  } else if (fs::exists(glb)) {
    page.glb_name = "mesh.glb";
    std::ifstream file(glb, std::ios::binary);
    page.glb.assign(std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>());
    if (!file && !file.eof()) throw InputError(glb.string() + ": cannot read back for report.html");
  }
  WriteTextFileAtomically((staging / "report.html").string(), ReportPageHtml(page));
}

void CarvePipeline::WriteOutputs() {
  CHECK(staged_) << "PlanOutputs must run before WriteOutputs";
  const Clock::time_point start = Clock::now();
  const fs::path out(staged_->path());
  staged_->Write([&] {
    exporter::WritePointCloudPly(points_, (out / "cloud.ply").string());
    if (request_.mesh_kind == "voxels") {
      const exporter::MeshSummary mesh = exporter::WriteVoxelMeshPly(*run_.result, (out / "mesh.ply").string());
      run_.num_mesh_triangles = mesh.num_triangles;
      run_.num_mesh_vertices = mesh.num_vertices;
    } else {
      exporter::WritePointVisibility(visibility_, (out / "cloud.ply.vis").string());
      if (mesh_written_.valid() &&
          mesh_written_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
        LOG(INFO) << "cloud.ply written; waiting for the mesh files ...";
      }
      if (mesh_written_.valid()) mesh_written_.get();
      WriteDenseWorkspace(out);
    }
    RecordSeconds("export", export_seconds_ + SecondsSince(start));
    LOG(INFO) << "outputs written in " << export_seconds_ + SecondsSince(start) << " s";
    WriteMasks(out);
    std::ostringstream csv;
    csv << "seconds,carved,evaluated\n";
    for (const CurveSample& sample : run_.result->statistics.curve) {
      csv << sample.seconds << "," << sample.carved << "," << sample.evaluated << "\n";
    }
    WriteTextFileAtomically((out / "convergence.csv").string(), csv.str());
    WriteReportPage(out);
    WriteTextFileAtomically((out / "report.json").string(), CarveReportJson(request_, run_));
  });
  staged_->MoveIntoPlace("report.json");
}

}  // namespace raycarve
