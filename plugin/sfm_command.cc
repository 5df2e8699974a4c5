// raycarve sfm: photos -> COLMAP structure-from-motion on the CPU -> a COLMAP project to carve.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>
#include <sstream>

#include <glog/logging.h>

#include "calib/camera_models.h"
#include "calib/image_reader.h"
#include "calib/input_error.h"
#include "calib/model_reader.h"
#include "plugin/colmap_runner.h"
#include "plugin/commands.h"
#include "plugin/option_parser.h"
#include "pipeline/workspace.h"

namespace raycarve {
namespace {

namespace fs = std::filesystem;

bool IsPhoto(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* known : {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".ppm", ".pgm"}) {
    if (extension == known) return true;
  }
  return false;
}

void RunStep(const std::string& colmap, const std::string& step,
             const std::vector<std::string>& arguments) {
  std::vector<std::string> full = {step};
  full.insert(full.end(), arguments.begin(), arguments.end());
  std::vector<std::string> tail;
  const int status = RunColmap(colmap, full, &tail);
  if (status == 0) return;
  std::string message = "colmap " + step + " failed with exit status " + std::to_string(status);
  if (status > 128) {
    // 128 + the signal: killed from outside, or by the kernel when memory ran out.
    message += " (killed by signal " + std::to_string(status - 128) +
               (status - 128 == 9 ? ": stopped from outside or out of memory" : "") + ")";
  }
  if (tail.empty()) {
    message += "; it printed nothing";
  } else {
    message += "; its last lines:";
    for (const std::string& line : tail) message += "\n    " + line;
  }
  throw InputError(message);
}

// What `raycarve sfm` takes.
struct SfmOptions {
  std::string image_path, workspace_path, camera_model = "SIMPLE_RADIAL", camera_params;
  std::string colmap_path = "colmap";
  std::string single_camera = "auto", matcher = "auto";
  int min_registered = 3, max_image_size = 1600, max_num_features = 4096, min_num_matches = 15;
  int init_min_num_inliers = 100, abs_pose_min_num_inliers = 30, num_threads = -1;
  double init_min_tri_angle = 16.0;
  std::string colmap_options;
};

std::pair<int, int> SizeKey(const cv::Size& size) { return {size.width, size.height}; }

// Checks everything before running anything; returns the number of photos and counts them by
// stored size in `sizes`.
int CheckSfmInput(const SfmOptions& o, std::map<std::pair<int, int>, int>* sizes) {
  if (o.single_camera != "auto" && o.single_camera != "1" && o.single_camera != "0") {
    throw InputError("--single_camera: '" + o.single_camera + "' is none of auto, 1, 0");
  }
  if (o.matcher != "auto" && o.matcher != "exhaustive" && o.matcher != "sequential") {
    throw InputError("--matcher: '" + o.matcher + "' is none of auto, exhaustive, sequential");
  }
  if (o.max_image_size < 100 || o.max_num_features < 100) {
    throw InputError("--max_image_size and --max_num_features must be at least 100");
  }
  const CameraModelId model_id = CameraModelIdFromName(o.camera_model, "--camera_model");
  if (!o.camera_params.empty()) {
    int count = 1;
    for (const char c : o.camera_params) count += c == ',';
    if (count != CameraModelNumParams(model_id)) {
      throw InputError("--camera_params: " + o.camera_model + " takes " +
                       std::to_string(CameraModelNumParams(model_id)) + " parameters, got " +
                       std::to_string(count));
    }
  }
  if (!fs::is_directory(o.image_path)) throw InputError(o.image_path + ": photo folder does not exist");
  int num_photos = 0;
  for (const fs::directory_entry& entry : fs::recursive_directory_iterator(o.image_path)) {
    if (!entry.is_regular_file() || !IsPhoto(entry.path())) continue;
    ++num_photos;
    if (sizes != nullptr) ++(*sizes)[SizeKey(ReadImageSize(entry.path().string()))];
  }
  if (num_photos < 2) {
    throw InputError(o.image_path + ": " + std::to_string(num_photos) +
                     " photos found (png, jpg, tif, bmp, ppm); structure-from-motion needs at "
                     "least 2");
  }
  const fs::path workspace(o.workspace_path);
  const fs::path database = workspace / "database.db", sparse = workspace / "sparse";
  if (fs::exists(database) || (fs::exists(sparse) && !fs::is_empty(sparse))) {
    throw InputError(o.workspace_path +
                     ": already holds database.db or sparse/; raycarve sfm never overwrites a "
                     "project: remove them or choose another --workspace_path");
  }
  return num_photos;
}

// The project's folders: sparse/ made, images/ a link to the photos.
void PrepareWorkspace(const SfmOptions& o, const fs::path& sparse) {
  const fs::path workspace(o.workspace_path);
  std::error_code error;
  fs::create_directories(sparse, error);
  if (error) throw InputError(sparse.string() + ": cannot create: " + error.message());
  const fs::path images = workspace / "images";
  const fs::path absolute_images = fs::absolute(o.image_path);
  if (!fs::exists(images)) {
    fs::create_directory_symlink(absolute_images, images, error);
    if (error) throw InputError(images.string() + ": cannot link to the photos: " + error.message());
  } else if (fs::equivalent(images, absolute_images, error) == false) {
    LOG(WARNING) << images.string() << " exists and is not " << o.image_path
                 << "; raycarve carve will read " << images.string()
                 << " unless given --image_path " << o.image_path;
  }
}

// What sfm decided for the photos it found: one camera for all or one per photo, and the matcher.
struct SfmPlan {
  bool single_camera = true;
  std::string matcher = "exhaustive";
};

// Exhaustive matching matches every pair: n(n-1)/2 of them, about 0.1-0.2 s each on a CPU at
// 4096 features. Up to 50 photos (1,225 pairs, a few minutes) it is the surest; beyond, each
// photo is matched with its 20 neighbours in name order (and at quadratic steps), as photos taken
// in a walk around the subject are named in order. COLMAP's own automatic reconstructor switches
// at 200 photos with a GPU and a vocabulary tree, which a CPU install without network lacks.
constexpr int kMaxExhaustivePhotos = 50;

SfmPlan PlanSfm(const SfmOptions& o, int num_photos, const std::map<std::pair<int, int>, int>& sizes) {
  SfmPlan plan;
  if (o.single_camera == "auto") {
    // COLMAP refuses one camera for photos of different sizes (a phone's portrait and landscape
    // shots): then each photo gets its own.
    plan.single_camera = sizes.size() <= 1;
    if (!plan.single_camera) {
      std::string list;
      for (const auto& [size, count] : sizes) {
        list += (list.empty() ? "" : ", ") + std::to_string(count) + " of " +
                std::to_string(size.first) + "x" + std::to_string(size.second);
      }
      LOG(INFO) << "sfm: photos of " << sizes.size() << " sizes (" << list
                << "): one camera per photo (--single_camera auto)";
    }
  } else {
    plan.single_camera = o.single_camera == "1";
    if (plan.single_camera && sizes.size() > 1) {
      throw InputError("--single_camera 1: the photos in " + o.image_path + " have " +
                       std::to_string(sizes.size()) + " different sizes, and COLMAP refuses one "
                       "camera for them; use --single_camera auto");
    }
  }
  plan.matcher = o.matcher != "auto" ? o.matcher
                 : num_photos <= kMaxExhaustivePhotos ? "exhaustive" : "sequential";
  return plan;
}

// COLMAP's three steps, on the CPU, each with the options of its sections last.
void RunColmapSteps(const SfmOptions& o, const SfmPlan& plan, const std::string& colmap,
                    int num_photos, const fs::path& database, const fs::path& sparse) {
  const ColmapPassThrough passed = SplitColmapOptions(o.colmap_options);
  const std::string threads = std::to_string(o.num_threads);
  LOG(INFO) << "sfm: " << num_photos << " photos in " << o.image_path << "; 1/3 feature extraction"
            << " (at most " << o.max_image_size << " px, " << o.max_num_features << " features)";
  std::vector<std::string> extract = {
      "--database_path", database.string(), "--image_path", o.image_path,
      "--ImageReader.camera_model", o.camera_model,
      "--ImageReader.single_camera", plan.single_camera ? "1" : "0",
      "--SiftExtraction.use_gpu", "0",
      "--SiftExtraction.max_image_size", std::to_string(o.max_image_size),
      "--SiftExtraction.max_num_features", std::to_string(o.max_num_features),
      "--SiftExtraction.num_threads", threads};
  if (!o.camera_params.empty()) {
    extract.insert(extract.end(), {"--ImageReader.camera_params", o.camera_params});
  }
  extract.insert(extract.end(), passed.extractor.begin(), passed.extractor.end());
  RunStep(colmap, "feature_extractor", extract);
  LOG(INFO) << "sfm: 2/3 " << plan.matcher << " matching";
  std::vector<std::string> match = {"--database_path", database.string(),
                                    "--SiftMatching.use_gpu", "0", "--SiftMatching.num_threads",
                                    threads};
  if (plan.matcher == "exhaustive") {
    // Blocks of 10 photos rather than COLMAP's 50: the same pairs, and a progress line per block
    // (25 photos of 12 MP matched in one block printed nothing for two minutes).
    match.insert(match.end(), {"--ExhaustiveMatching.block_size", "10"});
  }
  if (plan.matcher == "sequential") {
    match.insert(match.end(), {"--SequentialMatching.overlap", "20",
                               "--SequentialMatching.quadratic_overlap", "1"});
  }
  match.insert(match.end(), passed.matcher.begin(), passed.matcher.end());
  RunStep(colmap, plan.matcher + "_matcher", match);
  LOG(INFO) << "sfm: 3/3 mapping";
  std::vector<std::string> map = {
      "--database_path", database.string(), "--image_path", o.image_path,
      "--output_path", sparse.string(),
      "--Mapper.num_threads", threads,
      "--Mapper.min_num_matches", std::to_string(o.min_num_matches),
      "--Mapper.init_min_num_inliers", std::to_string(o.init_min_num_inliers),
      "--Mapper.abs_pose_min_num_inliers", std::to_string(o.abs_pose_min_num_inliers),
      "--Mapper.init_min_tri_angle", std::to_string(o.init_min_tri_angle)};
  if (!o.camera_params.empty()) {
    // Known intrinsics stay as given: on narrow object rings the focal length drifts otherwise.
    map.insert(map.end(), {"--Mapper.ba_refine_focal_length", "0",
                           "--Mapper.ba_refine_principal_point", "0",
                           "--Mapper.ba_refine_extra_params", "0"});
  }
  map.insert(map.end(), passed.mapper.begin(), passed.mapper.end());
  RunStep(colmap, "mapper", map);

}

// The mapper's models, the largest's figures, and what to do next.
void ReportModels(const SfmOptions& o, int num_photos, const fs::path& sparse) {
  const std::vector<ModelCandidate> models = NumberedModels(sparse.string());
  if (models.empty()) {
    throw InputError("colmap mapper made no model in " + sparse.string() +
                     ": no initial pair of photos was found; try --init_min_num_inliers 50 "
                     "--init_min_tri_angle 4, or known --camera_params");
  }
  const ModelCandidate& best = *std::max_element(
      models.begin(), models.end(), [](const ModelCandidate& a, const ModelCandidate& b) {
        return a.num_images < b.num_images;
      });
  const Reconstruction reconstruction = ReadModel(best.path);
  double error_sum = 0.0;
  size_t observations = 0;
  for (const auto& [id, point] : reconstruction.points3D) {
    error_sum += point.error;
    observations += point.track.size();
  }
  std::printf("\nsfm: %zu model(s) in %s", models.size(), sparse.string().c_str());
  for (const ModelCandidate& model : models) {
    std::printf("%s%s: %lld photos", &model == &models.front() ? " (" : ", ",
                fs::path(model.path).filename().string().c_str(),
                static_cast<long long>(model.num_images));
  }
  std::printf(")\n  largest         %s: %zu of %d photos registered, %zu points, mean track %.2f, "
              "mean reprojection error %.3f px\n",
              best.path.c_str(), reconstruction.images.size(), num_photos,
              reconstruction.points3D.size(),
              reconstruction.points3D.empty() ? 0.0
                                              : static_cast<double>(observations) /
                                                    reconstruction.points3D.size(),
              reconstruction.points3D.empty() ? 0.0 : error_sum / reconstruction.points3D.size());
  if (static_cast<int>(reconstruction.images.size()) < o.min_registered) {
    throw InputError("colmap registered only " + std::to_string(reconstruction.images.size()) +
                     " of " + std::to_string(num_photos) + " photos (--min_registered " +
                     std::to_string(o.min_registered) + "); try known --camera_params, "
                     "--abs_pose_min_num_inliers 15 or --init_min_tri_angle 4");
  }
  if (static_cast<int>(reconstruction.images.size()) < num_photos) {
    // Which ones, by name: COLMAP's lines above say why a photo was refused at extraction; the
    // others found too few matches to be placed.
    std::set<std::string> registered;
    for (const auto& [id, image] : reconstruction.images) registered.insert(image.name);
    std::vector<std::string> missing;
    for (const fs::directory_entry& entry : fs::recursive_directory_iterator(o.image_path)) {
      if (!entry.is_regular_file() || !IsPhoto(entry.path())) continue;
      const std::string name = fs::relative(entry.path(), o.image_path).generic_string();
      if (!registered.count(name)) missing.push_back(name);
    }
    std::sort(missing.begin(), missing.end());
    std::string names;
    for (size_t i = 0; i < missing.size() && i < 8; ++i) names += (i ? ", " : "") + missing[i];
    if (missing.size() > 8) names += ", ...";
    std::printf("  unregistered    %d photos (%s): too few matches to place them (or refused at "
                "extraction: see COLMAP's lines above). More overlap between photos helps; on a "
                "narrow object ring, --abs_pose_min_num_inliers 15 --init_min_tri_angle 8\n",
                num_photos - static_cast<int>(reconstruction.images.size()), names.c_str());
  }
  std::printf("  next            raycarve carve --workspace_path %s\n", o.workspace_path.c_str());
}

}  // namespace

ColmapPassThrough SplitColmapOptions(const std::string& text) {
  ColmapPassThrough passed;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    if (item.empty()) continue;
    const size_t dot = item.find('.'), equals = item.find('=');
    if (dot == std::string::npos || equals == std::string::npos || dot > equals || dot == 0 ||
        equals == dot + 1 || equals + 1 == item.size()) {
      throw InputError("--colmap_options: '" + item + "' is not Section.name=value");
    }
    const std::string section = item.substr(0, dot);
    const std::vector<std::string> option = {"--" + item.substr(0, equals),
                                             item.substr(equals + 1)};
    std::vector<std::string>* step = nullptr;
    if (section == "ImageReader" || section == "SiftExtraction") step = &passed.extractor;
    if (section == "SiftMatching" || section == "ExhaustiveMatching" ||
        section == "SequentialMatching" || section == "TwoViewGeometry") {
      step = &passed.matcher;
    }
    if (section == "Mapper") step = &passed.mapper;
    if (step == nullptr) {
      throw InputError("--colmap_options: section '" + section +
                       "' is none of the steps' (ImageReader, SiftExtraction: feature_extractor; "
                       "SiftMatching, ExhaustiveMatching, SequentialMatching, TwoViewGeometry: "
                       "the matcher; "
                       "Mapper: mapper)");
    }
    step->insert(step->end(), option.begin(), option.end());
  }
  return passed;
}

int RunSfm(int argc, char** argv) {
  SfmOptions o;
  OptionParser parser(
      "sfm",
      "Runs COLMAP's structure-from-motion on the CPU (feature_extractor, exhaustive or "
      "sequential matcher, mapper) and leaves a standard COLMAP project in --workspace_path: database.db, sparse/N "
      "(the mapper's models), images (a link to --image_path). Known intrinsics can be given "
      "and are then held fixed. Then: raycarve carve --workspace_path P.");
  parser.AddRequired("image_path", &o.image_path, "folder of photos");
  parser.AddRequired("workspace_path", &o.workspace_path,
                     "project folder to create (must not hold a database or models yet)");
  parser.AddDefault("camera_model", &o.camera_model,
                    "COLMAP camera model of the photos (e.g. SIMPLE_RADIAL, PINHOLE, OPENCV)");
  parser.AddDefault("camera_params", &o.camera_params,
                    "known intrinsics, comma-separated in the model's order (COLMAP's); held "
                    "fixed by the mapper. Empty: estimated");
  parser.AddDefault("single_camera", &o.single_camera,
                    "1: all photos share one camera; 0: one camera per photo; auto: 1 when all "
                    "photos have one size, else 0", {"auto", "1", "0"});
  parser.AddDefault("matcher", &o.matcher,
                    "exhaustive (every pair), sequential (each photo with its 20 neighbours in "
                    "name order), or auto: exhaustive up to " +
                        std::to_string(kMaxExhaustivePhotos) + " photos",
                    {"auto", "exhaustive", "sequential"});
  parser.AddDefault("colmap_path", &o.colmap_path, "the colmap program");
  parser.AddDefault("min_registered", &o.min_registered,
                    "fail unless the largest model registers at least this many photos");
  parser.AddDefault("max_image_size", &o.max_image_size,
                    "SiftExtraction.max_image_size: features are found on photos scaled down to "
                    "this longer side (COLMAP's default 3200 takes many seconds a photo on a CPU)");
  parser.AddDefault("max_num_features", &o.max_num_features,
                    "SiftExtraction.max_num_features (COLMAP's default 8192 makes matching on a "
                    "CPU 4x slower)");
  parser.AddDefault("min_num_matches", &o.min_num_matches, "Mapper.min_num_matches");
  parser.AddDefault("init_min_num_inliers", &o.init_min_num_inliers, "Mapper.init_min_num_inliers");
  parser.AddDefault("abs_pose_min_num_inliers", &o.abs_pose_min_num_inliers,
                    "Mapper.abs_pose_min_num_inliers (lower it for hard sets)");
  parser.AddDefault("init_min_tri_angle", &o.init_min_tri_angle,
                    "Mapper.init_min_tri_angle in degrees (lower it for narrow rings)");
  parser.AddDefault("num_threads", &o.num_threads, "threads for COLMAP (-1: all)");
  parser.AddDefault("colmap_options", &o.colmap_options,
                    "further COLMAP options, comma-separated Section.name=value (e.g. "
                    "SiftExtraction.max_num_features=4096,Mapper.ba_refine_focal_length=0), each "
                    "given to the step that takes its section; they come last, so they win");
  if (!parser.Parse(argc, argv)) return 0;
  SplitColmapOptions(o.colmap_options);  // checked before anything runs

  std::map<std::pair<int, int>, int> sizes;
  const int num_photos = CheckSfmInput(o, &sizes);
  const SfmPlan plan = PlanSfm(o, num_photos, sizes);
  const fs::path workspace(o.workspace_path);
  const fs::path database = workspace / "database.db", sparse = workspace / "sparse";
  const std::string colmap = FindColmap(o.colmap_path);
  PrepareWorkspace(o, sparse);
  RunColmapSteps(o, plan, colmap, num_photos, database, sparse);
  ReportModels(o, num_photos, sparse);
  return 0;
}

}  // namespace raycarve
