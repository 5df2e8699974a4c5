#pragma once

#include <string>

namespace raycarve {

// Where a COLMAP project keeps its model and photos.
struct WorkspacePaths {
  std::string model_path;  // folder with cameras/images/points3D
  std::string image_path;  // folder the model's image names are relative to
  std::string layout;      // how it was found: "explicit", "sparse/0", "sparse", "dense/sparse"
};

// Resolves a project in COLMAP's layouts. With `input_path` (and `image_path`) given, they are
// used as they are. Otherwise, in `workspace_path`, the first of sparse/0, sparse,
// dense/sparse that holds a model (a cameras.bin or cameras.txt), with images/ beside it
// (dense/images for a dense/ workspace from `colmap image_undistorter`); an explicit
// `image_path` overrides the photos' folder. Throws InputError saying what was looked for.
WorkspacePaths ResolveWorkspace(const std::string& workspace_path,
                                const std::string& input_path,
                                const std::string& image_path);

}  // namespace raycarve
