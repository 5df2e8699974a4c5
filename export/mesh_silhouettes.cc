#include "export/mesh_silhouettes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "carve/view_workers.h"
#include "export/mesh_renderer.h"
#include "export/parallel_ranges.h"

namespace raycarve {
namespace exporter {
namespace {

// Signed distance (pixels) from each pixel centre to the mask's edge, positive on the background:
// the edge lies half a pixel beyond the last object pixel.
cv::Mat SignedMaskDistance(const cv::Mat& mask) {
  cv::Mat inside, outside;
  cv::distanceTransform(mask, inside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  const cv::Mat background = mask == 0;
  cv::distanceTransform(background, outside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  cv::Mat distance(mask.size(), CV_32F);
  for (int row = 0; row < mask.rows; ++row) {
    const uint8_t* object = mask.ptr<uint8_t>(row);
    const float* in = inside.ptr<float>(row);
    const float* out = outside.ptr<float>(row);
    float* d = distance.ptr<float>(row);
    for (int col = 0; col < mask.cols; ++col) {
      d[col] = object[col] != 0 ? 0.5f - in[col] : out[col] - 0.5f;
    }
  }
  return distance;
}

// Bilinear sample of a CV_32F image at a COLMAP pixel position (centres at +0.5), clamped to
// the image's centres.
float SampleField(const cv::Mat& field, double x, double y) {
  const double u = std::clamp(x - 0.5, 0.0, field.cols - 1.0);
  const double v = std::clamp(y - 0.5, 0.0, field.rows - 1.0);
  const int c0 = std::min(static_cast<int>(u), std::max(field.cols - 2, 0));
  const int r0 = std::min(static_cast<int>(v), std::max(field.rows - 2, 0));
  const int c1 = std::min(c0 + 1, field.cols - 1), r1 = std::min(r0 + 1, field.rows - 1);
  const float fu = static_cast<float>(u - c0), fv = static_cast<float>(v - r0);
  return (1.0f - fv) * ((1.0f - fu) * field.at<float>(r0, c0) + fu * field.at<float>(r0, c1)) +
         fv * ((1.0f - fu) * field.at<float>(r1, c0) + fu * field.at<float>(r1, c1));
}

// The pixels a depth buffer leaves uncovered that connect (4-connected) to the image's border:
// 255; covered pixels and see-through holes inside the outline: 0.
cv::Mat ExteriorPixels(const cv::Mat& depths) {
  cv::Mat padded(depths.rows + 2, depths.cols + 2, CV_8UC1, cv::Scalar(1));
  for (int row = 0; row < depths.rows; ++row) {
    const float* depth = depths.ptr<float>(row);
    uint8_t* out = padded.ptr<uint8_t>(row + 1) + 1;
    for (int col = 0; col < depths.cols; ++col) out[col] = std::isfinite(depth[col]) ? 0 : 1;
  }
  cv::floodFill(padded, cv::Point(0, 0), cv::Scalar(255), nullptr, cv::Scalar(0), cv::Scalar(0), 4);
  return padded(cv::Rect(1, 1, depths.cols, depths.rows)) == 255;
}

std::vector<size_t> MaskedViews(const std::vector<CalibratedView>& views) {
  std::vector<size_t> masked;
  for (size_t v = 0; v < views.size(); ++v) {
    if (!views[v].mask.empty()) masked.push_back(v);
  }
  return masked;
}

}  // namespace

std::string MeshPartsSummary::Summary() const {
  char text[256];
  if (!judged_by_masks) {
    std::snprintf(text, sizeof(text),
                  "mesh parts: %d; %d specks (under %.0f%% of the largest part, no sparse point on "
                  "them, no masks) removed (%lld vertices), %d small parts kept for their sparse "
                  "points; in %.2f s",
                  parts, removed, 100.0 * kSpeckShare, static_cast<long long>(removed_vertices),
                  anchored, seconds);
    return text;
  }
  std::snprintf(text, sizeof(text),
                "mesh parts: %d; %d that fewer than %d of %d masked photos need and no sparse "
                "point holds removed (%lld vertices), %d kept for a sparse point alone; in %.2f s",
                parts, removed, min_needing_views, masked_views,
                static_cast<long long>(removed_vertices), anchored, seconds);
  return text;
}

namespace {

// The mesh's triangles grouped by part, as DrawMeshParts needs them; *triangle_part the part of
// each.
TriangleMesh GroupedByPart(const TriangleMesh& mesh, const std::vector<int>& part,
                           std::vector<int>* triangle_part_out) {
  std::vector<int>& triangle_part = *triangle_part_out;
  TriangleMesh grouped;
  grouped.vertices = mesh.vertices;
  std::vector<size_t> order(mesh.triangles.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return part[mesh.triangles[a][0]] < part[mesh.triangles[b][0]];
  });
  triangle_part.assign(order.size(), 0);
  grouped.triangles.reserve(order.size());
  for (size_t k = 0; k < order.size(); ++k) {
    grouped.triangles.push_back(mesh.triangles[order[k]]);
    triangle_part[k] = part[mesh.triangles[order[k]][0]];
  }
  return grouped;
}

// Per masked view (`masked`, indices into `views`), the parts it needs: half or more of what a
// part covers in the view is object that no other part covers.
std::vector<std::vector<uint8_t>> PartsNeeded(const std::vector<CalibratedView>& views,
                                              const std::vector<size_t>& masked,
                                              const TriangleMesh& grouped,
                                              const std::vector<int>& triangle_part,
                                              int parts,
                                              int num_threads) {
  std::vector<std::vector<uint8_t>> needs(masked.size(), std::vector<uint8_t>(parts, 0));
  ParallelRanges(masked.size(), ResolveNumThreads(num_threads), /*min_per_thread=*/1,
                 [&](size_t first, size_t last) {
    cv::Mat count, last_part;
    std::vector<int64_t> covered, alone(parts);
    for (size_t m = first; m < last; ++m) {
      const CalibratedView& view = views[masked[m]];
      DrawMeshParts(grouped, triangle_part, parts, view, &count, &last_part, &covered);
      std::fill(alone.begin(), alone.end(), 0);
      for (int row = 0; row < view.height; ++row) {
        const uint8_t* c = count.ptr<uint8_t>(row);
        const int* p = last_part.ptr<int>(row);
        const uint8_t* object = view.mask.ptr<uint8_t>(row);
        for (int col = 0; col < view.width; ++col) {
          if (c[col] == 1 && object[col] != 0) ++alone[p[col]];
        }
      }
      for (int p = 0; p < parts; ++p) needs[m][p] = covered[p] > 0 && 2 * alone[p] >= covered[p];
    }
  });
  return needs;
}

// The parts other than `largest` that hold a sparse point (`anchors`, within `anchor_radius`).
std::vector<uint8_t> AnchoredParts(const TriangleMesh& mesh, const std::vector<int>& part,
                                   int parts, int largest,
                                   const std::vector<Eigen::Vector3d>& anchors,
                                   double anchor_radius) {
  const int n = static_cast<int>(mesh.vertices.size());
  std::vector<uint8_t> anchored(parts, 0);
  if (anchors.empty() || !(anchor_radius > 0.0)) return anchored;
  pcl::PointCloud<pcl::PointXYZ>::Ptr others(new pcl::PointCloud<pcl::PointXYZ>);
  pcl::PointCloud<pcl::PointXYZ>::Ptr main_part(new pcl::PointCloud<pcl::PointXYZ>);
  std::vector<int> vertex_of;
  for (int i = 0; i < n; ++i) {
    const pcl::PointXYZ point(mesh.vertices[i].x(), mesh.vertices[i].y(), mesh.vertices[i].z());
    if (part[i] == largest) {
      main_part->push_back(point);
    } else {
      others->push_back(point);
      vertex_of.push_back(i);
    }
  }
  if (others->empty()) return anchored;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree, main_tree;
  tree.setInputCloud(others);
  if (!main_part->empty()) main_tree.setInputCloud(main_part);
  std::vector<int> found, nearest(1);
  std::vector<float> squared, nearest_squared(1);
  for (const Eigen::Vector3d& point : anchors) {
    const pcl::PointXYZ query(static_cast<float>(point.x()), static_cast<float>(point.y()),
                              static_cast<float>(point.z()));
    if (tree.radiusSearch(query, anchor_radius, found, squared) == 0) continue;
    // A sparse point holds the part it lies nearest to: one beside the main surface and a speck
    // off it is the main surface's.
    const size_t k = std::min_element(squared.begin(), squared.end()) - squared.begin();
    if (!main_part->empty() && main_tree.nearestKSearch(query, 1, nearest, nearest_squared) == 1 &&
        nearest_squared[0] <= squared[k]) {
      continue;
    }
    anchored[part[vertex_of[found[k]]]] = 1;
  }
  return anchored;
}

// Per part (ConnectedParts: `part` per vertex, `parts` of them) its vertices; *largest the part
// with the most.
std::vector<int64_t> PartSizes(const std::vector<int>& part, int parts, int* largest) {
  std::vector<int64_t> sizes(parts, 0);
  for (const int p : part) ++sizes[p];
  *largest = static_cast<int>(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  return sizes;
}

// Per part: a speck (under kSpeckShare of the largest part's vertices, not anchored).
std::vector<uint8_t> SpeckParts(const std::vector<int64_t>& part_vertices, int largest,
                                const std::vector<uint8_t>& anchored) {
  std::vector<uint8_t> speck(part_vertices.size(), 0);
  for (size_t p = 0; p < part_vertices.size(); ++p) {
    speck[p] = static_cast<int>(p) != largest && !anchored[p] &&
               part_vertices[p] < kSpeckShare * static_cast<double>(part_vertices[largest]);
  }
  return speck;
}

}  // namespace

std::vector<uint8_t> SpeckVertices(const TriangleMesh& mesh,
                                   const std::vector<Eigen::Vector3d>& anchors,
                                   double anchor_radius) {
  std::vector<uint8_t> on_speck(mesh.vertices.size(), 0);
  int parts = 0;
  const std::vector<int> part = ConnectedParts(mesh, &parts);
  if (parts < 2 || anchors.empty()) return on_speck;
  int largest = 0;
  const std::vector<int64_t> part_vertices = PartSizes(part, parts, &largest);
  const std::vector<uint8_t> speck =
      SpeckParts(part_vertices, largest, AnchoredParts(mesh, part, parts, largest, anchors, anchor_radius));
  for (size_t i = 0; i < part.size(); ++i) on_speck[i] = speck[part[i]];
  return on_speck;
}

MeshPartsSummary RemoveUnneededParts(const std::vector<CalibratedView>& views,
                                     int min_needing_views,
                                     const std::vector<Eigen::Vector3d>& anchors,
                                     double anchor_radius, int num_threads, TriangleMesh* mesh) {
  const auto start = std::chrono::steady_clock::now();
  MeshPartsSummary summary;
  summary.min_needing_views = min_needing_views;
  const std::vector<size_t> masked = MaskedViews(views);
  summary.masked_views = static_cast<int>(masked.size());
  int parts = 0;
  const std::vector<int> part = ConnectedParts(*mesh, &parts);
  summary.parts = parts;
  summary.judged_by_masks =
      min_needing_views > 0 && static_cast<int>(masked.size()) >= min_needing_views;
  if (parts < 2 || (!summary.judged_by_masks && anchors.empty())) {
    summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return summary;
  }
  int largest = 0;
  const std::vector<int64_t> part_vertices = PartSizes(part, parts, &largest);
  if (!summary.judged_by_masks) {
    // No masks to say what the model needs: the sparse points alone speak for small parts.
    const std::vector<uint8_t> anchored =
        AnchoredParts(*mesh, part, parts, largest, anchors, anchor_radius);
    const std::vector<uint8_t> speck = SpeckParts(part_vertices, largest, anchored);
    std::vector<uint8_t> keep(parts, 1);
    for (int p = 0; p < parts; ++p) {
      summary.anchored += p != largest && anchored[p] && !speck[p];
      if (!speck[p]) continue;
      keep[p] = 0;
      ++summary.removed;
      summary.removed_vertices += part_vertices[p];
    }
    if (summary.removed > 0) KeepParts(part, keep, mesh);
    summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return summary;
  }
  // The triangles grouped by part, as DrawMeshParts needs them.
  std::vector<int> triangle_part;
  const TriangleMesh grouped = GroupedByPart(*mesh, part, &triangle_part);
  // Per masked view, the parts it needs.
  const std::vector<std::vector<uint8_t>> needs =
      PartsNeeded(views, masked, grouped, triangle_part, parts, num_threads);
  // Parts holding a sparse point: the anchors' neighbours among the other parts' vertices.
  const std::vector<uint8_t> anchored =
      AnchoredParts(*mesh, part, parts, largest, anchors, anchor_radius);
  std::vector<uint8_t> keep(parts, 0);
  for (int p = 0; p < parts; ++p) {
    int needing = 0;
    for (size_t m = 0; m < masked.size(); ++m) needing += needs[m][p];
    keep[p] = p == largest || needing >= min_needing_views || anchored[p];
    if (p != largest && needing < min_needing_views && anchored[p]) ++summary.anchored;
    VLOG(1) << "mesh part " << p << ": " << part_vertices[p] << " vertices, needed by " << needing
            << " masked photos" << (anchored[p] ? ", holds a sparse point" : "")
            << (keep[p] ? "" : ": removed");
    if (!keep[p]) {
      ++summary.removed;
      summary.removed_vertices += part_vertices[p];
    }
  }
  if (summary.removed > 0) KeepParts(part, keep, mesh);
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

bool SilhouetteFitOptions::IsValid(std::string* reason) const {
  if (passes < 0 || smoothing_passes < 0) {
    *reason = "silhouette fit passes must be >= 0";
    return false;
  }
  if (!(max_move > 0.0) || !(depth_tolerance > 0.0) || !std::isfinite(max_move) ||
      !std::isfinite(depth_tolerance)) {
    *reason = "silhouette fit needs a finite max_move and depth_tolerance > 0";
    return false;
  }
  return true;
}

std::string SilhouetteFitSummary::Summary() const {
  char text[320];
  std::snprintf(text, sizeof(text),
                "mesh outlines: %lld vertices on %d masked photos' outlines, %lld pulled in onto "
                "the masks; beyond the masks by %.2f px on average before, %.2f px before the "
                "last of %d passes; in %.2f s",
                static_cast<long long>(outline_vertices), masked_views,
                static_cast<long long>(pulled_vertices), mean_outside_pixels_first,
                mean_outside_pixels_last, passes, seconds);
  return text;
}

namespace {

// One view's say on one outline vertex: the move along its normal (<= 0) and how far beyond
// the mask's edge it lies (pixels, 0 on the object).
struct Vote {
  uint32_t vertex;
  float move;
  float outside;
};

// One masked view's votes: each vertex on the mesh's outline in the view (visible, next to a
// pixel the mesh does not cover), moved along its normal to the mask's edge (at most max_move,
// inwards only); `distance` is the view's signed distance to its mask's edge.
std::vector<Vote> OutlineVotes(const CalibratedView& view,
                               const cv::Mat& distance,
                               const SilhouetteFitOptions& options,
                               const TriangleMesh& mesh) {
  std::vector<Vote> votes;
  const size_t n = mesh.vertices.size();
  const cv::Mat depths = RenderMeshDepth(mesh, view, /*front_faces_only=*/true);
  const Eigen::Matrix3d M = view.P.leftCols<3>();
  const cv::Mat exterior = ExteriorPixels(depths);
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d h = view.P * mesh.vertices[i].cast<double>().homogeneous();
    if (!(h.z() > 0.0)) continue;
    const double x = h.x() / h.z(), y = h.y() / h.z();
    const int col = static_cast<int>(std::floor(x)), row = static_cast<int>(std::floor(y));
    if (col < 1 || row < 1 || col >= view.width - 1 || row >= view.height - 1) continue;
    const float own = depths.at<float>(row, col);
    if (std::isfinite(own) && h.z() > own + options.depth_tolerance) continue;  // hidden
    bool outline = false;
    for (int dr = -1; dr <= 1 && !outline; ++dr) {
      for (int dc = -1; dc <= 1 && !outline; ++dc) {
        outline = exterior.at<uint8_t>(row + dr, col + dc) != 0;
      }
    }
    if (!outline) continue;
    // The projection's velocity (pixels per world unit along the normal) and the rate at
    // which it changes the signed distance; the normal must carry the projection across
    // the edge outwards, not along it.
    const Eigen::Vector3d dh = M * mesh.normals[i].cast<double>();
    const double z2 = h.z() * h.z();
    const Eigen::Vector2d velocity((dh.x() * h.z() - h.x() * dh.z()) / z2,
                                   (dh.y() * h.z() - h.y() * dh.z()) / z2);
    const float d = SampleField(distance, x, y);
    const double gx = 0.5 * (SampleField(distance, x + 1.0, y) - SampleField(distance, x - 1.0, y));
    const double gy = 0.5 * (SampleField(distance, x, y + 1.0) - SampleField(distance, x, y - 1.0));
    const double rate = gx * velocity.x() + gy * velocity.y();
    if (!(rate > 0.5 * velocity.norm() * std::hypot(gx, gy))) continue;
    const double move = std::clamp(-d / rate, -options.max_move, 0.0);
    votes.push_back({static_cast<uint32_t>(i), static_cast<float>(move), std::max(d, 0.0f)});
  }
  return votes;
}

}  // namespace

SilhouetteFitSummary FitMeshToSilhouettes(const std::vector<CalibratedView>& views,
                                          const SilhouetteFitOptions& options, TriangleMesh* mesh) {
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  const auto start = std::chrono::steady_clock::now();
  SilhouetteFitSummary summary;
  const std::vector<size_t> masked = MaskedViews(views);
  summary.masked_views = static_cast<int>(masked.size());
  const size_t n = mesh->vertices.size();
  if (n == 0 || masked.empty() || options.passes == 0) return summary;
  if (mesh->normals.size() != n) ComputeVertexNormals(mesh);
  const std::vector<std::vector<int>> neighbours = VertexNeighbours(*mesh);
  const int threads = ResolveNumThreads(options.num_threads);
  std::vector<cv::Mat> distances(masked.size());
  ParallelRanges(masked.size(), threads, /*min_per_thread=*/1, [&](size_t first, size_t last) {
    for (size_t m = first; m < last; ++m) distances[m] = SignedMaskDistance(views[masked[m]].mask);
  });
  double move_sum = 0.0;
  int64_t moves_made = 0;
  for (int pass = 0; pass < options.passes; ++pass) {
    std::vector<std::vector<Vote>> votes(masked.size());
    ParallelRanges(masked.size(), threads, /*min_per_thread=*/1, [&](size_t first, size_t last) {
      for (size_t m = first; m < last; ++m) {
        votes[m] = OutlineVotes(views[masked[m]], distances[m], options, *mesh);
      }
    });
    std::vector<std::vector<float>> moves(n);
    double outside_sum = 0.0;
    int64_t sightings = 0;
    for (const std::vector<Vote>& view_votes : votes) {
      for (const Vote& vote : view_votes) {
        moves[vote.vertex].push_back(vote.move);
        outside_sum += vote.outside;
        ++sightings;
      }
    }
    const double mean_outside = sightings > 0 ? outside_sum / sightings : 0.0;
    if (pass == 0) summary.mean_outside_pixels_first = mean_outside;
    summary.mean_outside_pixels_last = mean_outside;
    std::vector<float> weighted(n, 0.0f), weights(n, 0.0f);
    int64_t outline = 0, pulled = 0;
    for (size_t i = 0; i < n; ++i) {
      std::vector<float>& m = moves[i];
      if (m.empty()) continue;
      ++outline;
      std::sort(m.begin(), m.end());
      const size_t half = m.size() / 2;
      const float median = m.size() % 2 == 1 ? m[half] : 0.5f * (m[half - 1] + m[half]);
      if (median < 0.0f) ++pulled;
      weighted[i] = median;
      weights[i] = 1.0f;
    }
    if (pass == 0) {
      summary.outline_vertices = outline;
      summary.pulled_vertices = pulled;
    }
    // The weighted mean of the outline vertices' moves over each vertex's neighbourhood; a
    // vertex whose neighbourhood holds less than half an outline vertex's weight moves by that
    // share (the band fades into the surface).
    AverageOverNeighbours(neighbours, options.smoothing_passes, &weighted, threads);
    AverageOverNeighbours(neighbours, options.smoothing_passes, &weights, threads);
    for (size_t i = 0; i < n; ++i) {
      if (!(weights[i] > 0.0f) || weighted[i] == 0.0f) continue;
      const float move = weighted[i] / std::max(weights[i], 0.5f);
      mesh->vertices[i] += move * mesh->normals[i];
      move_sum += std::abs(move);
      ++moves_made;
    }
    ComputeVertexNormals(mesh);
    summary.passes = pass + 1;
    VLOG(1) << "silhouette fit pass " << pass + 1 << ": " << outline << " outline vertices, "
            << pulled << " pulled in; beyond the masks " << mean_outside << " px on average";
  }
  summary.mean_move = moves_made > 0 ? move_sum / moves_made : 0.0;
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace exporter
}  // namespace raycarve
