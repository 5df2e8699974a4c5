#include "carve/layered_depth_visibility.h"

#include <glog/logging.h>

namespace raycarve {

LayeredDepthVisibility::LayeredDepthVisibility(const std::vector<CalibratedView>& views,
                                               const Volume& volume)
    : views_(views), volume_(volume) {
  CHECK_LE(volume.grid().num_voxels(), int64_t{1} << 32) << "grid too large for 32-bit entries";
  for (const CalibratedView& view : views) {
    coverage_.emplace_back(view, volume.grid());
    heads_.emplace_back(static_cast<size_t>(view.width) * view.height, -1);
  }
  for (const int64_t voxel : volume.SurfaceVoxels()) InsertVoxel(voxel, nullptr);
}

bool LayeredDepthVisibility::Insert(int view, int pixel, uint32_t voxel, float depth) {
  int32_t node;
  if (free_ != -1) {
    node = free_;
    free_ = nodes_[node].next;
    --num_free_;
  } else {
    CHECK_LT(nodes_.size(), size_t{1} << 31) << "too many layered depth entries";
    node = static_cast<int32_t>(nodes_.size());
    nodes_.push_back({});
  }
  nodes_[node].voxel = voxel;
  nodes_[node].depth = depth;
  int32_t* link = &heads_[view][pixel];
  const bool head = *link == -1 || Before(depth, voxel, nodes_[*link]);
  while (*link != -1 && !Before(depth, voxel, nodes_[*link])) link = &nodes_[*link].next;
  nodes_[node].next = *link;
  *link = node;
  return head;
}

bool LayeredDepthVisibility::Remove(int view, int pixel, uint32_t voxel) {
  int32_t* link = &heads_[view][pixel];
  const bool head = *link != -1 && nodes_[*link].voxel == voxel;
  while (*link != -1 && nodes_[*link].voxel != voxel) link = &nodes_[*link].next;
  CHECK_NE(*link, -1) << "voxel " << voxel << " missing from the list of pixel " << pixel
                      << " of view " << view;
  const int32_t node = *link;
  *link = nodes_[node].next;
  nodes_[node].next = free_;
  free_ = node;
  ++num_free_;
  return head;
}

void LayeredDepthVisibility::InsertVoxel(int64_t voxel, std::vector<int64_t>* changed) {
  const Eigen::Vector3i coordinates = volume_.grid().Voxel(voxel);
  bool head = false;
  for (size_t v = 0; v < views_.size(); ++v) {
    coverage_[v].ForEach(coordinates, [&](int pixel, double t) {
      head |= Insert(static_cast<int>(v), pixel, static_cast<uint32_t>(voxel),
                     static_cast<float>(t));
    });
  }
  if (head && changed != nullptr) changed->push_back(voxel);
}

void LayeredDepthVisibility::ComputeVis(int64_t voxel, std::vector<PixelRef>* pixels) {
  const uint32_t item = static_cast<uint32_t>(voxel);
  AppendVoxelPixels(views_, volume_.grid(), voxel,
                    [&](size_t v, int pixel) {
                      const int32_t head = heads_[v][pixel];
                      return head != -1 && nodes_[head].voxel == item;
                    },
                    pixels);
}

void LayeredDepthVisibility::UpdateAfterCarve(int64_t voxel,
                                              const std::vector<PixelRef>& /*vis*/,
                                              const std::vector<int64_t>& newly_exposed,
                                              std::vector<int64_t>* changed) {
  // Newly exposed voxels lie behind V wherever V covers them, so none becomes a head yet unless
  // it covers a pixel V does not; V's removal then uncovers the right voxel per pixel.
  for (const int64_t exposed : newly_exposed) InsertVoxel(exposed, changed);
  const Eigen::Vector3i coordinates = volume_.grid().Voxel(voxel);
  const uint32_t item = static_cast<uint32_t>(voxel);
  for (size_t v = 0; v < views_.size(); ++v) {
    const std::vector<int32_t>& heads = heads_[v];
    coverage_[v].ForEach(coordinates, [&](int pixel, double /*t*/) {
      if (Remove(static_cast<int>(v), pixel, item) && heads[pixel] != -1) {
        changed->push_back(nodes_[heads[pixel]].voxel);
      }
    });
  }
}

size_t LayeredDepthVisibility::MemoryBytes() const {
  size_t bytes = nodes_.capacity() * sizeof(Node);
  for (const std::vector<int32_t>& heads : heads_) bytes += heads.capacity() * sizeof(int32_t);
  return bytes;
}

std::vector<int64_t> LayeredDepthVisibility::List(int view, int pixel) const {
  std::vector<int64_t> voxels;
  for (int32_t node = heads_[view][pixel]; node != -1; node = nodes_[node].next) {
    voxels.push_back(nodes_[node].voxel);
  }
  return voxels;
}

std::vector<float> LayeredDepthVisibility::Depths(int view, int pixel) const {
  std::vector<float> depths;
  for (int32_t node = heads_[view][pixel]; node != -1; node = nodes_[node].next) {
    depths.push_back(nodes_[node].depth);
  }
  return depths;
}

}  // namespace raycarve
