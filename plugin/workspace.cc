#include "plugin/workspace.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include <glog/logging.h>

#include "calib/colour_calibration.h"
#include "calib/input_error.h"
#include "calib/model_reader.h"
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

LoadedProject LoadProject(const std::string& command,
                          const std::string& workspace_path,
                          const std::string& input_path,
                          const std::string& image_path,
                          const std::string& output_path,
                          const BoundsFlags& bounds_flags,
                          const ViewReaderOptions& view_options,
                          int min_images,
                          int model_index,
                          bool colour_calibration) {
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
  project.bounds = ResolveBounds(project.reconstruction, bounds_flags, paths.model_path);
  LOG(INFO) << project.bounds.Summary();
  LOG(INFO) << "loading and undistorting " << registered << " photos from " << paths.image_path;
  project.views = ReadCalibratedViews(project.reconstruction, paths.image_path, view_options,
                                      &project.view_summary);
  LOG(INFO) << project.view_summary.Summary();
  if (static_cast<int>(project.views.size()) < min_images) {
    throw InputError(paths.image_path + ": only " + std::to_string(project.views.size()) +
                     " photos could be loaded; raycarve " + command + " needs at least " +
                     std::to_string(min_images));
  }
  if (colour_calibration) {
    project.colour = EstimateColourCalibration(project.reconstruction, project.views);
    if (project.colour.points_used == 0) {
      LOG(WARNING) << "colour calibration: no sparse point is seen by 3 or more photos; the "
                      "photos are used as they are";
    } else {
      ApplyColourCalibration(project.colour, &project.views);
      LOG(INFO) << project.colour.Summary();
    }
  }
  return project;
}

}  // namespace raycarve
