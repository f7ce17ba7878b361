#include "stages/handeye/synthetic_motions.hpp"

#include <cmath>

namespace fusecal {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

Eigen::Vector3d GaussianVector(std::mt19937& rng, double sigma) {
  std::normal_distribution<double> n(0.0, 1.0);
  const double x = n(rng), y = n(rng), z = n(rng);
  return sigma * Eigen::Vector3d(x, y, z);
}

Eigen::Vector3d RandomUnitVector(std::mt19937& rng) {
  Eigen::Vector3d v;
  do v = GaussianVector(rng, 1.0);
  while (v.norm() < 1e-6);
  return v.normalized();
}

Isometry3 AddNoise(const Isometry3& T, std::mt19937& rng, double rot_sigma_rad, double trans_sigma_m) {
  const Eigen::Vector3d n_rot = GaussianVector(rng, rot_sigma_rad);
  const Eigen::Vector3d n_trans = GaussianVector(rng, trans_sigma_m);
  return MakeIsometry(T.linear() * ExpSO3(n_rot), T.translation() + n_trans);
}

Matrix6 NoiseCovariance(double rot_sigma_rad, double trans_sigma_m) {
  Matrix6 C = Matrix6::Zero();
  C.diagonal() << Eigen::Vector3d::Constant(rot_sigma_rad * rot_sigma_rad),
      Eigen::Vector3d::Constant(trans_sigma_m * trans_sigma_m);
  return C;
}

}  // namespace

Isometry3 RandomIsometry(std::mt19937& rng, double max_translation_m) {
  std::normal_distribution<double> n(0.0, 1.0);
  const double w = n(rng), x = n(rng), y = n(rng), z = n(rng);
  const Eigen::Quaterniond q = Eigen::Quaterniond(w, x, y, z).normalized();
  std::uniform_real_distribution<double> u(-max_translation_m, max_translation_m);
  const double tx = u(rng), ty = u(rng), tz = u(rng);
  return MakeIsometry(q.toRotationMatrix(), Eigen::Vector3d(tx, ty, tz));
}

SyntheticMotionSet GenerateSyntheticMotions(const SyntheticMotionSettings& s) {
  std::mt19937 rng(s.seed);
  SyntheticMotionSet out;
  out.T_camera_lidar = s.T_camera_lidar ? *s.T_camera_lidar : RandomIsometry(rng, 0.5);
  const Isometry3& X = out.T_camera_lidar;
  const double rot_sigma = s.rotation_noise_deg * kDegToRad;
  std::uniform_real_distribution<double> angle_dist(s.min_angle_deg, s.max_angle_deg);
  std::uniform_real_distribution<double> trans_dist(-s.max_translation_m, s.max_translation_m);
  std::uniform_int_distribution<int> sign_dist(0, 1);
  for (int k = 0; k < s.num_motions; ++k) {
    Eigen::Vector3d axis;
    if (s.axes.empty()) {
      axis = RandomUnitVector(rng);
    } else {
      std::uniform_int_distribution<size_t> pick(0, s.axes.size() - 1);
      axis = s.axes[pick(rng)].normalized();
    }
    const double angle = angle_dist(rng) * kDegToRad * (sign_dist(rng) ? 1.0 : -1.0);
    const double tx = trans_dist(rng), ty = trans_dist(rng), tz = trans_dist(rng);
    const Isometry3 B = MakeIsometry(ExpSO3(angle * axis), Eigen::Vector3d(tx, ty, tz));
    const Isometry3 A = X * B * X.inverse();  // A X = X B
    out.A_true.push_back(A);
    out.B_true.push_back(B);
    out.true_scales.push_back(A.translation().norm());

    MotionPair p;
    p.station_i = k;
    p.station_j = k + 1;
    p.A = AddNoise(A, rng, rot_sigma, s.translation_noise_m);
    p.B = AddNoise(B, rng, rot_sigma, s.translation_noise_m);
    if (s.attach_covariance) {
      p.cov_A = NoiseCovariance(rot_sigma, s.translation_noise_m);
      p.cov_B = NoiseCovariance(rot_sigma, s.translation_noise_m);
    }
    if (s.scaleless) {
      p.camera_scaled = false;
      const double norm = p.A.translation().norm();
      if (norm > 0.0) p.A.translation() /= norm;
    }
    out.pairs.push_back(p);
  }
  return out;
}

Vector6 ExtrinsicError(const Isometry3& estimate, const Isometry3& truth) {
  Vector6 e;
  e << LogSO3(estimate.linear().transpose() * truth.linear()), truth.translation() - estimate.translation();
  return e;
}

ChangingMotionSet GenerateChangingMotions(SyntheticMotionSettings settings, int change_at, const Isometry3& delta) {
  ChangingMotionSet out;
  out.change_at = change_at;
  const SyntheticMotionSet before = GenerateSyntheticMotions(settings);
  out.before = before.T_camera_lidar;
  out.after = change_at < 0 ? out.before : Isometry3(out.before * delta);
  settings.T_camera_lidar = out.after;
  const SyntheticMotionSet after = GenerateSyntheticMotions(settings);
  for (int k = 0; k < static_cast<int>(before.pairs.size()); ++k) {
    MotionPair p = change_at < 0 || k < change_at ? before.pairs[k] : after.pairs[k];
    if (k == change_at) p.A = out.before * p.B * out.after.inverse();
    out.pairs.push_back(p);
  }
  return out;
}

}  // namespace fusecal
