#include "pipeline/workspace.h"

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

#include "calib/input_error.h"
#include "calib/model_reader.h"

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

}  // namespace raycarve
