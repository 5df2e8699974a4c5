#include "plugin/progress_display.h"

#include <cmath>
#include <cstdio>
#include <iomanip>

#include <glog/logging.h>
#include <unistd.h>

namespace raycarve {

ProgressDisplay::ProgressDisplay(std::string label)
    : label_(std::move(label)), terminal_(isatty(STDERR_FILENO) != 0) {}

void ProgressDisplay::Update(const CarveProgress& p) {
  const double share =
      p.evaluated + p.queued > 0 ? static_cast<double>(p.evaluated) / (p.evaluated + p.queued) : 0.0;
  const double rate = p.seconds > 0 ? p.evaluated / p.seconds : 0.0;
  const double left = rate > 0 ? p.queued / rate : 0.0;
  const std::string level = p.levels > 1 ? "level " + std::to_string(p.level + 1) + "/" +
                                               std::to_string(p.levels) + " "
                                         : std::string();
  if (p.setting_up) {
    if (terminal_) {
      std::fprintf(stderr, "\r%s %ssetting up (the rays from the photos) ...%24s", label_.c_str(),
                   level.c_str(), "");
      std::fflush(stderr);
      drawn_ = true;
      return;
    }
    LOG(INFO) << label_ << " " << level << std::fixed << std::setprecision(1) << p.seconds
              << " s: setting up (the start volume from the level before, the photos scaled, "
              << "the rays cast) ...";
    return;
  }
  if (terminal_) {
    const int width = 30, filled = static_cast<int>(std::lround(share * width));
    std::fprintf(stderr, "\r%s %s[%s%s] %3.0f%%  %.1f s, about %.1f s left  ", label_.c_str(),
                 level.c_str(), std::string(filled, '#').c_str(),
                 std::string(width - filled, ' ').c_str(), 100.0 * share, p.seconds, left);
    std::fflush(stderr);
    drawn_ = true;
    return;
  }
  LOG(INFO) << label_ << " " << level << std::fixed << std::setprecision(1) << p.seconds
            << " s: evaluated " << p.evaluated << ", carved " << p.carved << ", queue " << p.queued
            << " (about " << std::lround(100.0 * share) << "% of the work seen, " << left
            << " s left at " << static_cast<int64_t>(rate) << " evaluations/s)";
}

void ProgressDisplay::Finish() {
  if (terminal_ && drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace raycarve
