#include "stages/camera_frontend/masks.hpp"

#include <cmath>
#include <opencv2/imgproc.hpp>

namespace fusecal::camera_frontend {

cv::Mat BlankAreas(const cv::Mat& grey, int blank_value, int margin_px) {
  cv::Mat blank = cv::Mat::zeros(grey.size(), CV_8U);
  if (blank_value < 0 || grey.empty()) return blank;
  cv::compare(grey, cv::Scalar(blank_value), blank, cv::CMP_EQ);
  // Keep constant areas only (erode with 5x5), then grow them by 2 + margin to cover the area itself and
  // the border band whose descriptors would see the fill.
  const cv::Mat core = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5));
  cv::erode(blank, blank, core, cv::Point(-1, -1), 1, cv::BORDER_REPLICATE);
  const int grow = 2 + margin_px;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * grow + 1, 2 * grow + 1));
  cv::dilate(blank, blank, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  return blank;
}

cv::Mat PoleRows(const CameraModel& camera, double max_abs_latitude_deg) {
  cv::Mat rows = cv::Mat::zeros(camera.height(), camera.width(), CV_8U);
  if (!camera.WrapsHorizontally()) return rows;
  const double limit = max_abs_latitude_deg * M_PI / 180.0;
  for (int v = 0; v < camera.height(); ++v) {
    // Equirectangular rows: lat = pi/2 - (v + 0.5) / height * pi (camera_model.hpp).
    const double lat = M_PI / 2.0 - (v + 0.5) / camera.height() * M_PI;
    if (std::abs(lat) > limit) rows.row(v).setTo(255);
  }
  return rows;
}

cv::Mat FeatureMask(const cv::Mat& grey, const CameraModel& camera, const FeatureSettings& settings) {
  cv::Mat excluded = BlankAreas(grey, settings.blank_value, settings.blank_margin_px);
  cv::bitwise_or(excluded, PoleRows(camera, settings.max_abs_latitude_deg), excluded);
  cv::Mat mask;
  cv::bitwise_not(excluded, mask);
  return mask;
}

}  // namespace fusecal::camera_frontend
