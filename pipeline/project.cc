#include "pipeline/project.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <locale>
#include <map>
#include <set>
#include <sstream>

#include <glog/logging.h>
#include <unistd.h>

#include "calib/input_error.h"
#include "calib/photos_up.h"
#include "calib/model_reader.h"
#include "carve/carver.h"
#include "pipeline/output_files.h"
#include "pipeline/workspace.h"

namespace raycarve {

Bounds ParseBoxText(const std::string& text, const std::string& flag) {
  std::vector<double> values;
  std::stringstream stream(text);
  stream.imbue(std::locale::classic());
  std::string item;
  while (std::getline(stream, item, ',')) {
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size()) {
      throw InputError(flag + ": '" + item + "' is not a number");
    }
    values.push_back(value);
  }
  if (values.size() != 6) {
    throw InputError(flag + ": expected 6 comma-separated numbers, found " +
                     std::to_string(values.size()));
  }
  return ExplicitBounds(Eigen::Vector3d(values[0], values[1], values[2]),
                        Eigen::Vector3d(values[3], values[4], values[5]));
}

Bounds ResolveBounds(const Reconstruction& reconstruction,
                     const BoundsRequest& flags,
                     const std::string& source) {
  if (!flags.bbox.empty()) return ParseBoxText(flags.bbox, "--bbox");
  std::string reason;
  if (!flags.options.IsValid(&reason)) throw InputError("bounds options: " + reason);
  return ComputeBounds(reconstruction, flags.options, source);
}


ProjectRequest ProjectRequestOf(const CarveRequest& request, const std::string& command) {
  ProjectRequest project;
  project.command = command;
  project.workspace_path = request.workspace_path;
  project.input_path = request.input_path;
  project.image_path = request.image_path;
  project.output_path = request.output_path;
  project.bounds = request.bounds;
  project.view_options = request.view_options;
  project.model_index = request.model_index;
  project.colour_calibration = ColourCalibrationModeOf(request);
  project.resolution = request.options.resolution;
  return project;
}

double PhysicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGESIZE);
  return pages > 0 && page_size > 0 ? static_cast<double>(pages) * page_size : 0.0;
}

void CheckFitsInMemory(double bytes, const std::string& what, const std::string& how,
                       const std::string& remedy) {
  const double physical = PhysicalMemoryBytes();
  if (physical <= 0.0 || bytes <= kUsableMemoryShare * physical) return;
  std::ostringstream text;
  text << std::setprecision(3) << what << " needs about " << bytes / (1 << 30) << " GiB (" << how
       << "), more than " << 100 * kUsableMemoryShare << "% of this machine's "
       << physical / (1 << 30) << " GiB: " << remedy;
  throw InputError(text.str());
}

void CheckPhotosFitInMemory(const Reconstruction& reconstruction, int max_image_size,
                            double physical_bytes) {
  if (physical_bytes <= 0.0) physical_bytes = PhysicalMemoryBytes();
  if (physical_bytes <= 0.0) return;  // unknown: nothing to compare with
  double pixels = 0.0;
  Eigen::Vector2i largest(0, 0);
  for (const auto& [id, image] : reconstruction.images) {
    const Camera& camera = reconstruction.cameras.at(image.camera_id);
    const Eigen::Vector2i size = LimitedImageSize(camera.width, camera.height, max_image_size);
    pixels += static_cast<double>(size.x()) * size.y();
    if (size.x() * static_cast<double>(size.y()) > largest.x() * static_cast<double>(largest.y())) {
      largest = size;
    }
  }
  const double needed = kBytesPerPhotoPixel * pixels;
  if (needed <= kUsableMemoryShare * physical_bytes) return;
  // The longer side at which the photos would fit, for the message.
  const double fit_scale = std::sqrt(kUsableMemoryShare * physical_bytes / needed);
  const int suggestion = static_cast<int>(std::max(largest.x(), largest.y()) * fit_scale) / 100 * 100;
  std::ostringstream text;
  text << reconstruction.images.size() << " photos of up to " << largest.x() << "x" << largest.y()
       << " pixels ("
       << (max_image_size > 0 ? "after --max_image_size " + std::to_string(max_image_size)
                              : std::string("full size"))
       << ") need about "
       << std::setprecision(3) << needed / (1 << 30) << " GiB while carving ("
       << kBytesPerPhotoPixel << " bytes a pixel), more than " << kUsableMemoryShare * 100
       << "% of this machine's " << physical_bytes / (1 << 30)
       << " GiB: give --max_image_size " << std::max(100, suggestion)
       << " or fewer, or use fewer photos";
  throw InputError(text.str());
}

WorkspacePaths ResolveProjectPaths(const ProjectRequest& request, std::string* output_path) {
  const WorkspacePaths paths =
      request.paths ? *request.paths
                    : ResolveWorkspace(request.workspace_path, request.input_path,
                                       request.image_path, request.model_index);
  *output_path = request.output_path;
  if (output_path->empty()) {
    if (request.workspace_path.empty()) throw InputError("raycarve " + request.command + ": give --output_path");
    *output_path = (std::filesystem::path(request.workspace_path) / "raycarve").string();
  }
  CheckOutputDoesNotOverwrite(*output_path, paths.model_path, "input model");
  CheckOutputDoesNotOverwrite(*output_path, paths.image_path, "photo folder");
  return paths;
}

int MinorityBackdropMasks(const ViewReaderSummary& summary) {
  int automatic = 0, given = 0;
  for (const PhotoMaskInfo& photo : summary.photos) {
    automatic += photo.source == "backdrop";
    given += photo.source == "file" || photo.source == "colour";
  }
  const int photos = static_cast<int>(summary.photos.size());
  return given > 0 || automatic == 0 || 2 * automatic >= photos ? 0 : automatic;
}

bool CaptureIsMasked(const ViewReaderSummary& summary) {
  return summary.masks_from_files + summary.masks_from_backdrop > MinorityBackdropMasks(summary);
}

void NarrowToMaskedHull(LoadedProject* project) {
  const HullBox hull = VisualHullBox(
      project->views, CheckedPoints(project->reconstruction, project->bounds.box),
      project->bounds.box, kHullBoxResolution, /*num_threads=*/0, kHullBoxBackgroundViews);
  const Eigen::Vector3d before = project->bounds.box.sizes();
  const Eigen::AlignedBox3d box = hull.box.intersection(project->bounds.box);
  if (box.isEmpty()) {
    LOG(INFO) << "volume: the masks' visual hull leaves nothing that two photos frame: the box "
                 "kept";
    return;
  }
  if (box.sizes().maxCoeff() > kHullBoxMaxSide * before.maxCoeff()) {
    LOG(INFO) << std::setprecision(3) << "volume: the masks' visual hull spans "
              << box.sizes().maxCoeff() / before.maxCoeff()
              << " of the box the sparse points gave: the box kept";
    return;
  }
  project->bounds.points_box = project->bounds.box;
  project->bounds.box = box;
  project->bounds.around_hull = true;
  LOG(INFO) << std::setprecision(3) << "volume: the box around what the masks call the object ("
            << "their visual hull on a grid of " << kHullBoxResolution << ": " << hull.pieces
            << " pieces of " << hull.voxels << " voxels holding " << hull.points
            << " sparse points, " << hull.pieces_left << " pieces with too few left out; "
            << hull.seconds << " s): extent " << box.sizes().transpose()
            << " of " << before.transpose() << " the sparse points gave";
}

void ChooseCaptureBox(const BoundsRequest& request, int resolution, LoadedProject* project) {
  if (project->bounds.is_explicit || request.capture == "scene") return;
  const bool masked = CaptureIsMasked(project->view_summary);
  if (masked) NarrowToMaskedHull(project);
  const CaptureLayout& layout = project->layout;
  const bool object = request.capture == "object" || (layout.object_centred && !masked);
  if (!object) {
    if (masked || resolution <= 0) return;
    std::map<image_t, double> focal_px;
    for (const CalibratedView& view : project->views) {
      focal_px[view.image_id] = 0.5 * (view.K(0, 0) + view.K(1, 1));
    }
    const DepthResolution depth =
        ResolveSceneDepth(project->reconstruction, focal_px, project->bounds.box, resolution);
    LOG(INFO) << "scene depth: " << depth.Summary();
    if (depth.box.isEmpty()) return;
    project->bounds.box = depth.box;
    project->bounds.depth_resolved_points = depth.resolved;
    project->bounds.depth_tried_points = depth.points;
    LOG(INFO) << "volume: a scene's box narrowed to the " << depth.resolved << " of "
              << depth.points << " sparse points its photos place in depth to two voxels (the rest "
              << "lie too far for the cameras' baseline; --capture scene or --bbox keeps them)";
    return;
  }
  if (layout.focus_box.isEmpty()) {
    LOG(WARNING) << "too few sparse points around the cameras' focus (" << layout.focus_box_points
                 << "): the box keeps every sparse point";
    return;
  }
  const Eigen::AlignedBox3d box = layout.focus_box.intersection(project->bounds.box);
  if (box.isEmpty() || box.isApprox(project->bounds.box)) return;
  project->bounds.box = box;
  project->bounds.around_focus = true;
  LOG(INFO) << "volume: the box around the cameras' focus (" << layout.focus_box_points
            << " sparse points framed there"
            << (layout.occluder_points >= kMinOccluderPoints
                    ? ", grown to hold " + std::to_string(layout.occluder_points) +
                          " in front of them that hide some of them from photos"
                    : std::string())
            << "; --capture " << request.capture << ")";
}

namespace {
// The photos a point's track holds, each once.
int DistinctImages(const Point3D& point) {
  std::set<image_t> images;
  for (const TrackElement& e : point.track) images.insert(e.image_id);
  return static_cast<int>(images.size());
}
}  // namespace

std::vector<Eigen::Vector3d> CheckedPoints(const Reconstruction& reconstruction,
                                          const Eigen::AlignedBox3d& box) {
  std::vector<Eigen::Vector3d> checked, all;
  for (const auto& [id, point] : reconstruction.points3D) {
    if (!box.contains(point.xyz)) continue;
    const int images = DistinctImages(point);
    if (images >= 2) all.push_back(point.xyz);
    if (images >= kCheckedTrack) checked.push_back(point.xyz);
  }
  return static_cast<int>(checked.size()) >= kMinCheckedPoints ? checked : all;
}

LoadedProject LoadProject(const ProjectRequest& request) {
  LoadedProject project;
  const WorkspacePaths paths = ResolveProjectPaths(request, &project.output_path);
  project.model_path = paths.model_path;
  project.image_path = paths.image_path;

  LOG(INFO) << "reading model " << paths.model_path << " (" << paths.layout << ")";
  project.reconstruction = ReadModel(paths.model_path);
  const size_t registered = project.reconstruction.images.size();
  if (registered == 0) throw InputError(paths.model_path + ": the model has no registered images");
  if (static_cast<int>(registered) < request.min_images) {
    throw InputError(paths.model_path + ": the model has " + std::to_string(registered) +
                     " registered images; raycarve " + request.command + " needs at least " +
                     std::to_string(request.min_images));
  }
  if (request.hold_out_every > 0) {
    project.held_out = HoldOutImages(request.hold_out_every, &project.reconstruction,
                                     &project.held_out_points);
    LOG(INFO) << "holding out " << project.held_out.size() << " of " << registered
              << " images (every " << request.hold_out_every << "th in name order); "
              << project.reconstruction.points3D.size()
              << " sparse points keep two or more observations without them";
  }
  project.bounds = ResolveBounds(project.reconstruction, request.bounds, paths.model_path);
  LOG(INFO) << project.bounds.Summary();
  project.layout = DescribeCapture(project.reconstruction);
  LOG(INFO) << "capture: " << project.layout.Summary();
  CheckPhotosFitInMemory(project.reconstruction, request.view_options.max_image_size);
  LOG(INFO) << "loading and undistorting " << registered << " photos from " << paths.image_path;
  ViewReaderOptions reader_options = request.view_options;
  reader_options.volume = project.bounds.box;
  project.views = ReadCalibratedViews(project.reconstruction, paths.image_path, reader_options,
                                      &project.view_summary);
  LOG(INFO) << project.view_summary.Summary();
  if (static_cast<int>(project.views.size()) < request.min_images) {
    throw InputError(paths.image_path + ": only " + std::to_string(project.views.size()) +
                     " photos could be loaded; raycarve " + request.command + " needs at least " +
                     std::to_string(request.min_images));
  }
  if (request.colour_calibration != ColourCalibrationMode::kOff) {
    project.colour = EstimateColourCalibration(project.reconstruction, project.views);
    if (project.colour.points_used == 0) {
      if (request.colour_calibration == ColourCalibrationMode::kOn) {
        LOG(WARNING) << "colour calibration: no sparse point is seen by 3 or more photos; the "
                        "photos are used as they are";
      }
    } else if (request.colour_calibration == ColourCalibrationMode::kOn ||
               ColourCalibrationPays(project.colour)) {
      ApplyColourCalibration(project.colour, &project.views);
      project.colour.applied = true;
      LOG(INFO) << project.colour.Summary() << "; the photos corrected";
    } else {
      LOG(INFO) << project.colour.Summary()
                << "; the photos used as they are (--colour_calibration auto corrects them "
                   "where that at least halves the spread: different exposures)";
    }
  }
  ChooseCaptureBox(request.bounds, request.resolution, &project);
  {
    // A wrong match between two photos triangulates anywhere, under the floor too (a chequered
    // floor or a repeated pattern, measured: docs/studies/2026-12-05-colmap-points.md), and points
    // below a plane rule it out; a third photo checks the match.
    std::vector<Eigen::Vector3d> cameras;
    std::vector<Rigid3d> poses;
    const std::vector<Eigen::Vector3d> points =
        CheckedPoints(project.reconstruction, project.bounds.box);
    for (const auto& [id, image] : project.reconstruction.images) {
      cameras.push_back(image.ProjectionCenter());
      poses.push_back(image.cam_from_world);
    }
    project.plane = exporter::FitSupportingPlane(
        points, cameras, EstimatePhotosUp(poses),
        kPlaneTolerance * project.bounds.box.sizes().maxCoeff());
    LOG(INFO) << "support: " << project.plane.Summary();
  }
  project.surface_points =
      SurfacePointsOf(project.reconstruction, project.views, project.bounds.box);
  return project;
}

void CheckVolumeSeen(const std::string& command,
                     const LoadedProject& project,
                     const std::vector<CalibratedView>& views,
                     int min_views,
                     const BoundsRequest& bounds_flags) {
  const Eigen::AlignedBox3d& box = project.bounds.box;
  const BoxCoverage coverage = MeasureBoxCoverage(views, box, min_views);
  if (coverage.seen_share > 0.0) {
    if (coverage.seen_share < 0.5) {
      LOG(WARNING) << "only " << std::lround(100.0 * coverage.seen_share) << "% of the volume is "
                   << "seen by " << min_views << " or more photos; the rest cannot be carved";
    }
    return;
  }
  const auto format = [](const Eigen::AlignedBox3d& b) {
    std::ostringstream text;
    text << "(" << b.min().x() << ", " << b.min().y() << ", " << b.min().z() << ") - ("
         << b.max().x() << ", " << b.max().y() << ", " << b.max().z() << ")";
    return text.str();
  };
  std::ostringstream text;
  text << "raycarve " << command << ": the volume " << format(box)
       << (project.bounds.is_explicit ? " (--bbox)" : " (from the sparse points)")
       << " is seen by fewer than " << min_views << " photos (--min_views) everywhere: nothing "
       << "in it can be carved. Share of it each photo sees:";
  for (size_t v = 0; v < views.size(); ++v) {
    if (v == 12) {
      text << " ... (" << views.size() - v << " more)";
      break;
    }
    text << (v > 0 ? "," : "") << " " << views[v].name << " "
         << std::lround(100.0 * coverage.view_share[v]) << "%";
  }
  if (project.bounds.is_explicit) {
    BoundsRequest from_points = bounds_flags;
    from_points.bbox.clear();
    try {
      const Bounds own = ResolveBounds(project.reconstruction, from_points, project.model_path);
      text << ". The sparse points' own box is " << format(own.box)
           << ": is the --bbox in the model's frame and units?";
    } catch (const InputError&) {
      text << ". (The sparse points cannot bound a volume of their own.)";
    }
  }
  throw InputError(text.str());
}

std::vector<SurfacePoint> SurfacePointsOf(const Reconstruction& reconstruction,
                                          const std::vector<CalibratedView>& views,
                                          const Eigen::AlignedBox3d& box) {
  std::map<image_t, int> view_of;
  for (size_t v = 0; v < views.size(); ++v) view_of[views[v].image_id] = static_cast<int>(v);
  std::vector<SurfacePoint> points;
  for (const auto& [id, point3D] : reconstruction.points3D) {
    if (!(point3D.error >= 0.0 && point3D.error <= kMaxSurfaceError)) continue;
    if (!box.contains(point3D.xyz)) continue;
    SurfacePoint point;
    point.xyz = point3D.xyz;
    for (const TrackElement& element : point3D.track) {
      const auto found = view_of.find(element.image_id);
      if (found != view_of.end()) point.views.push_back(found->second);
    }
    std::sort(point.views.begin(), point.views.end());
    point.views.erase(std::unique(point.views.begin(), point.views.end()), point.views.end());
    if (static_cast<int>(point.views.size()) >= kMinSurfaceTrack) points.push_back(std::move(point));
  }
  return points;
}

std::vector<std::string> HoldOutImages(
    int every, Reconstruction* reconstruction,
    std::map<std::string, std::vector<Eigen::Vector3d>>* seen_points) {
  CHECK_GT(every, 0);
  std::vector<std::pair<std::string, image_t>> by_name;
  for (const auto& [id, image] : reconstruction->images) by_name.emplace_back(image.name, id);
  std::sort(by_name.begin(), by_name.end());
  std::vector<std::string> names;
  std::set<image_t> held;
  for (size_t i = 0; i < by_name.size(); i += every) {
    names.push_back(by_name[i].first);
    held.insert(by_name[i].second);
  }
  for (auto it = reconstruction->points3D.begin(); it != reconstruction->points3D.end();) {
    std::vector<TrackElement>& track = it->second.track;
    if (seen_points != nullptr) {
      std::set<image_t> others, held_seeing;
      for (const TrackElement& e : track) (held.count(e.image_id) ? held_seeing : others).insert(e.image_id);
      if (others.size() >= 2) {
        for (image_t id : held_seeing) {
          (*seen_points)[reconstruction->images.at(id).name].push_back(it->second.xyz);
        }
      }
    }
    track.erase(std::remove_if(track.begin(), track.end(),
                               [&](const TrackElement& e) { return held.count(e.image_id) > 0; }),
                track.end());
    if (DistinctImages(it->second) < 2) {
      for (const TrackElement& e : track) {
        Image& image = reconstruction->images.at(e.image_id);
        if (e.point2D_idx < image.points2D.size()) {
          image.points2D[e.point2D_idx].point3D_id = kInvalidPoint3DId;
        }
      }
      it = reconstruction->points3D.erase(it);
    } else {
      ++it;
    }
  }
  for (image_t id : held) {
    for (Point2D& point2D : reconstruction->images.at(id).points2D) {
      point2D.point3D_id = kInvalidPoint3DId;
    }
  }
  return names;
}

}  // namespace raycarve
