#include "samples/triangle_mesh.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>

#include "calib/input_error.h"

namespace raycarve {
namespace {

constexpr int kLeafSize = 4;

bool RayBox(const Eigen::Vector3d& origin, const Eigen::Vector3d& inverse, const Eigen::Vector3d& low,
            const Eigen::Vector3d& high, double t_min, double t_max) {
  for (int axis = 0; axis < 3; ++axis) {
    double t0 = (low[axis] - origin[axis]) * inverse[axis];
    double t1 = (high[axis] - origin[axis]) * inverse[axis];
    if (t0 > t1) std::swap(t0, t1);
    t_min = std::max(t_min, t0);
    t_max = std::min(t_max, t1);
    if (t_min > t_max) return false;
  }
  return true;
}

// Cubic Bernstein basis and its derivative at t.
void Bernstein(double t, double b[4], double d[4]) {
  const double s = 1.0 - t;
  b[0] = s * s * s;
  b[1] = 3.0 * t * s * s;
  b[2] = 3.0 * t * t * s;
  b[3] = t * t * t;
  d[0] = -3.0 * s * s;
  d[1] = 3.0 * s * s - 6.0 * t * s;
  d[2] = 6.0 * t * s - 3.0 * t * t;
  d[3] = 3.0 * t * t;
}

}  // namespace

TriangleMesh::TriangleMesh(std::vector<Eigen::Vector3d> vertices,
                           std::vector<Eigen::Vector3d> normals,
                           std::vector<std::array<int, 3>> triangles)
    : vertices_(std::move(vertices)), normals_(std::move(normals)), triangles_(std::move(triangles)) {
  order_.resize(triangles_.size());
  std::iota(order_.begin(), order_.end(), 0);
  if (!triangles_.empty()) Build(0, static_cast<int>(triangles_.size()));
}

int TriangleMesh::Build(int begin, int end) {
  const int index = static_cast<int>(nodes_.size());
  nodes_.emplace_back();
  Eigen::Vector3d low = Eigen::Vector3d::Constant(INFINITY), high = -low;
  Eigen::Vector3d centre_low = low, centre_high = high;
  for (int i = begin; i < end; ++i) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const int v : triangles_[order_[i]]) {
      low = low.cwiseMin(vertices_[v]);
      high = high.cwiseMax(vertices_[v]);
      centre += vertices_[v] / 3.0;
    }
    centre_low = centre_low.cwiseMin(centre);
    centre_high = centre_high.cwiseMax(centre);
  }
  nodes_[index].low = low;
  nodes_[index].high = high;
  if (end - begin <= kLeafSize) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  (centre_high - centre_low).maxCoeff(&axis);
  const int middle = (begin + end) / 2;
  auto centre_of = [&](int triangle) {
    const std::array<int, 3>& t = triangles_[triangle];
    return vertices_[t[0]][axis] + vertices_[t[1]][axis] + vertices_[t[2]][axis];
  };
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](int a, int b) { return centre_of(a) < centre_of(b); });
  const int left = Build(begin, middle);
  const int right = Build(middle, end);
  nodes_[index].first = left;
  nodes_[index].right = right;
  return index;
}

Eigen::Vector3d TriangleMesh::Normal(int triangle, double u, double v) const {
  const std::array<int, 3>& t = triangles_[triangle];
  Eigen::Vector3d normal;
  if (normals_.empty()) {
    normal = (vertices_[t[1]] - vertices_[t[0]]).cross(vertices_[t[2]] - vertices_[t[0]]);
  } else {
    normal = (1.0 - u - v) * normals_[t[0]] + u * normals_[t[1]] + v * normals_[t[2]];
  }
  return normal.normalized();
}

bool TriangleMesh::Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                             double t_min, double t_max, RayHit* hit) const {
  if (nodes_.empty()) return false;
  const Eigen::Vector3d inverse = direction.cwiseInverse();
  int stack[64];
  int size = 0;
  stack[size++] = 0;
  bool found = false;
  double best_u = 0.0, best_v = 0.0;
  while (size > 0) {
    const Node& node = nodes_[stack[--size]];
    if (!RayBox(origin, inverse, node.low, node.high, t_min, t_max)) continue;
    if (node.count == 0) {
      stack[size++] = node.first;
      stack[size++] = node.right;
      continue;
    }
    for (int i = node.first; i < node.first + node.count; ++i) {
      // Moller-Trumbore.
      const std::array<int, 3>& t = triangles_[order_[i]];
      const Eigen::Vector3d e1 = vertices_[t[1]] - vertices_[t[0]];
      const Eigen::Vector3d e2 = vertices_[t[2]] - vertices_[t[0]];
      const Eigen::Vector3d p = direction.cross(e2);
      const double det = e1.dot(p);
      if (std::abs(det) < 1e-14) continue;
      const Eigen::Vector3d s = origin - vertices_[t[0]];
      const double u = s.dot(p) / det;
      if (u < 0.0 || u > 1.0) continue;
      const Eigen::Vector3d q = s.cross(e1);
      const double v = direction.dot(q) / det;
      if (v < 0.0 || u + v > 1.0) continue;
      const double distance = e2.dot(q) / det;
      if (distance <= t_min || distance >= t_max) continue;
      t_max = distance;
      hit->t = distance;
      hit->triangle = order_[i];
      best_u = u;
      best_v = v;
      found = true;
    }
  }
  if (found) hit->normal = Normal(hit->triangle, best_u, best_v);
  return found;
}

double TriangleMesh::Area(int triangle) const {
  const std::array<int, 3>& t = triangles_[triangle];
  return 0.5 * (vertices_[t[1]] - vertices_[t[0]]).cross(vertices_[t[2]] - vertices_[t[0]]).norm();
}

Eigen::Vector3d TriangleMesh::PointOn(int triangle, double r1, double r2,
                                      Eigen::Vector3d* normal) const {
  const double a = std::sqrt(r1);
  const double u = a * (1.0 - r2), v = a * r2;
  const std::array<int, 3>& t = triangles_[triangle];
  *normal = Normal(triangle, u, v);
  return (1.0 - u - v) * vertices_[t[0]] + u * vertices_[t[1]] + v * vertices_[t[2]];
}

namespace {

using Patch = std::array<int, 16>;

// The patch file: "vertices N", N lines "x y z", "patches M", M lines of 16 control-point indices.
void ReadTeapotPatches(const std::string& path, std::vector<Eigen::Vector3d>* control,
                       std::vector<Patch>* patches) {
  std::ifstream file(path);
  if (!file) throw InputError(path + ": cannot open the teapot's patch file");
  std::string line;
  int line_number = 0;
  int expected_vertices = -1, expected_patches = -1;
  auto fail = [&](const std::string& what) {
    throw InputError(path + ": line " + std::to_string(line_number) + ": " + what);
  };
  while (std::getline(file, line)) {
    ++line_number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string word;
    fields >> word;
    if (word == "vertices") {
      if (!(fields >> expected_vertices) || expected_vertices < 4) fail("bad vertex count");
      continue;
    }
    if (word == "patches") {
      if (!(fields >> expected_patches) || expected_patches < 1) fail("bad patch count");
      if (static_cast<int>(control->size()) != expected_vertices) fail("fewer vertices than stated");
      continue;
    }
    fields.clear();
    fields.str(line);
    if (expected_patches < 0) {
      Eigen::Vector3d p;
      if (expected_vertices < 0 || !(fields >> p.x() >> p.y() >> p.z())) fail("expected 'x y z'");
      control->push_back(p);
    } else {
      Patch patch;
      for (int& index : patch) {
        if (!(fields >> index) || index < 0 || index >= static_cast<int>(control->size())) {
          fail("expected 16 control-point indices below " + std::to_string(control->size()));
        }
      }
      patches->push_back(patch);
    }
  }
  if (expected_patches < 0 || static_cast<int>(patches->size()) != expected_patches) {
    throw InputError(path + ": expected " + std::to_string(expected_patches) + " patches, read " +
                     std::to_string(patches->size()));
  }
}

// The patch's unit normal at (u, v); at a collapsed edge (the lid's knob, the bottom's centre),
// where the tangents are parallel, the normal a little way in.
Eigen::Vector3d PatchNormal(const std::vector<Eigen::Vector3d>& control, const Patch& patch,
                            double u, double v, const Eigen::Vector3d& su, const Eigen::Vector3d& sv) {
  Eigen::Vector3d normal = su.cross(sv);
  if (normal.norm() < 1e-9) {
    double bu[4], du[4], bv[4], dv[4];
    Bernstein(std::clamp(u, 1e-3, 1 - 1e-3), bu, du);
    Bernstein(std::clamp(v, 1e-3, 1 - 1e-3), bv, dv);
    Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = a;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) {
        a += du[r] * bv[c] * control[patch[r * 4 + c]];
        b += bu[r] * dv[c] * control[patch[r * 4 + c]];
      }
    }
    normal = a.cross(b);
  }
  return normal.normalized();
}

// Appends the patch's (n + 1)^2 grid of points (scaled, moved) with normals, and its triangles
// of non-zero area.
void TessellatePatch(const std::vector<Eigen::Vector3d>& control, const Patch& patch, int n,
                     double scale, const Eigen::Vector3d& offset,
                     std::vector<Eigen::Vector3d>* vertices, std::vector<Eigen::Vector3d>* normals,
                     std::vector<std::array<int, 3>>* triangles) {
  const int base = static_cast<int>(vertices->size());
  for (int i = 0; i <= n; ++i) {
    for (int j = 0; j <= n; ++j) {
      const double u = static_cast<double>(i) / n, v = static_cast<double>(j) / n;
      double bu[4], du[4], bv[4], dv[4];
      Bernstein(u, bu, du);
      Bernstein(v, bv, dv);
      Eigen::Vector3d point = Eigen::Vector3d::Zero(), su = point, sv = point;
      for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) {
          const Eigen::Vector3d& p = control[patch[r * 4 + c]];
          point += bu[r] * bv[c] * p;
          su += du[r] * bv[c] * p;
          sv += bu[r] * dv[c] * p;
        }
      }
      vertices->push_back(scale * point + offset);
      normals->push_back(PatchNormal(control, patch, u, v, su, sv));
    }
  }
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const int a = base + i * (n + 1) + j, b = a + 1, c = a + (n + 1), d = c + 1;
      for (const std::array<int, 3>& t : {std::array<int, 3>{a, c, b}, std::array<int, 3>{b, c, d}}) {
        const std::vector<Eigen::Vector3d>& x = *vertices;
        const double area = (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).norm();
        if (area > 1e-14 * scale * scale) triangles->push_back(t);
      }
    }
  }
}

}  // namespace

TriangleMesh ReadBezierTeapot(const std::string& path, int tessellation, double scale,
                              const Eigen::Vector3d& offset) {
  std::vector<Eigen::Vector3d> control;
  std::vector<Patch> patches;
  ReadTeapotPatches(path, &control, &patches);
  std::vector<Eigen::Vector3d> vertices, normals;
  std::vector<std::array<int, 3>> triangles;
  const int n = tessellation;
  for (const Patch& patch : patches) {
    TessellatePatch(control, patch, n, scale, offset, &vertices, &normals, &triangles);
  }
  // Outward normals: the patches' parameterisations do not agree on a side. A point just off a
  // patch's middle along its normal is inside the closed surface when a ray from it crosses the
  // surface an odd number of times; then the patch's normals are flipped.
  TriangleMesh mesh(vertices, normals, triangles);
  const int per_patch = (n + 1) * (n + 1);
  const Eigen::Vector3d probe = Eigen::Vector3d(0.3, 0.5, 0.81).normalized();
  for (size_t patch = 0; patch < patches.size(); ++patch) {
    const int middle = static_cast<int>(patch) * per_patch + (n / 2) * (n + 1) + n / 2;
    Eigen::Vector3d origin = vertices[middle] + 1e-4 * scale * normals[middle];
    int crossings = 0;
    TriangleMesh::RayHit hit;
    double t = 0.0;
    while (crossings < 64 && mesh.Intersect(origin, probe, t + 1e-9, INFINITY, &hit)) {
      ++crossings;
      t = hit.t;
    }
    if (crossings % 2 == 1) {
      for (int k = 0; k < per_patch; ++k) normals[patch * per_patch + k] *= -1.0;
    }
  }
  return TriangleMesh(std::move(vertices), std::move(normals), std::move(triangles));
}

}  // namespace raycarve
