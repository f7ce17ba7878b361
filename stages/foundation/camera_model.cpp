#include "camera_model.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fusecal {

std::string CameraParams::Validate() const {
  if (model != "pinhole" && model != "equidistant" && model != "equirectangular")
    return "model: unknown camera model '" + model + "' (expected pinhole, equidistant or equirectangular)";
  if (width <= 0) return "width: must be positive, got " + std::to_string(width);
  if (height <= 0) return "height: must be positive, got " + std::to_string(height);
  if (HasIntrinsics()) {
    if (!(fx > 0)) return "fx: must be positive";
    if (!(fy > 0)) return "fy: must be positive";
    if (!std::isfinite(cx)) return "cx: must be finite";
    if (!std::isfinite(cy)) return "cy: must be finite";
    for (double d : dist)
      if (!std::isfinite(d)) return "dist: coefficients must be finite";
  }
  return {};
}

// ---------------------------------------------------------------------------------------------- pinhole

namespace {
// Radial factor 1 + k1 r^2 + k2 r^4 + k3 r^6.
double RadialFactor(const std::array<double, 5>& d, double r2) { return 1.0 + r2 * (d[0] + r2 * (d[1] + r2 * d[4])); }
}  // namespace

PinholeCamera::PinholeCamera(const CameraParams& params) : CameraModel(params) {
  // Distorted radius r * f(r^2) must grow with r; beyond its first maximum points fold back into the
  // image and would be projected to wrong pixels. Find that radius once.
  const auto& d = params.dist;
  double r_max = 10.0;  // about 168 degrees off axis: beyond any real pinhole lens
  double prev = 0.0;
  for (double r = 1e-3; r <= 10.0; r += 1e-3) {
    const double rd = r * RadialFactor(d, r * r);
    if (rd <= prev) {
      r_max = r - 1e-3;
      break;
    }
    prev = rd;
  }
  max_radius2_ = r_max * r_max;
}

Eigen::Vector2d PinholeCamera::Distort(const Eigen::Vector2d& xy) const {
  const auto& d = params().dist;
  const double x = xy.x(), y = xy.y();
  const double r2 = x * x + y * y;
  const double radial = RadialFactor(d, r2);
  return {x * radial + 2.0 * d[2] * x * y + d[3] * (r2 + 2.0 * x * x),
          y * radial + d[2] * (r2 + 2.0 * y * y) + 2.0 * d[3] * x * y};
}

Eigen::Vector2d PinholeCamera::Undistort(const Eigen::Vector2d& xy_distorted) const {
  // Gauss-Newton on Distort(xy) = xy_distorted, numeric Jacobian; converges in a few steps for lenses
  // within the monotonic range.
  Eigen::Vector2d xy = xy_distorted;
  for (int iter = 0; iter < 50; ++iter) {
    const Eigen::Vector2d residual = Distort(xy) - xy_distorted;
    if (residual.norm() < 1e-15) break;
    Eigen::Matrix2d J;
    const double h = 1e-7;
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d step = Eigen::Vector2d::Zero();
      step[k] = h;
      J.col(k) = (Distort(xy + step) - Distort(xy - step)) / (2.0 * h);
    }
    xy -= J.partialPivLu().solve(residual);
  }
  return xy;
}

bool PinholeCamera::Project(const Eigen::Vector3d& p, Eigen::Vector2d* pixel) const {
  if (!(p.z() > 1e-9) || !p.allFinite()) return false;
  const Eigen::Vector2d xy(p.x() / p.z(), p.y() / p.z());
  if (xy.squaredNorm() > max_radius2_) return false;
  const Eigen::Vector2d xyd = Distort(xy);
  const auto& c = params();
  *pixel = Eigen::Vector2d(c.fx * xyd.x() + c.cx, c.fy * xyd.y() + c.cy);
  return InImage(*pixel);
}

Eigen::Vector3d PinholeCamera::Unproject(const Eigen::Vector2d& pixel) const {
  const auto& c = params();
  const Eigen::Vector2d xyd((pixel.x() - c.cx) / c.fx, (pixel.y() - c.cy) / c.fy);
  const Eigen::Vector2d xy = Undistort(xyd);
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

// ------------------------------------------------------------------------------------------ equidistant

EquidistantCamera::EquidistantCamera(const CameraParams& params) : CameraModel(params) {
  // Like the pinhole's radius: beyond the first maximum of theta_d rays fold back; find it once.
  max_theta_ = M_PI;
  double prev = 0.0;
  for (double theta = 1e-3; theta <= M_PI; theta += 1e-3) {
    const double theta_d = DistortAngle(theta);
    if (theta_d <= prev) {
      max_theta_ = theta - 1e-3;
      break;
    }
    prev = theta_d;
  }
}

double EquidistantCamera::DistortAngle(double theta) const {
  const auto& k = params().dist;
  const double t2 = theta * theta;
  return theta * (1.0 + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3]))));
}

double EquidistantCamera::UndistortAngle(double theta_d) const {
  // Newton on DistortAngle(theta) = theta_d, numeric derivative, started at theta_d.
  double theta = std::min(theta_d, max_theta_);
  for (int iter = 0; iter < 30; ++iter) {
    const double residual = DistortAngle(theta) - theta_d;
    if (std::abs(residual) < 1e-14) break;
    const double h = 1e-7;
    const double slope = (DistortAngle(theta + h) - DistortAngle(theta - h)) / (2.0 * h);
    if (!(slope > 1e-12)) break;
    theta = std::clamp(theta - residual / slope, 0.0, max_theta_);
  }
  return theta;
}

bool EquidistantCamera::Project(const Eigen::Vector3d& p, Eigen::Vector2d* pixel) const {
  if (!p.allFinite()) return false;
  const double r = std::hypot(p.x(), p.y());
  const double theta = std::atan2(r, p.z());
  if (theta > max_theta_ || r + std::abs(p.z()) < 1e-12) return false;
  const double scale = r > 1e-12 ? DistortAngle(theta) / r : 1.0 / p.z();
  const auto& c = params();
  *pixel = Eigen::Vector2d(c.fx * p.x() * scale + c.cx, c.fy * p.y() * scale + c.cy);
  return InImage(*pixel);
}

Eigen::Vector3d EquidistantCamera::Unproject(const Eigen::Vector2d& pixel) const {
  const auto& c = params();
  const Eigen::Vector2d xyd((pixel.x() - c.cx) / c.fx, (pixel.y() - c.cy) / c.fy);
  const double theta_d = xyd.norm();
  if (theta_d < 1e-12) return Eigen::Vector3d::UnitZ();
  const double theta = UndistortAngle(theta_d);
  const Eigen::Vector2d direction = xyd / theta_d;
  return {std::sin(theta) * direction.x(), std::sin(theta) * direction.y(), std::cos(theta)};
}

// -------------------------------------------------------------------------------------- equirectangular

EquirectangularCamera::EquirectangularCamera(const CameraParams& params) : CameraModel(params) {}

bool EquirectangularCamera::Project(const Eigen::Vector3d& p, Eigen::Vector2d* pixel) const {
  const double horizontal = std::hypot(p.x(), p.z());
  if (!p.allFinite() || horizontal + std::abs(p.y()) < 1e-12) return false;
  const double lon = std::atan2(p.x(), p.z());
  const double lat = std::atan2(-p.y(), horizontal);
  *pixel = Eigen::Vector2d((lon + M_PI) / (2.0 * M_PI) * width() - 0.5, (M_PI / 2.0 - lat) / M_PI * height() - 0.5);
  return true;  // every direction is in the panorama
}

Eigen::Vector3d EquirectangularCamera::Unproject(const Eigen::Vector2d& pixel) const {
  const double lon = (pixel.x() + 0.5) / width() * 2.0 * M_PI - M_PI;
  const double lat = M_PI / 2.0 - (pixel.y() + 0.5) / height() * M_PI;
  return {std::cos(lat) * std::sin(lon), -std::sin(lat), std::cos(lat) * std::cos(lon)};
}

std::unique_ptr<CameraModel> MakeCameraModel(const CameraParams& params) {
  const std::string error = params.Validate();
  if (!error.empty()) throw std::invalid_argument("camera " + error);
  if (params.model == "pinhole") return std::make_unique<PinholeCamera>(params);
  if (params.model == "equidistant") return std::make_unique<EquidistantCamera>(params);
  return std::make_unique<EquirectangularCamera>(params);
}

std::string TrackableSizeProblem(int width, int height) {
  if (width >= kMinTrackedImageSide && height >= kMinTrackedImageSide) return {};
  return std::to_string(width) + "x" + std::to_string(height) + ", too small to track (at least " +
         std::to_string(kMinTrackedImageSide) + "x" + std::to_string(kMinTrackedImageSide) + " pixels)";
}

}  // namespace fusecal
