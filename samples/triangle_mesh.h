#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace raycarve {

// A triangle mesh with per-vertex normals and a bounding-volume hierarchy for ray casting: how
// the synthetic scenes draw curved objects (the teapot) exactly as they sample their truth.
class TriangleMesh {
 public:
  struct RayHit {
    double t = 0.0;
    int triangle = -1;
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // interpolated, unit length
  };

  // Builds the hierarchy. Triangles index `vertices`; `normals` (one per vertex) may be empty
  // (face normals are then used).
  TriangleMesh(std::vector<Eigen::Vector3d> vertices,
               std::vector<Eigen::Vector3d> normals,
               std::vector<std::array<int, 3>> triangles);

  // The nearest hit with t in (t_min, t_max) of origin + t direction, or false.
  bool Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction, double t_min,
                 double t_max, RayHit* hit) const;

  // Area of a triangle, and a point of it from two uniform numbers in [0, 1) with its normal.
  double Area(int triangle) const;
  Eigen::Vector3d PointOn(int triangle, double r1, double r2, Eigen::Vector3d* normal) const;

  int num_triangles() const { return static_cast<int>(triangles_.size()); }
  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }
  Eigen::Vector3d BoxMin() const { return nodes_.empty() ? Eigen::Vector3d::Zero() : nodes_[0].low; }
  Eigen::Vector3d BoxMax() const { return nodes_.empty() ? Eigen::Vector3d::Zero() : nodes_[0].high; }

 private:
  struct Node {
    Eigen::Vector3d low, high;
    int first = 0;   // leaf: first of `count` entries of order_; inner: left child index
    int count = 0;   // 0 for inner nodes (right child is first + 1... stored in `right`)
    int right = -1;
  };
  int Build(int begin, int end);
  Eigen::Vector3d Normal(int triangle, double u, double v) const;

  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<int> order_;  // triangle indices, grouped by leaf
  std::vector<Node> nodes_;
};

// The Utah teapot from a file of bicubic Bezier patches (the format of
// ../shared/data/teapot/teapot_bezier.txt: 'vertices N', N lines 'x y z', 'patches M', M lines of
// 16 zero-based control-point indices, '#' comments), each patch tessellated into
// `tessellation` x `tessellation` quads with normals from the patch's derivatives; degenerate
// triangles (collapsed patch edges) are dropped. Coordinates are scaled by `scale` and moved by
// `offset`. Throws InputError naming the file and line on a malformed file.
TriangleMesh ReadBezierTeapot(const std::string& path, int tessellation, double scale,
                              const Eigen::Vector3d& offset);

}  // namespace raycarve
