#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace raycarve {

// Where a COLMAP project keeps its model and photos.
struct WorkspacePaths {
  std::string model_path;  // folder with cameras/images/points3D
  std::string image_path;  // folder the model's image names are relative to
  std::string layout;      // how it was found: "explicit", "sparse/0", "sparse", "dense/sparse"
};

// A model folder among COLMAP mapper's numbered outputs (sparse/0, sparse/1, ...).
struct ModelCandidate {
  int index = 0;
  std::string path;
  int64_t num_images = 0;  // registered images, from the images file's header or lines
};
// The numbered model folders in `sparse_path`, in index order (empty when there are none).
std::vector<ModelCandidate> NumberedModels(const std::string& sparse_path);

// Resolves a project in COLMAP's layouts. With `input_path` (and `image_path`) given, they are
// used as they are. Otherwise, in `workspace_path`, the first of sparse/0, sparse,
// dense/sparse that holds a model (a cameras.bin or cameras.txt), with images/ beside it
// (dense/images for a dense/ workspace from `colmap image_undistorter`); an explicit
// `image_path` overrides the photos' folder. When the mapper left several numbered models in
// sparse/, the one with the most registered images is taken, or sparse/<model_index> when
// model_index >= 0. Throws InputError saying what was looked for.
WorkspacePaths ResolveWorkspace(const std::string& workspace_path,
                                const std::string& input_path,
                                const std::string& image_path,
                                int model_index = -1);

}  // namespace raycarve
