#include "carve/carver.h"

#include <sstream>

namespace raycarve {

std::string CarveStatistics::FreeSpaceSummary() const {
  std::ostringstream text;
  text << "free space: " << free_space_sight_lines << " sight lines from the photos to the sparse "
       << "points they saw carved " << free_space_carved << " voxels (" << free_space_level0_carved
       << " at the first level) in " << free_space_seconds << " s";
  if (free_space_through_ground > 0) {
    text << "; " << free_space_through_ground
         << " more would have passed down through the held ground, to points under it (wrong "
            "matches), and were not drawn";
  }
  return text.str();
}

std::string CarveStatistics::FloaterSummary() const {
  std::ostringstream text;
  text << "floaters: " << unsupported_components << " pieces of the model without a sparse point ("
       << unsupported_component_carved << " voxels; the largest was expected to hold "
       << unsupported_largest_expected << " at the model's density) carved";
  return text.str();
}

std::string CarveStatistics::Summary() const {
  std::ostringstream text;
  text.precision(3);
  text << visibility << " carving of a " << dimensions.x() << "x" << dimensions.y() << "x"
       << dimensions.z() << " grid: " << carved << " voxels carved, " << evaluated
       << " evaluated in " << carve_seconds << " s on " << ThreadsText() << " (set-up "
       << setup_seconds << " s), " << final_surface << " surface voxels (" << visible_surface
       << " seen), peak memory "
       << peak_memory_bytes / (1024.0 * 1024.0) << " MiB";
  return text.str();
}

std::string CarveStatistics::ThreadsText() const {
  std::string text = std::to_string(threads) + (threads == 1 ? " thread" : " threads");
  if (threads > 1 && inline_runs > 0 && parallel_runs > 0) {
    const double share = 100.0 * static_cast<double>(inline_runs) / parallel_runs;
    text += " (one alone for " + std::to_string(static_cast<int>(std::lround(share))) +
            "% of the parallel runs: the other cores were busy)";
  }
  return text;
}

}  // namespace raycarve
