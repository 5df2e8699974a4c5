#include "carve/carver.h"

#include <cmath>
#include <sstream>

namespace raycarve {

std::string CarveMethodToString(CarveMethod method) {
  switch (method) {
    case CarveMethod::kRay:
      return "ray";
    case CarveMethod::kGvc:
      return "gvc";
    case CarveMethod::kGvcLdi:
      return "gvc_ldi";
  }
  return "unknown";
}

bool CarveMethodFromString(const std::string& text, CarveMethod* method) {
  for (CarveMethod candidate : {CarveMethod::kRay, CarveMethod::kGvc, CarveMethod::kGvcLdi}) {
    if (text == CarveMethodToString(candidate)) {
      *method = candidate;
      return true;
    }
  }
  return false;
}

std::string CarveDecisionToString(CarveDecision decision) {
  return decision == CarveDecision::kThreshold ? "threshold" : "reprojection";
}

bool CarveDecisionFromString(const std::string& text, CarveDecision* decision) {
  for (CarveDecision candidate : {CarveDecision::kThreshold, CarveDecision::kReprojection}) {
    if (text == CarveDecisionToString(candidate)) {
      *decision = candidate;
      return true;
    }
  }
  return false;
}

std::string CarveOrderToString(CarveOrder order) {
  return order == CarveOrder::kFifo ? "fifo" : "visible_pixels";
}

bool CarveOrderFromString(const std::string& text, CarveOrder* order) {
  for (CarveOrder candidate : {CarveOrder::kFifo, CarveOrder::kVisiblePixels}) {
    if (text == CarveOrderToString(candidate)) {
      *order = candidate;
      return true;
    }
  }
  return false;
}

bool CarveOptions::IsValid(std::string* reason) const {
  if (resolution < 1 || resolution > 4096) {
    *reason = "resolution must be in [1, 4096], got " + std::to_string(resolution);
    return false;
  }
  if (!std::isfinite(threshold)) {
    *reason = "threshold must be a finite number";
    return false;
  }

  if (!std::isfinite(adaptive_threshold) || adaptive_threshold < 0.0) {
    *reason = "adaptive_threshold must be a finite number >= 0";
    return false;
  }
  if (!std::isfinite(spread_floor) || spread_floor < 0.0) {
    *reason = "spread_floor must be a finite number >= 0";
    return false;
  }
  if (min_views < 1) {
    *reason = "min_views must be >= 1";
    return false;
  }
  if (batch_voxels < 1 || batch_voxels > 65536) {
    *reason = "batch_voxels must be in [1, 65536], got " + std::to_string(batch_voxels);
    return false;
  }
  if (!(auto_threshold_quantile > 0.0 && auto_threshold_quantile <= 1.0)) {
    *reason = "auto_threshold_quantile must be in (0, 1], got " +
              std::to_string(auto_threshold_quantile);
    return false;
  }
  if (decision == CarveDecision::kReprojection && method != CarveMethod::kRay) {
    *reason = "the reprojection decision needs ray casting (--method ray)";
    return false;
  }
  if (incremental_statistics && method != CarveMethod::kRay) {
    *reason = "incremental statistics need ray casting (--method ray)";
    return false;
  }
  if (supersample != kAutomaticSupersample &&
      (supersample < 1 || supersample > kMaxSupersample || (supersample & (supersample - 1)) != 0)) {
    *reason = "supersample must be 0 (automatic), 1, 2 or 4, got " + std::to_string(supersample);
    return false;
  }
  std::vector<int> resolutions;
  if (!LevelResolutions(resolution, lod_levels, &resolutions, reason)) return false;
  if (!(lod_threshold_scale >= 1.0 && lod_threshold_scale <= 10.0)) {
    *reason = "lod_threshold_scale must be in [1, 10], got " + std::to_string(lod_threshold_scale);
    return false;
  }
  if (min_component_voxels < 0) {
    *reason = "min_component_voxels must be >= 0";
    return false;
  }
  if (lod_carve_depth < 0 || lod_carve_depth > 8) {
    *reason = "lod_carve_depth must be in [0, 8], got " + std::to_string(lod_carve_depth);
    return false;
  }
  if (lod_band < 0 || lod_band > 8) {
    *reason = "lod_band must be in [0, 8], got " + std::to_string(lod_band);
    return false;
  }
  if (!(max_memory_gib > 0.0)) {
    *reason = "max_memory_gib must be > 0";
    return false;
  }
  return true;
}

}  // namespace raycarve
