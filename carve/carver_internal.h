#pragma once
// Internal to carve/: helpers shared by the files of the incremental carver (carver.h's
// implementation). Not installed for use outside carve/.

#include <chrono>
#include <cstdint>
#include <vector>

#include "calib/calibrated_view.h"
#include "carve/ray_cast_visibility.h"
#include "carve/voxel_colour_sums.h"

namespace raycarve {

using Clock = std::chrono::steady_clock;

inline double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

inline int64_t ElapsedNanoseconds(Clock::time_point since) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - since).count();
}

// Appends to `stats` the colour statistics of pixels [begin, end), grouped view by view (a new
// entry wherever the view changes).
void GatherColours(const std::vector<CalibratedView>& views,
                   const PixelRef* begin,
                   const PixelRef* end,
                   std::vector<ViewColourStats>* stats);

}  // namespace raycarve
