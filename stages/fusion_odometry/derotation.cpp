#include "stages/fusion_odometry/derotation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

namespace fusecal::fusion_odometry {

namespace {
constexpr float kOutside = -1e4f;  // a direction camera j cannot see: far outside image j

// A panorama's column u into [0, width).
template <class T>
T WrapColumn(T u, int width) {
  u = std::fmod(u, static_cast<T>(width));
  return u < 0 ? u + static_cast<T>(width) : u;
}
}  // namespace

DerotationMap::DerotationMap(const CameraModel& camera, const Eigen::Matrix3d& R_ci_cj, int grid_step)
    : width_(camera.width()),
      height_(camera.height()),
      step_(std::max(1, grid_step)),
      wrap_(camera.WrapsHorizontally()) {
  grid_w_ = (width_ - 1 + step_ - 1) / step_ + 1;
  grid_h_ = (height_ - 1 + step_ - 1) / step_ + 1;
  const Eigen::Matrix3d R_cj_ci = R_ci_cj.transpose();
  // Exact map on the grid: where in image j the direction of derotated pixel (x, y) lies.
  gx_.resize(static_cast<size_t>(grid_w_) * grid_h_);
  gy_.resize(gx_.size());
  for (int r = 0; r < grid_h_; ++r) {
    for (int c = 0; c < grid_w_; ++c) {
      const Eigen::Vector2d pixel(c * step_, r * step_);  // the last row and column may lie just outside
      Eigen::Vector2d source(std::numeric_limits<double>::quiet_NaN(), 0.0);
      camera.Project(R_cj_ci * camera.Unproject(pixel), &source);  // outside the image: still set, or NaN
      const bool ok = source.allFinite();
      gx_[r * grid_w_ + c] = ok ? static_cast<float>(source.x()) : kOutside;
      gy_[r * grid_w_ + c] = ok ? static_cast<float>(source.y()) : kOutside;
    }
  }
  if (wrap_) {  // make the columns continuous across the seam, along rows and from row to row
    const float W = static_cast<float>(width_);
    for (int r = 0; r < grid_h_; ++r) {
      float* row = &gx_[r * grid_w_];
      if (r > 0) row[0] += W * std::round((gx_[(r - 1) * grid_w_] - row[0]) / W);
      for (int c = 1; c < grid_w_; ++c) row[c] += W * std::round((row[c - 1] - row[c]) / W);
    }
  }
}

Eigen::Vector2f DerotationMap::Interpolate(float x, float y) const {
  const int last_r = std::max(grid_h_ - 2, 0), last_c = std::max(grid_w_ - 2, 0);
  const int r = std::clamp(static_cast<int>(std::floor(y / step_)), 0, last_r);
  const int c = std::clamp(static_cast<int>(std::floor(x / step_)), 0, last_c);
  const float fy = grid_h_ > 1 ? (y - static_cast<float>(r * step_)) / step_ : 0.0f;
  const float fx = grid_w_ > 1 ? (x - static_cast<float>(c * step_)) / step_ : 0.0f;
  const int c1 = std::min(c + 1, grid_w_ - 1), r1 = std::min(r + 1, grid_h_ - 1);
  const int k = r * grid_w_ + c, k1 = r * grid_w_ + c1, k2 = r1 * grid_w_ + c, k3 = r1 * grid_w_ + c1;
  const float a = (1 - fx) * (1 - fy), b = fx * (1 - fy), d = (1 - fx) * fy, e = fx * fy;
  return {a * gx_[k] + b * gx_[k1] + d * gx_[k2] + e * gx_[k3], a * gy_[k] + b * gy_[k1] + d * gy_[k2] + e * gy_[k3]};
}

Eigen::Vector2d DerotationMap::SourcePixel(double x, double y) const {
  const Eigen::Vector2f s = Interpolate(static_cast<float>(x), static_cast<float>(y));
  const double u = s.x();
  return {wrap_ ? WrapColumn(u, width_) : u, static_cast<double>(s.y())};
}

cv::Mat DerotationMap::Resample(const cv::Mat& grey_j) const {
  cv::Mat map_x(height_, width_, CV_32F), map_y(height_, width_, CV_32F);
  const int pad = wrap_ ? 1 : 0;
  cv::parallel_for_(cv::Range(0, height_), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      float* mx = map_x.ptr<float>(y);
      float* my = map_y.ptr<float>(y);
      for (int x = 0; x < width_; ++x) {
        const Eigen::Vector2f s = Interpolate(static_cast<float>(x), static_cast<float>(y));
        mx[x] = wrap_ ? WrapColumn(s.x(), width_) + pad : s.x();  // plus the offset of the padded source
        my[x] = s.y();
      }
    }
  });
  cv::Mat source = grey_j;
  if (wrap_) cv::copyMakeBorder(grey_j, source, 0, 0, pad, pad, cv::BORDER_WRAP);
  cv::Mat derotated;
  cv::remap(source, derotated, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return derotated;
}

cv::Mat DerotateImage(const cv::Mat& grey_j, const CameraModel& camera, const Eigen::Matrix3d& R_ci_cj, int grid_step) {
  return DerotationMap(camera, R_ci_cj, grid_step).Resample(grey_j);
}

}  // namespace fusecal::fusion_odometry
