#include "export/mesh_refinement.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <glog/logging.h>

#include "export/mesh_colouring.h"
#include "carve/view_workers.h"
#include "export/parallel_ranges.h"

namespace raycarve {
namespace exporter {
namespace {

constexpr int kPatchSamples = 5;

// A vertex's patch in one view, in homogeneous pixel coordinates (P times the world point): the
// vertex, a unit step along its normal, and the patch's offsets from the vertex.
struct Projected {
  Eigen::Vector3d centre;
  Eigen::Vector3d normal;
  Eigen::Vector3d around[kPatchSamples];
};

// Two unit vectors spanning the plane normal to `n`.
void TangentBasis(const Eigen::Vector3d& n, Eigen::Vector3d* u, Eigen::Vector3d* w) {
  const Eigen::Vector3d helper =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  *u = n.cross(helper).normalized();
  *w = n.cross(*u);
}

// How firmly the costs of the offsets tried place a vertex (MeshRefinementSummary::pinned).
float PinnedShare(double cost_sum, int costs, double best_cost, int best_terms) {
  if (costs < 3 || best_terms < 1 || !(best_cost >= 0.0) || !std::isfinite(cost_sum)) return 0.0f;
  const double mean_cost = cost_sum / costs;
  const double standard_error = std::max(best_cost, 1e-9) * std::sqrt(2.0 / best_terms);
  const double z = (mean_cost - best_cost) / standard_error;
  return static_cast<float>(std::clamp((z - 1.0) / 2.0, 0.0, 1.0));
}

}  // namespace

bool MeshRefinementOptions::IsValid(std::string* reason) const {
  if (passes < 0) {
    *reason = "mesh refinement passes must be >= 0";
    return false;
  }
  if (!(search_range > 0.0) || !(patch_radius > 0.0) || !(depth_tolerance > 0.0) ||
      !(voxel_size > 0.0)) {
    *reason = "mesh refinement needs a search range, patch radius and depth tolerance > 0";
    return false;
  }
  if (steps_per_side < 1 || min_views < 2 || smoothing_passes < 0 || max_views < min_views) {
    *reason = "mesh refinement needs steps_per_side >= 1, min_views >= 2, smoothing_passes >= 0, max_views >= min_views";
    return false;
  }
  if (!(converged_offset >= 0.0)) {
    *reason = "mesh refinement converged_offset must be >= 0";
    return false;
  }
  if (!(min_gain > 0.0 && min_gain <= 1.0)) {
    *reason = "mesh refinement min_gain must lie in (0, 1]";
    return false;
  }
  return true;
}

std::string MeshRefinementSummary::Summary() const {
  char text[384];
  std::snprintf(text, sizeof(text),
                "mesh refinement: %d passes; in the last %lld of %lld vertices judged, %lld "
                "moved (mean |offset| %.3g); mean offset per pass %.3g (|%.3g|) along the "
                "normals; pinned by the photos %.0f%% (mean); %lld whose photos cannot tell "
                "their offsets apart moved half a voxel in; in %.2f s",
                passes, static_cast<long long>(judged), static_cast<long long>(vertices),
                static_cast<long long>(moved), last_mean_abs_offset, mean_offset,
                mean_abs_offset, 100.0 * mean_pinned, static_cast<long long>(unresolved), seconds);
  return text;
}

namespace {

// The patch's colour spread over the views that see a vertex, with the vertex moved by t along
// its normal: the mean squared distance of each view's samples to their mean, over the samples
// every view has. False when a view's patch centre leaves its photo (or the object's mask), or
// no sample is shared by two views.
bool OffsetCost(const std::vector<CalibratedView>& views,
                const std::vector<VertexSighting>& seen,
                const std::vector<Projected>& projected,
                double t,
                std::vector<Eigen::Vector3f>* patch_buffer,
                double* cost_out,
                int* terms_out) {
  std::vector<Eigen::Vector3f>& patch = *patch_buffer;
  const int num_seen = static_cast<int>(seen.size());
  // Sample the patch in every view that sees the vertex; a view whose patch leaves its
  // photo's data (or the object's mask) says the offset is wrong.
  int views_used = 0;
  bool outside = false;
  Eigen::Matrix<float, 3, kPatchSamples> mean = Eigen::Matrix<float, 3, kPatchSamples>::Zero();
  for (int v = 0; v < num_seen; ++v) {
    const CalibratedView& view = views[seen[v].view];
    const Projected& at = projected[v];
    const Eigen::Vector3d moved = at.centre + t * at.normal;
    for (int k = 0; k < kPatchSamples && !outside; ++k) {
      Eigen::Vector3f colour;
      if (!SamplePhoto(view, (moved + at.around[k]).hnormalized(), &colour)) {
        outside = k == 0;  // only the centre must stay on the object
        colour = Eigen::Vector3f::Constant(-1.0f);
      }
      patch[views_used * kPatchSamples + k] = colour;
    }
    if (outside) break;
    ++views_used;
  }
  if (outside) return false;
  // Mean over the patch samples that every view has, then the spread about it.
  double cost = 0.0;
  int terms = 0;
  for (int k = 0; k < kPatchSamples; ++k) {
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    int count = 0;
    bool complete = true;
    for (int v = 0; v < views_used; ++v) {
      const Eigen::Vector3f& c = patch[v * kPatchSamples + k];
      if (c.x() < 0.0f) {
        complete = false;
        break;
      }
      sum += c;
      ++count;
    }
    if (!complete || count < 2) continue;
    mean.col(k) = sum / count;
    for (int v = 0; v < views_used; ++v) {
      cost += (patch[v * kPatchSamples + k] - mean.col(k)).squaredNorm();
      ++terms;
    }
  }
  if (terms == 0) return false;
  cost /= terms;
  *cost_out = cost;
  *terms_out = terms;
  return true;
}

// What one refinement pass decides for a vertex.
struct VertexMove {
  bool judged = false;  // seen by enough photos to be judged
  bool unresolved = false;  // seen by enough, but none two of them tell its offsets apart
  bool moved = false;
  float offset = 0.0f;  // along the normal, world units
  float pinned = 0.0f;  // how firmly the photos place it (PinnedShare)
};

// Whether two of the photos in `seen` see the vertex's offsets along its normal differently. An
// offset t moves the point a photo samples on the surface by t tan(angle) along the photo's
// direction across the surface (its unit vector u): t (d - cos(angle) n) / cos(angle), d the
// unit direction to the photo. Photos that all look from one side at a grazing angle (a
// forward-facing capture's floor) move it alike: the offsets then differ by where the samples
// fall, not by how well the photos agree, and the refinement follows the texture's edges (that
// floor came out bumpier than the carve left it). Two photos tell the offsets apart where, over
// the search range, their sampled points part by at least either's pixel footprint on the
// surface (depth / focal length, stretched by 1 / cos(angle) along the tilt).
bool OffsetsToldApart(const std::vector<CalibratedView>& views,
                      const std::vector<VertexSighting>& seen,
                      const Eigen::Vector3d& centre,
                      const Eigen::Vector3d& normal,
                      double search_range) {
  std::vector<Eigen::Vector3d> slide(seen.size());
  std::vector<double> footprint(seen.size());
  for (size_t k = 0; k < seen.size(); ++k) {
    const CalibratedView& view = views[seen[k].view];
    const Eigen::Vector3d d = (view.centre - centre).normalized();
    const double cosine = std::max(1e-6, d.dot(normal));
    slide[k] = (d - cosine * normal) / cosine;
    footprint[k] = view.Depth(centre) / view.K(0, 0) / cosine;
  }
  for (size_t k = 0; k < seen.size(); ++k) {
    for (size_t l = k + 1; l < seen.size(); ++l) {
      if (search_range * (slide[k] - slide[l]).norm() >= std::max(footprint[k], footprint[l])) return true;
    }
  }
  return false;
}

// Tries the vertex at `centre` (unit `normal`) at every offset of the search range in the photos
// of `seen` (the best-facing options.max_views of them) and keeps the offset whose patch the
// photos agree on best, when it beats staying by options.min_gain. `patch` and `projected` are
// buffers of the calling thread.
VertexMove JudgeVertex(const std::vector<CalibratedView>& views,
                       const MeshRefinementOptions& options,
                       std::vector<VertexSighting> seen,
                       bool on_rim,
                       const Eigen::Vector3d& centre,
                       const Eigen::Vector3d& normal,
                       std::vector<Eigen::Vector3f>* patch_buffer,
                       std::vector<Projected>* projected_buffer) {
  std::vector<Eigen::Vector3f>& patch = *patch_buffer;
  std::vector<Projected>& projected = *projected_buffer;
  const int steps = 2 * options.steps_per_side + 1;
  const double step = options.search_range / options.steps_per_side;
  VertexMove result;
  if (static_cast<int>(seen.size()) < options.min_views) return result;
  // The best-facing photos judge: grazing views add blur and misregistration, and time.
  if (static_cast<int>(seen.size()) > options.max_views) {
    std::partial_sort(seen.begin(), seen.begin() + options.max_views, seen.end(),
                      [](const VertexSighting& a, const VertexSighting& b) {
                        return a.facing > b.facing;
                      });
    seen.resize(options.max_views);
  }
  if (!OffsetsToldApart(views, seen, centre, normal, options.search_range)) {
    result.unresolved = true;
    return result;
  }
  result.judged = true;
  Eigen::Vector3d u, w;
  TangentBasis(normal, &u, &w);
  const Eigen::Vector3d around[kPatchSamples] = {
      Eigen::Vector3d::Zero(), options.patch_radius * u, -options.patch_radius * u,
      options.patch_radius * w, -options.patch_radius * w};
  // Projection is linear in homogeneous coordinates: per view, the centre's image and those
  // of a step along the normal and of the patch's offsets, so that each sample costs a
  // division rather than a matrix product.
  const int num_seen = static_cast<int>(seen.size());
  for (int v = 0; v < num_seen; ++v) {
    const Eigen::Matrix<double, 3, 4>& P = views[seen[v].view].P;
    const Eigen::Matrix3d M = P.leftCols<3>();
    Projected& at = projected[v];
    at.centre = M * centre + P.col(3);
    at.normal = M * normal;
    for (int k = 0; k < kPatchSamples; ++k) at.around[k] = M * around[k];
  }
  double best_cost = std::numeric_limits<double>::infinity(), stay_cost = best_cost;
  double cost_sum = 0.0;
  int costs = 0, best_terms = 0;
  int best = options.steps_per_side;
  // A silhouette's rim holds the surface where the mask says: no moving inwards there.
  const int first_step = on_rim ? options.steps_per_side : 0;
  for (int s = first_step; s < steps; ++s) {
    const double t = (s - options.steps_per_side) * step;
    double cost = 0.0;
    int terms = 0;
    if (!OffsetCost(views, seen, projected, t, &patch, &cost, &terms)) continue;
    if (s == options.steps_per_side) stay_cost = cost;
    cost_sum += cost;
    ++costs;
    if (cost < best_cost) {
      best_terms = terms;
      best_cost = cost;
      best = s;
    }
  }
  result.pinned = PinnedShare(cost_sum, costs, best_cost, best_terms);
  if (best != options.steps_per_side && std::isfinite(stay_cost) &&
      best_cost < options.min_gain * stay_cost) {
    result.offset = static_cast<float>((best - options.steps_per_side) * step);
    result.moved = true;
  } else if (!std::isfinite(stay_cost) && std::isfinite(best_cost)) {
    // Staying puts the vertex off the object in a photo that sees it: take the best.
    result.offset = static_cast<float>((best - options.steps_per_side) * step);
    result.moved = true;
  }
  return result;
}

}  // namespace

MeshRefinementSummary RefineMeshFromPhotos(const std::vector<CalibratedView>& views,
                                           const MeshRefinementOptions& options,
                                           TriangleMesh* mesh) {
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  const auto start = std::chrono::steady_clock::now();
  const size_t n = mesh->vertices.size();
  MeshRefinementSummary summary;
  summary.vertices = static_cast<int64_t>(n);
  summary.search_range = options.search_range;
  if (mesh->normals.size() != n) ComputeVertexNormals(mesh);
  const std::vector<std::vector<int>> neighbours = VertexNeighbours(*mesh);
  double offset_sum = 0.0, abs_offset_sum = 0.0;
  const std::vector<cv::Mat> mask_distances = MaskDistances(views, options.num_threads);
  for (int pass = 0; pass < options.passes; ++pass) {
    std::vector<uint8_t> on_rim;
    const std::vector<std::vector<VertexSighting>> sightings = FindVertexSightings(
        views, *mesh, options.depth_tolerance, &on_rim, options.voxel_size, 1.0,
        options.num_threads, &mask_distances);
    std::vector<float> offsets(n, 0.0f);
    std::vector<uint8_t> judged(n, 0), moved(n, 0), unresolved(n, 0);
    summary.pinned.assign(n, 0.0f);
    const int threads = options.num_threads > 0 ? options.num_threads : ResolveNumThreads(-1);
    ParallelRanges(n, threads, /*min_per_thread=*/1024, [&](size_t begin, size_t end) {
    std::vector<Eigen::Vector3f> patch(static_cast<size_t>(kPatchSamples) * views.size());
    std::vector<Projected> projected(views.size());
    for (size_t i = begin; i < end; ++i) {
      const VertexMove move = JudgeVertex(views, options, sightings[i], on_rim[i] != 0,
                                          mesh->vertices[i].cast<double>(),
                                          mesh->normals[i].cast<double>(), &patch, &projected);
      judged[i] = move.judged;
      unresolved[i] = move.unresolved;
      moved[i] = move.moved;
      offsets[i] = move.offset;
      if (move.judged) summary.pinned[i] = move.pinned;
    }
    });
    summary.judged = std::count(judged.begin(), judged.end(), 1);
    summary.moved = std::count(moved.begin(), moved.end(), 1);
    if (pass == 0) {
      // Where no two photos tell a vertex's offsets apart, nothing places it but the carve: its
      // surface voxels hold the surface somewhere inside them, and the iso-surface runs along
      // their outer faces, half a voxel out on average. Such vertices move half a voxel in, once.
      for (size_t i = 0; i < n; ++i) {
        if (unresolved[i]) offsets[i] = static_cast<float>(-0.5 * options.voxel_size);
      }
      summary.unresolved = std::count(unresolved.begin(), unresolved.end(), 1);
    }
    AverageOverNeighbours(neighbours, options.smoothing_passes, &offsets, options.num_threads);
    double pass_abs_sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
      mesh->vertices[i] += offsets[i] * mesh->normals[i];
      offset_sum += offsets[i];
      pass_abs_sum += std::abs(offsets[i]);
    }
    abs_offset_sum += pass_abs_sum;
    ComputeVertexNormals(mesh);
    summary.passes = pass + 1;
    summary.last_mean_abs_offset = n > 0 ? pass_abs_sum / static_cast<double>(n) : 0.0;
    VLOG(1) << "mesh refinement pass " << pass + 1 << ": " << summary.judged << " judged, "
            << summary.moved << " moved, mean |offset| " << summary.last_mean_abs_offset;
    if (summary.last_mean_abs_offset < options.converged_offset) break;
  }
  if (!summary.pinned.empty()) {
    // Averaged over neighbours as the offsets are: a blend that changes from vertex to vertex
    // would make bumps of its own.
    AverageOverNeighbours(neighbours, options.smoothing_passes, &summary.pinned,
                          options.num_threads);
    summary.mean_pinned =
        std::accumulate(summary.pinned.begin(), summary.pinned.end(), 0.0) / static_cast<double>(n);
  }
  if (summary.passes > 0 && n > 0) {
    summary.mean_offset = offset_sum / (static_cast<double>(n) * summary.passes);
    summary.mean_abs_offset = abs_offset_sum / (static_cast<double>(n) * summary.passes);
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace exporter
}  // namespace raycarve
