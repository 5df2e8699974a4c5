#include "plugin/workspace.h"

#include <filesystem>

#include "calib/input_error.h"

namespace raycarve {
namespace {

bool HoldsModel(const std::filesystem::path& folder) {
  return std::filesystem::exists(folder / "cameras.bin") ||
         std::filesystem::exists(folder / "cameras.txt");
}

}  // namespace

WorkspacePaths ResolveWorkspace(const std::string& workspace_path,
                                const std::string& input_path,
                                const std::string& image_path) {
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
