#include "export/mesh_formats.h"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include <glog/logging.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <tiny_gltf.h>

#include "calib/atomic_file.h"
#include "calib/input_error.h"

namespace raycarve {
namespace exporter {

namespace {

// An sRGB byte as a linear value in 0..65535 (the sRGB transfer function inverted): glTF's vertex
// colours are linear, and 16 bits keep the dark shades that 8 linear bits would merge.
uint16_t LinearFromSrgb(uint8_t value) {
  const double c = value / 255.0;
  const double linear = c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
  return static_cast<uint16_t>(std::lround(65535.0 * linear));
}

// The mesh's corners as vertices of their own where one vertex has several texture coordinates:
// per output vertex, its mesh vertex and its coordinates; per triangle corner, its output vertex.
struct SplitVertices {
  std::vector<int> vertex;
  std::vector<Eigen::Vector2f> uv;
  std::vector<int> corner;
};

SplitVertices SplitByTextureCoordinates(const TriangleMesh& mesh) {
  SplitVertices split;
  struct Key {
    int vertex;
    float u, v;
    bool operator==(const Key& o) const { return vertex == o.vertex && u == o.u && v == o.v; }
  };
  struct KeyHash {
    size_t operator()(const Key& k) const {
      uint32_t u, v;
      std::memcpy(&u, &k.u, 4);
      std::memcpy(&v, &k.v, 4);
      return std::hash<uint64_t>()((static_cast<uint64_t>(k.vertex) << 32) ^ (u * 2654435761u) ^ v);
    }
  };
  std::unordered_map<Key, int, KeyHash> index;
  index.reserve(mesh.corner_uvs.size());
  split.corner.reserve(mesh.corner_uvs.size());
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2f& uv = mesh.corner_uvs[3 * t + k];
      const Key key{mesh.triangles[t][k], uv.x(), uv.y()};
      const auto [found, added] = index.emplace(key, static_cast<int>(split.vertex.size()));
      if (added) {
        split.vertex.push_back(key.vertex);
        split.uv.push_back(uv);
      }
      split.corner.push_back(found->second);
    }
  }
  return split;
}

std::vector<uint8_t> EncodePng(const cv::Mat& rgb, const std::string& path) {
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> bytes;
  if (!cv::imencode(".png", bgr, bytes)) throw InputError(path + ": cannot encode the texture");
  return bytes;
}

// Writes `model` as glTF binary, through a temporary name and a rename.
void SaveGlb(tinygltf::Model* model, const std::string& path) {
  const std::string temporary = TemporaryPathFor(path);
  tinygltf::TinyGLTF writer;
  errno = 0;
  if (!writer.WriteGltfSceneToFile(model, temporary, /*embedImages=*/false, /*embedBuffers=*/true,
                                   /*prettyPrint=*/false, /*writeBinary=*/true)) {
    ThrowWriteFailure(temporary, "the glTF mesh", errno);
  }
  RenameIntoPlace(temporary, path);
}

void WriteBytes(const std::string& path, const std::string& what, const char* data, size_t size) {
  const std::string temporary = TemporaryPathFor(path);
  errno = 0;
  std::ofstream file(temporary, std::ios::binary);
  file.write(data, static_cast<std::streamsize>(size));
  file.close();
  if (!file) ThrowWriteFailure(temporary, what, errno);
  RenameIntoPlace(temporary, path);
}

// WriteTexturedObj with the corners split and the atlas encoded already.
void WriteObjFiles(const TriangleMesh& mesh, const std::string& obj_path, const SplitVertices& split,
                   const std::vector<uint8_t>& png) {
  const std::filesystem::path obj(obj_path);
  const std::string stem = obj.stem().string();
  const std::filesystem::path folder = obj.parent_path();
  const std::string mtl_name = stem + ".mtl", png_name = stem + "_texture.png";
  WriteBytes((folder / png_name).string(), "the texture", reinterpret_cast<const char*>(png.data()),
             png.size());
  const std::string mtl = "# raycarve: the texture atlas from the photos\nnewmtl raycarve\n"
                          "Ka 1 1 1\nKd 1 1 1\nKs 0 0 0\nd 1\nillum 1\nmap_Kd " + png_name + "\n";
  WriteBytes((folder / mtl_name).string(), "the material", mtl.data(), mtl.size());
  std::ostringstream text;
  text.imbue(std::locale::classic());
  text.precision(9);
  text << "# raycarve: textured mesh, " << mesh.vertices.size() << " vertices, "
       << mesh.triangles.size() << " triangles\nmtllib " << mtl_name << "\n";
  for (const Eigen::Vector3f& v : mesh.vertices) text << "v " << v.x() << ' ' << v.y() << ' ' << v.z() << '\n';
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  if (normals) {
    for (const Eigen::Vector3f& n : mesh.normals) text << "vn " << n.x() << ' ' << n.y() << ' ' << n.z() << '\n';
  }
  // OBJ's v runs up from the image's bottom.
  for (const Eigen::Vector2f& uv : split.uv) text << "vt " << uv.x() << ' ' << 1.0f - uv.y() << '\n';
  text << "usemtl raycarve\n";
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    text << 'f';
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.triangles[t][k] + 1, vt = split.corner[3 * t + k] + 1;
      text << ' ' << v << '/' << vt;
      if (normals) text << '/' << v;
    }
    text << '\n';
  }
  const std::string bytes = text.str();
  WriteBytes(obj_path, "the mesh", bytes.data(), bytes.size());
}

// A GLB's one binary buffer and the views and accessors into it, appended in order.
class GlbBuffer {
 public:
  explicit GlbBuffer(tinygltf::Model* model) : model_(model) {}

  // `bytes` of `data` as a buffer view (4-byte aligned); returns its index.
  int AddView(const void* data, size_t bytes, int target) {
    const size_t offset = buffer_.data.size();
    buffer_.data.resize(offset + bytes);
    if (bytes > 0) std::memcpy(buffer_.data.data() + offset, data, bytes);
    while (buffer_.data.size() % 4 != 0) buffer_.data.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = offset;
    view.byteLength = bytes;
    view.target = target;
    model_->bufferViews.push_back(view);
    return static_cast<int>(model_->bufferViews.size() - 1);
  }

  // `values` as a view and an accessor of `count` elements; returns the accessor's index.
  template <typename T>
  int AddAccessor(const std::vector<T>& values, int target, int component, int type,
                  size_t count, bool normalized) {
    tinygltf::Accessor accessor;
    accessor.bufferView = AddView(values.data(), values.size() * sizeof(T), target);
    accessor.componentType = component;
    accessor.type = type;
    accessor.count = count;
    accessor.normalized = normalized;
    model_->accessors.push_back(accessor);
    return static_cast<int>(model_->accessors.size() - 1);
  }

  void Finish() { model_->buffers.push_back(std::move(buffer_)); }

 private:
  tinygltf::Model* model_;
  tinygltf::Buffer buffer_;
};

// The mesh's attributes and indices, one vertex per split corner: positions, normals where the
// mesh has them, linear colours (untextured) or texture coordinates (textured).
tinygltf::Primitive GlbPrimitive(const TriangleMesh& mesh, const SplitVertices& split,
                                 bool textured, tinygltf::Model* model, GlbBuffer* buffer) {
  const size_t n = split.vertex.size();
  const bool normals = mesh.normals.size() == mesh.vertices.size();
  const bool colours = !textured && mesh.colours.size() == mesh.vertices.size();
  std::vector<float> positions, normal_values, uvs;
  std::vector<uint16_t> colour_values;  // linear, as glTF's COLOR_0 is (the PLY's are sRGB)
  Eigen::Vector3f low = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
  Eigen::Vector3f high = -low;
  for (const int v : split.vertex) {
    const Eigen::Vector3f& p = mesh.vertices[v];
    positions.insert(positions.end(), {p.x(), p.y(), p.z()});
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
    if (normals) normal_values.insert(normal_values.end(), {mesh.normals[v].x(), mesh.normals[v].y(), mesh.normals[v].z()});
    if (colours) {
      colour_values.insert(colour_values.end(), {LinearFromSrgb(mesh.colours[v][0]),
                                                 LinearFromSrgb(mesh.colours[v][1]),
                                                 LinearFromSrgb(mesh.colours[v][2]), 65535});
    }
  }
  for (const Eigen::Vector2f& uv : split.uv) uvs.insert(uvs.end(), {uv.x(), uv.y()});
  const std::vector<uint32_t> indices(split.corner.begin(), split.corner.end());
  constexpr int kArray = TINYGLTF_TARGET_ARRAY_BUFFER;
  tinygltf::Primitive primitive;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  const int position_accessor = buffer->AddAccessor(
      positions, kArray, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n, false);
  if (n > 0) {
    model->accessors[position_accessor].minValues = {low.x(), low.y(), low.z()};
    model->accessors[position_accessor].maxValues = {high.x(), high.y(), high.z()};
  }
  primitive.attributes["POSITION"] = position_accessor;
  if (normals) {
    primitive.attributes["NORMAL"] = buffer->AddAccessor(
        normal_values, kArray, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, n, false);
  }
  if (colours) {
    primitive.attributes["COLOR_0"] = buffer->AddAccessor(
        colour_values, kArray, TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, TINYGLTF_TYPE_VEC4, n, true);
  }
  if (textured) {
    primitive.attributes["TEXCOORD_0"] = buffer->AddAccessor(
        uvs, kArray, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, n, false);
  }
  primitive.indices = buffer->AddAccessor(indices, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER,
                                          TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                          TINYGLTF_TYPE_SCALAR, indices.size(), false);
  primitive.material = 0;
  return primitive;
}

// The one material: matte, with the atlas (`png`, when not null) as its base colour.
void AddGlbMaterial(const std::vector<uint8_t>* png, tinygltf::Model* model, GlbBuffer* buffer) {
  tinygltf::Material material;
  material.name = "raycarve";
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 1.0;
  if (png != nullptr) {
    tinygltf::Image image;
    image.mimeType = "image/png";
    image.bufferView = buffer->AddView(png->data(), png->size(), 0);
    model->images.push_back(image);
    tinygltf::Sampler sampler;
    sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
    sampler.wrapS = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    sampler.wrapT = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    model->samplers.push_back(sampler);
    tinygltf::Texture texture;
    texture.source = 0;
    texture.sampler = 0;
    model->textures.push_back(texture);
    material.pbrMetallicRoughness.baseColorTexture.index = 0;
  }
  model->materials.push_back(material);
}

// WriteGlb with the corners split and, textured (`png` not null), the atlas encoded already.
void WriteGlbFile(const TriangleMesh& mesh, const std::string& path, const SplitVertices& split,
                  const std::vector<uint8_t>* png) {
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "raycarve";
  if (mesh.triangles.empty()) {
    // glTF has no empty accessors: an empty carve gives a scene with nothing in it.
    model.scenes.emplace_back();
    model.defaultScene = 0;
    SaveGlb(&model, path);
    return;
  }
  GlbBuffer buffer(&model);
  tinygltf::Mesh gltf_mesh;
  gltf_mesh.name = "raycarve";
  gltf_mesh.primitives.push_back(GlbPrimitive(mesh, split, png != nullptr, &model, &buffer));
  AddGlbMaterial(png, &model, &buffer);
  model.meshes.push_back(gltf_mesh);
  tinygltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  buffer.Finish();
  SaveGlb(&model, path);
}

// The untextured mesh's corners: each vertex once.
SplitVertices Unsplit(const TriangleMesh& mesh) {
  SplitVertices split;
  split.vertex.resize(mesh.vertices.size());
  std::iota(split.vertex.begin(), split.vertex.end(), 0);
  for (const Eigen::Vector3i& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) split.corner.push_back(t[k]);
  }
  return split;
}

}  // namespace

void WriteTexturedObj(const TriangleMesh& mesh, const std::string& obj_path) {
  CHECK(mesh.textured());
  WriteObjFiles(mesh, obj_path, SplitByTextureCoordinates(mesh), EncodePng(mesh.texture, obj_path));
}

void WriteGlb(const TriangleMesh& mesh, const std::string& path) {
  if (!mesh.textured()) {
    WriteGlbFile(mesh, path, Unsplit(mesh), nullptr);
    return;
  }
  const std::vector<uint8_t> png = EncodePng(mesh.texture, path);
  WriteGlbFile(mesh, path, SplitByTextureCoordinates(mesh), &png);
}

void WriteMeshFormats(const TriangleMesh& mesh, const std::string& folder) {
  const std::filesystem::path out(folder);
  if (!mesh.textured()) {
    WriteGlb(mesh, (out / "mesh.glb").string());
    return;
  }
  // The corners split and the atlas encoded once for both files.
  const SplitVertices split = SplitByTextureCoordinates(mesh);
  const std::vector<uint8_t> png = EncodePng(mesh.texture, (out / "mesh_texture.png").string());
  WriteGlbFile(mesh, (out / "mesh.glb").string(), split, &png);
  WriteObjFiles(mesh, (out / "mesh.obj").string(), split, png);
}

}  // namespace exporter
}  // namespace raycarve
