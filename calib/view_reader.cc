#include "calib/view_reader.h"

#include <filesystem>
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
  if (no_plain_backdrop > 0) text << "; " << no_plain_backdrop << " photos without a plain backdrop";
  return text.str();
}

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
  std::vector<CalibratedView> views;
  for (const auto& [image_id, image] : reconstruction.images) {
    const std::string path = (std::filesystem::path(image_path) / image.name).string();
    if (!std::filesystem::is_regular_file(path)) {
      if (options.skip_missing_images) {
        LOG(WARNING) << path << ": photo of image " << image_id << " not found; skipped";
        summary->missing.push_back(path);
        continue;
      }
      throw InputError(path + ": photo of image " + std::to_string(image_id) + " ('" +
                       image.name + "') not found");
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
    if (!options.mask_path.empty()) {
      const std::filesystem::path folder(options.mask_path);
      const std::string colmap_style = (folder / (image.name + ".png")).string();
      const std::string same_name = (folder / image.name).string();
      mask_file = std::filesystem::is_regular_file(colmap_style) ? colmap_style : same_name;
      if (!std::filesystem::is_regular_file(mask_file)) {
        throw InputError(colmap_style + ": mask of image " + std::to_string(image_id) +
                         " not found (nor " + same_name + ")");
      }
      mask = ReadImage(mask_file, cv::IMREAD_GRAYSCALE);
      if (mask.empty()) throw InputError(mask_file + ": mask cannot be decoded as an image");
      ++summary->masks_from_files;
    } else if (options.background.mode != BackgroundOptions::Mode::kNone) {
      Eigen::Vector3d backdrop = options.background.colour;
      if (options.background.mode == BackgroundOptions::Mode::kAuto &&
          !EstimateBackdropColour(rgb, options.background.tolerance, &backdrop)) {
        LOG(WARNING) << path << ": the photo's border is not one colour; no backdrop mask";
        ++summary->no_plain_backdrop;
      } else {
        mask = ObjectMaskFromBackdrop(rgb, backdrop, options.background.tolerance);
        mask_file = path + " (backdrop mask)";
        summary->mean_backdrop += backdrop;
        ++summary->masks_from_backdrop;
      }
    }
    const Camera& camera = reconstruction.cameras.at(image.camera_id);
    views.push_back(MakeCalibratedView(camera, image, rgb, path, mask, mask_file));
    VLOG(1) << path << ": view built";
  }
  summary->num_loaded = static_cast<int>(views.size());
  if (summary->masks_from_backdrop > 0) summary->mean_backdrop /= summary->masks_from_backdrop;
  if (views.empty()) {
    throw InputError(image_path + ": no view could be built: the model has " +
                     std::to_string(reconstruction.images.size()) +
                     " registered images and none of their photos was found");
  }
  return views;
}

}  // namespace raycarve
