// The carve pipeline's decisions for a capture without masks, before the carve: the ground under
// the supporting plane, and the photo pixels that show what lies beyond the volume (sky, far
// hills) or show the ground; their rays are free space (CarveOptions::distant_rays).
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <glog/logging.h>

#include "calib/input_error.h"
#include "carve/ground_pixels.h"
#include "pipeline/carve_pipeline.h"

namespace raycarve {

bool CarvePipeline::CaptureIsObject() const {
  return request_.bounds.capture == "object" ||
         (request_.bounds.capture == "auto" && run_.layout.object_centred);
}

std::string CarvePipeline::ObjectRulesWithheld() const {
  if (!request_.options.auto_threshold) return "--threshold given";
  if (run_.masks_from_files + run_.masks_from_backdrop > 0) {
    return "masks (their threshold keeps the surface)";
  }
  if (!CaptureIsObject()) return "a scene (seen from one side)";
  return "";
}

void CarvePipeline::DecideObjectRules() {
  // The threshold comes from the sparse points, whose tracks are neighbouring photos that agree
  // on everything; the photos around the object that judge a voxel across a texture edge disagree
  // by up to its spread at the true surface.
  const std::string withheld = ObjectRulesWithheld();
  run_.spread_floor = request_.options.spread_floor;
  if (!request_.auto_spread_floor) {
    run_.spread_floor_reason = "as given";
  } else if (!withheld.empty()) {
    run_.spread_floor_reason = "none: " + withheld;
  } else {
    run_.spread_floor = kAutoSpreadFloor;
    run_.spread_floor_reason = "an object without masks, cameras around it";
  }
  if (request_.auto_spread_floor) {
    LOG(INFO) << "spread floor: the threshold at least " << run_.spread_floor
              << " x each voxel's within-view colour spread (" << run_.spread_floor_reason << ")";
  }
  // Likewise the photos that judge each sparse point when the threshold is measured: every photo
  // that sees it, not its track alone (measured: docs/studies/2026-12-06-seen-views.md).
  run_.threshold_seen_views = request_.options.threshold_seen_views;
  if (!request_.auto_threshold_views) {
    run_.threshold_views_reason = "as given";
  } else if (!withheld.empty()) {
    run_.threshold_seen_views = false;
    run_.threshold_views_reason = "tracks: " + withheld;
  } else {
    run_.threshold_seen_views = true;
    run_.threshold_views_reason = "an object without masks, cameras around it";
  }
  if (request_.auto_threshold_views && run_.threshold_seen_views) {
    LOG(INFO) << "threshold: each sparse point judged from every photo that sees it through a "
                 "first pass of the coarsest level, not its track alone ("
              << run_.threshold_views_reason << ")";
  }
}

void CarvePipeline::DecideGround() {
  run_.ground = Ground();
  run_.support = Ground();
  if (run_.plane.found) {
    // The floor runs on beyond the box: its points around the box too (the box's margin has
    // none of its own), those of the carved photos.
    const Eigen::AlignedBox3d& box = project_.bounds.box;
    const Eigen::AlignedBox3d around(box.min() - 0.5 * box.sizes(), box.max() + 0.5 * box.sizes());
    // A point under the plane opens a hole in the ground; a wrong match between two photos lies
    // anywhere, so holes come from the points three or more photos saw, as the plane does
    // (CheckedPoints), where there are enough.
    // A lone point on the plane that no third photo checked is left out of the ground too: one
    // wrong match past the ground's edge would stretch its outline over empty space.
    std::vector<Eigen::Vector3d> points, checked;
    std::vector<bool> is_checked;
    for (const SurfacePoint& point : SurfacePointsOf(project_.reconstruction, carved_, around)) {
      points.push_back(point.xyz);
      is_checked.push_back(static_cast<int>(point.views.size()) >= kCheckedTrack);
      if (is_checked.back()) checked.push_back(point.xyz);
    }
    const bool enough = static_cast<int>(checked.size()) >= kMinCheckedPoints;
    if (!enough) is_checked.clear();
    run_.support = exporter::GroundUnder(run_.plane, points, enough ? checked : points, is_checked);
  }
  if (!run_.plane.found) {
    run_.ground_reason = "no supporting plane";
  } else if (run_.masks_from_files + run_.masks_from_backdrop > 0) {
    run_.ground_reason = "masks bound the subject";
  } else if (!request_.hold_ground) {
    run_.ground_reason = "--hold_ground 0";
  } else {
    run_.ground = run_.support;
    std::ostringstream text;
    text.precision(3);
    if (run_.ground.empty()) {
      text << "no sparse point of the carved photos on the plane";
    } else {
      text << "held solid under the plane, within " << run_.ground.radius << " of its "
           << run_.ground.footprint.size() << " sparse points";
      if (run_.ground.lone_points > 0) {
        text << " (" << run_.ground.lone_points
             << (run_.ground.lone_points == 1 ? " lone point" : " lone points")
             << " on it that only two photos saw left out as wrong matches)";
      }
    }
    run_.ground_reason = text.str();
  }
  LOG(INFO) << "ground: " << run_.ground_reason;
}

void CarvePipeline::FindDistant() {
  run_.distant = DistantPixels();
  distant_rays_.clear();
  if (run_.masks_from_files + run_.masks_from_backdrop > 0) {
    run_.distant_reason = "masks say what is background";
  } else if (!request_.distant_free_space) {
    run_.distant_reason = "--distant_free_space 0";
  } else {
    run_.distant_reason.clear();
  }
  if (scope_.distant != nullptr) {
    // A tile job takes its plan's rays whatever they hold: the plan decided with the same options,
    // and its rays carry the ground pixels' too (with --distant_free_space 0, only those).
    for (const DistantRay& ray : scope_.distant->rays) {
      if (ray.view < 0 || ray.view >= static_cast<int>(carved_.size())) {
        throw InputError("raycarve " + scope_.command + ": the given distant pixels name view " +
                         std::to_string(ray.view) + " of " + std::to_string(carved_.size()) +
                         ": not this project's (plan again)");
      }
    }
    distant_rays_ = scope_.distant->rays;
    if (run_.distant_reason.empty()) {
      run_.distant = *scope_.distant;
      run_.distant.rays.clear();
      run_.distant.seconds = 0.0;
    }
    LOG(INFO) << distant_rays_.size() << " rays of distant and ground pixels from the tile plan";
    return;
  }
  if (run_.distant_reason.empty()) {
    DistantOptions options;
    options.num_threads = request_.options.num_threads;
    LOG(INFO) << "looking for pixels that show what lies beyond the volume (sky, far hills) in "
              << carved_.size() << " photos ...";
    // The photos' own pixels of the sparse points in the volume: plain regions holding one are
    // surfaces, not sky.
    run_.distant = FindDistantPixels(carved_, project_.bounds.box, options,
                                     SurfacePointPixels(carved_, surface_points_));
    LOG(INFO) << run_.distant.Summary();
    distant_rays_ = std::move(run_.distant.rays);
    run_.distant.rays.clear();
    RecordSeconds("distant_pixels", run_.distant.seconds);
  }
}

void CarvePipeline::FindGroundPixels() {
  run_.ground_pixels = DistantPixels();
  if (scope_.distant != nullptr) {
    run_.ground_pixels_reason = "in the tile plan's rays";
  } else if (run_.ground.empty()) {
    run_.ground_pixels_reason = "no ground held";
  } else if (!request_.ground_free_space) {
    run_.ground_pixels_reason = "--ground_free_space 0";
  } else {
    run_.ground_pixels_reason.clear();
    DistantOptions options;
    options.num_threads = request_.options.num_threads;
    options.grow_plain_regions = false;
    // The rays stop where the plane's tolerance begins (the band the sparse points on the plane
    // lie in), or higher where the photos do not tell that from the plane (FindGroundPixels).
    const double clearance = run_.ground.depth;
    LOG(INFO) << "looking for pixels that show the ground in " << carved_.size() << " photos ...";
    run_.ground_pixels = raycarve::FindGroundPixels(carved_, project_.bounds.box, run_.ground, clearance,
                                                    options, SurfacePointPixels(carved_, surface_points_));
    LOG(INFO) << GroundPixelsSummary(run_.ground_pixels);
    distant_rays_.insert(distant_rays_.end(), run_.ground_pixels.rays.begin(), run_.ground_pixels.rays.end());
    run_.ground_pixels.rays.clear();
    RecordSeconds("ground_pixels", run_.ground_pixels.seconds);
  }
}

}  // namespace raycarve
