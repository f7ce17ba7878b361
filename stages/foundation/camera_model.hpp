// Camera models: everything downstream works on unit bearing vectors (docs/design.md section 1).
//
// Pixel convention (both models, as OpenCV): pixel (u, v) = (column, row), the centre of the top-left
// pixel is (0, 0), so the image spans [-0.5, width - 0.5] x [-0.5, height - 0.5].
// Camera frame: x right, y down, z forward.
//
// Equirectangular convention (the one place it is defined):
//   longitude lon = atan2(x, z) in (-pi, pi]: 0 looks along +z (image centre column), +pi/2 along +x;
//   latitude  lat = atan2(-y, sqrt(x^2 + z^2)) in [-pi/2, pi/2]: +pi/2 is up (-y), the top row;
//   u = (lon + pi) / (2 pi) * width - 0.5,   v = (pi/2 - lat) / pi * height - 0.5.
// Columns wrap around (the seam is at lon = +-pi, the left and right image borders).
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>

namespace fusecal {

struct CameraParams {
  std::string model = "pinhole";  // "pinhole", "equidistant" (fisheye) or "equirectangular"
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;      // pinhole and equidistant
  std::array<double, 5> dist{0, 0, 0, 0, 0};  // pinhole: k1 k2 p1 p2 k3 (OpenCV); equidistant: k1 k2 k3 k4 0

  bool HasIntrinsics() const { return model == "pinhole" || model == "equidistant"; }

  // Empty when valid, else a message naming the offending field.
  std::string Validate() const;
};

class CameraModel {
 public:
  explicit CameraModel(CameraParams params) : params_(std::move(params)) {}
  virtual ~CameraModel() = default;

  // Projects a point in the camera frame to a pixel. False when the point cannot be seen
  // (behind a pinhole camera, outside the valid distortion range, or outside the image).
  virtual bool Project(const Eigen::Vector3d& p_camera, Eigen::Vector2d* pixel) const = 0;

  // Unit bearing vector of a pixel, in the camera frame.
  virtual Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const = 0;

  // True for models whose columns wrap around (equirectangular).
  virtual bool WrapsHorizontally() const { return false; }

  bool InImage(const Eigen::Vector2d& pixel) const {
    return pixel.x() >= -0.5 && pixel.y() >= -0.5 && pixel.x() <= width() - 0.5 && pixel.y() <= height() - 0.5;
  }
  int width() const { return params_.width; }
  int height() const { return params_.height; }
  const CameraParams& params() const { return params_; }

 private:
  CameraParams params_;
};

class PinholeCamera : public CameraModel {
 public:
  explicit PinholeCamera(const CameraParams& params);
  bool Project(const Eigen::Vector3d& p_camera, Eigen::Vector2d* pixel) const override;
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const override;

  // Distortion of normalised coordinates (OpenCV radial-tangential) and its inverse.
  Eigen::Vector2d Distort(const Eigen::Vector2d& xy) const;
  Eigen::Vector2d Undistort(const Eigen::Vector2d& xy_distorted) const;

 private:
  double max_radius2_;  // squared normalised radius up to which the distortion is monotonic
};

// Equidistant fisheye (Kannala-Brandt, OpenCV's cv::fisheye and ROS's "equidistant"): a ray at angle
// theta from the optical axis lands at radius theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 +
// k4 theta^8) in normalised coordinates. Sees rays up to the first maximum of theta_d (beyond 90 deg).
class EquidistantCamera : public CameraModel {
 public:
  explicit EquidistantCamera(const CameraParams& params);
  bool Project(const Eigen::Vector3d& p_camera, Eigen::Vector2d* pixel) const override;
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const override;

  double DistortAngle(double theta) const;
  double UndistortAngle(double theta_d) const;

 private:
  double max_theta_;  // angle up to which theta_d grows with theta (at most pi)
};

class EquirectangularCamera : public CameraModel {
 public:
  explicit EquirectangularCamera(const CameraParams& params);
  bool Project(const Eigen::Vector3d& p_camera, Eigen::Vector2d* pixel) const override;
  Eigen::Vector3d Unproject(const Eigen::Vector2d& pixel) const override;
  bool WrapsHorizontally() const override { return true; }
};

// Builds the model named by params.model; throws std::invalid_argument naming the bad field.
std::unique_ptr<CameraModel> MakeCameraModel(const CameraParams& params);

// The smallest image side the front ends track features in: AKAZE's descriptor and the KLT window each
// span about this many pixels around a feature.
inline constexpr int kMinTrackedImageSide = 32;

// Empty when images of this size can be tracked, else why not ("WxH, too small to track ...").
std::string TrackableSizeProblem(int width, int height);

}  // namespace fusecal
