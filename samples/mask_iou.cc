// A small program using raycarve's libraries: how well one folder of object masks agrees with
// another (e.g. raycarve's automatic masks in <output>/masks against exact ones), per mask and
// over all, as intersection over union of the non-zero pixels.
//   mask_iou REFERENCE_DIR MASK_DIR
// Every PNG in REFERENCE_DIR is compared with the file of the same name in MASK_DIR (a missing
// one scores 0). Prints one line per mask, then a JSON line {"masks", "min_iou", "mean_iou"}.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calib/image_reader.h"
#include "calib/input_error.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s REFERENCE_DIR MASK_DIR\n", argv[0]);
    return 1;
  }
  try {
    std::vector<std::filesystem::path> references;
    for (const auto& entry : std::filesystem::directory_iterator(argv[1])) {
      if (entry.path().extension() == ".png") references.push_back(entry.path());
    }
    std::sort(references.begin(), references.end());
    if (references.empty()) throw raycarve::InputError(std::string(argv[1]) + ": no PNG masks");
    double sum = 0.0, worst = 1.0;
    for (const std::filesystem::path& reference_path : references) {
      const std::filesystem::path mask_path = std::filesystem::path(argv[2]) / reference_path.filename();
      const cv::Mat reference = raycarve::ReadImage(reference_path.string(), cv::IMREAD_GRAYSCALE);
      double iou = 0.0;
      if (std::filesystem::is_regular_file(mask_path)) {
        const cv::Mat mask = raycarve::ReadImage(mask_path.string(), cv::IMREAD_GRAYSCALE);
        if (reference.empty() || mask.empty() || mask.size() != reference.size()) {
          throw raycarve::InputError(mask_path.string() + ": not a mask of the reference's size");
        }
        const cv::Mat a = reference > 0, b = mask > 0;
        const int either = cv::countNonZero(a | b);
        iou = either == 0 ? 1.0 : static_cast<double>(cv::countNonZero(a & b)) / either;
      }
      std::printf("%s %.4f\n", reference_path.filename().c_str(), iou);
      sum += iou;
      worst = std::min(worst, iou);
    }
    std::printf("{\"masks\": %zu, \"min_iou\": %.4f, \"mean_iou\": %.4f}\n", references.size(),
                worst, sum / references.size());
  } catch (const std::exception& error) {
    std::fprintf(stderr, "mask_iou: %s\n", error.what());
    return 1;
  }
  return 0;
}
