#include "stages/handeye/handheld_motions.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace fusecal {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

Eigen::Vector3d Gaussian(std::mt19937& rng, double sigma) {
  std::normal_distribution<double> n(0.0, sigma);
  const double x = n(rng), y = n(rng), z = n(rng);
  return {x, y, z};
}

// A rig held in a hand: the camera looks roughly along the LiDAR's x axis, a few centimetres away.
Isometry3 HandheldExtrinsic(std::mt19937& rng) {
  const Eigen::Matrix3d nominal = RotationFromRpy(-90 * kDegToRad, 0, -90 * kDegToRad);
  const Eigen::Vector3d t(0.05, -0.08, -0.03);
  return MakeIsometry(nominal * ExpSO3(Gaussian(rng, 5 * kDegToRad)), t + Gaussian(rng, 0.02));
}

// The turn of motion k: log-normal about the median (a factor of about 1.6 either way), capped.
double TurnDeg(std::mt19937& rng, const HandheldMotionSettings& s, int k) {
  const int every = s.small_turns > 0 ? std::max(1, s.num_motions / s.small_turns) : 0;
  if (every > 0 && k % every == every / 2) return std::uniform_real_distribution<double>(0.5, 1.0)(rng);
  const double turn = s.median_turn_deg * std::exp(std::normal_distribution<double>(0.0, 0.5)(rng));
  return std::min(turn, s.max_turn_deg);
}

// The errors of one sensor: a 6-vector [rotation (rad) ; translation (m)] per motion, correlated in sequence.
class CorrelatedNoise {
 public:
  CorrelatedNoise(double rot_sigma, double trans_sigma, double rho) : rot_(rot_sigma), trans_(trans_sigma), rho_(rho) {}
  Vector6 Next(std::mt19937& rng) {
    Vector6 e;
    e << Gaussian(rng, rot_), Gaussian(rng, trans_);
    state_ = first_ ? e : Vector6(rho_ * state_ + std::sqrt(1.0 - rho_ * rho_) * e);
    first_ = false;
    return state_;
  }

 private:
  double rot_, trans_, rho_;
  Vector6 state_ = Vector6::Zero();
  bool first_ = true;
};

Isometry3 Perturb(const Isometry3& T, const Vector6& n) {
  return MakeIsometry(T.linear() * ExpSO3(n.head<3>()), T.translation() + n.tail<3>());
}

}  // namespace

HandheldMotionSet GenerateHandheldMotions(const HandheldMotionSettings& s) {
  std::mt19937 rng(s.seed);
  HandheldMotionSet out;
  out.T_camera_lidar = HandheldExtrinsic(rng);
  const Isometry3& X = out.T_camera_lidar;
  // The rotation axis (LiDAR frame) and the walking direction drift smoothly from motion to motion.
  Eigen::Vector3d axis = Gaussian(rng, 1.0).normalized();
  Eigen::Vector3d heading = Eigen::Vector3d::UnitX();
  const double rot_sigma = s.rotation_noise_deg * kDegToRad;
  CorrelatedNoise lidar_noise(rot_sigma, s.lidar_translation_noise_m, s.noise_correlation);
  CorrelatedNoise camera_noise(rot_sigma, s.camera_translation_noise_m, s.noise_correlation);
  for (int k = 0; k < s.num_motions; ++k) {
    axis = (axis + Gaussian(rng, 0.6)).normalized();
    heading = (heading + Gaussian(rng, 0.3)).normalized();
    const double turn = TurnDeg(rng, s, k);
    const double sign = std::uniform_int_distribution<int>(0, 1)(rng) ? 1.0 : -1.0;
    const Isometry3 B = MakeIsometry(ExpSO3(sign * turn * kDegToRad * axis), s.step_m * heading);
    const Isometry3 A = X * B * X.inverse();  // A X = X B, metric
    MotionPair p;
    p.station_i = k;
    p.station_j = k + 1;
    p.B = Perturb(B, lidar_noise.Next(rng));
    p.A = Perturb(A, camera_noise.Next(rng));
    const double units = s.camera_units == CameraUnits::kGlobalScale
                             ? s.camera_units_per_m
                             : std::uniform_real_distribution<double>(0.2, 5.0)(rng) / A.translation().norm();
    p.A.translation() *= units;
    p.camera_scaled = false;
    out.pairs.push_back(p);
  }
  return out;
}

}  // namespace fusecal
