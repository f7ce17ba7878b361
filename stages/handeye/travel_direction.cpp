#include "stages/handeye/travel_direction.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace fusecal::handeye {

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * kRadToDeg;
}

}  // namespace

std::optional<TravelDirection> FindTravelDirection(const std::vector<MotionPair>& pairs,
                                                   const HandEyeSettings& settings, double min_travel_m,
                                                   double max_spread_deg) {
  std::vector<Eigen::Vector3d> camera, lidar;
  std::vector<double> weights;
  TravelDirection travel;
  for (const auto& p : pairs) {
    if (!p.A.matrix().allFinite() || !p.B.matrix().allFinite()) continue;
    const double angle_a = LogSO3(p.A.linear()).norm() * kRadToDeg;
    const double angle_b = LogSO3(p.B.linear()).norm() * kRadToDeg;
    const Eigen::Vector3d ta = p.A.translation(), tb = p.B.translation();
    if (std::max(angle_a, angle_b) >= settings.min_rotation_deg || tb.norm() < min_travel_m || ta.norm() < 1e-9)
      continue;
    // Driving back reverses both directions: fold them onto the first pair's sense.
    const double sign = lidar.empty() || tb.dot(lidar.front()) >= 0.0 ? 1.0 : -1.0;
    camera.push_back(sign * ta.normalized());
    lidar.push_back(sign * tb.normalized());
    weights.push_back(tb.norm());
    travel.largest_rotation_deg = std::max({travel.largest_rotation_deg, angle_a, angle_b});
  }
  if (lidar.size() < 2) return std::nullopt;
  Eigen::Vector3d sum_camera = Eigen::Vector3d::Zero(), sum_lidar = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < lidar.size(); ++i) {
    sum_camera += weights[i] * camera[i];
    sum_lidar += weights[i] * lidar[i];
  }
  travel.camera = sum_camera.normalized();
  travel.lidar = sum_lidar.normalized();
  for (const auto& d : lidar)
    if (AngleDeg(d, travel.lidar) > max_spread_deg) return std::nullopt;  // more than one line of travel
  const Eigen::Matrix3d R = Eigen::Quaterniond::FromTwoVectors(travel.lidar, travel.camera).toRotationMatrix();
  double sum_squares = 0.0;
  for (size_t i = 0; i < lidar.size(); ++i) sum_squares += std::pow(AngleDeg(camera[i], R * lidar[i]), 2);
  travel.spread_deg = std::sqrt(sum_squares / lidar.size());
  travel.pairs = static_cast<int>(lidar.size());
  return travel;
}

}  // namespace fusecal::handeye
