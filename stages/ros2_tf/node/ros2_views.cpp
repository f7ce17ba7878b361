#include "stages/ros2_tf/node/ros2_views.hpp"

#include <algorithm>
#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "stages/formats/conversions.hpp"
#include "stages/formats/extrinsic_status.hpp"
#include "stages/formats/result_file.hpp"

namespace fusecal {

namespace {

std::string Number(double value, int digits) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, value);
  return text;
}

std::string Vector(const Eigen::Vector3d& v, int digits) {
  return "[" + Number(v.x(), digits) + ", " + Number(v.y(), digits) + ", " + Number(v.z(), digits) + "]";
}

}  // namespace

cv::Mat DrawPointsOnImage(const cv::Mat& image, const PointCloud& cloud, const CameraModel& camera,
                          const Isometry3& T_camera_lidar) {
  cv::Mat out;
  if (image.channels() == 1)
    cv::cvtColor(image, out, cv::COLOR_GRAY2BGR);
  else
    out = image.clone();
  const int radius = std::max(1, out.cols / 600);
  for (const Eigen::Vector3f& p : cloud.points) {
    const Eigen::Vector3d in_camera = T_camera_lidar * p.cast<double>();
    Eigen::Vector2d pixel;
    if (!camera.Project(in_camera, &pixel)) continue;
    // Depth 1 m (red) to 20 m (blue) on a log scale: hue 0..120 in OpenCV's 0..180 range.
    const double depth = in_camera.norm();
    const double f = std::clamp(std::log(std::max(depth, 1.0)) / std::log(20.0), 0.0, 1.0);
    cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(120 * f, 255, 255)), bgr;
    cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
    const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
    cv::circle(out, cv::Point(static_cast<int>(pixel.x()), static_cast<int>(pixel.y())), radius,
               cv::Scalar(c[0], c[1], c[2]), cv::FILLED);
  }
  return out;
}

DiagnosticReport DescribeExtrinsic(const extrinsic_t& latest, const extrinsic_t* held) {
  DiagnosticReport report;
  const bool holding = latest.status == extrinsic_t::STATUS_FAILED && held;
  const extrinsic_t& e = holding ? *held : latest;
  switch (latest.status) {
    case extrinsic_t::STATUS_CONVERGED:
      report.level = 0;
      break;
    case extrinsic_t::STATUS_INITIAL:
    case extrinsic_t::STATUS_REFINING:
    case extrinsic_t::STATUS_NOT_CONVERGED:
      report.level = 1;
      break;
    default:
      report.level = 2;
  }
  report.message =
      std::string(ExtrinsicStatusName(latest.status)) + " (" + ObservabilityName(latest.observability) + ")";
  if (!latest.message.empty()) report.message += ": " + latest.message;
  if (holding) {
    report.level = 1;
    report.message += "; tf_static holds version " + std::to_string(held->version);
  }
  const Isometry3 T = FromRowMajor(e.T_camera_lidar);
  const Matrix6 covariance = Matrix6FromArray(e.covariance);
  report.values = {
      {"version", std::to_string(e.version)},
      {"iteration", std::to_string(e.iteration)},
      {"status", ExtrinsicStatusName(latest.status)},
      {"observability", ObservabilityName(e.observability)},
      {"translation_m", Vector(T.translation(), 4)},
      {"rpy_deg", Vector(RpyFromRotation(T.linear()) * 180.0 / M_PI, 3)},
      {"std_rotation_deg", Vector(RotationStdDevDeg(covariance), 4)},
      {"std_translation_m", Vector(TranslationStdDevM(covariance), 4)},
      {"motions_used", std::to_string(e.num_used)},
      {"motions_rejected", std::to_string(e.num_rejected)},
      {"residual_rms_m", Number(e.residual_rms, 5)},
  };
  if (holding) report.values.push_back({"tf_static_version", std::to_string(held->version)});
  if (latest.num_changes > 0) {
    // The rig changed: the loop solves again from the motions after the newest change (WARN until converged).
    const int after = latest.change_after_station.back();
    report.message += "; extrinsic changed after station " + std::to_string(after);
    report.values.push_back({"changes", std::to_string(latest.num_changes)});
    report.values.push_back({"changed_after_station", std::to_string(after)});
    const Isometry3 before = FromRowMajor(latest.change_T_before.back().data());
    report.values.push_back({"before_translation_m", Vector(before.translation(), 4)});
    report.values.push_back({"before_rpy_deg", Vector(RpyFromRotation(before.linear()) * 180.0 / M_PI, 3)});
  }
  if (e.observability != extrinsic_t::OBSERVABILITY_OK)
    report.values.push_back(
        {"unobservable_direction_camera",
         Vector(Eigen::Vector3d(e.unobservable_direction[0], e.unobservable_direction[1], e.unobservable_direction[2]),
                4)});
  return report;
}

namespace {
std::string WithoutLeadingSlash(const std::string& frame) { return frame.rfind('/', 0) == 0 ? frame.substr(1) : frame; }
}  // namespace

void FrameParents::Add(const std::string& parent, const std::string& child) {
  parents_[WithoutLeadingSlash(child)].insert(WithoutLeadingSlash(parent));
}

std::string FrameParents::OtherParent(const std::string& parent, const std::string& child) const {
  const auto found = parents_.find(WithoutLeadingSlash(child));
  if (found == parents_.end()) return "";
  for (const std::string& p : found->second)
    if (p != WithoutLeadingSlash(parent)) return p;
  return "";
}

std::string FrameParents::ChildName(const std::string& parent, const std::string& child) const {
  return OtherParent(parent, child).empty() ? child : child + "_calibrated";
}

}  // namespace fusecal
