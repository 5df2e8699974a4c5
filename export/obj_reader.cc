// ReadObj of export/mesh_file_reader.h: an OBJ mesh (tinyobjloader), its materials' diffuse maps
// joined into one atlas.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <tiny_obj_loader.h>

#include "calib/image_reader.h"
#include "calib/input_error.h"
#include "export/mesh_file_reader.h"
#include "export/mesh_reading.h"

namespace raycarve {
namespace exporter {

using namespace mesh_reading;

namespace {

// The OBJ's vertices and their colours (`coloured`: any not white).
void AddObjVertices(const tinyobj::attrib_t& attrib, const std::string& path, TriangleMesh* mesh,
                    bool* coloured) {
  const size_t n = attrib.vertices.size() / 3;
  if (n > kMaxElements) throw InputError(path + ": more vertices than raycarve reads");
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3f v(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
    if (!v.allFinite()) throw InputError(path + ": vertex " + std::to_string(i + 1) + " is not a finite point");
    mesh->vertices.push_back(v);
    Eigen::Matrix<uint8_t, 3, 1> rgb = Eigen::Matrix<uint8_t, 3, 1>::Constant(255);
    if (attrib.colors.size() == attrib.vertices.size()) {
      for (int c = 0; c < 3; ++c) {
        const double value = attrib.colors[3 * i + c];
        rgb[c] = static_cast<uint8_t>(std::lround(255.0 * (value > 0.0 ? std::min(value, 1.0) : 0.0)));
        *coloured = *coloured || value != 1.0;
      }
    }
    mesh->colours.push_back(rgb);
  }
}

// The materials' diffuse maps, read once each, into `images`; returns each material's image
// (-1: none).
std::vector<int> ReadObjTextures(const std::vector<tinyobj::material_t>& materials,
                                 const std::string& path, std::map<int, cv::Mat>* images) {
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  std::map<std::string, int> image_of_file;
  std::vector<int> image_of_material(materials.size(), -1);
  for (size_t m = 0; m < materials.size(); ++m) {
    if (materials[m].diffuse_texname.empty()) continue;
    const std::string file = (folder / materials[m].diffuse_texname).string();
    const auto known = image_of_file.find(file);
    if (known != image_of_file.end()) {
      image_of_material[m] = known->second;
      continue;
    }
    const cv::Size size = ReadImageSize(file);
    const std::string refusal = TextureSizeRefusal(size.width, size.height);
    if (!refusal.empty()) throw InputError(file + ": the texture of " + path + " is " + refusal);
    const cv::Mat bgr = ReadImage(file, cv::IMREAD_COLOR);
    if (bgr.empty()) throw InputError(file + ": the texture of " + path + " cannot be decoded");
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    const int index = static_cast<int>(images->size());
    (*images)[index] = rgb;
    image_of_file[file] = index;
    image_of_material[m] = index;
  }
  return image_of_material;
}

// The shape's triangles (already triangulated), each with its material's image and corners'
// texture coordinates where it has both.
void AddObjFaces(const tinyobj::attrib_t& attrib, const tinyobj::shape_t& shape,
                 const std::vector<int>& image_of_material, const std::string& path,
                 Gathered* gathered) {
  TriangleMesh& mesh = gathered->mesh;
  const size_t n = attrib.vertices.size() / 3;
  const std::vector<tinyobj::index_t>& indices = shape.mesh.indices;
  for (size_t f = 0; f + 2 < indices.size(); f += 3) {
    if (mesh.triangles.size() >= kMaxElements) throw InputError(path + ": more triangles than raycarve reads");
    Eigen::Vector3i triangle;
    bool uv_known = true;
    for (int k = 0; k < 3; ++k) {
      const int v = indices[f + k].vertex_index;
      if (v < 0 || static_cast<size_t>(v) >= n) {
        throw InputError(path + ": face " + std::to_string(mesh.triangles.size() + 1) +
                         ": vertex " + std::to_string(v + 1) + " is past the file's " +
                         std::to_string(n) + " vertices");
      }
      triangle[k] = v;
      const int t = indices[f + k].texcoord_index;
      uv_known = uv_known && t >= 0 && static_cast<size_t>(2 * t + 1) < attrib.texcoords.size();
    }
    const size_t face = f / 3;
    const int material = face < shape.mesh.material_ids.size() ? shape.mesh.material_ids[face] : -1;
    const int image = material >= 0 && static_cast<size_t>(material) < image_of_material.size() && uv_known
                          ? image_of_material[material] : -1;
    mesh.triangles.push_back(triangle);
    gathered->triangle_texture.push_back(image);
    for (int k = 0; k < 3; ++k) {
      if (image < 0) {
        gathered->corner_uvs.push_back(Eigen::Vector2f::Zero());
        continue;
      }
      const int t = indices[f + k].texcoord_index;
      const Eigen::Vector2f uv(attrib.texcoords[2 * t], 1.0f - attrib.texcoords[2 * t + 1]);  // v down
      if (!(std::abs(uv.x()) < 1e6f && std::abs(uv.y()) < 1e6f)) {
        throw InputError(path + ": texture coordinate " + std::to_string(t + 1) + " is not a finite texture position");
      }
      gathered->corner_uvs.push_back(uv);
    }
  }
}

}  // namespace

TriangleMesh ReadObj(const std::string& path) {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = true;
  config.mtl_search_path = std::filesystem::path(path).parent_path().string();
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    std::string error = reader.Error();
    std::replace(error.begin(), error.end(), '\n', ' ');
    throw InputError(path + ": not a readable OBJ file: " + (error.empty() ? "unknown error" : error));
  }
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  Gathered gathered;
  TriangleMesh& mesh = gathered.mesh;
  bool coloured = false;
  AddObjVertices(attrib, path, &mesh, &coloured);
  std::map<int, cv::Mat> images;
  const std::vector<int> image_of_material = ReadObjTextures(reader.GetMaterials(), path, &images);
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    AddObjFaces(attrib, shape, image_of_material, path, &gathered);
  }
  if (mesh.triangles.empty()) throw InputError(path + ": no faces");
  if (!coloured) mesh.colours.clear();
  mesh.normals.assign(mesh.vertices.size(), Eigen::Vector3f::Zero());
  ComputeVertexNormals(&mesh);
  BuildAtlas(images, &gathered);
  return std::move(gathered.mesh);
}

bool IsObjPath(const std::string& path) { return LowerCaseExtension(path) == ".obj"; }

}  // namespace exporter
}  // namespace raycarve
