#include "export/mesh_texture.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>

#include <glog/logging.h>
#include <opencv2/imgproc.hpp>

#include "export/mesh_colouring.h"
#include "export/parallel_ranges.h"
#include "carve/view_workers.h"

namespace raycarve {
namespace exporter {
namespace {

// A triangle's photo: the view and the pixels its corners project to there.
struct Candidate {
  int view = -1;
  double area = 0.0;  // projected area in pixels
};

// The views that see all three corners (seen_by lists are sorted), with the triangle in the
// frame and facing the camera, and the area it covers in each.
std::vector<Candidate> CandidatesOf(const std::vector<CalibratedView>& views,
                                    const std::vector<std::vector<uint32_t>>& seen_by,
                                    const TriangleMesh& mesh, const Eigen::Vector3i& triangle) {
  std::vector<uint32_t> common = seen_by[triangle[0]];
  for (int corner = 1; corner < 3; ++corner) {
    std::vector<uint32_t> both;
    const std::vector<uint32_t>& other = seen_by[triangle[corner]];
    std::set_intersection(common.begin(), common.end(), other.begin(), other.end(),
                          std::back_inserter(both));
    common.swap(both);
  }
  std::vector<Candidate> candidates;
  for (const uint32_t v : common) {
    const CalibratedView& view = views[v];
    Eigen::Vector2d pixel[3];
    bool inside = true;
    for (int corner = 0; corner < 3 && inside; ++corner) {
      pixel[corner] = view.Project(mesh.vertices[triangle[corner]].cast<double>());
      inside = pixel[corner].x() >= 1.0 && pixel[corner].y() >= 1.0 &&
               pixel[corner].x() <= view.width - 1.0 && pixel[corner].y() <= view.height - 1.0;
    }
    if (!inside) continue;
    const Eigen::Vector2d ab = pixel[1] - pixel[0], ac = pixel[2] - pixel[0];
    // Facing the camera: clockwise on the screen (see RenderMesh).
    const double signed_area = 0.5 * (ab.x() * ac.y() - ab.y() * ac.x());
    if (!(signed_area < 0.0)) continue;
    candidates.push_back({static_cast<int>(v), -signed_area});
  }
  return candidates;
}

// Per triangle, the triangles sharing an edge with it.
std::vector<std::vector<int>> EdgeNeighbours(const TriangleMesh& mesh) {
  std::unordered_map<uint64_t, std::vector<int>> by_edge;
  by_edge.reserve(mesh.triangles.size() * 2);
  for (int t = 0; t < static_cast<int>(mesh.triangles.size()); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.triangles[t][k], b = mesh.triangles[t][(k + 1) % 3];
      by_edge[(static_cast<uint64_t>(std::min(a, b)) << 32) | static_cast<uint32_t>(std::max(a, b))]
          .push_back(t);
    }
  }
  std::vector<std::vector<int>> neighbours(mesh.triangles.size());
  for (const auto& [edge, triangles] : by_edge) {
    for (const int t : triangles) {
      for (const int u : triangles) {
        if (u != t) neighbours[t].push_back(u);
      }
    }
  }
  return neighbours;
}

// A piece of one photo holding a connected set of triangles that take that photo.
struct Chart {
  int view = -1;  // -1: the flat cells of triangles no photo sees whole
  std::vector<int> triangles;
  cv::Rect source;  // in the photo, padding included
  cv::Mat patch;    // what goes into the atlas (scaled, levelled)
  cv::Point at;     // its top-left corner in the atlas
};

// Shelf packing, tallest first: the charts' positions in an atlas `width` wide; returns the
// height used.
int Pack(int width, std::vector<Chart>* charts) {
  std::vector<size_t> order(charts->size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return (*charts)[a].patch.rows > (*charts)[b].patch.rows;
  });
  int x = 0, y = 0, shelf = 0;
  for (const size_t i : order) {
    Chart& chart = (*charts)[i];
    if (x + chart.patch.cols > width) {
      x = 0;
      y += shelf;
      shelf = 0;
    }
    chart.at = cv::Point(x, y);
    x += chart.patch.cols;
    shelf = std::max(shelf, chart.patch.rows);
  }
  return y + shelf;
}

// Pixels a side of the cell of a triangle no photo sees whole: its corners' colours at three of
// the cell's texel centres, (0.5, 0.5), (kFlatCell - 0.5, 0.5) and (0.5, kFlatCell - 0.5),
// blended in between as the vertex colours are.
constexpr int kFlatCell = 4;

// Each texel of the chart's triangles (in `patch`, the chart's piece of its own photo) becomes the
// mean of what the triangle's candidate photos see at its point, weighted by the area the
// triangle covers in each; samples far from the first mean (beyond twice the samples' spread
// and at least kBlendOutlier) are left out of the second. The point is the texel's barycentric
// blend of the corners (affine over the triangle: its projection is, to within a fraction of a
// pixel at a triangle's size). Texels outside the triangles keep the photo's pixels, so that
// sampling at a chart's edge blends with what the photo shows there.
constexpr double kBlendOutlier = 30.0;
void BlendViews(const std::vector<CalibratedView>& views, const TriangleMesh& mesh,
                const std::vector<std::vector<Candidate>>& candidates, const Chart& chart,
                const std::vector<std::array<Eigen::Vector2d, 3>>& corner_pixels, cv::Mat* patch) {
  std::vector<Eigen::Vector3f> samples;
  std::vector<double> weights;
  for (const int t : chart.triangles) {
    const Eigen::Vector2d offset(chart.source.x, chart.source.y);
    const Eigen::Vector2d a = corner_pixels[t][0] - offset, b = corner_pixels[t][1] - offset,
                          c = corner_pixels[t][2] - offset;
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (!(std::abs(area) > 1e-12)) continue;
    const Eigen::Vector3d corner[3] = {mesh.vertices[mesh.triangles[t][0]].cast<double>(),
                                       mesh.vertices[mesh.triangles[t][1]].cast<double>(),
                                       mesh.vertices[mesh.triangles[t][2]].cast<double>()};
    const int col_min = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int col_max = std::min(patch->cols - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
    const int row_min = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
    const int row_max = std::min(patch->rows - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
    for (int row = row_min; row <= row_max; ++row) {
      for (int col = col_min; col <= col_max; ++col) {
        const Eigen::Vector2d p(col + 0.5, row + 0.5);
        const double w0 = ((b.x() - p.x()) * (c.y() - p.y()) - (b.y() - p.y()) * (c.x() - p.x())) / area;
        const double w1 = ((c.x() - p.x()) * (a.y() - p.y()) - (c.y() - p.y()) * (a.x() - p.x())) / area;
        const double w2 = 1.0 - w0 - w1;
        // A texel whose centre is within half a texel of the triangle: its edge texels too.
        const double margin = 0.5 * std::sqrt(2.0) * 2.0 / std::sqrt(std::abs(area));
        if (w0 < -margin || w1 < -margin || w2 < -margin) continue;
        const Eigen::Vector3d point = w0 * corner[0] + w1 * corner[1] + w2 * corner[2];
        samples.clear();
        weights.clear();
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        double total = 0.0;
        for (const Candidate& candidate : candidates[t]) {
          Eigen::Vector3f colour;
          if (!SamplePhoto(views[candidate.view], views[candidate.view].Project(point), &colour)) continue;
          samples.push_back(colour);
          weights.push_back(candidate.area);
          sum += candidate.area * colour.cast<double>();
          total += candidate.area;
        }
        if (!(total > 0.0)) continue;
        const Eigen::Vector3d mean = sum / total;
        double spread = 0.0;
        for (size_t i = 0; i < samples.size(); ++i) {
          spread += weights[i] * (samples[i].cast<double>() - mean).squaredNorm();
        }
        const double limit = std::max(kBlendOutlier, 2.0 * std::sqrt(spread / total));
        Eigen::Vector3d kept = Eigen::Vector3d::Zero();
        double kept_weight = 0.0;
        for (size_t i = 0; i < samples.size(); ++i) {
          if ((samples[i].cast<double>() - mean).norm() > limit) continue;
          kept += weights[i] * samples[i].cast<double>();
          kept_weight += weights[i];
        }
        const Eigen::Vector3d colour = kept_weight > 0.0 ? Eigen::Vector3d(kept / kept_weight) : mean;
        cv::Vec3b& texel = patch->at<cv::Vec3b>(row, col);
        for (int k = 0; k < 3; ++k) {
          texel[k] = static_cast<uint8_t>(std::clamp(std::lround(colour[k]), 0L, 255L));
        }
      }
    }
  }
}

// The view where the triangle covers the most pixels; -1 where none sees it whole.
int BestView(const std::vector<Candidate>& candidates) {
  double best = 0.0;
  int best_view = -1;
  for (const Candidate& c : candidates) {
    if (c.area > best) {
      best = c.area;
      best_view = c.view;
    }
  }
  return best_view;
}

// Each triangle's photo: the one where it covers the most pixels, then, over the passes, the
// photo of most of its neighbours where that one is nearly as good (options.neighbour_share).
std::vector<int> LabelTriangles(const std::vector<std::vector<Candidate>>& candidates,
                                const std::vector<std::vector<int>>& neighbours,
                                const MeshTextureOptions& options) {
  const int num_triangles = static_cast<int>(candidates.size());
  std::vector<int> label(num_triangles, -1);
  for (int t = 0; t < num_triangles; ++t) label[t] = BestView(candidates[t]);
  for (int pass = 0; pass < options.relabel_passes; ++pass) {
    std::vector<int> next = label;
    for (int t = 0; t < num_triangles; ++t) {
      if (label[t] < 0) continue;
      std::map<int, int> votes;
      for (const int u : neighbours[t]) {
        if (label[u] >= 0 && label[u] != label[t]) ++votes[label[u]];
      }
      int own_votes = 0;
      for (const int u : neighbours[t]) own_votes += label[u] == label[t];
      double best = 0.0;
      for (const Candidate& c : candidates[t]) best = std::max(best, c.area);
      for (const auto& [view, count] : votes) {
        if (count <= own_votes || count < 2) continue;
        for (const Candidate& c : candidates[t]) {
          if (c.view == view && c.area >= options.neighbour_share * best) next[t] = view;
        }
      }
    }
    label.swap(next);
  }
  return label;
}

// Charts: edge-connected triangles with one photo. The triangles with none go to `flat`.
std::vector<Chart> GrowCharts(const std::vector<int>& label,
                              const std::vector<std::vector<int>>& neighbours, Chart* flat) {
  const int num_triangles = static_cast<int>(label.size());
  std::vector<int> chart_of(num_triangles, -1);
  std::vector<Chart> charts;
  for (int t = 0; t < num_triangles; ++t) {
    if (label[t] < 0) {
      flat->triangles.push_back(t);
      continue;
    }
    if (chart_of[t] >= 0) continue;
    Chart chart;
    chart.view = label[t];
    std::vector<int> stack = {t};
    chart_of[t] = static_cast<int>(charts.size());
    while (!stack.empty()) {
      const int u = stack.back();
      stack.pop_back();
      chart.triangles.push_back(u);
      for (const int w : neighbours[u]) {
        if (chart_of[w] < 0 && label[w] == chart.view) {
          chart_of[w] = chart_of[t];
          stack.push_back(w);
        }
      }
    }
    charts.push_back(std::move(chart));
  }
  return charts;
}

// The chart's piece of its photo (its triangles' corners' pixels into `corner_pixels`), blended
// across the candidate photos or levelled to the vertices' colours (single photos only: the
// gain of the sums of the vertices' and the photo's colours at the corners).
void MakeChartPatch(const std::vector<CalibratedView>& views, const TriangleMesh& mesh,
                    const std::vector<std::vector<Candidate>>& candidates,
                    const MeshTextureOptions& options, Chart* chart,
                    std::vector<std::array<Eigen::Vector2d, 3>>* corner_pixels) {
  const bool level = !options.blend_views && options.level_colours;
  const CalibratedView& view = views[chart->view];
  Eigen::Vector2d low(1e300, 1e300), high(-1e300, -1e300);
  Eigen::Vector3d vertex_sum = Eigen::Vector3d::Zero(), photo_sum = Eigen::Vector3d::Zero();
  for (const int t : chart->triangles) {
    for (int corner = 0; corner < 3; ++corner) {
      const int vertex = mesh.triangles[t][corner];
      const Eigen::Vector2d pixel = view.Project(mesh.vertices[vertex].cast<double>());
      (*corner_pixels)[t][corner] = pixel;
      low = low.cwiseMin(pixel);
      high = high.cwiseMax(pixel);
      Eigen::Vector3f colour;
      if (level && SampleBilinear(view.image, pixel, &colour)) {
        photo_sum += colour.cast<double>();
        vertex_sum += mesh.colours[vertex].cast<double>();
      }
    }
  }
  const int x0 = std::max(0, static_cast<int>(std::floor(low.x())) - options.padding);
  const int y0 = std::max(0, static_cast<int>(std::floor(low.y())) - options.padding);
  const int x1 = std::min(view.width, static_cast<int>(std::ceil(high.x())) + options.padding);
  const int y1 = std::min(view.height, static_cast<int>(std::ceil(high.y())) + options.padding);
  chart->source = cv::Rect(x0, y0, std::max(1, x1 - x0), std::max(1, y1 - y0));
  chart->patch = view.image(chart->source).clone();
  if (options.blend_views) {
    BlendViews(views, mesh, candidates, *chart, *corner_pixels, &chart->patch);
  } else if (level && photo_sum.minCoeff() > 0.0) {
    cv::Mat levelled;
    chart->patch.convertTo(levelled, CV_32FC3);
    cv::Scalar gain;
    for (int k = 0; k < 3; ++k) gain[k] = std::clamp(vertex_sum[k] / photo_sum[k], 1.0 / 1.4, 1.4);
    cv::multiply(levelled, gain, levelled);
    levelled.convertTo(chart->patch, CV_8UC3);  // saturating
  }
}

// The cells of the triangles no photo sees whole, in a square block (`flat->patch`); returns the
// block's side in cells.
int MakeFlatPatch(const TriangleMesh& mesh, Chart* flat) {
  const int flat_count = static_cast<int>(flat->triangles.size());
  const int flat_side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(flat_count))));
  if (flat_count == 0) return flat_side;
  flat->patch = cv::Mat(flat_side * kFlatCell, flat_side * kFlatCell, CV_8UC3, cv::Scalar::all(128));
  const double span = kFlatCell - 1.0;
  for (int i = 0; i < flat_count; ++i) {
    const Eigen::Vector3i& triangle = mesh.triangles[flat->triangles[i]];
    const int x0 = (i % flat_side) * kFlatCell, y0 = (i / flat_side) * kFlatCell;
    for (int y = 0; y < kFlatCell; ++y) {
      for (int x = 0; x < kFlatCell; ++x) {
        // Barycentric weights of the texel centre, clamped onto the triangle.
        double w1 = x / span, w2 = y / span;
        if (w1 + w2 > 1.0) {
          const double sum = w1 + w2;
          w1 /= sum;
          w2 /= sum;
        }
        const double w0 = 1.0 - w1 - w2;
        cv::Vec3b& texel = flat->patch.at<cv::Vec3b>(y0 + y, x0 + x);
        for (int k = 0; k < 3; ++k) {
          const double value = w0 * mesh.colours[triangle[0]][k] +
                               w1 * mesh.colours[triangle[1]][k] +
                               w2 * mesh.colours[triangle[2]][k];
          texel[k] = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
        }
      }
    }
  }
  return flat_side;
}

struct AtlasSize {
  bool fits = false;
  int width = 0;
  int height = 0;
  double scale = 1.0;  // of the charts against the photos' resolution
};

// Packing: an atlas about as wide as tall, the charts scaled down until it fits the longest side
// allowed (or 40 tries, down to 0.9^39, about 1.6% of the photos' resolution, have failed).
AtlasSize PackAtlas(int max_atlas_side, std::vector<Chart>* charts, Chart* flat) {
  double area = 0.0;
  for (const Chart& chart : *charts) area += static_cast<double>(chart.patch.total());
  std::vector<cv::Mat> originals;
  for (const Chart& chart : *charts) originals.push_back(chart.patch);
  AtlasSize atlas;
  double scale = 1.0;
  for (int attempt = 0; attempt < 40; ++attempt) {
    int width = 64;
    while (width < max_atlas_side &&
           static_cast<double>(width) * width < 1.2 * (area * scale * scale + flat->patch.total())) {
      width *= 2;
    }
    for (size_t i = 0; i < charts->size(); ++i) {
      if (scale < 1.0) {
        const cv::Size size(std::max(1, static_cast<int>(std::lround(originals[i].cols * scale))),
                            std::max(1, static_cast<int>(std::lround(originals[i].rows * scale))));
        cv::resize(originals[i], (*charts)[i].patch, size, 0, 0, cv::INTER_AREA);
      }
    }
    // No narrower than the widest chart.
    for (const Chart& chart : *charts) width = std::max(width, chart.patch.cols);
    width = std::max(width, flat->patch.cols);
    charts->push_back(*flat);
    atlas.height = Pack(width, charts);
    *flat = charts->back();
    charts->pop_back();
    atlas.width = width;
    atlas.scale = scale;
    if (atlas.height <= max_atlas_side && width <= max_atlas_side) {
      atlas.fits = true;
      return atlas;
    }
    scale *= 0.9;
  }
  return atlas;
}

// The atlas image and every triangle corner's texture coordinates in it.
void DrawAtlas(const std::vector<Chart>& charts, const Chart& flat, int flat_side,
               const std::vector<std::array<Eigen::Vector2d, 3>>& corner_pixels,
               const AtlasSize& atlas, TriangleMesh* mesh) {
  const int width = atlas.width, height = atlas.height;
  mesh->texture = cv::Mat(height, width, CV_8UC3, cv::Scalar::all(128));
  mesh->corner_uvs.assign(3 * mesh->triangles.size(), Eigen::Vector2f::Zero());
  for (const Chart& chart : charts) {
    const double sx = static_cast<double>(chart.patch.cols) / chart.source.width;
    const double sy = static_cast<double>(chart.patch.rows) / chart.source.height;
    chart.patch.copyTo(mesh->texture(cv::Rect(chart.at, chart.patch.size())));
    for (const int t : chart.triangles) {
      for (int corner = 0; corner < 3; ++corner) {
        const Eigen::Vector2d& pixel = corner_pixels[t][corner];
        mesh->corner_uvs[3 * t + corner] =
            Eigen::Vector2f((chart.at.x + (pixel.x() - chart.source.x) * sx) / width,
                            (chart.at.y + (pixel.y() - chart.source.y) * sy) / height);
      }
    }
  }
  const int flat_count = static_cast<int>(flat.triangles.size());
  if (flat_count == 0) return;
  flat.patch.copyTo(mesh->texture(cv::Rect(flat.at, flat.patch.size())));
  for (int i = 0; i < flat_count; ++i) {
    const float x0 = static_cast<float>(flat.at.x + (i % flat_side) * kFlatCell) + 0.5f;
    const float y0 = static_cast<float>(flat.at.y + (i / flat_side) * kFlatCell) + 0.5f;
    const float span = kFlatCell - 1.0f;
    const Eigen::Vector2f corners[3] = {{x0, y0}, {x0 + span, y0}, {x0, y0 + span}};
    for (int corner = 0; corner < 3; ++corner) {
      mesh->corner_uvs[3 * flat.triangles[i] + corner] =
          corners[corner].cwiseQuotient(Eigen::Vector2f(width, height));
    }
  }
}

}  // namespace

bool MeshTextureOptions::IsValid(std::string* reason) const {
  if (!(neighbour_share > 0.0 && neighbour_share <= 1.0)) {
    *reason = "neighbour_share must be in (0, 1]";
    return false;
  }
  if (relabel_passes < 0 || padding < 1 || padding > 16) {
    *reason = "relabel_passes must be >= 0 and padding in [1, 16]";
    return false;
  }
  if (max_atlas_side < 64 || max_atlas_side > 16384) {
    *reason = "max_atlas_side must be in [64, 16384]";
    return false;
  }
  return true;
}

std::string MeshTextureSummary::Summary() const {
  std::ostringstream text;
  text.precision(3);
  if (too_large) {
    text << "mesh texture: none: " << triangles << " triangles would need an atlas of "
         << needed_width << " x " << needed_height << " texels, over the limit of its longest side; "
         << "the mesh keeps its vertex colours (a coarser --resolution textures), in " << seconds
         << " s";
    return text.str();
  }
  text << "mesh texture: " << textured << " of " << triangles << " triangles from the photos in "
       << charts << " charts (" << relabelled << " took their neighbours' photo), the rest from their vertices' colours; atlas "
       << atlas_width << " x " << atlas_height;
  if (scale < 1.0) text << " at " << scale << " of the photos' resolution";
  if (seam_edges > 0) {
    text << "; across the " << seam_edges << " chart borders the colour steps by " << seam_step
         << " on average, inside the charts by " << inner_step;
  }
  text << ", in " << seconds << " s";
  return text.str();
}

MeshTextureSummary TextureMeshFromPhotos(const std::vector<CalibratedView>& views,
                                         const std::vector<std::vector<uint32_t>>& seen_by,
                                         const MeshTextureOptions& options, TriangleMesh* mesh) {
  const auto start = std::chrono::steady_clock::now();
  std::string reason;
  CHECK(options.IsValid(&reason)) << reason;
  CHECK_EQ(seen_by.size(), mesh->vertices.size());
  CHECK_EQ(mesh->colours.size(), mesh->vertices.size());
  MeshTextureSummary summary;
  const int num_triangles = static_cast<int>(mesh->triangles.size());
  summary.triangles = num_triangles;
  mesh->corner_uvs.clear();
  mesh->texture.release();
  if (num_triangles == 0) return summary;
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };

  std::vector<std::vector<Candidate>> candidates(num_triangles);
  for (int t = 0; t < num_triangles; ++t) {
    candidates[t] = CandidatesOf(views, seen_by, *mesh, mesh->triangles[t]);
  }
  const std::vector<std::vector<int>> neighbours = EdgeNeighbours(*mesh);
  const std::vector<int> label = LabelTriangles(candidates, neighbours, options);
  Chart flat;
  std::vector<Chart> charts = GrowCharts(label, neighbours, &flat);
  summary.charts = static_cast<int64_t>(charts.size());
  summary.textured = num_triangles - static_cast<int64_t>(flat.triangles.size());
  for (int t = 0; t < num_triangles; ++t) {
    summary.relabelled += label[t] >= 0 && label[t] != BestView(candidates[t]);
  }

  // Each chart's piece of its photo. Charts are independent (each triangle in one): any thread
  // count gives the same atlas.
  std::vector<std::array<Eigen::Vector2d, 3>> corner_pixels(num_triangles);
  ParallelRanges(charts.size(), ResolveNumThreads(options.num_threads), 16,
                 [&](size_t begin, size_t end) {
                   for (size_t i = begin; i < end; ++i) {
                     MakeChartPatch(views, *mesh, candidates, options, &charts[i], &corner_pixels);
                   }
                 });
  const int flat_side = MakeFlatPatch(*mesh, &flat);

  const AtlasSize atlas = PackAtlas(options.max_atlas_side, &charts, &flat);
  if (!atlas.fits) {
    // Even at the smallest scale tried the charts do not fit, or the cells of the
    // triangles no photo sees whole fill the atlas alone (millions of them on a grid finer than
    // the photos): no texture, the mesh keeps its vertex colours (readers refuse larger images).
    summary.too_large = true;
    summary.textured = 0;
    summary.charts = 0;
    summary.relabelled = 0;
    summary.needed_width = atlas.width;
    summary.needed_height = atlas.height;
    summary.seconds = elapsed();
    return summary;
  }
  summary.scale = atlas.scale;
  summary.atlas_width = atlas.width;
  summary.atlas_height = atlas.height;
  DrawAtlas(charts, flat, flat_side, corner_pixels, atlas, mesh);
  const TextureSeams seams = MeasureTextureSeams(*mesh);
  summary.seam_edges = seams.seam_edges;
  summary.seam_step = seams.seam_step;
  summary.inner_step = seams.inner_step;
  summary.seconds = elapsed();
  return summary;
}

}  // namespace exporter
}  // namespace raycarve
