#include "fusion_odometry/derotation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace fusecal::fusion_odometry {

cv::Mat DerotateImage(const cv::Mat& grey_j, const CameraModel& camera, const Eigen::Matrix3d& R_ci_cj,
                      int grid_step) {
  const int w = camera.width(), h = camera.height();
  const bool wrap = camera.WrapsHorizontally();
  const int step = std::max(1, grid_step);
  const int gw = (w - 1 + step - 1) / step + 1, gh = (h - 1 + step - 1) / step + 1;
  const Eigen::Matrix3d R_cj_ci = R_ci_cj.transpose();
  constexpr float kOutside = -1e4f;  // replicated border

  // Exact map on the grid: where in image j the direction of derotated pixel (x, y) lies.
  std::vector<float> gx(static_cast<size_t>(gw) * gh), gy(gx.size());
  for (int r = 0; r < gh; ++r) {
    for (int c = 0; c < gw; ++c) {
      const Eigen::Vector2d pixel(c * step, r * step);  // the last row and column may lie just outside
      Eigen::Vector2d source(std::numeric_limits<double>::quiet_NaN(), 0.0);
      camera.Project(R_cj_ci * camera.Unproject(pixel), &source);  // outside the image: still set, or NaN
      const bool ok = source.allFinite();
      gx[r * gw + c] = ok ? static_cast<float>(source.x()) : kOutside;
      gy[r * gw + c] = ok ? static_cast<float>(source.y()) : kOutside;
    }
  }
  if (wrap) {  // make the columns continuous across the seam, along rows and from row to row
    const float W = static_cast<float>(w);
    for (int r = 0; r < gh; ++r) {
      float* row = &gx[r * gw];
      if (r > 0) row[0] += W * std::round((gx[(r - 1) * gw] - row[0]) / W);
      for (int c = 1; c < gw; ++c) row[c] += W * std::round((row[c - 1] - row[c]) / W);
    }
  }

  // Bilinear interpolation of the grid at every pixel.
  cv::Mat map_x(h, w, CV_32F), map_y(h, w, CV_32F);
  const int pad = wrap ? 1 : 0;
  cv::parallel_for_(cv::Range(0, h), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      const int r = std::min(y / step, gh - 2 < 0 ? 0 : gh - 2);
      const float fy = gh > 1 ? static_cast<float>(y - r * step) / step : 0.0f;
      float* mx = map_x.ptr<float>(y);
      float* my = map_y.ptr<float>(y);
      for (int x = 0; x < w; ++x) {
        const int c = std::min(x / step, gw - 2 < 0 ? 0 : gw - 2);
        const float fx = gw > 1 ? static_cast<float>(x - c * step) / step : 0.0f;
        const int k = r * gw + c, k1 = std::min(c + 1, gw - 1) + r * gw;
        const int k2 = std::min(r + 1, gh - 1) * gw + c, k3 = std::min(r + 1, gh - 1) * gw + std::min(c + 1, gw - 1);
        const float a = (1 - fx) * (1 - fy), b = fx * (1 - fy), d = (1 - fx) * fy, e = fx * fy;
        float u = a * gx[k] + b * gx[k1] + d * gx[k2] + e * gx[k3];
        const float v = a * gy[k] + b * gy[k1] + d * gy[k2] + e * gy[k3];
        if (wrap) {  // into [0, w), then the offset of the padded source
          u = std::fmod(u, static_cast<float>(w));
          if (u < 0) u += static_cast<float>(w);
          u += pad;
        }
        mx[x] = u;
        my[x] = v;
      }
    }
  });

  cv::Mat source = grey_j;
  if (wrap) cv::copyMakeBorder(grey_j, source, 0, 0, pad, pad, cv::BORDER_WRAP);
  cv::Mat derotated;
  cv::remap(source, derotated, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return derotated;
}

}  // namespace fusecal::fusion_odometry
