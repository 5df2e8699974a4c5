#include "export/mesh_colouring.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "export/mesh_renderer.h"
#include "carve/view_workers.h"
#include "export/parallel_ranges.h"
#include "export/point_cloud_io.h"

namespace raycarve {
namespace exporter {
namespace {

// Below this (RGB units), disagreement between photos is noise and quantisation, not an outlier.
constexpr double kMinOutlierDistance = 12.0;

struct Sample {
  Eigen::Vector3f colour;
  float weight;
};

float WeightedMedian(std::vector<std::pair<float, float>>* values) {
  std::sort(values->begin(), values->end());
  float total = 0.0f;
  for (const auto& v : *values) total += v.second;
  float running = 0.0f;
  for (const auto& v : *values) {
    running += v.second;
    if (running >= 0.5f * total) return v.first;
  }
  return values->back().first;
}

// The weighted mean of the samples without those far from their per-channel median.
Eigen::Vector3f RobustColour(const std::vector<Sample>& samples, double outlier_factor) {
  Eigen::Vector3f median;
  std::vector<std::pair<float, float>> values(samples.size());
  for (int k = 0; k < 3; ++k) {
    for (size_t i = 0; i < samples.size(); ++i) values[i] = {samples[i].colour[k], samples[i].weight};
    median[k] = WeightedMedian(&values);
  }
  std::vector<float> distances(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) distances[i] = (samples[i].colour - median).norm();
  std::vector<float> sorted = distances;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double limit = std::max(kMinOutlierDistance, outlier_factor * sorted[sorted.size() / 2]);
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  float weight = 0.0f;
  for (size_t i = 0; i < samples.size(); ++i) {
    if (distances[i] > limit) continue;
    sum += samples[i].weight * samples[i].colour;
    weight += samples[i].weight;
  }
  return weight > 0.0f ? Eigen::Vector3f(sum / weight) : median;
}

}  // namespace

std::vector<cv::Mat> MaskDistances(const std::vector<CalibratedView>& views, int num_threads) {
  std::vector<cv::Mat> distances(views.size());
  ParallelRanges(views.size(), ResolveNumThreads(num_threads), /*min_per_thread=*/1,
                 [&](size_t first, size_t last) {
    for (size_t v = first; v < last; ++v) {
      if (!views[v].mask.empty()) cv::distanceTransform(views[v].mask, distances[v], cv::DIST_L2, 3);
    }
  });
  return distances;
}

namespace {

// What one view sees of the mesh: the vertices in front of its depth buffer, facing it, on valid
// object pixels, with how squarely (in vertex order), and in *rim those within rim_voxels voxel
// widths of its mask's edge (`to_background`: each object pixel's distance to the background,
// empty for none).
std::vector<std::pair<uint32_t, float>> SightingsInView(const CalibratedView& view,
                                                        const TriangleMesh& mesh,
                                                        double depth_tolerance,
                                                        const cv::Mat& to_background,
                                                        double voxel_size,
                                                        double rim_voxels,
                                                        std::vector<uint32_t>* rim) {
  std::vector<std::pair<uint32_t, float>> seen;
  const size_t n = mesh.vertices.size();
  // The mesh is closed (MeshSolidVoxels) and the cameras outside it: front faces suffice.
  const cv::Mat depths = RenderMeshDepth(mesh, view, /*front_faces_only=*/true);
  const double focal = 0.5 * (view.K(0, 0) + view.K(1, 1));
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d world = mesh.vertices[i].cast<double>();
    // P's last row is the camera's z (K's last row is (0, 0, 1)): one product gives both.
    const Eigen::Vector3d image = view.P * world.homogeneous();
    const double depth = image.z();
    if (!(depth > 0.0)) continue;
    const Eigen::Vector2d pixel = image.head<2>() / depth;
    const int col = static_cast<int>(std::floor(pixel.x()));
    const int row = static_cast<int>(std::floor(pixel.y()));
    if (col < 0 || row < 0 || col >= view.width || row >= view.height) continue;
    if (depth > depths.at<float>(row, col) + depth_tolerance) continue;
    if (!to_background.empty() && view.mask.at<uint8_t>(row, col) != 0 &&
        to_background.at<float>(row, col) <= rim_voxels * focal * voxel_size / depth) {
      rim->push_back(static_cast<uint32_t>(i));
    }
    const double facing = mesh.normals[i].cast<double>().dot((view.centre - world).normalized());
    if (!(facing > 0.0)) continue;
    if (view.valid.at<uint8_t>(row, col) == 0) continue;
    if (!view.mask.empty() && view.mask.at<uint8_t>(row, col) == 0) continue;
    seen.emplace_back(static_cast<uint32_t>(i), static_cast<float>(facing));
  }
  return seen;
}

}  // namespace

std::vector<std::vector<VertexSighting>> FindVertexSightings(
    const std::vector<CalibratedView>& views, const TriangleMesh& mesh, double depth_tolerance,
    std::vector<uint8_t>* on_rim, double voxel_size, double rim_voxels, int num_threads,
    const std::vector<cv::Mat>* mask_distances) {
  CHECK(mesh.normals.size() == mesh.vertices.size()) << "the mesh needs vertex normals";
  CHECK(mask_distances == nullptr || mask_distances->size() == views.size());
  const size_t n = mesh.vertices.size();
  const int threads = ResolveNumThreads(num_threads);
  std::vector<std::vector<VertexSighting>> sightings(n);
  if (on_rim != nullptr) on_rim->assign(n, 0);
  // The rims need each mask's distances to the background: the caller's, or made here.
  std::vector<cv::Mat> own_distances;
  if (on_rim != nullptr && voxel_size > 0.0 && mask_distances == nullptr) {
    own_distances = MaskDistances(views, threads);
    mask_distances = &own_distances;
  }
  // Each view on its own (in parallel): the vertices it sees, and which lie on its mask's rim.
  std::vector<std::vector<std::pair<uint32_t, float>>> per_view(views.size());
  std::vector<std::vector<uint32_t>> rims(views.size());
  ParallelRanges(views.size(), threads, /*min_per_thread=*/1, [&](size_t first, size_t last) {
    for (size_t v = first; v < last; ++v) {
      const CalibratedView& view = views[v];
      // Distance (pixels) from each object pixel to the nearest background pixel.
      cv::Mat to_background;
      if (on_rim != nullptr && !view.mask.empty() && voxel_size > 0.0) {
        to_background = (*mask_distances)[v];
      }
      per_view[v] = SightingsInView(view, mesh, depth_tolerance, to_background, voxel_size,
                                    rim_voxels, &rims[v]);
    }
  });
  // Per vertex in view order, the vertices split over the threads: each view's list is in vertex
  // order, so a range of vertices is a range of each list.
  ParallelRanges(n, threads, /*min_per_thread=*/4096, [&](size_t first, size_t last) {
    std::vector<std::pair<size_t, size_t>> spans(views.size());
    std::vector<uint8_t> count(last - first, 0);
    for (size_t v = 0; v < views.size(); ++v) {
      const auto& list = per_view[v];
      const auto by_vertex = [](const std::pair<uint32_t, float>& a, size_t i) { return a.first < i; };
      const size_t begin = std::lower_bound(list.begin(), list.end(), first, by_vertex) - list.begin();
      const size_t end = std::lower_bound(list.begin() + begin, list.end(), last, by_vertex) - list.begin();
      spans[v] = {begin, end};
      for (size_t k = begin; k < end; ++k) {
        if (count[list[k].first - first] < 255) ++count[list[k].first - first];
      }
    }
    for (size_t i = first; i < last; ++i) sightings[i].reserve(count[i - first]);
    for (size_t v = 0; v < views.size(); ++v) {
      const auto& list = per_view[v];
      for (size_t k = spans[v].first; k < spans[v].second; ++k) {
        sightings[list[k].first].push_back({static_cast<uint32_t>(v), list[k].second});
      }
      if (on_rim != nullptr) {
        for (uint32_t i : rims[v]) {
          if (i >= first && i < last) (*on_rim)[i] = 1;
        }
      }
    }
  });
  return sightings;
}

bool MeshColouringOptions::IsValid(std::string* reason) const {
  if (min_views < 1) {
    *reason = "mesh colouring needs min_views >= 1";
    return false;
  }
  if (!(depth_tolerance > 0.0) || !std::isfinite(depth_tolerance)) {
    *reason = "mesh colouring needs a depth tolerance > 0";
    return false;
  }
  if (!(outlier_factor > 0.0)) {
    *reason = "mesh colouring needs an outlier factor > 0";
    return false;
  }
  return true;
}

std::string MeshColouringSummary::Summary() const {
  char text[256];
  std::snprintf(text, sizeof(text),
                "mesh colours: %lld of %lld vertices (%.1f%%) from the photos (%.1f photos each), "
                "%lld from seen neighbours, %lld uncoloured, in %.2f s",
                static_cast<long long>(from_photos), static_cast<long long>(vertices),
                100.0 * SeenShare(), mean_views, static_cast<long long>(from_neighbours),
                static_cast<long long>(uncoloured), seconds);
  return text;
}

namespace {

// Colours the vertices no photo coloured (`known` 0) from their coloured neighbours, ring by ring
// inwards; returns how many it coloured.
int64_t FillFromNeighbours(const TriangleMesh& mesh,
                           std::vector<Eigen::Vector3f>* colours_io,
                           std::vector<char>* known_io) {
  std::vector<Eigen::Vector3f>& colours = *colours_io;
  std::vector<char>& known = *known_io;
  const size_t n = mesh.vertices.size();
  int64_t filled_count = 0;
  std::vector<std::vector<int>> neighbours(n);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) {
      neighbours[t[k]].push_back(t[(k + 1) % 3]);
      neighbours[t[k]].push_back(t[(k + 2) % 3]);
    }
  }
  std::vector<int> frontier;
  for (size_t i = 0; i < n; ++i) {
    if (!known[i]) frontier.push_back(static_cast<int>(i));
  }
  while (!frontier.empty()) {
    std::vector<std::pair<int, Eigen::Vector3f>> filled;
    std::vector<int> still;
    for (int i : frontier) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int count = 0;
      for (int j : neighbours[i]) {
        if (!known[j]) continue;
        sum += colours[j];
        ++count;
      }
      if (count > 0) {
        filled.emplace_back(i, sum / count);
      } else {
        still.push_back(i);
      }
    }
    if (filled.empty()) break;
    for (const auto& [i, colour] : filled) {
      colours[i] = colour;
      known[i] = 1;
    }
    filled_count += static_cast<int64_t>(filled.size());
    frontier.swap(still);
  }
  return filled_count;
}

}  // namespace

MeshColouringSummary ColourMeshFromPhotos(const std::vector<CalibratedView>& views,
                                          const MeshColouringOptions& options,
                                          TriangleMesh* mesh,
                                          std::vector<std::vector<uint32_t>>* seen_by) {
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  CHECK(mesh->normals.size() == mesh->vertices.size()) << "the mesh needs vertex normals";
  const auto start = std::chrono::steady_clock::now();
  const size_t n = mesh->vertices.size();
  MeshColouringSummary summary;
  summary.vertices = static_cast<int64_t>(n);
  const std::vector<std::vector<VertexSighting>> sightings = FindVertexSightings(
      views, *mesh, options.depth_tolerance, nullptr, 0.0, 1.0, options.num_threads);
  std::vector<std::vector<Sample>> samples(n);
  if (seen_by != nullptr) seen_by->assign(n, {});
  // Each vertex on its own: its samples, and the robust colour of those (in parallel).
  std::vector<Eigen::Vector3f> colours(n, Eigen::Vector3f::Zero());
  std::vector<char> known(n, 0);
  ParallelRanges(n, ResolveNumThreads(options.num_threads), /*min_per_thread=*/4096,
                 [&](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      const Eigen::Vector3d world = mesh->vertices[i].cast<double>();
      for (const VertexSighting& sighting : sightings[i]) {
        Eigen::Vector3f colour;
        if (!SamplePhoto(views[sighting.view], views[sighting.view].Project(world), &colour)) continue;
        samples[i].push_back({colour, sighting.facing});
        if (seen_by != nullptr) (*seen_by)[i].push_back(sighting.view);
      }
      if (static_cast<int>(samples[i].size()) < options.min_views) continue;
      colours[i] = RobustColour(samples[i], options.outlier_factor);
      known[i] = 1;
    }
  });

  // Colour from the photos where enough saw the vertex; the rest from coloured neighbours,
  // ring by ring.
  double views_sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!known[i]) continue;
    ++summary.from_photos;
    views_sum += samples[i].size();
  }
  summary.mean_views = summary.from_photos > 0 ? views_sum / summary.from_photos : 0.0;
  summary.from_neighbours = FillFromNeighbours(*mesh, &colours, &known);
  mesh->colours.resize(n);
  for (size_t i = 0; i < n; ++i) {
    if (known[i]) {
      mesh->colours[i] = ToRgb(colours[i]);
    } else {
      mesh->colours[i] = Eigen::Matrix<uint8_t, 3, 1>(128, 128, 128);
      ++summary.uncoloured;
    }
  }
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace exporter
}  // namespace raycarve
