// Helpers shared by the simulator tests.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "runtime/config_reader.hpp"
#include "runtime/sim/simulator/lidar.hpp"
#include "runtime/sim/simulator/scenario.hpp"
#include "stages/foundation/camera_model.hpp"

namespace fusecal::testing {

inline std::string ScenarioPath(const std::string& name) {
  return std::string(FUSECAL_SOURCE_DIR) + "/configs/scenarios/" + name;
}

// `text` with the first `from` replaced by `to`; a test failure when `text` has none.
inline std::string ReplaceFirst(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "test setup: '" << from << "' not in the text";
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

// Expects `load(text)` to throw a ConfigError whose message contains `key`.
inline void ExpectConfigErrorNaming(const std::function<void(const std::string&)>& load, const std::string& text,
                                    const std::string& key) {
  try {
    load(text);
    ADD_FAILURE() << "accepted a bad scenario; expected an error naming " << key;
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << "message: " << e.what();
  }
}

inline double Pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    sa += a[i];
    sb += b[i];
    saa += a[i] * a[i];
    sbb += b[i] * b[i];
    sab += a[i] * b[i];
  }
  const double cov = sab / n - (sa / n) * (sb / n);
  const double va = saa / n - (sa / n) * (sa / n), vb = sbb / n - (sb / n) * (sb / n);
  return cov / std::sqrt(va * vb);
}

// Bilinear grey value of an 8-bit single-channel image at a pixel (OpenCV centres), false outside.
inline bool SampleBilinear(const cv::Mat& image, const Eigen::Vector2d& px, double* value) {
  const int x0 = static_cast<int>(std::floor(px.x())), y0 = static_cast<int>(std::floor(px.y()));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= image.cols || y0 + 1 >= image.rows) return false;
  const double ax = px.x() - x0, ay = px.y() - y0;
  auto at = [&](int y, int x) { return static_cast<double>(image.at<uint8_t>(y, x)); };
  *value = (1 - ay) * ((1 - ax) * at(y0, x0) + ax * at(y0, x0 + 1)) +
           ay * ((1 - ax) * at(y0 + 1, x0) + ax * at(y0 + 1, x0 + 1));
  return true;
}

// Pearson correlation of LiDAR intensity with the image grey value at the projection of each point
// through T_camera_lidar.
inline double IntensityCorrelation(const sim::SimulatedScan& scan, const cv::Mat& image, const CameraModel& camera,
                                   const Isometry3& T_camera_lidar, size_t* used = nullptr) {
  std::vector<double> lidar, pixel;
  for (const auto& p : scan.points) {
    const Eigen::Vector3d pc = T_camera_lidar * Eigen::Vector3d(p.x, p.y, p.z);
    Eigen::Vector2d px;
    double v;
    if (!camera.Project(pc, &px) || !SampleBilinear(image, px, &v)) continue;
    lidar.push_back(p.intensity);
    pixel.push_back(v);
  }
  if (used) *used = lidar.size();
  return Pearson(lidar, pixel);
}

}  // namespace fusecal::testing
