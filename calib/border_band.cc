#include "calib/border_band.h"

#include <algorithm>

namespace raycarve {

BorderBand MakeBand(const cv::Mat& rgb, const int frame[4]) {
  BorderBand band;
  for (int k = 0; k < 4; ++k) band.frame[k] = frame[k];
  const int band_rows = std::max(1, rgb.rows / 50), band_cols = std::max(1, rgb.cols / 50);
  band.top = frame[0] + band_rows;
  band.bottom = frame[1] + band_rows;
  band.left = frame[2] + band_cols;
  band.right = frame[3] + band_cols;
  return band;
}


}  // namespace raycarve
