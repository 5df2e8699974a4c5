#include "carve/ray_cast_visibility.h"

#include "carve/footprint.h"

namespace raycarve {

RayCastVisibility::RayCastVisibility(const std::vector<CalibratedView>& views,
                                     const Volume& volume)
    : views_(views), volume_(volume) {
  rays_.reserve(views.size());
  for (const CalibratedView& view : views) {
    const Eigen::Matrix3d world_from_pixel =
        view.cam_from_world.rotation.toRotationMatrix().transpose() * view.K.inverse();
    rays_.emplace_back(volume.grid(), world_from_pixel, view.centre, view.width, view.height,
                       view.valid);
    rays_.back().Initialise(volume);
  }
}

void RayCastVisibility::ComputeVis(int64_t voxel, std::vector<PixelRef>* pixels) {
  const Eigen::Vector3i coordinates = volume_.grid().Voxel(voxel);
  const uint64_t key = RayImage::Key(coordinates);
  for (size_t v = 0; v < views_.size(); ++v) {
    const CalibratedView& view = views_[v];
    const Footprint footprint =
        ComputeFootprint(view.P, view.width, view.height, volume_.grid(), coordinates);
    const uint64_t* keys = rays_[v].keys();
    for (int row = footprint.row_min; row <= footprint.row_max; ++row) {
      const int base = row * view.width;
      for (int col = footprint.col_min; col <= footprint.col_max; ++col) {
        if (keys[base + col] == key) {
          pixels->push_back({static_cast<uint32_t>(v), static_cast<uint32_t>(base + col)});
        }
      }
    }
  }
}

void RayCastVisibility::UpdateAfterCarve(int64_t /*voxel*/,
                                         const std::vector<PixelRef>& vis,
                                         const std::vector<int64_t>& /*newly_exposed*/,
                                         std::vector<int64_t>* changed) {
  for (const PixelRef& ref : vis) {
    const int64_t next = rays_[ref.view].Advance(static_cast<int>(ref.pixel), volume_);
    if (next != RayImage::kNoVoxel) changed->push_back(next);
  }
}

size_t RayCastVisibility::MemoryBytes() const {
  size_t bytes = 0;
  for (const RayImage& rays : rays_) bytes += rays.MemoryBytes();
  return bytes;
}

}  // namespace raycarve
