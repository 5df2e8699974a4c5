#include "calib/view_reader.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <filesystem>
#include <thread>
#include <sstream>

#include <glog/logging.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "calib/image_reader.h"
#include "calib/input_error.h"

namespace raycarve {

std::string ViewReaderSummary::Summary() const {
  std::ostringstream text;
  text << "views: " << num_loaded << " of " << num_registered << " registered images loaded";
  if (!missing.empty()) text << ", " << missing.size() << " skipped (photo missing)";
  if (masks_from_files > 0) text << "; " << masks_from_files << " masks from files";
  if (masks_from_backdrop > 0) {
    text << "; " << masks_from_backdrop << " masks from the backdrop (mean colour "
         << mean_backdrop.transpose() << ")";
  }
  if (object_on_border > 0) {
    text << "; " << object_on_border << " photos with the object running out of the frame ("
         << std::lround(100.0 * object_border_share)
         << "% of their border on average in its colours, by the sparse points, not backdrop)";
  }
  if (no_plain_backdrop > 0) text << "; " << no_plain_backdrop << " photos without a plain backdrop";
  if (num_downscaled > 0) text << "; " << num_downscaled << " photos reduced (--max_image_size)";
  return text.str();
}

namespace {

// The pixels of the image's sparse points that lie inside `volume` (all, when it is empty).
std::vector<Eigen::Vector2d> SeedPixels(const Reconstruction& reconstruction, const Image& image,
                                        const Eigen::AlignedBox3d& volume,
                                        const Eigen::Vector2d& pixel_scale) {
  std::vector<Eigen::Vector2d> seeds;
  for (const Point2D& point2D : image.points2D) {
    const auto found = reconstruction.points3D.find(point2D.point3D_id);
    if (found == reconstruction.points3D.end()) continue;
    if (!volume.isEmpty() && !volume.contains(found->second.xyz)) continue;
    seeds.push_back(point2D.xy.cwiseProduct(pixel_scale));
  }
  return seeds;
}

// Where the sparse points inside `volume` (all, when it is empty) fall in the photo, whether or
// not the image observed them: a point of the scene projects onto the scene (itself, or what
// stands in front of it), never onto the backdrop behind. This tells the object's colours from
// the backdrop's in every photo, held-out ones included (whose own observations are removed).
std::vector<Eigen::Vector2d> ProjectedPointPixels(const Reconstruction& reconstruction,
                                                  const Camera& camera, const Image& image,
                                                  const Eigen::AlignedBox3d& volume) {
  std::vector<Eigen::Vector2d> pixels;
  Eigen::Vector2d pixel;
  for (const auto& [id, point] : reconstruction.points3D) {
    if (!volume.isEmpty() && !volume.contains(point.xyz)) continue;
    if (ProjectIntoFrame(camera, image.cam_from_world, point.xyz, &pixel)) pixels.push_back(pixel);
  }
  return pixels;
}

// Points along the outline of `volume` in the photo (its twelve edges, sampled so that the
// camera's distortion bends them as it bends the photo); empty when the volume is unknown or
// reaches behind the camera, where no outline bounds what the photo shows of it.
std::vector<cv::Point> VolumeOutline(const Camera& camera, const Image& image,
                                     const Eigen::AlignedBox3d& volume) {
  std::vector<cv::Point> outline;
  if (volume.isEmpty()) return outline;
  const int steps = 16;
  for (int corner = 0; corner < 8; ++corner) {
    for (int axis = 0; axis < 3; ++axis) {
      if (corner & (1 << axis)) continue;  // each edge once, from its lower end
      const Eigen::Vector3d start = volume.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
      Eigen::Vector3d end = start;
      end[axis] = volume.max()[axis];
      for (int i = 0; i <= steps; ++i) {
        const Eigen::Vector3d world = start + (end - start) * (static_cast<double>(i) / steps);
        const Eigen::Vector3d local = image.cam_from_world * world;
        if (!(local.z() > 1e-9)) return {};
        const Eigen::Vector2d pixel = camera.ImgFromCam(local.head<2>() / local.z());
        if (!pixel.allFinite() || pixel.cwiseAbs().maxCoeff() > 1e7) return {};
        outline.emplace_back(static_cast<int>(std::lround(pixel.x())),
                             static_cast<int>(std::lround(pixel.y())));
      }
    }
  }
  return outline;
}

}  // namespace

namespace {

// What loading one registered image gave.
struct LoadedView {
  bool missing = false;  // photo not found, skipped
  bool downscaled = false;
  std::string path;
  CalibratedView view;
  PhotoMaskInfo info;
  std::exception_ptr error;
};

// The mask file of `image` in options.mask_path (COLMAP's "<name>.png", else the photo's own name),
// read and, when the photo was reduced, reduced with it; *mask_file its path.
cv::Mat ReadMaskFile(const Image& image, image_t image_id, const ViewReaderOptions& options,
                     const Camera& full_camera, const Eigen::Vector2i& size, bool reduced,
                     std::string* mask_file) {
  const std::filesystem::path folder(options.mask_path);
  const std::string colmap_style = (folder / (image.name + ".png")).string();
  const std::string same_name = (folder / image.name).string();
  *mask_file = WhyNotAFile(colmap_style) != "not found" ? colmap_style : same_name;
  const std::string why_mask = WhyNotAFile(*mask_file);
  if (why_mask == "not found") {
    throw InputError(colmap_style + ": mask of image " + std::to_string(image_id) +
                     " not found (nor " + same_name + ")");
  }
  if (!why_mask.empty()) {
    throw InputError(*mask_file + ": mask of image " + std::to_string(image_id) + " " + why_mask);
  }
  cv::Mat mask = ReadImage(*mask_file, cv::IMREAD_GRAYSCALE);
  if (mask.empty()) throw InputError(*mask_file + ": mask cannot be decoded as an image");
  if (reduced && mask.cols == static_cast<int>(full_camera.width) &&
      mask.rows == static_cast<int>(full_camera.height)) {
    cv::resize(mask, mask, cv::Size(size.x(), size.y()), 0, 0, cv::INTER_NEAREST);
  }
  return mask;
}

// The automatic mask from the photo's backdrop (options.background.mode kAuto): none where the
// border is no plain backdrop, nor where the mask would hold no object. Fills `info`.
cv::Mat BackdropMask(const Reconstruction& reconstruction, const Image& image, const Camera& camera,
                     const cv::Mat& rgb, const Eigen::Vector2d& pixel_scale,
                     const ViewReaderOptions& options, const std::string& path,
                     PhotoMaskInfo* info) {
  cv::Mat mask;
  const std::vector<Eigen::Vector2d> seeds =
      SeedPixels(reconstruction, image, options.volume, pixel_scale);
  info->backdrop = EstimateBackdropModel(
      rgb, options.background.tolerance,
      ProjectedPointPixels(reconstruction, camera, image, options.volume));
  if (!info->backdrop.found) {
    LOG(WARNING) << path << ": " << info->backdrop.Summary() << "; no backdrop mask";
  } else {
    mask = ObjectMaskFromModel(rgb, info->backdrop, options.background, seeds,
                               VolumeOutline(camera, image, options.volume), &info->mask);
    info->source = "backdrop";
  }
  if (!mask.empty() && cv::countNonZero(mask) == 0) {
    // A photo of the object is never all backdrop: a mask that says so found no object in
    // its colours (a grey photo, a backdrop that matches it), and would carve the model away
    // in every photo through the visual hull. The photo is carved without a mask.
    LOG(WARNING) << path << ": the backdrop mask holds no object; the photo is used without a mask";
    mask.release();
    info->source = "none";
  } else if (info->source == "backdrop") {
    VLOG(1) << path << ": backdrop " << info->backdrop.Summary() << ", object "
            << std::lround(100.0 * info->mask.object_share) << "% of the photo, "
            << info->mask.seeds << " sparse points as seeds";
  }
  return mask;
}

// Refuses a view whose camera's distortion folds the image: almost no pixel of the undistorted
// photo has a source, nothing to carve with.
void CheckViewHoldsPixels(const CalibratedView& view, const Camera& camera, const std::string& path) {
  const double valid_share =
      static_cast<double>(cv::countNonZero(view.valid)) / view.valid.total();
  if (valid_share < kMinValidShare) {
    std::ostringstream text;
    text << path << ": camera " << camera.camera_id << " (" << CameraModelName(camera.model)
         << ", params";
    for (double param : camera.params) text << " " << param;
    text << ") leaves " << 100.0 * valid_share
         << "% of the undistorted photo with a source pixel: its distortion folds the image; "
            "check the camera's parameters";
    throw InputError(text.str());
  }
}

LoadedView LoadView(const Reconstruction& reconstruction, image_t image_id, const Image& image,
                    const std::string& image_path, const ViewReaderOptions& options) {
  LoadedView loaded;
  const std::string path = (std::filesystem::path(image_path) / image.name).string();
  loaded.path = path;
  const std::string why = WhyNotAFile(path);
  if (!why.empty()) {
    if (options.skip_missing_images && why == "not found") {
      LOG(WARNING) << path << ": photo of image " << image_id << " not found; skipped";
      loaded.missing = true;
      return loaded;
    }
    throw InputError(path + ": photo of image " + std::to_string(image_id) + " ('" + image.name +
                     "') " + why);
  }
  const cv::Mat bgr = ReadImage(path, cv::IMREAD_COLOR);
  if (bgr.empty()) {
    throw InputError(path + ": photo of image " + std::to_string(image_id) +
                     " cannot be decoded as an image");
  }
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  cv::Mat mask;
  std::string mask_file;
  PhotoMaskInfo& info = loaded.info;
  info.name = image.name;
  info.source = "none";
  const Camera& full_camera = reconstruction.cameras.at(image.camera_id);
  if (rgb.cols != static_cast<int>(full_camera.width) ||
      rgb.rows != static_cast<int>(full_camera.height)) {
    throw InputError(path + ": photo of image " + std::to_string(image_id) + " is " +
                     std::to_string(rgb.cols) + "x" + std::to_string(rgb.rows) + ", its camera " +
                     std::to_string(full_camera.camera_id) + " " +
                     std::to_string(full_camera.width) + "x" + std::to_string(full_camera.height));
  }
  // Photos larger than max_image_size are reduced before anything else, one at a time.
  const Eigen::Vector2i size =
      LimitedImageSize(full_camera.width, full_camera.height, options.max_image_size);
  const bool reduced = size.x() != rgb.cols || size.y() != rgb.rows;
  const Camera camera = reduced ? RescaledCamera(full_camera, size.x(), size.y()) : full_camera;
  const Eigen::Vector2d pixel_scale(static_cast<double>(size.x()) / full_camera.width,
                                    static_cast<double>(size.y()) / full_camera.height);
  if (reduced) {
    cv::resize(rgb, rgb, cv::Size(size.x(), size.y()), 0, 0, cv::INTER_AREA);
    loaded.downscaled = true;
  }
  if (!options.mask_path.empty()) {
    mask = ReadMaskFile(image, image_id, options, full_camera, size, reduced, &mask_file);
    info.source = "file";
  } else if (options.background.mode == BackgroundOptions::Mode::kColour) {
    mask = ObjectMaskFromBackdrop(rgb, options.background.colour, options.background.tolerance);
    mask_file = path + " (backdrop mask)";
    info.source = "colour";
  } else if (options.background.mode == BackgroundOptions::Mode::kAuto) {
    mask = BackdropMask(reconstruction, image, camera, rgb, pixel_scale, options, path, &info);
    if (!mask.empty()) mask_file = path + " (backdrop mask)";
  }
  if (!mask.empty()) info.object_share = static_cast<double>(cv::countNonZero(mask)) / mask.total();
  loaded.view = MakeCalibratedView(camera, image, rgb, path, mask, mask_file);
  CheckViewHoldsPixels(loaded.view, camera, path);
  VLOG(1) << path << ": view built";
  return loaded;
}

}  // namespace

std::vector<CalibratedView> ReadCalibratedViews(const Reconstruction& reconstruction,
                                                const std::string& image_path,
                                                const ViewReaderOptions& options,
                                                ViewReaderSummary* summary) {
  ViewReaderSummary local_summary;
  if (summary == nullptr) summary = &local_summary;
  *summary = ViewReaderSummary();
  summary->num_registered = static_cast<int>(reconstruction.images.size());
  if (!std::filesystem::is_directory(image_path)) {
    throw InputError(image_path + ": image folder does not exist or is not a folder");
  }
  // Photos are decoded, masked and undistorted on several threads; the views, the summary and
  // the first error (in image-id order) are the same for any thread count.
  std::vector<std::pair<image_t, const Image*>> images;
  for (const auto& [image_id, image] : reconstruction.images) images.emplace_back(image_id, &image);
  std::vector<LoadedView> loaded(images.size());
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const int num_threads = static_cast<int>(std::min<size_t>(
      images.size(), options.num_threads > 0 ? options.num_threads : cores));
  std::atomic<size_t> next{0};
  const auto work = [&] {
    for (size_t i = next++; i < images.size(); i = next++) {
      try {
        loaded[i] = LoadView(reconstruction, images[i].first, *images[i].second, image_path,
                             options);
      } catch (...) {
        loaded[i].error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < num_threads; ++t) threads.emplace_back(work);
  work();
  for (std::thread& thread : threads) thread.join();

  std::vector<CalibratedView> views;
  for (LoadedView& result : loaded) {
    if (result.error) std::rethrow_exception(result.error);
    if (result.missing) {
      summary->missing.push_back(result.path);
      continue;
    }
    const PhotoMaskInfo& info = result.info;
    if (info.source == "file") ++summary->masks_from_files;
    if (info.source == "colour") {
      summary->mean_backdrop += options.background.colour;
      ++summary->masks_from_backdrop;
    }
    if (info.source == "backdrop") {
      summary->mean_backdrop += info.backdrop.colours[0];
      ++summary->masks_from_backdrop;
    }
    if (options.mask_path.empty() && options.background.mode == BackgroundOptions::Mode::kAuto &&
        !info.backdrop.found) {
      ++summary->no_plain_backdrop;
    }
    if (!info.backdrop.object_colours.empty()) {
      ++summary->object_on_border;
      summary->object_border_share += info.backdrop.object_border_share;
    }
    summary->photos.push_back(info);
    summary->num_downscaled += result.downscaled;
    views.push_back(std::move(result.view));
  }
  summary->num_loaded = static_cast<int>(views.size());
  if (summary->masks_from_backdrop > 0) summary->mean_backdrop /= summary->masks_from_backdrop;
  if (summary->object_on_border > 0) summary->object_border_share /= summary->object_on_border;
  if (views.empty()) {
    throw InputError(image_path + ": no view could be built: the model has " +
                     std::to_string(reconstruction.images.size()) +
                     " registered images and none of their photos was found");
  }
  return views;
}

}  // namespace raycarve
