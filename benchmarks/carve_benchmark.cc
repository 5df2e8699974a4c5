// Carving benchmark: the generated scene (samples/synthetic_scene) at N views of WxH, carved at
// each requested resolution; prints convergence time, memory, voxels carved and evaluated as a
// table and as JSON. A benchmark, not a test: figures depend on the machine.
// With each result, its quality against the scene's exact surface: the share of the seen
// surface voxels whose centre lies within 2 voxels of it (precision), and the share of a sample of
// the true surface seen by 2 views with a seen surface voxel centre within 2 voxels
// (completeness).
//   scripts/run_benchmark.sh [--views 14 --width 800 --height 600 --resolutions 128,256
//                             --threads 1,2 --vis_lookup footprint --incremental_statistics 1
//                             --lod_levels 1,0,3 --batch_voxels 1,64]   (levels 0: automatic,
//                             the command line's default; the levels column shows how many it
//                             chose)
// Per run also where the threads' time went: the wall time of the parallel sections of carving
// and colouring, and per thread its work in them and its waiting (the rest of that wall time).
// The serial time (convergence + colouring - parallel) and the total work project the time on
// more cores: about serial + work / n, while the work per batch outweighs a hand-over.
// With --repeats N, each configuration runs N times, the thread counts alternating (a virtual
// machine's speed drifts within seconds: runs side by side compare, runs minutes apart do not),
// and a last table gives per configuration the median convergence time and its speed-up over
// the first thread count's median.
// Before each run (--core_check 1, the default), a pointer chase over 8 MiB on each core the
// process may use: its nanoseconds per load, the last column and "core_latency_ns". On a virtual
// machine whose cores share their last-level cache with other tenants, a core's figure moves
// from run to run (20-150 ns measured on this 2-core VM, the two cores rarely alike), and the
// carve's times with it (README, "Threads"): runs compare when their cores' figures do. Then
// the round trip of a cache line between the first two cores ("trip", "core_round_trip_ns"):
// the least a hand-over between the carve's threads costs.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#if defined(__linux__)
#include <sched.h>
#endif

#include "calib/calibrated_view.h"
#include "carve/carver.h"
#include "samples/synthetic_scene.h"

namespace {

// The process's peak resident memory (VmHWM), in MiB.
double PeakResidentMiB() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return -1.0;
}

// A cycle through `bytes` of memory, one step per 64-byte line, in a random order: each load's
// address is the previous load's value, so the loads cannot overlap (a cache or memory latency).
std::vector<uint64_t> MakeChase(size_t bytes) {
  const size_t lines = bytes / 64, stride = 64 / sizeof(uint64_t);
  std::vector<uint64_t> order(lines);
  std::iota(order.begin(), order.end(), uint64_t{0});
  std::shuffle(order.begin(), order.end(), std::mt19937_64(1));
  std::vector<uint64_t> chase(lines * stride, 0);
  for (size_t i = 0; i < lines; ++i) chase[order[i] * stride] = order[(i + 1) % lines] * stride;
  return chase;
}

// The cores this process may run on, in order (empty where the system cannot list them).
std::vector<int> AllowedCores() {
  std::vector<int> cores;
#if defined(__linux__)
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof(allowed), &allowed) != 0) return cores;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed)) cores.push_back(cpu);
  }
#endif
  return cores;
}

// Binds the calling thread to `core`; false where it cannot.
bool PinToCore(int core) {
#if defined(__linux__)
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(core, &one);
  return sched_setaffinity(0, sizeof(one), &one) == 0;
#else
  (void)core;
  return false;
#endif
}

// Nanoseconds per load of `chase` on each core this process may use (AllowedCores' order), each
// on a thread pinned to it: one warm-up lap, then `loads` loads (-1 where it could not be pinned).
std::vector<double> CoreLatencies(const std::vector<uint64_t>& chase, int loads) {
  std::vector<double> nanoseconds;
  const size_t lines = chase.size() / (64 / sizeof(uint64_t));
  for (const int core : AllowedCores()) {
    double result = -1.0;
    std::thread probe([&] {
      if (!PinToCore(core)) return;
      uint64_t at = 0;
      for (size_t i = 0; i < lines; ++i) at = chase[at];
      const auto start = std::chrono::steady_clock::now();
      for (int i = 0; i < loads; ++i) at = chase[at];
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      volatile uint64_t sink = at;  // the loads' result is used: they are not optimised away
      (void)sink;
      result = 1e9 * seconds / loads;
    });
    probe.join();
    nanoseconds.push_back(result);
  }
  return nanoseconds;
}

// Nanoseconds for a write on the first core this process may use to be seen on the second and
// answered (a cache line's trip there and back: what every hand-over between the carve's threads
// costs at least), the median of 16 rounds of 4096 trips, each side on a thread pinned to its
// core. Negative where the process has fewer than two cores.
double CoreRoundTrip() {
  const std::vector<int> cores = AllowedCores();
  if (cores.size() < 2) return -1.0;
  constexpr int kTrips = 4096, kRounds = 16;
  alignas(64) std::atomic<int> flag{0};
  std::thread answer([&] {
    PinToCore(cores[1]);
    for (int i = 0; i < kTrips * kRounds; ++i) {
      while (flag.load(std::memory_order_acquire) != 2 * i + 1) {
      }
      flag.store(2 * i + 2, std::memory_order_release);
    }
  });
  std::vector<double> rounds;
  std::thread ask([&] {
    PinToCore(cores[0]);
    for (int round = 0; round < kRounds; ++round) {
      const auto start = std::chrono::steady_clock::now();
      for (int i = round * kTrips; i < (round + 1) * kTrips; ++i) {
        flag.store(2 * i + 1, std::memory_order_release);
        while (flag.load(std::memory_order_acquire) != 2 * i + 2) {
        }
      }
      rounds.push_back(1e9 / kTrips *
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
                           .count());
    }
  });
  ask.join();
  answer.join();
  std::sort(rounds.begin(), rounds.end());
  return rounds[kRounds / 2];
}

struct Quality {
  double precision = 0.0;
  double completeness = 0.0;
};

Quality MeasureQuality(const raycarve::CarveResult& result,
                       const std::vector<Eigen::Vector3d>& truth) {
  const raycarve::VoxelGrid& grid = result.volume.grid();
  const double within = 2.0 * grid.voxel_size();
  std::vector<uint8_t> seen(grid.num_voxels(), 0);
  int64_t num_seen = 0, near = 0;
  for (const raycarve::ColouredVoxel& voxel : result.surface) {
    if (voxel.num_pixels == 0) continue;
    seen[voxel.index] = 1;
    ++num_seen;
    near += raycarve::TrueSurfaceDistance(grid.Centre(grid.Voxel(voxel.index))) <= within;
  }
  int64_t covered = 0;
  for (const Eigen::Vector3d& point : truth) {
    const Eigen::Vector3i at = grid.VoxelOf(point);
    bool found = false;
    for (int dz = -2; dz <= 2 && !found; ++dz) {
      for (int dy = -2; dy <= 2 && !found; ++dy) {
        for (int dx = -2; dx <= 2 && !found; ++dx) {
          const Eigen::Vector3i voxel = at + Eigen::Vector3i(dx, dy, dz);
          found = grid.Contains(voxel) && seen[grid.Index(voxel)] &&
                  (grid.Centre(voxel) - point).norm() <= within;
        }
      }
    }
    covered += found;
  }
  Quality quality;
  quality.precision = num_seen == 0 ? 0.0 : static_cast<double>(near) / num_seen;
  quality.completeness = truth.empty() ? 0.0 : static_cast<double>(covered) / truth.size();
  return quality;
}

// What the benchmark runs: the scene, and every combination of the lists.
struct BenchmarkPlan {
  raycarve::SyntheticSceneOptions scene;
  std::vector<int> resolutions = {128, 256};
  std::vector<raycarve::VisLookup> lookups = {raycarve::VisLookup::kFootprint,
                                              raycarve::VisLookup::kRayLists};
  // 40: at 30 these 800x600 photos are carved into (completeness 35.9% at 128 voxels, measured).
  double threshold = 40.0;
  bool incremental_statistics = false;
  // One thread (the paper's setting) and every hardware thread; ray lists always use one.
  std::vector<int> thread_counts = {1};
  // One level (the paper's ray casting) and the command line's automatic levels of detail.
  std::vector<int> level_counts = {1, raycarve::kAutomaticLevels};
  std::vector<int> batch_sizes = {raycarve::CarveOptions().batch_voxels};
  int repeats = 1;
  bool core_check = true;

  BenchmarkPlan() {
    scene.num_views = 14;
    scene.width = 800;
    scene.height = 600;
    scene.num_surface_samples = 0;
    if (raycarve::ResolveNumThreads(-1) > 1) thread_counts.push_back(raycarve::ResolveNumThreads(-1));
  }
};

// Reads the flags into *plan; false, with a line on stderr, for a flag it does not know or a
// value it cannot take.
bool ParsePlan(int argc, char** argv, BenchmarkPlan* plan) {
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i], value = argv[i + 1];
    if (flag == "--views") plan->scene.num_views = std::stoi(value);
    else if (flag == "--width") plan->scene.width = std::stoi(value);
    else if (flag == "--height") plan->scene.height = std::stoi(value);
    else if (flag == "--threshold") plan->threshold = std::stod(value);
    else if (flag == "--repeats") plan->repeats = std::max(1, std::stoi(value));
    else if (flag == "--incremental_statistics") plan->incremental_statistics = std::stoi(value) != 0;
    else if (flag == "--core_check") plan->core_check = std::stoi(value) != 0;
    else if (flag == "--vis_lookup") {
      raycarve::VisLookup lookup;
      if (value != "both" && !raycarve::VisLookupFromString(value, &lookup)) {
        std::fprintf(stderr, "--vis_lookup: footprint, ray_lists or both\n");
        return false;
      }
      if (value != "both") plan->lookups = {lookup};
    } else if (flag == "--resolutions" || flag == "--threads" || flag == "--lod_levels" ||
               flag == "--batch_voxels") {
      std::vector<int>& numbers = flag == "--threads"        ? plan->thread_counts
                                  : flag == "--lod_levels"   ? plan->level_counts
                                  : flag == "--batch_voxels" ? plan->batch_sizes
                                                             : plan->resolutions;
      numbers.clear();
      std::stringstream list(value);
      std::string item;
      while (std::getline(list, item, ',')) numbers.push_back(std::stoi(item));
    } else {
      std::fprintf(stderr, "unknown flag %s\n", flag.c_str());
      return false;
    }
  }
  std::string reason;
  if (!plan->scene.IsValid(&reason)) {
    std::fprintf(stderr, "%s\n", reason.c_str());
    return false;
  }
  return true;
}

// One combination of the plan's lists.
struct Configuration {
  int resolution = 0;
  int levels = 1;
  raycarve::VisLookup lookup = raycarve::VisLookup::kFootprint;
  int batch = 0;
  int repeat = 0;
  int threads = 1;
};

// What the runs share: the photos as views, the scene's box, the truth, the pointer chase.
struct Inputs {
  std::vector<raycarve::CalibratedView> views;
  Eigen::AlignedBox3d box;
  std::vector<Eigen::Vector3d> truth;
  std::vector<uint64_t> chase;
};

// The rows' JSON and the convergence seconds per (resolution, levels, lookup, batch, threads)
// over the repeats, in the order first run.
using Key = std::tuple<int, int, std::string, int, int>;
struct Results {
  std::ostringstream json;
  bool first = true;
  std::map<Key, std::vector<double>> convergence;
  std::vector<Key> key_order;
};

void PrintHeader() {
  std::printf("%-10s %-10s %-5s %-7s %-6s %-14s %8s %10s %8s %10s %10s %10s %12s %12s %9s %12s   %s   %s\n",
              "resolution", "vis", "batch", "threads", "levels", "grid", "set-up s", "converge s",
              "colour s", "parallel s", "memory MiB", "peak RSS", "carved", "evaluated",
              "precision", "completeness", "work s / wait s per thread",
              "ns per load per core, round trip");
}

// Each thread's work and wait seconds, for the table and for JSON.
void FormatThreads(const raycarve::CarveStatistics& s, std::string* text, std::string* json) {
  for (size_t t = 0; t < s.thread_work_seconds.size(); ++t) {
    const double work = s.thread_work_seconds[t], wait = s.parallel_seconds - work;
    char entry[64];
    std::snprintf(entry, sizeof(entry), "%s%.2f/%.2f", t == 0 ? "" : " ", work, wait);
    *text += entry;
    std::snprintf(entry, sizeof(entry), "%s{\"work_seconds\": %.4f, \"wait_seconds\": %.4f}",
                  t == 0 ? "" : ", ", work, wait);
    *json += entry;
  }
}

// The cores' load latencies and round trip, for the table and for JSON.
void FormatLatencies(const std::vector<double>& latencies, double round_trip, std::string* text,
                     std::string* json) {
  for (size_t c = 0; c < latencies.size(); ++c) {
    char entry[32];
    std::snprintf(entry, sizeof(entry), "%s%.0f", c == 0 ? "" : "/", latencies[c]);
    *text += entry;
    std::snprintf(entry, sizeof(entry), "%s%.1f", c == 0 ? "" : ", ", latencies[c]);
    *json += entry;
  }
  if (round_trip > 0.0) {
    char entry[32];
    std::snprintf(entry, sizeof(entry), ", trip %.0f", round_trip);
    *text += entry;
  }
}

// Carves one configuration, prints its row and adds it to *results; false (with a line on
// stderr) when the carve would not fit in memory.
bool RunConfiguration(const BenchmarkPlan& plan, const Inputs& inputs, const Configuration& c,
                      Results* results) {
  raycarve::CarveOptions options;
  options.resolution = c.resolution;
  options.threshold = plan.threshold;
  options.vis_lookup = c.lookup;
  options.incremental_statistics = plan.incremental_statistics;
  options.num_threads = c.lookup == raycarve::VisLookup::kRayLists ? 1 : c.threads;
  options.lod_levels = c.levels;
  options.batch_voxels = c.batch;
  const std::string vis = raycarve::VisLookupToString(c.lookup);
  std::string reason;
  if (!raycarve::CheckCarveFits(inputs.views, inputs.box, options, &reason)) {
    std::fprintf(stderr, "resolution %d: %s\n", c.resolution, reason.c_str());
    return false;
  }
  const std::vector<double> latencies =
      plan.core_check ? CoreLatencies(inputs.chase, 1 << 20) : std::vector<double>();
  const double round_trip = plan.core_check ? CoreRoundTrip() : -1.0;
  const raycarve::CarveResult result = raycarve::CarveVolume(inputs.views, inputs.box, options);
  const raycarve::CarveStatistics& s = result.statistics;
  char grid[32];
  std::snprintf(grid, sizeof(grid), "%dx%dx%d", s.dimensions.x(), s.dimensions.y(), s.dimensions.z());
  const double memory = s.peak_memory_bytes / (1024.0 * 1024.0);
  const Quality quality = MeasureQuality(result, inputs.truth);
  std::string threads_text, threads_json, latency_text, latency_json;
  FormatThreads(s, &threads_text, &threads_json);
  FormatLatencies(latencies, round_trip, &latency_text, &latency_json);
  std::printf("%-10d %-10s %-5d %-7d %-6d %-14s %8.2f %10.2f %8.2f %10.2f %10.1f %10.1f %12lld %12lld %8.1f%% %11.1f%%   %s   %s\n",
              c.resolution, vis.c_str(), c.batch, s.threads, static_cast<int>(s.levels.size()),
              grid, s.setup_seconds, s.carve_seconds, s.colour_seconds, s.parallel_seconds,
              memory, PeakResidentMiB(), static_cast<long long>(s.carved),
              static_cast<long long>(s.evaluated), 100.0 * quality.precision,
              100.0 * quality.completeness, threads_text.c_str(), latency_text.c_str());
  std::fflush(stdout);
  const Key key{c.resolution, static_cast<int>(s.levels.size()), vis, c.batch, s.threads};
  if (results->convergence.count(key) == 0) results->key_order.push_back(key);
  results->convergence[key].push_back(s.carve_seconds);
  results->json << (results->first ? "" : ",") << "\n  {\"resolution\": " << c.resolution
       << ", \"repeat\": " << c.repeat
       << ", \"vis_lookup\": \"" << vis << "\", \"batch_voxels\": " << c.batch
       << ", \"threads_asked\": " << options.num_threads << ", \"threads\": " << s.threads
       << ", \"lod_levels\": " << s.levels.size()
       << ", \"lod_automatic\": " << (c.levels == raycarve::kAutomaticLevels ? "true" : "false")
       << ", \"grid\": \"" << grid
       << "\", \"views\": " << inputs.views.size() << ", \"width\": " << plan.scene.width
       << ", \"height\": " << plan.scene.height << ", \"setup_seconds\": " << s.setup_seconds
       << ", \"convergence_seconds\": " << s.carve_seconds
       << ", \"colour_seconds\": " << s.colour_seconds
       << ", \"parallel_seconds\": " << s.parallel_seconds
       << ", \"parallel_runs\": " << s.parallel_runs << ", \"inline_runs\": " << s.inline_runs
       << ", \"per_thread\": [" << threads_json << "]"
       << ", \"core_latency_ns\": [" << latency_json << "]"
       << ", \"core_round_trip_ns\": " << round_trip
       << ", \"memory_mib\": " << memory
       << ", \"peak_rss_mib\": " << PeakResidentMiB() << ", \"carved\": " << s.carved
       << ", \"evaluated\": " << s.evaluated << ", \"precision\": " << quality.precision
       << ", \"completeness\": " << quality.completeness << "}";
  results->first = false;
  return true;
}

// With repeats: the median convergence per configuration and its speed-up over the first thread
// count run for it.
void PrintMedians(int repeats, const Results& results) {
  auto median = [](std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const size_t n = values.size();
    return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  };
  std::printf("\nmedian of %d runs\n%-10s %-6s %-10s %-5s %-7s %10s %9s\n", repeats, "resolution",
              "levels", "vis", "batch", "threads", "converge s", "speed-up");
  for (const Key& key : results.key_order) {
    // The first thread count run for this configuration (key itself, if no other).
    const auto same_configuration = [&key](const Key& other) {
      return std::get<0>(other) == std::get<0>(key) && std::get<1>(other) == std::get<1>(key) &&
             std::get<2>(other) == std::get<2>(key) && std::get<3>(other) == std::get<3>(key);
    };
    const Key& first_threads =
        *std::find_if(results.key_order.begin(), results.key_order.end(), same_configuration);
    const double seconds = median(results.convergence.at(key));
    std::printf("%-10d %-6d %-10s %-5d %-7d %10.2f %8.2fx\n", std::get<0>(key), std::get<1>(key),
                std::get<2>(key).c_str(), std::get<3>(key), std::get<4>(key), seconds,
                median(results.convergence.at(first_threads)) / seconds);
  }
}

}  // namespace

int main(int argc, char** argv) {
  BenchmarkPlan plan;
  if (!ParsePlan(argc, argv, &plan)) return 1;
  std::fprintf(stderr, "rendering %d views of %dx%d...\n", plan.scene.num_views, plan.scene.width,
               plan.scene.height);
  const raycarve::SyntheticScene scene = raycarve::GenerateSyntheticScene(plan.scene);
  Inputs inputs;
  for (const auto& [image_id, image] : scene.reconstruction.images) {
    inputs.views.push_back(raycarve::MakeCalibratedView(
        scene.reconstruction.cameras.at(image.camera_id), image, scene.photos.at(image_id), image.name));
  }
  inputs.box = scene.object_box;
  inputs.truth = raycarve::SampleTrueSurface(scene, 20000, 5, 2);
  PrintHeader();
  if (plan.core_check) inputs.chase = MakeChase(size_t{8} << 20);
  Results results;
  results.json << "[";
  Configuration c;
  for (const int resolution : plan.resolutions) {
    for (const int levels : plan.level_counts) {
      for (const raycarve::VisLookup lookup : plan.lookups) {
        for (const int batch : plan.batch_sizes) {
          for (int repeat = 0; repeat < plan.repeats; ++repeat) {
            for (const int threads : plan.thread_counts) {
              // Ray lists run on one thread: once per repeat.
              if (lookup == raycarve::VisLookup::kRayLists && threads != plan.thread_counts.front()) {
                continue;
              }
              c = Configuration{resolution, levels, lookup, batch, repeat, threads};
              if (!RunConfiguration(plan, inputs, c, &results)) return 1;
            }
          }
        }
      }
    }
  }
  if (plan.repeats > 1) PrintMedians(plan.repeats, results);
  results.json << "\n]\n";
  std::printf("\n%s", results.json.str().c_str());
  return 0;
}
