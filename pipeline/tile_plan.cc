#include "pipeline/tile_plan.h"

#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <type_traits>
#include <sstream>

#include <glog/logging.h>
#include <nlohmann/json.hpp>

#include "calib/atomic_file.h"
#include "calib/input_error.h"
#include "carve/level_of_detail.h"
#include "pipeline/output_files.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr char kMagic[8] = {'R', 'C', 'V', 'O', 'X', 'E', 'L', '1'};
constexpr int kMaxDimension = 4096;

// The fixed header of a voxel block file.
struct BlockHeader {
  char magic[8];
  char plan_id[16];
  int32_t job;  // -1: the coarse volume
  int32_t lo[3];
  int32_t hi[3];
  uint64_t words;
};

json Vector(const Eigen::Vector3i& v) { return json::array({v.x(), v.y(), v.z()}); }

int64_t Voxels(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
  const Eigen::Vector3i n = hi - lo;
  return static_cast<int64_t>(n.x()) * n.y() * n.z();
}

void WriteBlock(const std::string& path, const std::string& plan_id, int job,
                const Eigen::Vector3i& lo, const Eigen::Vector3i& hi,
                const std::vector<uint64_t>& bits) {
  BlockHeader header{};
  std::memcpy(header.magic, kMagic, sizeof(kMagic));
  std::memcpy(header.plan_id, plan_id.data(), std::min<size_t>(16, plan_id.size()));
  header.job = job;
  for (int axis = 0; axis < 3; ++axis) {
    header.lo[axis] = lo[axis];
    header.hi[axis] = hi[axis];
  }
  header.words = bits.size();
  // A temporary name of this process's own: a job run again while an earlier run of it is still
  // writing (a cluster's requeue) must not write into the same file.
  const fs::path target(path);
  const std::string temporary =
      (target.parent_path() / (".tmp." + std::to_string(getpid()) + "." + target.filename().string()))
          .string();
  {
    errno = 0;
    std::ofstream stream(temporary, std::ios::binary);
    if (!stream) throw InputError(temporary + ": cannot open for writing: " + std::strerror(errno));
    stream.write(reinterpret_cast<const char*>(&header), sizeof(header));
    stream.write(reinterpret_cast<const char*>(bits.data()),
                 static_cast<std::streamsize>(bits.size() * sizeof(uint64_t)));
    stream.close();
    if (!stream) ThrowWriteFailure(temporary, "the voxels (" + path + " is unchanged)", errno);
  }
  RenameIntoPlace(temporary, path);
}

std::vector<uint64_t> ReadBlock(const std::string& path, const std::string& what,
                                const std::string& plan_id, int job,
                                const Eigen::Vector3i& lo, const Eigen::Vector3i& hi) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw InputError(path + ": cannot read " + what + " (" +
                     (fs::exists(path) ? "not readable" : "missing") + ")");
  }
  BlockHeader header{};
  in.read(reinterpret_cast<char*>(&header), sizeof(header));
  if (!in || std::memcmp(header.magic, kMagic, sizeof(kMagic)) != 0) {
    throw InputError(path + ": not a raycarve voxel file (" + what + ")");
  }
  if (std::string(header.plan_id, 16) != plan_id) {
    throw InputError(path + ": plan_id " + std::string(header.plan_id, 16) + " is not the plan's " +
                     plan_id + ": " + what + " from another plan (plan again or run the job again)");
  }
  if (header.job != job) {
    throw InputError(path + ": job " + std::to_string(header.job) + ", expected " +
                     std::to_string(job));
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (header.lo[axis] != lo[axis] || header.hi[axis] != hi[axis]) {
      throw InputError(path + ": its block of voxels does not match the plan's (" + what + ")");
    }
  }
  const uint64_t words = (static_cast<uint64_t>(Voxels(lo, hi)) + 63) / 64;
  if (header.words != words) {
    throw InputError(path + ": words " + std::to_string(header.words) + ", expected " +
                     std::to_string(words));
  }
  std::vector<uint64_t> bits(words);
  in.read(reinterpret_cast<char*>(bits.data()), static_cast<std::streamsize>(words * 8));
  if (!in || in.peek() != std::char_traits<char>::eof()) {
    throw InputError(path + ": " + (in ? "longer" : "shorter") + " than its header says (" +
                     what + ")");
  }
  return bits;
}

// The field `key` of `object` (in `path`), which must exist: InputError naming both otherwise.
const json& Field(const json& object, const char* key, const std::string& path) {
  if (!object.is_object() || !object.contains(key)) {
    throw InputError(path + ": field " + key + " is missing");
  }
  return object.at(key);
}

Eigen::Vector3i ReadVector(const json& object, const char* key, const std::string& path,
                           int min_value, int max_value) {
  const json& value = Field(object, key, path);
  if (!value.is_array() || value.size() != 3) {
    throw InputError(path + ": field " + key + " must be an array of 3 integers");
  }
  Eigen::Vector3i v;
  for (int axis = 0; axis < 3; ++axis) {
    if (!value[axis].is_number_integer() || value[axis].get<int64_t>() < min_value ||
        value[axis].get<int64_t>() > max_value) {
      throw InputError(path + ": field " + key + " must hold integers in [" +
                       std::to_string(min_value) + ", " + std::to_string(max_value) + "]");
    }
    v[axis] = value[axis].get<int>();
  }
  return v;
}

template <typename T>
T ReadNumber(const json& object, const char* key, const std::string& path) {
  const json& value = Field(object, key, path);
  if (!value.is_number()) throw InputError(path + ": field " + key + " must be a number");
  if constexpr (std::is_integral_v<T>) {
    const double number = value.get<double>();
    if (!value.is_number_integer() || number < static_cast<double>(std::numeric_limits<T>::min()) ||
        number > static_cast<double>(std::numeric_limits<T>::max())) {
      throw InputError(path + ": field " + key + " must be an integer in range");
    }
  } else if (!std::isfinite(value.get<double>())) {
    throw InputError(path + ": field " + key + " must be finite");
  }
  return value.get<T>();
}

std::string ReadString(const json& object, const char* key, const std::string& path) {
  const json& value = Field(object, key, path);
  if (!value.is_string()) throw InputError(path + ": field " + key + " must be a string");
  return value.get<std::string>();
}


// Solid voxels of `volume` (a coarse grid) in the coarse voxels that hold the final grid's
// [lo, hi) of `tile`.
int64_t CoarseSolidIn(const Volume& volume, const TileRegion& tile) {
  const VoxelGrid& grid = volume.grid();
  const Eigen::Vector3i lo = tile.lo / 2;
  const Eigen::Vector3i hi = ((tile.hi.array() + 1) / 2).matrix().cwiseMin(grid.dimensions());
  int64_t count = 0;
  for (int z = lo.z(); z < hi.z(); ++z) {
    for (int y = lo.y(); y < hi.y(); ++y) {
      for (int x = lo.x(); x < hi.x(); ++x) {
        count += volume.IsSolid(grid.Index(Eigen::Vector3i(x, y, z)));
      }
    }
  }
  return count;
}

}  // namespace

TilePlan MakeTilePlan(const std::vector<CalibratedView>& views,
                      const Eigen::AlignedBox3d& box,
                      const CarveOptions& options,
                      const CoarseCarve& coarse,
                      const Eigen::Vector3i& tiles,
                      int overlap,
                      double load_seconds,
                      std::vector<std::string> arguments,
                      std::string working_directory) {
  const VoxelGrid grid(box, options.resolution);
  const Volume band = DilateSolid(coarse.volume, options.lod_band);
  TilePlan plan;
  plan.working_directory = std::move(working_directory);
  plan.arguments = std::move(arguments);
  plan.resolution = options.resolution;
  plan.dimensions = grid.dimensions();
  plan.coarse_dimensions = coarse.volume.grid().dimensions();
  plan.tiles_per_axis = tiles;
  plan.overlap = overlap;
  plan.final_threshold = coarse.final_threshold;
  plan.final_pattern_threshold = coarse.final_pattern_threshold;
  // Estimates for the jobs' requests, from what the plan's process measured: the photos as loaded
  // (about 14 bytes a pixel, README), a ray and a valid byte a pixel, a few bytes a voxel; the
  // time of loading, and of the coarse carve shared out by the tiles' solid coarse voxels (a
  // finer level costs about 4 times its coarser one), three times over.
  const double gib = 1024.0 * 1024.0 * 1024.0;
  double pixels = 0.0;
  for (const CalibratedView& view : views) pixels += static_cast<double>(view.width) * view.height;
  // Supersampling (CarveOptions::supersample): the final level's rays and enlarged photos (RGB,
  // valid, mask) in place of one ray a pixel.
  const int supersample = FinalSupersample(views, grid.Box(), options);
  const double enlarged_bytes =
      supersample > 1 ? pixels * (9.0 * supersample * supersample - 4.0) : 0.0;
  const double coarse_seconds = coarse.statistics.carve_seconds + coarse.statistics.setup_seconds;
  const double total_solid = std::max<double>(1.0, band.num_solid());
  const double coarse_bytes = 2.0 * coarse.volume.grid().num_voxels();
  for (const TileRegion& region : SplitIntoTiles(plan.dimensions, tiles, overlap)) {
    TilePlan::Tile tile;
    tile.region = region;
    tile.coarse_solid = CoarseSolidIn(band, region);
    const Eigen::AlignedBox3d region_box = grid.Region(region.lo, region.hi).Box();
    for (const CalibratedView& view : views) tile.views += BoxInView(view, region_box);
    if (tile.coarse_solid > 0) tile.job = plan.jobs++;
    const Eigen::Vector3i n = region.hi - region.lo;
    const double voxels = static_cast<double>(n.x()) * n.y() * n.z();
    tile.memory_gib = 0.5 + (pixels * 19.0 + enlarged_bytes + voxels * 3.0 + coarse_bytes) / gib;
    tile.minutes = std::max(
        5.0, 3.0 * (load_seconds + 4.0 * coarse_seconds * tile.coarse_solid / total_solid) / 60.0);
    plan.tiles.push_back(tile);
  }
  // The merge also meshes, refines, colours and textures the whole surface, which dominates its
  // memory and time: about 2 KB and 150 us per final surface voxel (one carve of the paper scene:
  // 0.64 GB and 22 s for 200,000 surface voxels at 256, 2.05 GB and 115 s for 862,000 at 512),
  // the final surface being about 4 times the coarse level's.
  const double surface = 4.0 * static_cast<double>(coarse.volume.num_surface());
  plan.merge_memory_gib =
      1.0 + (pixels * 18.0 + enlarged_bytes + grid.num_voxels() * 3.0 + surface * 2048.0) / gib;
  plan.merge_minutes = std::max(
      10.0, 3.0 * (load_seconds + 8.0 * coarse_seconds + 150e-6 * surface) / 60.0);
  std::string identity;
  for (const std::string& argument : plan.arguments) identity += argument + '\0';
  identity += std::to_string(plan.resolution) + "," + std::to_string(plan.dimensions.x()) + "," +
              std::to_string(plan.dimensions.y()) + "," + std::to_string(plan.dimensions.z());
  const std::vector<uint64_t>& bits = coarse.volume.solid_bits();
  identity.append(reinterpret_cast<const char*>(bits.data()), bits.size() * sizeof(uint64_t));
  plan.plan_id = HexDigest(identity);
  return plan;
}

const TilePlan::Tile* TilePlan::TileOfJob(int job) const {
  if (job < 0) return nullptr;
  for (const Tile& tile : tiles) {
    if (tile.job == job) return &tile;
  }
  return nullptr;
}

std::string HexDigest(const std::string& bytes) {
  uint64_t hash = 1469598103934665603ull;
  for (unsigned char c : bytes) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

std::string TilePlanJson(const TilePlan& plan) {
  json root;
  root["schema"] = TilePlan::kSchema;
  root["kind"] = "raycarve tile plan";
  root["plan_id"] = plan.plan_id;
  root["working_directory"] = plan.working_directory;
  root["arguments"] = plan.arguments;
  root["resolution"] = plan.resolution;
  root["dimensions"] = Vector(plan.dimensions);
  root["coarse_dimensions"] = Vector(plan.coarse_dimensions);
  root["tiles_per_axis"] = Vector(plan.tiles_per_axis);
  root["overlap_voxels"] = plan.overlap;
  root["final_threshold"] = plan.final_threshold;
  root["final_pattern_threshold"] = plan.final_pattern_threshold;
  root["coarse_file"] = "coarse.bin";
  root["jobs"] = plan.jobs;
  root["merge"] = {{"memory_gib", plan.merge_memory_gib}, {"minutes", plan.merge_minutes}};
  json tiles = json::array();
  for (const TilePlan::Tile& tile : plan.tiles) {
    json t;
    t["index"] = tile.region.index;
    t["job"] = tile.job;
    t["core_lo"] = Vector(tile.region.core_lo);
    t["core_hi"] = Vector(tile.region.core_hi);
    t["lo"] = Vector(tile.region.lo);
    t["hi"] = Vector(tile.region.hi);
    t["coarse_solid_voxels"] = tile.coarse_solid;
    t["views"] = tile.views;
    t["memory_gib"] = tile.memory_gib;
    t["minutes"] = tile.minutes;
    t["part"] = tile.job >= 0 ? TilePartPath("", tile.job) : "";
    tiles.push_back(t);
  }
  root["tiles"] = tiles;
  return root.dump(2) + "\n";
}

TilePlan ReadTilePlan(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    throw InputError(path + ": cannot read the tile plan (" +
                     (fs::exists(path) ? "not readable" : "missing: run raycarve tile plan") + ")");
  }
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const json root = json::parse(text, nullptr, false);
  if (root.is_discarded() || !root.is_object()) {
    throw InputError(path + ": not a JSON object (a tile plan is written by raycarve tile plan)");
  }
  TilePlan plan;
  if (ReadNumber<int>(root, "schema", path) != TilePlan::kSchema) {
    throw InputError(path + ": field schema is not " + std::to_string(TilePlan::kSchema));
  }
  plan.plan_id = ReadString(root, "plan_id", path);
  if (plan.plan_id.size() != 16) throw InputError(path + ": field plan_id must be 16 hex digits");
  plan.working_directory = ReadString(root, "working_directory", path);
  const json& arguments = Field(root, "arguments", path);
  if (!arguments.is_array()) throw InputError(path + ": field arguments must be an array");
  for (const json& argument : arguments) {
    if (!argument.is_string()) throw InputError(path + ": field arguments must hold strings");
    plan.arguments.push_back(argument.get<std::string>());
  }
  plan.resolution = ReadNumber<int>(root, "resolution", path);
  plan.dimensions = ReadVector(root, "dimensions", path, 1, kMaxDimension);
  plan.coarse_dimensions = ReadVector(root, "coarse_dimensions", path, 1, kMaxDimension);
  plan.tiles_per_axis = ReadVector(root, "tiles_per_axis", path, 1, 64);
  plan.overlap = ReadNumber<int>(root, "overlap_voxels", path);
  plan.final_threshold = ReadNumber<double>(root, "final_threshold", path);
  plan.final_pattern_threshold = ReadNumber<double>(root, "final_pattern_threshold", path);
  plan.jobs = ReadNumber<int>(root, "jobs", path);
  const json& merge = Field(root, "merge", path);
  plan.merge_memory_gib = ReadNumber<double>(merge, "memory_gib", path);
  plan.merge_minutes = ReadNumber<double>(merge, "minutes", path);
  const json& tiles = Field(root, "tiles", path);
  const int64_t expected = static_cast<int64_t>(plan.tiles_per_axis.x()) *
                           plan.tiles_per_axis.y() * plan.tiles_per_axis.z();
  if (!tiles.is_array() || static_cast<int64_t>(tiles.size()) != expected) {
    throw InputError(path + ": field tiles must list " + std::to_string(expected) + " tiles");
  }
  std::vector<int> seen_jobs(plan.jobs, 0);
  if (plan.jobs < 0 || plan.jobs > expected) throw InputError(path + ": field jobs out of range");
  for (const json& t : tiles) {
    TilePlan::Tile tile;
    tile.region.index = ReadNumber<int>(t, "index", path);
    tile.job = ReadNumber<int>(t, "job", path);
    tile.region.core_lo = ReadVector(t, "core_lo", path, 0, kMaxDimension);
    tile.region.core_hi = ReadVector(t, "core_hi", path, 0, kMaxDimension);
    tile.region.lo = ReadVector(t, "lo", path, 0, kMaxDimension);
    tile.region.hi = ReadVector(t, "hi", path, 0, kMaxDimension);
    tile.coarse_solid = ReadNumber<int64_t>(t, "coarse_solid_voxels", path);
    tile.views = ReadNumber<int>(t, "views", path);
    tile.memory_gib = ReadNumber<double>(t, "memory_gib", path);
    tile.minutes = ReadNumber<double>(t, "minutes", path);
    const TileRegion& r = tile.region;
    if (!((r.lo.array() <= r.core_lo.array()).all() && (r.core_lo.array() < r.core_hi.array()).all() &&
          (r.core_hi.array() <= r.hi.array()).all() &&
          (r.hi.array() <= plan.dimensions.array()).all())) {
      throw InputError(path + ": tile " + std::to_string(r.index) +
                       ": its region does not lie in the grid");
    }
    if (tile.job < -1 || tile.job >= plan.jobs) {
      throw InputError(path + ": tile " + std::to_string(r.index) + ": field job out of range");
    }
    if (tile.job >= 0 && seen_jobs[tile.job]++ > 0) {
      throw InputError(path + ": job " + std::to_string(tile.job) + " is listed twice");
    }
    plan.tiles.push_back(tile);
  }
  return plan;
}

void WriteCoarseVolume(const std::string& path, const std::string& plan_id, const Volume& volume) {
  WriteBlock(path, plan_id, -1, Eigen::Vector3i::Zero(), volume.grid().dimensions(),
             volume.solid_bits());
}

std::vector<uint64_t> ReadCoarseVolume(const std::string& path, const TilePlan& plan) {
  return ReadBlock(path, "the coarse volume", plan.plan_id, -1, Eigen::Vector3i::Zero(),
                   plan.coarse_dimensions);
}

void WriteTilePart(const std::string& path, const TilePlan& plan, int job,
                   const std::vector<uint64_t>& core_bits) {
  const TilePlan::Tile* tile = plan.TileOfJob(job);
  CHECK(tile != nullptr);
  WriteBlock(path, plan.plan_id, job, tile->region.core_lo, tile->region.core_hi, core_bits);
}

std::vector<uint64_t> ReadTilePart(const std::string& path, const TilePlan& plan, int job) {
  const TilePlan::Tile* tile = plan.TileOfJob(job);
  CHECK(tile != nullptr);
  return ReadBlock(path, "job " + std::to_string(job) + "'s part", plan.plan_id, job,
                   tile->region.core_lo, tile->region.core_hi);
}

namespace {

constexpr char kRaysMagic[8] = {'R', 'C', 'R', 'A', 'Y', 'S', '0', '3'};

struct RaysHeader {
  char magic[8];
  char plan_id[16];
  int64_t textured;
  int64_t distant;
  int64_t nearer;
  int64_t grown;
  int64_t grown_refused;
  int64_t photos_judged;
  uint64_t count;
};

struct RayRecord {
  int64_t view;
  double direction[3];
  double length;  // +infinity for a distant pixel's ray
};

}  // namespace

void WriteDistantPixels(const std::string& path, const std::string& plan_id,
                        const DistantPixels& distant) {
  RaysHeader header{};
  std::memcpy(header.magic, kRaysMagic, sizeof(kRaysMagic));
  std::memcpy(header.plan_id, plan_id.data(), std::min<size_t>(16, plan_id.size()));
  header.textured = distant.textured;
  header.distant = distant.distant;
  header.nearer = distant.nearer;
  header.grown = distant.grown;
  header.grown_refused = distant.grown_refused;
  header.photos_judged = distant.photos_judged;
  header.count = distant.rays.size();
  std::string bytes(reinterpret_cast<const char*>(&header), sizeof(header));
  for (const DistantRay& ray : distant.rays) {
    const RayRecord record{ray.view, {ray.direction.x(), ray.direction.y(), ray.direction.z()}, ray.length};
    bytes.append(reinterpret_cast<const char*>(&record), sizeof(record));
  }
  WriteTextFileAtomically(path, bytes);
}

DistantPixels ReadDistantPixels(const std::string& path, const TilePlan& plan) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw InputError(path + ": cannot read the plan's distant pixels (" +
                     (fs::exists(path) ? "not readable" : "missing: run raycarve tile plan again") +
                     ")");
  }
  RaysHeader header{};
  in.read(reinterpret_cast<char*>(&header), sizeof(header));
  if (!in || std::memcmp(header.magic, kRaysMagic, sizeof(kRaysMagic)) != 0) {
    throw InputError(path + ": not a raycarve distant-pixel file");
  }
  if (std::string(header.plan_id, 16) != plan.plan_id) {
    throw InputError(path + ": plan_id " + std::string(header.plan_id, 16) + " is not the plan's " +
                     plan.plan_id + " (plan again)");
  }
  std::error_code error;
  const uintmax_t size = fs::file_size(path, error);
  if (error || size != sizeof(header) + header.count * sizeof(RayRecord)) {
    throw InputError(path + ": count " + std::to_string(header.count) +
                     " does not match the file's size");
  }
  DistantPixels distant;
  distant.textured = header.textured;
  distant.distant = header.distant;
  distant.nearer = header.nearer;
  distant.grown = header.grown;
  distant.grown_refused = header.grown_refused;
  if (header.photos_judged < 0 || header.photos_judged > std::numeric_limits<int>::max()) {
    throw InputError(path + ": photos_judged out of range");
  }
  distant.photos_judged = static_cast<int>(header.photos_judged);
  distant.rays.reserve(header.count);
  for (uint64_t i = 0; i < header.count; ++i) {
    RayRecord record{};
    in.read(reinterpret_cast<char*>(&record), sizeof(record));
    const Eigen::Vector3d direction(record.direction[0], record.direction[1], record.direction[2]);
    if (!in || record.view < 0 || record.view > std::numeric_limits<int>::max() ||
        !direction.allFinite() || !(direction.norm() > 0.0) || !(record.length > 0.0)) {
      throw InputError(path + ": ray " + std::to_string(i) +
                       " is not a view, a direction and a positive length");
    }
    distant.rays.push_back({static_cast<int>(record.view), direction, record.length});
  }
  return distant;
}

std::string TilePartPath(const std::string& folder, int job) {
  const std::string name = "tile_" + std::to_string(job) + ".bin";
  return folder.empty() ? name : (fs::path(folder) / name).string();
}

}  // namespace raycarve
