#include "support/synthetic_room.hpp"

#include <cmath>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusecal::test {

namespace {

cv::Mat LoadGrey(const std::string& path, int flip_code, bool flip) {
  cv::Mat image = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (image.empty()) throw std::runtime_error("cannot read texture " + path);
  if (flip) cv::flip(image, image, flip_code);
  cv::Mat out;
  image.convertTo(out, CV_32F);
  return out;
}

float Bilinear(const cv::Mat& tex, double x, double y) {
  x = std::clamp(x, 0.0, tex.cols - 1.001);
  y = std::clamp(y, 0.0, tex.rows - 1.001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float ax = static_cast<float>(x - x0), ay = static_cast<float>(y - y0);
  const float* r0 = tex.ptr<float>(y0);
  const float* r1 = tex.ptr<float>(y0 + 1);
  return (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x0 + 1]) + ay * ((1 - ax) * r1[x0] + ax * r1[x0 + 1]);
}

}  // namespace

SyntheticRoom::SyntheticRoom(const std::string& data_dir) {
  const std::string b = data_dir + "/building.jpg", a = data_dir + "/aero1.jpg", s = data_dir + "/stuff.jpg";
  textures_[0] = LoadGrey(a, 0, false);  // -x wall
  textures_[1] = LoadGrey(b, 0, false);  // +x wall
  textures_[2] = LoadGrey(b, 0, true);   // -y ceiling: building upside down
  textures_[3] = LoadGrey(s, 0, false);  // +y floor
  textures_[4] = LoadGrey(s, 1, true);   // -z wall: stuff mirrored
  textures_[5] = LoadGrey(a, -1, true);  // +z wall: aero rotated by 180 degrees
}

float SyntheticRoom::Trace(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  // Exit point of the ray from the box: the nearest of the three faces it heads for.
  double best = std::numeric_limits<double>::infinity();
  int face = -1;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(d[axis]) < 1e-12) continue;
    const double bound = d[axis] > 0 ? max_corner[axis] : min_corner[axis];
    const double s = (bound - o[axis]) / d[axis];
    if (s > 0 && s < best) {
      best = s;
      face = 2 * axis + (d[axis] > 0 ? 1 : 0);
    }
  }
  if (face < 0) return 0.0f;
  const Eigen::Vector3d p = o + best * d;
  const int axis = face / 2;
  const int u_axis = axis == 0 ? 2 : 0;  // texture columns along z on the x walls, else along x
  const int v_axis = axis == 1 ? 2 : 1;  // texture rows along z on floor and ceiling, else along y
  const cv::Mat& tex = textures_[face];
  const double u = (p[u_axis] - min_corner[u_axis]) / (max_corner[u_axis] - min_corner[u_axis]);
  const double v = (p[v_axis] - min_corner[v_axis]) / (max_corner[v_axis] - min_corner[v_axis]);
  return Bilinear(tex, u * (tex.cols - 1), v * (tex.rows - 1));
}

cv::Mat SyntheticRoom::Render(const CameraModel& camera, const Isometry3& T_world_camera, int supersample,
                              double noise_sigma, unsigned seed) const {
  cv::Mat accum(camera.height(), camera.width(), CV_32F);
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Vector3d o = T_world_camera.translation();
  const int n = std::max(1, supersample);
  cv::parallel_for_(cv::Range(0, camera.height()), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      float* out = accum.ptr<float>(v);
      for (int u = 0; u < camera.width(); ++u) {
        float sum = 0;
        for (int sy = 0; sy < n; ++sy) {
          for (int sx = 0; sx < n; ++sx) {
            const Eigen::Vector2d pixel(u - 0.5 + (sx + 0.5) / n, v - 0.5 + (sy + 0.5) / n);
            sum += Trace(o, R * camera.Unproject(pixel));
          }
        }
        out[u] = sum / (n * n);
      }
    }
  });
  if (noise_sigma > 0) {
    cv::Mat noise(accum.size(), CV_32F);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    accum += noise;
  }
  cv::Mat image;
  accum.convertTo(image, CV_8U);  // rounds and saturates
  return image;
}

}  // namespace fusecal::test
