#include "export/mesh_file_reader.h"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <tiny_gltf.h>

#include "calib/image_reader.h"
#include "calib/input_error.h"
#include "export/mesh_reading.h"

namespace raycarve {
namespace exporter {
namespace mesh_reading {

// The most texels one texture may have: 8192 x 8192 (192 MiB decoded). A header that announces
// more is refused before decoding (a small PNG of zeros can announce gigabytes).
constexpr int64_t kMaxTexturePixels = int64_t{1} << 26;

std::string TextureSizeRefusal(int64_t width, int64_t height) {
  if (width > 0 && height > 0 && width <= kMaxTexturePixels / height) return "";
  return std::to_string(width) + " x " + std::to_string(height) + " pixels (at most " +
         std::to_string(kMaxTexturePixels) + " are read)";
}

std::string LowerCaseExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

void BuildAtlas(const std::map<int, cv::Mat>& images, Gathered* gathered) {
  std::map<int, int> column;  // image -> x offset
  int width = 1, height = 1;
  for (const int image : gathered->triangle_texture) {
    if (image < 0 || column.count(image)) continue;
    column[image] = width;
    width += images.at(image).cols;
    height = std::max(height, images.at(image).rows);
  }
  if (column.empty()) return;
  cv::Mat atlas(height, width, CV_8UC3, cv::Scalar::all(255));
  for (const auto& [image, x] : column) {
    images.at(image).copyTo(atlas(cv::Rect(x, 0, images.at(image).cols, images.at(image).rows)));
  }
  std::vector<Eigen::Vector2f>& uvs = gathered->corner_uvs;
  for (size_t t = 0; t < gathered->triangle_texture.size(); ++t) {
    const int image = gathered->triangle_texture[t];
    if (image < 0) {
      for (int k = 0; k < 3; ++k) uvs[3 * t + k] = Eigen::Vector2f(0.5f / width, 0.5f / height);
      continue;
    }
    const cv::Mat& texture = images.at(image);
    Eigen::Vector2f low = uvs[3 * t].cwiseMin(uvs[3 * t + 1]).cwiseMin(uvs[3 * t + 2]);
    const Eigen::Vector2f shift(std::floor(low.x()), std::floor(low.y()));
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2f local = (uvs[3 * t + k] - shift).cwiseMax(0.0f).cwiseMin(1.0f);
      uvs[3 * t + k] = Eigen::Vector2f((column.at(image) + local.x() * texture.cols) / width,
                                       local.y() * texture.rows / height);
    }
  }
  gathered->mesh.texture = atlas;
  gathered->mesh.corner_uvs = uvs;
}

}  // namespace mesh_reading

namespace {

using namespace mesh_reading;

// The images, decoded by OpenCV as tinygltf hands them over (not by tinygltf's own decoder), RGB,
// by image index. `model` is the model being loaded: its buffer views are read before its images.
struct ImageLoad {
  const tinygltf::Model* model = nullptr;
  std::map<int, cv::Mat> images;
};


// The width and height a PNG's IHDR or a JPEG's frame header announces; {0, 0} when not found.
std::pair<int64_t, int64_t> AnnouncedSize(const unsigned char* bytes, int size, bool png) {
  const auto big_endian = [bytes](int at, int count) {
    int64_t value = 0;
    for (int k = 0; k < count; ++k) value = (value << 8) | bytes[at + k];
    return value;
  };
  if (png) {
    if (size < 24) return {0, 0};
    return {big_endian(16, 4), big_endian(20, 4)};
  }
  // JPEG: segments after SOI; a start of frame (0xC0-0xCF but 0xC4, 0xC8, 0xCC) holds the size.
  int at = 2;
  while (at + 9 < size) {
    if (bytes[at] != 0xFF) return {0, 0};
    const int marker = bytes[at + 1];
    if (marker == 0xFF) {
      ++at;
      continue;
    }
    const int length = static_cast<int>(big_endian(at + 2, 2));
    if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
      return {big_endian(at + 7, 2), big_endian(at + 5, 2)};
    }
    if (length < 2) return {0, 0};
    at += 2 + length;
  }
  return {0, 0};
}

bool DecodeImage(tinygltf::Image* image, const int index, std::string* error, std::string*, int,
                 int, const unsigned char* bytes, int size, void* user_data) {
  auto* load = static_cast<ImageLoad*>(user_data);
  const std::string name = "image " + std::to_string(index) + " (" + image->name + image->uri + ")";
  // tinygltf hands over an image's buffer view as it stands: one reaching past its buffer is
  // refused here, before anything reads it.
  if (image->bufferView >= 0) {
    const tinygltf::Model& model = *load->model;
    const bool view_known = image->bufferView < static_cast<int>(model.bufferViews.size());
    const tinygltf::BufferView* view = view_known ? &model.bufferViews[image->bufferView] : nullptr;
    if (view == nullptr || view->buffer < 0 || view->buffer >= static_cast<int>(model.buffers.size()) ||
        view->byteOffset > model.buffers[view->buffer].data.size() ||
        view->byteLength > model.buffers[view->buffer].data.size() - view->byteOffset) {
      *error = name + ": its buffer view reaches past its buffer";
      return false;
    }
  }
  // glTF's images are PNG or JPEG: only those signatures reach OpenCV's decoders (which would
  // otherwise try every format they know on whatever bytes a damaged file holds).
  static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  static const unsigned char kJpeg[3] = {0xFF, 0xD8, 0xFF};
  const bool png = size >= 8 && std::memcmp(bytes, kPng, 8) == 0;
  const bool jpeg = size >= 3 && std::memcmp(bytes, kJpeg, 3) == 0;
  if (png || jpeg) {
    const auto [width, height] = AnnouncedSize(bytes, size, png);
    const std::string refusal = TextureSizeRefusal(width, height);
    if (!refusal.empty()) {
      *error = name + ": its header announces " + refusal;
      return false;
    }
  }
  cv::Mat encoded(1, std::max(size, 0), CV_8UC1, const_cast<unsigned char*>(bytes));
  cv::Mat bgr;
  try {
    if (png || jpeg) bgr = cv::imdecode(encoded, cv::IMREAD_COLOR);
  } catch (const cv::Exception&) {
    bgr = cv::Mat();
  }
  if (bgr.empty()) {
    *error = name + " does not decode as PNG or JPEG";
    return false;
  }
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  load->images[index] = rgb;
  return true;
}

// One accessor's elements as doubles (normalized integers scaled to 0-1), checked against its
// buffer; `components` values per element.
std::vector<double> ReadAccessor(const tinygltf::Model& model, int index, int components,
                                 const std::string& what, const std::string& path) {
  if (index < 0 || index >= static_cast<int>(model.accessors.size())) {
    throw InputError(path + ": " + what + ": accessor " + std::to_string(index) + " does not exist");
  }
  const tinygltf::Accessor& accessor = model.accessors[index];
  const std::string where = path + ": " + what + " (accessor " + std::to_string(index) + ")";
  if (tinygltf::GetNumComponentsInType(accessor.type) != components) {
    throw InputError(where + ": field 'type' has " +
                     std::to_string(tinygltf::GetNumComponentsInType(accessor.type)) +
                     " components, " + std::to_string(components) + " expected");
  }
  const int component_size = tinygltf::GetComponentSizeInBytes(accessor.componentType);
  if (component_size <= 0) throw InputError(where + ": field 'componentType' is not a glTF type");
  if (accessor.count > kMaxElements) throw InputError(where + ": field 'count' is too large");
  if (accessor.bufferView < 0 || accessor.bufferView >= static_cast<int>(model.bufferViews.size())) {
    throw InputError(where + ": field 'bufferView' does not exist (sparse accessors are not read)");
  }
  const tinygltf::BufferView& view = model.bufferViews[accessor.bufferView];
  if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size())) {
    throw InputError(where + ": its buffer view's field 'buffer' does not exist");
  }
  const std::vector<unsigned char>& buffer = model.buffers[view.buffer].data;
  const size_t element = static_cast<size_t>(component_size) * components;
  const size_t stride = view.byteStride > 0 ? view.byteStride : element;
  // The last element must end within the view, and the view within its buffer (checked so that
  // no sum overflows): the count is bounded by the bytes read, before anything is allocated.
  if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset ||
      (accessor.count > 0 &&
       (stride < element || accessor.byteOffset > view.byteLength ||
        element > view.byteLength - accessor.byteOffset ||
        accessor.count - 1 > (view.byteLength - accessor.byteOffset - element) / stride))) {
    throw InputError(where + ": fields 'count'/'byteOffset'/'byteStride' reach past its buffer view");
  }
  const size_t start = view.byteOffset + accessor.byteOffset;
  std::vector<double> values(accessor.count * components, 0.0);
  for (size_t i = 0; i < accessor.count; ++i) {
    const unsigned char* at = buffer.data() + start + i * stride;
    for (int c = 0; c < components; ++c) {
      const unsigned char* value = at + c * component_size;
      double v = 0.0;
      switch (accessor.componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, value, 4); v = f; break; }
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: { std::memcpy(&v, value, 8); break; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = *value; if (accessor.normalized) v /= 255.0; break;
        case TINYGLTF_COMPONENT_TYPE_BYTE: v = static_cast<int8_t>(*value); if (accessor.normalized) v = std::max(v / 127.0, -1.0); break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t s; std::memcpy(&s, value, 2); v = s; if (accessor.normalized) v /= 65535.0; break; }
        case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t s; std::memcpy(&s, value, 2); v = s; if (accessor.normalized) v = std::max(v / 32767.0, -1.0); break; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: { uint32_t u; std::memcpy(&u, value, 4); v = u; break; }
        case TINYGLTF_COMPONENT_TYPE_INT: { int32_t s; std::memcpy(&s, value, 4); v = s; break; }
        default: throw InputError(where + ": field 'componentType' is not a glTF type");
      }
      values[i * components + c] = v;
    }
  }
  return values;
}

Eigen::Matrix4d NodeTransform(const tinygltf::Node& node) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  if (node.matrix.size() == 16) {
    for (int k = 0; k < 16; ++k) m(k % 4, k / 4) = node.matrix[k];  // column-major
    return m;
  }
  Eigen::Affine3d t = Eigen::Affine3d::Identity();
  if (node.translation.size() == 3) {
    t.translate(Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]));
  }
  if (node.rotation.size() == 4) {
    t.rotate(Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]).normalized());
  }
  if (node.scale.size() == 3) t.scale(Eigen::Vector3d(node.scale[0], node.scale[1], node.scale[2]));
  return t.matrix();
}

uint8_t SrgbByteFromLinear(double linear) {
  if (!(linear > 0.0)) return 0;  // NaN too
  const double l = std::min(linear, 1.0);
  const double s = l <= 0.0031308 ? 12.92 * l : 1.055 * std::pow(l, 1.0 / 2.4) - 0.055;
  return static_cast<uint8_t>(std::lround(255.0 * std::clamp(s, 0.0, 1.0)));
}

// The primitive's `n` vertices (as `xyz`) moved by `transform`, and their normals (turned by its
// inverse transpose) where it has them.
void AddVertices(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                 const std::vector<double>& xyz, const Eigen::Matrix4d& transform,
                 const std::string& path, Gathered* out) {
  const size_t n = xyz.size() / 3;
  TriangleMesh& mesh = out->mesh;
  const Eigen::Matrix3d normal_transform = transform.topLeftCorner<3, 3>().inverse().transpose();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector4d p = transform * Eigen::Vector4d(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2], 1.0);
    const Eigen::Vector3f v = p.head<3>().cast<float>();
    if (!v.allFinite()) {
      throw InputError(path + ": POSITION: vertex " + std::to_string(i) +
                       " is not a finite point (after its node's transform)");
    }
    mesh.vertices.push_back(v);
  }
  const auto normal = primitive.attributes.find("NORMAL");
  if (normal == primitive.attributes.end()) {
    out->any_normals = false;
    mesh.normals.resize(mesh.vertices.size(), Eigen::Vector3f::Zero());
    return;
  }
  const std::vector<double> v = ReadAccessor(model, normal->second, 3, "NORMAL", path);
  if (v.size() != xyz.size()) throw InputError(path + ": NORMAL: its count differs from POSITION's");
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d d = normal_transform * Eigen::Vector3d(v[3 * i], v[3 * i + 1], v[3 * i + 2]);
    mesh.normals.push_back(d.norm() > 0.0 ? Eigen::Vector3f(d.normalized().cast<float>()) : Eigen::Vector3f::Zero());
  }
}

// The primitive's `n` vertex colours (linear in glTF, sRGB bytes in the mesh); white without.
void AddColours(const tinygltf::Model& model, const tinygltf::Primitive& primitive, size_t base,
                size_t n, const std::string& path, Gathered* out) {
  TriangleMesh& mesh = out->mesh;
  const auto colour = primitive.attributes.find("COLOR_0");
  mesh.colours.resize(base, Eigen::Matrix<uint8_t, 3, 1>::Constant(255));
  if (colour == primitive.attributes.end()) {
    mesh.colours.resize(mesh.vertices.size(), Eigen::Matrix<uint8_t, 3, 1>::Constant(255));
    return;
  }
  const bool known = colour->second >= 0 && colour->second < static_cast<int>(model.accessors.size());
  const int components = known && model.accessors[colour->second].type == TINYGLTF_TYPE_VEC4 ? 4 : 3;
  const std::vector<double> v = ReadAccessor(model, colour->second, components, "COLOR_0", path);
  if (v.size() / components != n) throw InputError(path + ": COLOR_0: its count differs from POSITION's");
  for (size_t i = 0; i < n; ++i) {
    mesh.colours.emplace_back(SrgbByteFromLinear(v[components * i]),
                              SrgbByteFromLinear(v[components * i + 1]),
                              SrgbByteFromLinear(v[components * i + 2]));
  }
  out->any_colours = true;
}

// The primitive's texture: its material's base colour texture (the image's index; -1 without),
// with the coordinates of its `n` vertices into `uv`.
int PrimitiveTexture(const tinygltf::Model& model, const tinygltf::Primitive& primitive, size_t n,
                     const std::map<int, cv::Mat>& images, const std::string& path,
                     std::vector<double>* uv) {
  if (primitive.material < 0 || primitive.material >= static_cast<int>(model.materials.size())) {
    return -1;
  }
  const tinygltf::TextureInfo& info =
      model.materials[primitive.material].pbrMetallicRoughness.baseColorTexture;
  const auto coordinates = primitive.attributes.find("TEXCOORD_" + std::to_string(std::max(0, info.texCoord)));
  if (info.index < 0 || info.index >= static_cast<int>(model.textures.size()) ||
      coordinates == primitive.attributes.end() || !images.count(model.textures[info.index].source)) {
    return -1;
  }
  *uv = ReadAccessor(model, coordinates->second, 2, "TEXCOORD", path);
  if (uv->size() / 2 != n) throw InputError(path + ": TEXCOORD: its count differs from POSITION's");
  for (size_t i = 0; i < uv->size(); ++i) {
    // Beyond a million repeats of the texture a float no longer tells texels apart.
    if (!(std::abs((*uv)[i]) < 1e6)) {
      throw InputError(path + ": TEXCOORD: coordinate " + std::to_string(i / 2) + " is not a finite texture position");
    }
  }
  return model.textures[info.index].source;
}

// The primitive's vertex indices, three a triangle: its index accessor's, or its vertices in
// order.
std::vector<double> PrimitiveIndices(const tinygltf::Model& model,
                                     const tinygltf::Primitive& primitive, size_t n,
                                     const std::string& path) {
  std::vector<double> indices;
  if (primitive.indices < 0) {
    indices.resize(n - n % 3);
    for (size_t i = 0; i < indices.size(); ++i) indices[i] = static_cast<double>(i);
    return indices;
  }
  indices = ReadAccessor(model, primitive.indices, 1, "indices", path);
  const int type = model.accessors[primitive.indices].componentType;  // known: read above
  if (type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT && type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    throw InputError(path + ": indices (accessor " + std::to_string(primitive.indices) +
                     "): field 'componentType' is not an unsigned integer type");
  }
  return indices;
}

void AddPrimitive(const tinygltf::Model& model, const tinygltf::Primitive& primitive,
                  const Eigen::Matrix4d& transform, const std::map<int, cv::Mat>& images,
                  const std::string& path, Gathered* out) {
  if (primitive.mode != TINYGLTF_MODE_TRIANGLES && primitive.mode != -1) return;
  const auto position = primitive.attributes.find("POSITION");
  if (position == primitive.attributes.end()) return;
  const std::vector<double> xyz = ReadAccessor(model, position->second, 3, "POSITION", path);
  const size_t n = xyz.size() / 3;
  TriangleMesh& mesh = out->mesh;
  const size_t base = mesh.vertices.size();
  if (base + n > kMaxElements) throw InputError(path + ": more vertices than raycarve reads");
  AddVertices(model, primitive, xyz, transform, path, out);
  AddColours(model, primitive, base, n, path, out);
  std::vector<double> uv;
  const int texture_image = PrimitiveTexture(model, primitive, n, images, path, &uv);
  const std::vector<double> indices = PrimitiveIndices(model, primitive, n, path);
  if (mesh.triangles.size() + indices.size() / 3 > kMaxElements) {
    throw InputError(path + ": more triangles than raycarve reads");
  }
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    Eigen::Vector3i triangle;
    for (int k = 0; k < 3; ++k) {
      const double index = indices[t + k];
      if (!(index >= 0.0 && index < static_cast<double>(n))) {
        char text[64];
        std::snprintf(text, sizeof(text), "%.0f", index);
        throw InputError(path + ": indices: " + text + " is past the primitive's " +
                         std::to_string(n) + " vertices");
      }
      triangle[k] = static_cast<int>(base + static_cast<size_t>(index));
    }
    mesh.triangles.push_back(triangle);
    out->triangle_texture.push_back(texture_image);
    for (int k = 0; k < 3; ++k) {
      const size_t i = static_cast<size_t>(indices[t + k]);
      out->corner_uvs.push_back(texture_image >= 0 ? Eigen::Vector2f(static_cast<float>(uv[2 * i]),
                                                                     static_cast<float>(uv[2 * i + 1]))
                                                   : Eigen::Vector2f::Zero());
    }
  }
}

}  // namespace

TriangleMesh ReadGltf(const std::string& path) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  ImageLoad load;
  load.model = &model;
  loader.SetImageLoader(DecodeImage, &load);
  const std::map<int, cv::Mat>& images = load.images;
  std::string error, warning;
  const bool binary = LowerCaseExtension(path) != ".gltf";
  const bool loaded = binary ? loader.LoadBinaryFromFile(&model, &error, &warning, path)
                             : loader.LoadASCIIFromFile(&model, &error, &warning, path);
  if (!loaded) {
    std::replace(error.begin(), error.end(), '\n', ' ');
    throw InputError(path + ": not a readable glTF 2.0 file: " + (error.empty() ? "unknown error" : error));
  }
  Gathered gathered;
  // The scene's nodes, depth first, each with its transform down the tree (at most as deep as
  // there are nodes: a cycle in a damaged file stops there).
  std::vector<int> roots;
  const int scene = model.defaultScene >= 0 ? model.defaultScene : (model.scenes.empty() ? -1 : 0);
  if (scene >= 0 && scene < static_cast<int>(model.scenes.size())) {
    roots = model.scenes[scene].nodes;
  } else {
    std::vector<uint8_t> child(model.nodes.size(), 0);
    for (const tinygltf::Node& node : model.nodes) {
      for (int c : node.children) if (c >= 0 && c < static_cast<int>(child.size())) child[c] = 1;
    }
    for (size_t i = 0; i < model.nodes.size(); ++i) if (!child[i]) roots.push_back(static_cast<int>(i));
  }
  std::vector<std::pair<int, Eigen::Matrix4d>> stack;
  for (int root : roots) stack.emplace_back(root, Eigen::Matrix4d::Identity());
  size_t visited = 0;
  while (!stack.empty()) {
    const auto [index, parent] = stack.back();
    stack.pop_back();
    if (index < 0 || index >= static_cast<int>(model.nodes.size())) {
      throw InputError(path + ": node " + std::to_string(index) + " does not exist");
    }
    if (++visited > 16 * model.nodes.size() + 16) throw InputError(path + ": the node tree has a cycle");
    const tinygltf::Node& node = model.nodes[index];
    const Eigen::Matrix4d transform = parent * NodeTransform(node);
    if (node.mesh >= 0) {
      if (node.mesh >= static_cast<int>(model.meshes.size())) {
        throw InputError(path + ": node " + std::to_string(index) + ": field 'mesh' does not exist");
      }
      for (const tinygltf::Primitive& primitive : model.meshes[node.mesh].primitives) {
        AddPrimitive(model, primitive, transform, images, path, &gathered);
      }
    }
    for (int child : node.children) stack.emplace_back(child, transform);
  }
  if (gathered.mesh.triangles.empty()) throw InputError(path + ": no triangles in its scene");
  if (!gathered.any_colours) gathered.mesh.colours.clear();
  if (!gathered.any_normals) ComputeVertexNormals(&gathered.mesh);
  BuildAtlas(images, &gathered);
  return std::move(gathered.mesh);
}

bool IsGltfPath(const std::string& path) {
  const std::string extension = LowerCaseExtension(path);
  return extension == ".glb" || extension == ".gltf";
}

TriangleMesh ReadModelFile(const std::string& path) {
  if (IsGltfPath(path)) return ReadGltf(path);
  if (IsObjPath(path)) return ReadObj(path);
  return ReadMeshOrCloudPly(path);
}

}  // namespace exporter
}  // namespace raycarve
