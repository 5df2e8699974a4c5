#include "carve/block_occupancy.h"

namespace raycarve {

BlockOccupancy::BlockOccupancy(const Volume& volume) {
  const Eigen::Vector3i& n = volume.grid().dimensions();
  dimensions_ = (n.array() + (kSize - 1)) / kSize;
  occupied_.assign(static_cast<size_t>(dimensions_.prod()), 0);
  // Only the set bits are visited: a word at a time, so an empty region costs a load per 64
  // voxels.
  const std::vector<uint64_t>& bits = volume.solid_bits();
  const int64_t nx = n.x(), nxy = static_cast<int64_t>(n.x()) * n.y();
  const int64_t bx = dimensions_.x(), bxy = static_cast<int64_t>(dimensions_.x()) * dimensions_.y();
  for (size_t word = 0; word < bits.size(); ++word) {
    for (uint64_t rest = bits[word]; rest != 0; rest &= rest - 1) {
      const int64_t index = static_cast<int64_t>(word) * 64 + __builtin_ctzll(rest);
      const int64_t z = index / nxy, y = (index - z * nxy) / nx, x = index - z * nxy - y * nx;
      occupied_[(x >> kShift) + bx * (y >> kShift) + bxy * (z >> kShift)] = 1;
    }
  }
  for (uint8_t value : occupied_) num_occupied_ += value;
  const Eigen::Vector3i& nb = dimensions_;
  for (int z = 0; z < nb.z(); ++z) {
    for (int y = 0; y < nb.y(); ++y) {
      for (int x = 0; x < nb.x(); ++x) {
        if (!IsOccupied(x, y, z)) continue;
        const bool on_edge = x == 0 || y == 0 || z == 0 || x + 1 == nb.x() || y + 1 == nb.y() ||
                             z + 1 == nb.z();
        if (on_edge || !IsOccupied(x - 1, y, z) || !IsOccupied(x + 1, y, z) ||
            !IsOccupied(x, y - 1, z) || !IsOccupied(x, y + 1, z) || !IsOccupied(x, y, z - 1) ||
            !IsOccupied(x, y, z + 1)) {
          boundary_.emplace_back(x, y, z);
        }
      }
    }
  }
}

}  // namespace raycarve
