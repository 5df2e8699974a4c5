// Google Benchmark figures for calib/: the cost of undistortion maps per camera model, of
// unprojecting pixels, and of reading models in both formats. Run:
//   scripts/run_benchmark.sh builds it; then build/benchmarks/calib_benchmark
#include <filesystem>
#include <random>

#include <benchmark/benchmark.h>

#include "calib/model_reader.h"
#include "calib/model_writer.h"
#include "calib/undistortion.h"
#include "samples/synthetic_scene.h"

namespace raycarve {
namespace {

Camera ExampleCamera(CameraModelId model) {
  Camera camera;
  camera.model = model;
  camera.width = 640;
  camera.height = 480;
  camera.params = ExampleCameraParams(model, 640, 480, 600.0);
  return camera;
}

void BM_BuildUndistortionMaps640x480(benchmark::State& state) {
  const CameraModelId model = static_cast<CameraModelId>(state.range(0));
  const Camera camera = ExampleCamera(model);
  for (auto _ : state) benchmark::DoNotOptimize(BuildUndistortionMaps(camera));
  state.SetLabel(CameraModelName(model));
  state.SetItemsProcessed(state.iterations() * 640 * 480);
}
BENCHMARK(BM_BuildUndistortionMaps640x480)->DenseRange(0, 10)->Unit(benchmark::kMillisecond);

void BM_CamFromImg(benchmark::State& state) {
  const CameraModelId model = static_cast<CameraModelId>(state.range(0));
  const Camera camera = ExampleCamera(model);
  std::mt19937 random(1);
  std::uniform_real_distribution<double> x(0, 640), y(0, 480);
  std::vector<Eigen::Vector2d> pixels(1024);
  for (Eigen::Vector2d& pixel : pixels) pixel = Eigen::Vector2d(x(random), y(random));
  size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(camera.CamFromImg(pixels[i++ % pixels.size()]));
  state.SetLabel(CameraModelName(model));
}
BENCHMARK(BM_CamFromImg)->DenseRange(0, 10);

void BM_ReadModel(benchmark::State& state) {
  const ModelFormat format = state.range(0) == 0 ? ModelFormat::kBinary : ModelFormat::kText;
  SyntheticSceneOptions options;
  options.num_views = 16;
  options.width = 64;  // photos are not read; keep rendering cheap
  options.height = 48;
  options.num_surface_samples = 20000;
  const SyntheticScene scene = GenerateSyntheticScene(options);
  const std::string folder =
      (std::filesystem::temp_directory_path() / "raycarve_benchmark_model").string();
  WriteModel(scene.reconstruction, folder, format);
  for (auto _ : state) benchmark::DoNotOptimize(ReadModel(folder));
  state.SetLabel(ModelFormatToString(format) + ", " +
                 std::to_string(scene.reconstruction.points3D.size()) + " points");
  std::filesystem::remove_all(folder);
}
BENCHMARK(BM_ReadModel)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace raycarve

BENCHMARK_MAIN();
