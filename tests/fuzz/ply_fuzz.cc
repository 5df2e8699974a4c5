// The PLY readers (raycarve's own ReadPly), then what compare and holdout --model do next:
// nearest neighbours over the points, and the mesh's topology.
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "calib/input_error.h"
#include "export/point_cloud_compare.h"
#include "export/point_cloud_io.h"
#include "export/surface_mesh.h"
#include "tests/fuzz/fuzz_target.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = raycarve::fuzzing::WriteInputFile("ply", ".ply", data, size);
  try {
    const std::vector<raycarve::exporter::ColouredPoint> cloud = raycarve::exporter::ReadPointCloudPly(path);
    std::vector<Eigen::Vector3f> xyz;
    for (const auto& point : cloud) xyz.push_back(point.xyz);
    if (xyz.size() >= 2) raycarve::exporter::MedianNeighbourSpacing(xyz);
  } catch (const raycarve::InputError&) {
  }
  try {
    const std::vector<Eigen::Vector3f> points = raycarve::exporter::ReadComparablePoints(path, 64);
    raycarve::exporter::CompareOptions options;
    raycarve::exporter::CompareClouds(points, points, options);
  } catch (const raycarve::InputError&) {
  }
  try {
    const raycarve::exporter::TriangleMesh mesh = raycarve::exporter::ReadMeshOrCloudPly(path);
    raycarve::exporter::AnalyseTopology(mesh);
  } catch (const raycarve::InputError&) {
  }
  return 0;
}
