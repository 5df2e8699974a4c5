#include "carve/visual_hull.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include <opencv2/imgproc.hpp>

#include "carve/footprint.h"
#include "carve/view_workers.h"

namespace raycarve {
namespace {

// Inclusive-rectangle sums over a CV_32S integral image of size (rows + 1) x (cols + 1).
int RectSum(const cv::Mat& integral, const Footprint& f) {
  return integral.at<int>(f.row_max + 1, f.col_max + 1) - integral.at<int>(f.row_min, f.col_max + 1) -
         integral.at<int>(f.row_max + 1, f.col_min) + integral.at<int>(f.row_min, f.col_min);
}

// Whether the voxel's projection lies inside the image (not touching its first row or column),
// with its footprint.
bool FullyInside(const Eigen::Matrix<double, 3, 4>& P,
                 int width,
                 int height,
                 const VoxelGrid& grid,
                 const Eigen::Vector3i& voxel,
                 Footprint* footprint) {
  // Computed as if the image were unbounded: inside, clipping would change nothing.
  *footprint = ComputeFootprint(P, 1 << 20, 1 << 20, grid, voxel);
  return !footprint->empty() && footprint->col_min > 0 && footprint->row_min > 0 &&
         footprint->col_max < width && footprint->row_max < height;
}

}  // namespace

namespace {

struct MaskedView {
  const CalibratedView* view;
  cv::Mat object_integral;
  cv::Mat valid_integral;
};

// Per masked view, the integral images of its silhouette (grown by one pixel: a binary mask
// drops pixels less than half covered, which would cut slivers of the object, thin parts and
// corners, out of the hull) and of its valid pixels.
std::vector<MaskedView> MaskedViewsOf(const std::vector<CalibratedView>& views) {
  std::vector<MaskedView> masked;
  for (const CalibratedView& view : views) {
    if (view.mask.empty()) continue;
    MaskedView m{&view, cv::Mat(), cv::Mat()};
    cv::Mat object;
    cv::dilate(view.mask != 0, object, cv::Mat::ones(3, 3, CV_8U));
    object &= (view.valid != 0);
    cv::integral(object / 255, m.object_integral, CV_32S);
    cv::integral(view.valid / 255, m.valid_integral, CV_32S);
    masked.push_back(std::move(m));
  }
  return masked;
}

constexpr int kBlock = 4;

// Judges the solid voxels of the 4x4x4 block `block` (of `blocks` along each axis): marks in
// `outside` those that `min_background_views` views show entirely on background. `asked` and
// `solid` are buffers of the calling thread.
void JudgeBlock(const std::vector<MaskedView>& masked,
                const Volume& volume,
                const Eigen::Vector3i& blocks,
                int64_t block,
                int min_background_views,
                std::vector<const MaskedView*>* asked_buffer,
                std::vector<int64_t>* solid_buffer,
                std::vector<uint8_t>* outside_out) {
  const VoxelGrid& grid = volume.grid();
  const Eigen::Vector3i& n = grid.dimensions();
  std::vector<const MaskedView*>& asked = *asked_buffer;
  std::vector<int64_t>& solid = *solid_buffer;
  std::vector<uint8_t>& outside = *outside_out;
  const Eigen::Vector3i first =
      kBlock * Eigen::Vector3i(static_cast<int>(block % blocks.x()),
                               static_cast<int>(block / blocks.x() % blocks.y()),
                               static_cast<int>(block / blocks.x() / blocks.y()));
  const Eigen::Vector3i last = (first.array() + kBlock).min(n.array()) - 1;
  solid.clear();
  for (int z = first.z(); z <= last.z(); ++z) {
    for (int y = first.y(); y <= last.y(); ++y) {
      for (int x = first.x(); x <= last.x(); ++x) {
        const int64_t index = grid.Index(Eigen::Vector3i(x, y, z));
        if (volume.IsSolid(index)) solid.push_back(index);
      }
    }
  }
  if (solid.empty()) return;
  asked.clear();
  for (const MaskedView& m : masked) {
    Footprint wide = ComputeFootprint(m.view->P, 1 << 20, 1 << 20, grid, first, kBlock);
    const bool all_object =
        !wide.empty() && --wide.col_min >= 0 && --wide.row_min >= 0 &&
        ++wide.col_max < m.view->width && ++wide.row_max < m.view->height &&
        RectSum(m.object_integral, wide) == wide.area();
    if (!all_object) asked.push_back(&m);
  }
  for (int64_t index : solid) {
    const Eigen::Vector3i voxel = grid.Voxel(index);
    int background = 0;
    for (const MaskedView* m : asked) {
      Footprint footprint;
      if (!FullyInside(m->view->P, m->view->width, m->view->height, grid, voxel, &footprint)) {
        continue;
      }
      if (RectSum(m->valid_integral, footprint) == 0) continue;  // no photo data there
      if (RectSum(m->object_integral, footprint) == 0 && ++background >= min_background_views) {
        outside[index] = 1;
        break;
      }
    }
  }
}

}  // namespace

VisualHullStatistics CarveVisualHull(const std::vector<CalibratedView>& views,
                                     Volume* volume,
                                     int num_threads,
                                     int min_background_views) {
  const auto start = std::chrono::steady_clock::now();
  VisualHullStatistics statistics;
  const std::vector<MaskedView> masked = MaskedViewsOf(views);
  statistics.views_with_masks = static_cast<int>(masked.size());
  if (masked.empty()) return statistics;
  const VoxelGrid& grid = volume->grid();
  // Judged in parallel (the decisions read nothing the carving changes), carved in order. Voxels
  // are judged a 4x4x4 block at a time: a view in which the block's footprint, one pixel wider
  // all round, is object everywhere cannot carve any of its voxels (each voxel's footprint lies
  // inside the block's and holds an object pixel), so its voxels skip that view. Inside the
  // hull, where every view must be asked, that is most views.
  const Eigen::Vector3i& n = grid.dimensions();
  const Eigen::Vector3i blocks = (n.array() + (kBlock - 1)) / kBlock;
  const int64_t num_blocks = static_cast<int64_t>(blocks.x()) * blocks.y() * blocks.z();
  std::vector<uint8_t> outside(grid.num_voxels(), 0);
  const int threads = std::max(1, std::min<int>(ResolveNumThreads(num_threads), 64));
  auto judge = [&](int thread) {
    std::vector<const MaskedView*> asked;
    std::vector<int64_t> solid;
    for (int64_t block = thread; block < num_blocks; block += threads) {
      JudgeBlock(masked, *volume, blocks, block, min_background_views, &asked, &solid, &outside);
    }
  };
  std::vector<std::thread> workers;
  for (int thread = 1; thread < threads; ++thread) workers.emplace_back(judge, thread);
  judge(0);
  for (std::thread& worker : workers) worker.join();
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (!outside[index]) continue;
    volume->Carve(index, nullptr);
    ++statistics.carved;
  }
  statistics.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return statistics;
}

HullBox VisualHullBox(const std::vector<CalibratedView>& views,
                      const std::vector<Eigen::Vector3d>& points,
                      const Eigen::AlignedBox3d& box,
                      int resolution,
                      int num_threads,
                      int min_background_views) {
  const auto start = std::chrono::steady_clock::now();
  HullBox hull;
  hull.box = box;
  Volume volume{VoxelGrid(box, resolution)};
  const VisualHullStatistics carved =
      CarveVisualHull(views, &volume, num_threads, min_background_views);
  if (carved.views_with_masks == 0) return hull;
  const VoxelGrid& grid = volume.grid();
  // The hull's voxels that two or more photos frame (their centres): what fewer frame is never
  // judged by colour nor meshed (the carve keeps it solid and leaves it out of the model).
  std::vector<int32_t> label(grid.num_voxels(), -1);  // -2: kept, not yet labelled
  for (int64_t index = 0; index < grid.num_voxels(); ++index) {
    if (!volume.IsSolid(index)) continue;
    const Eigen::Vector3d centre = grid.Centre(grid.Voxel(index));
    int framed = 0;
    for (const CalibratedView& view : views) {
      if (view.FramesPoint(centre) && ++framed >= 2) break;
    }
    if (framed >= 2) label[index] = -2;
  }
  // Its pieces (26-connected), each with its voxels' box and the sparse points inside it.
  struct Piece {
    Eigen::AlignedBox3d box;
    int64_t voxels = 0;
    int points = 0;
  };
  std::vector<Piece> pieces;
  std::vector<int64_t> queue;
  for (int64_t seed = 0; seed < grid.num_voxels(); ++seed) {
    if (label[seed] != -2) continue;
    const int32_t id = static_cast<int32_t>(pieces.size());
    pieces.emplace_back();
    Piece& piece = pieces.back();
    label[seed] = id;
    queue.assign(1, seed);
    while (!queue.empty()) {
      const int64_t index = queue.back();
      queue.pop_back();
      const Eigen::Vector3i voxel = grid.Voxel(index);
      piece.box.extend(grid.Corner(voxel, 0));
      piece.box.extend(grid.Corner(voxel, 7));
      ++piece.voxels;
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const Eigen::Vector3i next = voxel + Eigen::Vector3i(dx, dy, dz);
            if (!grid.Contains(next)) continue;
            const int64_t n = grid.Index(next);
            if (label[n] != -2) continue;
            label[n] = id;
            queue.push_back(n);
          }
        }
      }
    }
  }
  int points_in_hull = 0;
  for (const Eigen::Vector3d& point : points) {
    const Eigen::Vector3i voxel = grid.VoxelOf(point);
    if (!grid.Contains(voxel)) continue;
    const int32_t id = label[grid.Index(voxel)];
    if (id < 0) continue;
    ++pieces[id].points;
    ++points_in_hull;
  }
  // The object is where the masks and the sparse points agree: the piece holding the most points,
  // and those as densely pointed (points per voxel) within kHullPieceDensityShare (a second object
  // beside the first) with kHullPieceMinPoints or more. Masks that call part of the surroundings
  // object, such as a sky unlike the backdrop, leave pieces with none or a few stray ones.
  // Without points in the hull, every piece.
  const Piece* most = nullptr;
  for (const Piece& piece : pieces) {
    if (most == nullptr || piece.points > most->points) most = &piece;
  }
  const double least_density =
      most == nullptr ? 0.0
                      : kHullPieceDensityShare * most->points / static_cast<double>(most->voxels);
  Eigen::AlignedBox3d kept;  // empty
  for (const Piece& piece : pieces) {
    if (points_in_hull > 0 && &piece != most &&
        (piece.points < kHullPieceMinPoints ||
         piece.points < least_density * static_cast<double>(piece.voxels))) {
      continue;
    }
    kept.extend(piece.box);
    hull.voxels += piece.voxels;
    hull.points += piece.points;
    ++hull.pieces;
  }
  hull.pieces_left = static_cast<int>(pieces.size()) - hull.pieces;
  if (!kept.isEmpty()) {
    const Eigen::Vector3d grow = Eigen::Vector3d::Constant(grid.voxel_size());
    kept = Eigen::AlignedBox3d(kept.min() - grow, kept.max() + grow);
  }
  hull.box = kept;
  hull.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return hull;
}

}  // namespace raycarve
