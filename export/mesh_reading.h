// Internal to export/: what the glTF reader (export/mesh_file_reader.cc) and the OBJ reader
// (export/obj_reader.cc) share: the limits on what they read, and the mesh as it is gathered
// with its textures, joined into one atlas.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "export/surface_mesh.h"

namespace raycarve {
namespace exporter {
namespace mesh_reading {

// More vertices or triangles than this in one file is refused (the mesh would not fit in memory
// on the machines raycarve runs on, and a damaged count must not drive an allocation).
constexpr size_t kMaxElements = size_t{1} << 28;

// Why a texture of `width` x `height` is not read ("" when it is): not a size, or more texels
// than 8192 x 8192 (checked without overflow).
std::string TextureSizeRefusal(int64_t width, int64_t height);

// A path's extension in lower case (".glb", ".obj"; "" without one).
std::string LowerCaseExtension(const std::string& path);

// The mesh as it is gathered: per triangle, which texture (-1: none) and its corners' coordinates.
struct Gathered {
  TriangleMesh mesh;
  std::vector<int> triangle_texture;
  std::vector<Eigen::Vector2f> corner_uvs;
  bool any_normals = true;
  bool any_colours = false;
};

// The textures side by side in one atlas (a white column last, for untextured triangles), each
// triangle's coordinates wrapped into 0-1 (as REPEAT does, by the triangle's lowest whole
// number) and moved into its texture's place.
void BuildAtlas(const std::map<int, cv::Mat>& images, Gathered* gathered);

}  // namespace mesh_reading
}  // namespace exporter
}  // namespace raycarve
