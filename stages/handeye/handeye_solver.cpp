#include "stages/handeye/handeye_solver.hpp"

#include <cmath>
#include <exception>
#include <limits>
#include <sstream>

#include "stages/foundation/observed_covariance.hpp"
#include "stages/handeye/observability.hpp"
#include "stages/handeye/outlier_rejection.hpp"
#include "stages/handeye/pair_model.hpp"
#include "stages/handeye/refinement.hpp"
#include "stages/handeye/rotation_noise.hpp"
#include "stages/handeye/rotation_solver.hpp"
#include "stages/handeye/screening.hpp"
#include "stages/handeye/serial_correlation.hpp"
#include "stages/handeye/shared_error.hpp"
#include "stages/handeye/translation_solver.hpp"
#include "stages/handeye/travel_direction.hpp"

namespace fusecal {
namespace {

using namespace handeye;
constexpr double kRadToDeg = 180.0 / M_PI;

using Working = PairSet;  // the pairs in use, and those set aside as outliers

// The pairs set aside as outliers go to the result's rejected pairs, with why.
void AppendOutliers(const Working& w, const std::vector<MotionPair>& input, HandEyeResult* r) {
  for (const auto& [i, why] : w.outliers) r->rejected_pairs.push_back(MakeRejected(input, i, why));
}

// Steps of the outlier rejection at most: each pair can go and come back once, and more.
int MaxRejectionSteps(const std::vector<MotionPair>& input) { return 2 * static_cast<int>(input.size()) + 2; }

void SetCovariance(const Matrix6& C, HandEyeResult* r) {
  r->covariance = 0.5 * (C + C.transpose());
  for (int k = 0; k < 3; ++k) {
    r->std_dev_rot_deg(k) = std::sqrt(std::max(r->covariance(k, k), 0.0)) * kRadToDeg;
    r->std_dev_trans_m(k) = std::sqrt(std::max(r->covariance(k + 3, k + 3), 0.0));
  }
}

// Motions that only translate (FindTravelDirection): the estimate takes the initial guess (or the identity)
// turned the least so that it maps the LiDAR's direction of travel onto the camera's, and the verdict names
// what stays unobserved. The status stays failed: two rotational degrees of freedom are not an extrinsic.
void DescribeTravelOnly(const TravelDirection& travel, const HandEyeSettings& s, const Isometry3* initial,
                        HandEyeResult* r) {
  const Eigen::Matrix3d R0 = initial ? Eigen::Matrix3d(initial->linear()) : Eigen::Matrix3d::Identity();
  r->T_camera_lidar = MakeIsometry(AlignAxis(R0, travel.lidar, travel.camera),
                                   initial ? Eigen::Vector3d(initial->translation()) : Eigen::Vector3d::Zero());
  r->unobservable_direction = travel.camera;
  const Eigen::IOFormat list(3, Eigen::DontAlignCols, ", ", ", ", "", "", "[", "]");
  std::ostringstream m;
  m.precision(3);
  m << "the motions translate without rotating (" << travel.pairs << " pairs, largest rotation "
    << travel.largest_rotation_deg << " deg < min_rotation_deg " << s.min_rotation_deg
    << "): unobservable are the rotation about the direction of travel, camera " << travel.camera.format(list)
    << ", and the whole translation; observed is only the direction of travel, LiDAR " << travel.lidar.format(list)
    << " = camera " << travel.camera.format(list) << " (spread " << travel.spread_deg
    << " deg); turn the rig about two different axes";
  r->message += "; " + m.str();
}

// No estimate: status failed, failure_reason `code` with the message as its text.
void MarkFailed(HandEyeFailure code, HandEyeResult* r) {
  r->status = HandEyeStatus::kFailed;
  r->converged = false;
  r->failure_reason = {code, r->message};
}

// Validates settings and the initial guess, screens the pairs. False (result filled as failed) when no
// estimate can be made.
bool Prepare(const std::vector<MotionPair>& input, const HandEyeSettings& s, bool scaled, const Isometry3* initial,
             HandEyeResult* r, Working* w) {
  r->scaled = scaled;
  r->status = HandEyeStatus::kFailed;
  r->observability = Observability::kTooFewMotions;
  if (initial) r->T_camera_lidar = *initial;
  SetCovariance(kUnobservableVariance * Matrix6::Identity(), r);
  const std::string settings_error = s.Validate();
  if (!settings_error.empty()) {
    r->message = "invalid settings: " + settings_error;
    MarkFailed(HandEyeFailure::kInvalidSettings, r);
    return false;
  }
  if (initial && !IsValidTransform(*initial, s.orthonormality_tolerance)) {
    r->message = "initial guess is not a valid rigid transform";
    MarkFailed(HandEyeFailure::kInvalidInitialGuess, r);
    return false;
  }
  ScreeningOutcome screen = ScreenPairs(input, s, scaled);
  r->rejected_pairs = screen.rejected;
  for (int i : screen.usable) {
    w->index.push_back(i);
    w->pairs.push_back(input[i]);
  }
  if (w->size() < 2) {
    std::ostringstream m;
    m << "too few usable motion pairs: " << w->size() << " of " << input.size() << " (at least 2 needed, "
      << s.min_pairs << " for a verdict)";
    r->message = m.str();
    if (const auto travel = FindTravelDirection(input, s)) DescribeTravelOnly(*travel, s, initial, r);
    MarkFailed(HandEyeFailure::kTooFewPairs, r);
    return false;
  }
  return true;
}

double RotationCostSum(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R) {
  double sum = 0.0;
  for (const auto& p : pairs) sum += RotationResidual(p, R).squaredNorm();
  return sum;
}

// Starting rotation (paper: linear solution from the rotation axes). The initial guess replaces it when it
// fits the rotations better. With (nearly) parallel axes the rotation about the axis is taken from the
// initial guess, or, for scaled motions, from the translations when they determine it.
Eigen::Matrix3d InitialRotation(const std::vector<MotionPair>& pairs, const HandEyeSettings& s, const NoiseModel& noise,
                                const Isometry3* initial, bool scaled) {
  const Eigen::Matrix3d R_axes = RotationFromAxes(pairs);
  Eigen::Vector3d k_b;
  const double weakest_deg = WeakestRotationFromAxes(pairs, R_axes, noise, &k_b) * kRadToDeg;
  if (!(weakest_deg > s.max_rotation_std_deg)) {
    if (initial && RotationCostSum(pairs, initial->linear()) < RotationCostSum(pairs, R_axes)) return initial->linear();
    return R_axes;
  }
  const Eigen::Vector3d k_a = (R_axes * k_b).normalized();
  const Eigen::Matrix3d base = initial ? AlignAxis(initial->linear(), k_b, k_a) : R_axes;
  Eigen::Matrix3d R_axis;
  if (scaled && RotationAboutCommonAxis(pairs, base, k_b, &R_axis)) {
    const Eigen::Vector3d t = SolveTranslation(pairs, R_axis, false).t;
    if (AnalyzeScaled(pairs, R_axis, t, noise, s).rotation_std_deg <= s.max_rotation_std_deg) return R_axis;
  }
  return base;
}

// Variance component estimation: the per-axis noise (both sensors alike) that explains the residuals of the
// pairs without covariances. E|r_rot|^2 = 6 sigma_r^2; E|r_t|^2 = 2 sigma_r^2 |t|^2 + 6 sigma_t^2 (scaled),
// corrected by n / (n - 1) for the 3 (+3) estimated parameters. With `by_axis`, the rotation's weights and
// covariance also take its noise by direction (rotation_noise.hpp); sigma_r stays the pooled one.
NoiseModel EstimateNoise(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                         const NoiseModel& prior, bool scaled, bool by_axis) {
  double sum_rot = 0.0, sum_trans = 0.0;
  int n = 0;
  for (const auto& p : pairs) {
    if (p.cov_A && p.cov_B) continue;
    sum_rot += RotationResidual(p, R).squaredNorm();
    if (scaled) sum_trans += TranslationResidual(p, R, t).squaredNorm();
    ++n;
  }
  if (n < 2) return prior;
  NoiseModel out = prior;
  const double var_rot = std::max(sum_rot / (6.0 * (n - 1)), std::pow(1e-6 * prior.rot_sigma_rad, 2));
  out.rot_sigma_rad = std::sqrt(var_rot);
  if (scaled) {
    const double var_trans = (sum_trans / (n - 1) - 2.0 * var_rot * t.squaredNorm()) / 6.0;
    out.trans_sigma_m = std::sqrt(std::max(var_trans, std::pow(1e-6 * prior.trans_sigma_m, 2)));
  }
  if (by_axis) out.rotation_by_axis = EstimateRotationNoiseByAxis(pairs, R, std::pow(1e-6 * prior.rot_sigma_rad, 2));
  return out;
}

// Sum of the whitened squared residuals per degree of freedom (6 per pair, 6 parameters): about 1 when the
// noise model explains the residuals.
double ReducedChiSquare(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                        const NoiseModel& noise) {
  const int dof = 6 * static_cast<int>(pairs.size()) - 6;
  if (dof <= 0) return 1.0;
  double sum = 0.0;
  for (const auto& p : pairs) {
    const Vector6 r = PairResidual(p, R, t);
    sum += r.dot(ResidualCovariance(p, R, t, noise).ldlt().solve(r));
  }
  return std::isfinite(sum) ? sum / dof : 1.0;
}

// Inflates the covariance along unobservable directions ([d_rot ; t] coordinates): the exact null vectors,
// and the reported direction (rotation about it, d_rot = R^T direction, and t along it).
Matrix6 Inflate(Matrix6 C, const ObservabilityReport& obs, const Eigen::Matrix3d& R) {
  std::vector<Vector6> directions = obs.null_directions;
  Vector6 v = Vector6::Zero();
  if (obs.verdict == Observability::kRotationDegenerate) {
    v.head<3>() = R.transpose() * obs.direction;
    directions.push_back(v);
  }
  if (obs.verdict != Observability::kOk) {
    v.setZero();
    v.tail<3>() = obs.direction;
    directions.push_back(v);
  }
  for (const auto& d : directions) C += kUnobservableVariance * d.normalized() * d.normalized().transpose();
  return C;
}

// Observability, status, residuals and message common to both solves.
void Finish(const Working& w, const std::vector<MotionPair>& input, const HandEyeSettings& s,
            const ObservabilityReport& obs, const RefineOutput& est, const std::vector<double>& scales,
            HandEyeResult* r) {
  r->T_camera_lidar = MakeIsometry(est.R, est.t);
  for (int k = 0; k < w.size(); ++k) {
    const int i = w.index[k];
    r->used_pairs.push_back({i, input[i].station_i, input[i].station_j});
  }
  double sum_rot = 0.0, sum_trans = 0.0;
  for (int k = 0; k < w.size(); ++k) {
    sum_rot += RotationResidual(w.pairs[k], est.R).squaredNorm();
    sum_trans += TranslationResidual(w.pairs[k], est.R, est.t, scales.empty() ? 1.0 : scales[k]).squaredNorm();
  }
  r->verdict_rotation_std_deg = obs.rotation_std_deg;
  r->verdict_translation_std_m = obs.translation_std_m;
  r->residual_rms_rot_deg = std::sqrt(sum_rot / w.size()) * kRadToDeg;
  r->residual_rms_trans_m = std::sqrt(sum_trans / w.size());

  std::ostringstream m;
  if (w.size() < s.min_pairs) {
    r->observability = Observability::kTooFewMotions;
    r->status = HandEyeStatus::kDegenerate;
    m << "too few motion pairs (" << w.size() << " < min_pairs " << s.min_pairs << "); ";
  } else if (obs.verdict != Observability::kOk) {
    r->observability = obs.verdict;
    r->unobservable_direction = obs.direction;
    r->status = HandEyeStatus::kDegenerate;
  } else if (!est.usable) {
    r->observability = obs.verdict;
    r->status = HandEyeStatus::kFailed;
  } else {
    r->observability = obs.verdict;
    r->status = est.converged ? HandEyeStatus::kConverged : HandEyeStatus::kNotConverged;
  }
  r->converged = r->status == HandEyeStatus::kConverged;
  m << "used " << w.size() << " of " << input.size() << " pairs; observability " << Name(obs.verdict)
    << " (rotation std <= " << obs.rotation_std_deg << " deg, translation std <= " << obs.translation_std_m
    << " m at the noise the residuals show, at least nominal); residual rms " << r->residual_rms_rot_deg << " deg, "
    << r->residual_rms_trans_m << " m; solver: " << est.message;
  if (r->serial_correlation_inflation > 1.0)
    m << "; residuals correlated in sequence (overlapping pairs?): uncertainty x "
      << std::sqrt(r->serial_correlation_inflation) << ", as " << w.size() / r->serial_correlation_inflation
      << " independent pairs";
  if (obs.verdict != Observability::kOk) {
    const ObservedUncertainty observed = ObservedPart(r->covariance, est.R, obs.direction);
    m << "; observed part (unobservable direction projected out): rotation std <= " << observed.max_rotation_std_deg
      << " deg, translation std <= " << observed.max_translation_std_m << " m";
  }
  r->message = m.str();
  if (r->status == HandEyeStatus::kFailed)
    MarkFailed(HandEyeFailure::kSolverFailed, r);
  else
    r->failure_reason = {};
}

HandEyeResult SolveScaledImpl(const std::vector<MotionPair>& input, const HandEyeSettings& s,
                              const Isometry3* initial) {
  HandEyeResult r;
  Working w;
  if (!Prepare(input, s, true, initial, &r, &w)) return r;
  const NoiseModel nominal = NominalNoise(s);
  const Eigen::Vector3d t_prior = initial ? Eigen::Vector3d(initial->translation()) : Eigen::Vector3d::Zero();
  const bool robust = s.robust_loss != RobustLoss::kNone;
  RefineOutput est;
  for (int step = 0;; ++step) {
    const Eigen::Matrix3d R0 = InitialRotation(w.pairs, s, nominal, initial, true);
    const Eigen::Vector3d t0 = SolveTranslation(w.pairs, R0, false, initial ? &t_prior : nullptr).t;
    est = RefinePose(w.pairs, R0, t0, nominal, robust, s);
    r.iterations += est.iterations;
    if (!s.reject_outliers || step >= MaxRejectionSteps(input)) break;
    const auto residuals = [&est](const MotionPair& p) {
      return std::make_pair(RotationResidual(p, est.R).norm() * kRadToDeg, TranslationResidual(p, est.R, est.t).norm());
    };
    if (!RejectOrRestoreOne(&w, input, residuals, nominal, s)) break;
  }
  AppendOutliers(w, input, &r);

  // Final plain least squares with the noise re-estimated from the residuals (twice: the whitening depends
  // on the estimate and the noise).
  const bool given_cov = AllHaveCovariances(w.pairs);
  NoiseModel noise = nominal;
  for (int round = 0; round < 2; ++round) {
    if (!given_cov && s.estimate_noise_from_residuals)
      noise = EstimateNoise(w.pairs, est.R, est.t, nominal, true, s.rotation_noise_by_axis);
    est = RefinePose(w.pairs, est.R, est.t, noise, false, s);
    r.iterations += est.iterations;
  }
  r.noise_rot_deg = noise.rot_sigma_rad * kRadToDeg;
  r.noise_trans_m = noise.trans_sigma_m;

  // The verdict from the noise the data show (never below nominal); given covariances count as they are
  // unless the residuals say they were too small; pairs correlated in sequence count as fewer.
  const VarianceFactor serial = SerialCorrelationInflation(w.pairs, est.R, est.t, noise, true);
  r.serial_correlation_inflation = serial.Largest();
  const double chi2_factor = given_cov ? std::max(1.0, ReducedChiSquare(w.pairs, est.R, est.t, noise)) : 1.0;
  const VarianceFactor variance_factor = serial * chi2_factor;
  const ObservabilityReport obs =
      AnalyzeScaled(w.pairs, est.R, est.t, VerdictNoise(nominal, noise), s, variance_factor);
  // Along unobservable directions the estimate is noise: keep the initial guess there (zero without one).
  if (obs.verdict == Observability::kRotationDegenerate) {
    if (initial) est.R = AlignAxis(initial->linear(), est.R.transpose() * obs.direction, obs.direction);
    est.t = SolveTranslation(w.pairs, est.R, false, &t_prior, {obs.direction}).t;
  } else if (obs.verdict == Observability::kTranslationPartlyUnobservable) {
    est.t += obs.direction * obs.direction.dot(t_prior - est.t);
  }
  Matrix6 C = Matrix6::Zero();
  double cost = 0.0;
  if (!PoseCovariance(w.pairs, est.R, est.t, noise, &C, &cost)) C = kUnobservableVariance * Matrix6::Identity();
  const int dof = 6 * w.size() - 6;
  if (!given_cov && dof > 0) C *= 2.0 * cost / dof;  // sigma^2 = 2 cost / dof
  if (given_cov) C *= chi2_factor;  // the given covariances were too small when the residuals exceed them
  C = serial.Inflate(C);
  C += SharedErrorCovariance(w.pairs, est.R, est.t, noise, s.shared_camera_errors, s.shared_lidar_errors);
  SetCovariance(Inflate(C, obs, est.R), &r);
  Finish(w, input, s, obs, est, {}, &r);
  return r;
}

// Residuals of a pair in the scaleless solve at (R, t): rotation (degrees) and translation with the scale that
// fits it best, s = t_a^T (R t_b - (R_a - I) t) / |t_a|^2 (metres; infinite for a scale <= 0: the camera
// translation points against the LiDAR's, a flipped direction). With (nearly) parallel axes the rotation
// about the axis is arbitrary, and so are the translation residuals: zero then (`rotation_weak`).
std::pair<double, double> ScalelessResiduals(const MotionPair& p, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                             bool rotation_weak) {
  const double rot_deg = RotationResidual(p, R).norm() * kRadToDeg;
  if (rotation_weak) return {rot_deg, 0.0};
  const Eigen::Vector3d ta = p.A.translation();
  const Eigen::Vector3d rhs = R * p.B.translation() - (p.A.linear() - Eigen::Matrix3d::Identity()) * t;
  const double scale = ta.squaredNorm() > 1e-24 ? ta.dot(rhs) / ta.squaredNorm() : 0.0;
  if (!(scale > 0.0)) return {rot_deg, std::numeric_limits<double>::infinity()};
  return {rot_deg, TranslationResidual(p, R, t, scale).norm()};
}

// The per-pair scales and their standard deviations, from the rotation covariance C_rr, the linear
// translation covariance C_tt_linear and the residual variance var_t.
void SetScales(const Working& w, const Eigen::Matrix3d& R, const LinearTranslation& lt, const Eigen::Matrix3d& C_rr,
               const Eigen::Matrix3d& C_tt_linear, double var_t, HandEyeResult* r) {
  const Eigen::Matrix3d& G = lt.dt_drot;
  // Scales: s_i = u^T (R Exp(d) t_b - A_i t) / |t_a| + e_i / |t_a|.
  for (int k = 0; k < w.size(); ++k) {
    const MotionPair& p = w.pairs[k];
    const double ta = p.A.translation().norm();
    r->scales.push_back(lt.scales[k]);
    if (ta <= 1e-12) {
      r->scale_std_devs.push_back(0.0);
      continue;
    }
    const Eigen::Vector3d u = p.A.translation() / ta;
    const Eigen::Matrix3d A = p.A.linear() - Eigen::Matrix3d::Identity();
    const Eigen::RowVector3d g = -u.transpose() * R * Skew(p.B.translation()) - u.transpose() * A * G;
    const Eigen::RowVector3d a = u.transpose() * A;
    const double var = (g * C_rr * g.transpose())(0) + (a * C_tt_linear * a.transpose())(0) + var_t;
    r->scale_std_devs.push_back(std::sqrt(std::max(var, 0.0)) / ta);
  }
}

HandEyeResult SolveScalelessImpl(const std::vector<MotionPair>& input, const HandEyeSettings& s,
                                 const Isometry3* initial) {
  HandEyeResult r;
  Working w;
  if (!Prepare(input, s, false, initial, &r, &w)) return r;
  const NoiseModel nominal = NominalNoise(s);
  const Eigen::Vector3d t_prior = initial ? Eigen::Vector3d(initial->translation()) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d* prior = initial ? &t_prior : nullptr;
  const bool robust = s.robust_loss != RobustLoss::kNone;
  RefineOutput est;
  LinearTranslation lt;
  for (int step = 0;; ++step) {
    const Eigen::Matrix3d R0 = InitialRotation(w.pairs, s, nominal, initial, false);
    est = RefineRotation(w.pairs, R0, nominal, robust, s);
    r.iterations += est.iterations;
    lt = SolveTranslation(w.pairs, est.R, true, prior);
    if (!s.reject_outliers || step >= MaxRejectionSteps(input)) break;
    Eigen::Vector3d axis_b;
    const bool rotation_weak =
        WeakestRotationFromAxes(w.pairs, est.R, nominal, &axis_b) * kRadToDeg > s.max_rotation_std_deg;
    const auto residuals = [&](const MotionPair& p) { return ScalelessResiduals(p, est.R, lt.t, rotation_weak); };
    if (!RejectOrRestoreOne(&w, input, residuals, nominal, s)) break;
  }
  AppendOutliers(w, input, &r);

  const bool given_cov = AllHaveCovariances(w.pairs);
  NoiseModel noise = nominal;
  if (!given_cov && s.estimate_noise_from_residuals)
    noise = EstimateNoise(w.pairs, est.R, est.t, nominal, false, s.rotation_noise_by_axis);
  est = RefineRotation(w.pairs, est.R, noise, false, s);
  r.iterations += est.iterations;
  lt = SolveTranslation(w.pairs, est.R, true, prior);
  NoiseModel shown = noise;  // the noise the data show: rotation estimated above, translation from lt
  if (lt.dof > 0) shown.trans_sigma_m = std::sqrt(0.5 * lt.residual_sum_squares / lt.dof);
  const VarianceFactor serial = SerialCorrelationInflation(w.pairs, est.R, est.t, noise, false);
  r.serial_correlation_inflation = serial.Largest();
  const ObservabilityReport obs = AnalyzeScaleless(w.pairs, est.R, lt, VerdictNoise(nominal, shown), s, serial);
  if (obs.verdict != Observability::kOk) {
    // Along unobservable directions the estimate is noise: keep the initial guess there (zero without one).
    if (initial && obs.verdict == Observability::kRotationDegenerate)
      est.R = AlignAxis(initial->linear(), est.R.transpose() * obs.direction, obs.direction);
    lt = SolveTranslation(w.pairs, est.R, true, &t_prior, {obs.direction});
  }
  est.t = lt.t;

  // Rotation covariance from Ceres; translation from the linear system with the scales marginalised,
  // sigma_t^2 = residual sum of squares / dof, plus the rotation uncertainty propagated through R t_b.
  Eigen::Matrix3d C_rr = Eigen::Matrix3d::Zero();
  double cost = 0.0;
  if (!RotationCovariance(w.pairs, est.R, noise, &C_rr, &cost))
    C_rr = kUnobservableVariance * Eigen::Matrix3d::Identity();
  if (!given_cov && w.size() > 1) C_rr *= 2.0 * cost / (3.0 * w.size() - 3.0);
  const double var_t = lt.dof > 0 ? lt.residual_sum_squares / lt.dof : 2.0 * std::pow(nominal.trans_sigma_m, 2);
  noise.trans_sigma_m = std::sqrt(0.5 * var_t);
  r.noise_rot_deg = noise.rot_sigma_rad * kRadToDeg;
  r.noise_trans_m = noise.trans_sigma_m;
  const Eigen::Matrix3d& G = lt.dt_drot;
  const Eigen::Matrix3d C_tt_linear = var_t * lt.N_pinv;
  Matrix6 C;
  C << C_rr, C_rr * G.transpose(), G * C_rr, C_tt_linear + G * C_rr * G.transpose();

  SetScales(w, est.R, lt, C_rr, C_tt_linear, var_t, &r);

  C = serial.Inflate(C);
  SetCovariance(Inflate(C, obs, est.R), &r);
  Finish(w, input, s, obs, est, lt.scales, &r);
  return r;
}

template <typename Impl>
HandEyeResult Guarded(Impl impl, bool scaled) {
  try {
    return impl();
  } catch (const std::exception& e) {
    HandEyeResult r;
    r.scaled = scaled;
    r.message = std::string("internal error: ") + e.what();
    r.failure_reason = {HandEyeFailure::kInternalError, r.message};
    return r;
  }
}

}  // namespace

HandEyeResult SolveScaleless(const std::vector<MotionPair>& pairs, const HandEyeSettings& settings,
                             const Isometry3* initial) {
  return Guarded([&] { return SolveScalelessImpl(pairs, settings, initial); }, false);
}

HandEyeResult SolveScaled(const std::vector<MotionPair>& pairs, const HandEyeSettings& settings,
                          const Isometry3* initial) {
  return Guarded([&] { return SolveScaledImpl(pairs, settings, initial); }, true);
}

}  // namespace fusecal
