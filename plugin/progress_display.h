#pragma once

#include <string>

#include "carve/carver.h"

namespace raycarve {

// The carve's progress on stderr: a bar redrawn in place on a terminal, a log line otherwise.
// Each report gives the share of the work seen so far (evaluations against evaluations plus the
// queue, an estimate: carving queues more) and the time left at the current rate.
class ProgressDisplay {
 public:
  explicit ProgressDisplay(std::string label = "carving");
  void Update(const CarveProgress& progress);
  // Ends the bar's line (a terminal only).
  void Finish();

 private:
  std::string label_;
  bool terminal_ = false;
  bool drawn_ = false;
};

}  // namespace raycarve
