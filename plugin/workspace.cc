#include "plugin/workspace.h"

#include <algorithm>
#include <iomanip>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <glog/logging.h>
#include <unistd.h>

#include "calib/colour_calibration.h"
#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "carve/carver.h"
#include "plugin/commands.h"

namespace raycarve {
namespace {

bool HoldsModel(const std::filesystem::path& folder) {
  return std::filesystem::exists(folder / "cameras.bin") ||
         std::filesystem::exists(folder / "cameras.txt");
}

// Registered images of a model: images.bin's leading count, or half the lines of images.txt
// after its comments.
int64_t CountImages(const std::filesystem::path& model) {
  std::ifstream binary(model / "images.bin", std::ios::binary);
  if (binary) {
    uint64_t count = 0;
    binary.read(reinterpret_cast<char*>(&count), sizeof(count));
    return binary ? static_cast<int64_t>(count) : 0;
  }
  std::ifstream text(model / "images.txt");
  int64_t lines = 0;
  std::string line;
  // Two lines an image; the second (its points) is empty for an image without observations.
  while (std::getline(text, line)) lines += line.empty() || line[0] != '#';
  return lines / 2;
}

}  // namespace

std::vector<ModelCandidate> NumberedModels(const std::string& sparse_path) {
  std::vector<ModelCandidate> models;
  std::error_code error;
  if (!std::filesystem::is_directory(sparse_path, error)) return models;
  for (const auto& entry : std::filesystem::directory_iterator(sparse_path, error)) {
    const std::string name = entry.path().filename().string();
    if (name.empty() || name.size() > 6 ||
        name.find_first_not_of("0123456789") != std::string::npos || !HoldsModel(entry.path())) {
      continue;
    }
    models.push_back({std::stoi(name), entry.path().string(), CountImages(entry.path())});
  }
  std::sort(models.begin(), models.end(),
            [](const ModelCandidate& a, const ModelCandidate& b) { return a.index < b.index; });
  return models;
}

WorkspacePaths ResolveWorkspace(const std::string& workspace_path,
                                const std::string& input_path,
                                const std::string& image_path,
                                int model_index) {
  WorkspacePaths paths;
  if (!input_path.empty()) {
    paths.model_path = input_path;
    paths.layout = "explicit";
    if (!image_path.empty()) {
      paths.image_path = image_path;
    } else if (!workspace_path.empty()) {
      paths.image_path = (std::filesystem::path(workspace_path) / "images").string();
    } else {
      throw InputError("--input_path given without --image_path or --workspace_path: the "
                       "photos' folder is unknown");
    }
    return paths;
  }
  if (workspace_path.empty()) {
    throw InputError("give --workspace_path (a COLMAP project) or --input_path and --image_path");
  }
  const std::filesystem::path root(workspace_path);
  if (!std::filesystem::is_directory(root)) {
    throw InputError(workspace_path + ": workspace folder does not exist");
  }
  const std::vector<ModelCandidate> numbered = NumberedModels((root / "sparse").string());
  if (model_index >= 0 || numbered.size() > 1) {
    const ModelCandidate* chosen = nullptr;
    for (const ModelCandidate& model : numbered) {
      if (model_index >= 0 ? model.index == model_index
                           : chosen == nullptr || model.num_images > chosen->num_images) {
        chosen = &model;
      }
    }
    if (chosen == nullptr) {
      throw InputError(workspace_path + ": --model_index " + std::to_string(model_index) +
                       ": no model in sparse/" + std::to_string(model_index) + " (" +
                       std::to_string(numbered.size()) + " numbered models in sparse/)");
    }
    if (model_index < 0) {
      LOG(INFO) << numbered.size() << " models in " << (root / "sparse").string() << ": taking "
                << chosen->path << " (" << chosen->num_images
                << " images, the most; --model_index chooses another)";
    }
    paths.model_path = chosen->path;
    paths.image_path = image_path.empty() ? (root / "images").string() : image_path;
    paths.layout = "sparse/" + std::to_string(chosen->index);
    return paths;
  }
  const struct {
    const char* model;
    const char* images;
  } layouts[] = {{"sparse/0", "images"}, {"sparse", "images"}, {"dense/sparse", "dense/images"}};
  for (const auto& layout : layouts) {
    if (HoldsModel(root / layout.model)) {
      paths.model_path = (root / layout.model).string();
      paths.image_path = image_path.empty() ? (root / layout.images).string() : image_path;
      paths.layout = layout.model;
      return paths;
    }
  }
  throw InputError(workspace_path +
                   ": no COLMAP model found in sparse/0, sparse or dense/sparse (looked for "
                   "cameras.bin or cameras.txt); give --input_path");
}

void CheckPhotosFitInMemory(const Reconstruction& reconstruction, int max_image_size,
                            double physical_bytes) {
  if (physical_bytes <= 0.0) {
    const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGESIZE);
    physical_bytes = pages > 0 && page_size > 0 ? static_cast<double>(pages) * page_size : 0.0;
  }
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

LoadedProject LoadProject(const std::string& command,
                          const std::string& workspace_path,
                          const std::string& input_path,
                          const std::string& image_path,
                          const std::string& output_path,
                          const BoundsFlags& bounds_flags,
                          const ViewReaderOptions& view_options,
                          int min_images,
                          int model_index,
                          ColourCalibrationMode colour_calibration,
                          int hold_out_every) {
  LoadedProject project;
  const WorkspacePaths paths =
      ResolveWorkspace(workspace_path, input_path, image_path, model_index);
  project.model_path = paths.model_path;
  project.image_path = paths.image_path;
  project.output_path = output_path;
  if (project.output_path.empty()) {
    if (workspace_path.empty()) throw InputError("raycarve " + command + ": give --output_path");
    project.output_path = (std::filesystem::path(workspace_path) / "raycarve").string();
  }
  CheckOutputDoesNotOverwrite(project.output_path, paths.model_path, "input model");
  CheckOutputDoesNotOverwrite(project.output_path, paths.image_path, "photo folder");

  LOG(INFO) << "reading model " << paths.model_path << " (" << paths.layout << ")";
  project.reconstruction = ReadModel(paths.model_path);
  const size_t registered = project.reconstruction.images.size();
  if (registered == 0) throw InputError(paths.model_path + ": the model has no registered images");
  if (static_cast<int>(registered) < min_images) {
    throw InputError(paths.model_path + ": the model has " + std::to_string(registered) +
                     " registered images; raycarve " + command + " needs at least " +
                     std::to_string(min_images));
  }
  if (hold_out_every > 0) {
    project.held_out = HoldOutImages(hold_out_every, &project.reconstruction);
    LOG(INFO) << "holding out " << project.held_out.size() << " of " << registered
              << " images (every " << hold_out_every << "th in name order); "
              << project.reconstruction.points3D.size()
              << " sparse points keep two or more observations without them";
  }
  project.bounds = ResolveBounds(project.reconstruction, bounds_flags, paths.model_path);
  LOG(INFO) << project.bounds.Summary();
  CheckPhotosFitInMemory(project.reconstruction, view_options.max_image_size);
  LOG(INFO) << "loading and undistorting " << registered << " photos from " << paths.image_path;
  ViewReaderOptions reader_options = view_options;
  reader_options.volume = project.bounds.box;
  project.views = ReadCalibratedViews(project.reconstruction, paths.image_path, reader_options,
                                      &project.view_summary);
  LOG(INFO) << project.view_summary.Summary();
  if (static_cast<int>(project.views.size()) < min_images) {
    throw InputError(paths.image_path + ": only " + std::to_string(project.views.size()) +
                     " photos could be loaded; raycarve " + command + " needs at least " +
                     std::to_string(min_images));
  }
  if (colour_calibration != ColourCalibrationMode::kOff) {
    project.colour = EstimateColourCalibration(project.reconstruction, project.views);
    if (project.colour.points_used == 0) {
      if (colour_calibration == ColourCalibrationMode::kOn) {
        LOG(WARNING) << "colour calibration: no sparse point is seen by 3 or more photos; the "
                        "photos are used as they are";
      }
    } else if (colour_calibration == ColourCalibrationMode::kOn ||
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
  project.surface_points =
      SurfacePointsOf(project.reconstruction, project.views, project.bounds.box);
  return project;
}

void CheckVolumeSeen(const std::string& command,
                     const LoadedProject& project,
                     const std::vector<CalibratedView>& views,
                     int min_views,
                     const BoundsFlags& bounds_flags) {
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
    BoundsFlags from_points = bounds_flags;
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

std::vector<std::string> HoldOutImages(int every, Reconstruction* reconstruction) {
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
    track.erase(std::remove_if(track.begin(), track.end(),
                               [&](const TrackElement& e) { return held.count(e.image_id) > 0; }),
                track.end());
    std::set<image_t> distinct;
    for (const TrackElement& e : track) distinct.insert(e.image_id);
    if (distinct.size() < 2) {
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
