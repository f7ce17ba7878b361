// Public types of the hand-eye solver core: input motion pairs, settings, result.
//
// Method: Ishikawa, Oishi, Ikeuchi, "LiDAR and Camera Calibration using Motion Estimated by Sensor Fusion
// Odometry", IROS 2018 (docs/design.md section 1, steps 3 and 5). For every motion i between two stations,
//   A_i X = X B_i,   A_i = T_ci_cj (camera), B_i = T_li_lj (LiDAR), X = T_camera_lidar,
// which splits into  R_a R = R R_b  (rotation)  and  R_a t + t_a = R t_b + t  (translation).
// No LCM, no file I/O here.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "stages/foundation/extrinsic_verdict.hpp"
#include "stages/foundation/se3.hpp"
#include "stages/foundation/stage_result.hpp"

namespace fusecal {

// Standard deviations of the entries of a linear map of a motion that all motions of one sensor share,
// d_rot = G w, d_t = (H + s I) t + K w (handeye/shared_error.hpp), and of its common length scale s.
struct SharedErrors {
  double rotation_per_rotation = 0.0;        // G: rad per rad of the motion's rotation
  double translation_per_translation = 0.0;  // H: m per m of the motion's translation
  double translation_per_rotation_m = 0.0;   // K: m per rad of the motion's rotation
  double translation_scale = 0.0;            // s: every translation long or short alike, d_t = s t (m/m)
  bool Any() const {
    return rotation_per_rotation > 0 || translation_per_translation > 0 || translation_per_rotation_m > 0 ||
           translation_scale > 0;
  }
  bool Valid() const {
    return rotation_per_rotation >= 0 && translation_per_translation >= 0 && translation_per_rotation_m >= 0 &&
           translation_scale >= 0;
  }
};

// One motion seen by both sensors.
//
// Covariances are 6x6 over [rotation (rad) ; translation (m)] with the perturbation model
//   R = R_hat * Exp(d_rot)   (rotation perturbed on the right, i.e. a rotation vector in frame j),
//   t = t_hat + d_trans      (translation perturbed additively, in frame i).
// The same model is used for the covariance of the result (frames: LiDAR for rotation, camera for t).
struct MotionPair {
  int station_i = -1;
  int station_j = -1;
  Isometry3 A = Isometry3::Identity();  // T_ci_cj, camera motion
  Isometry3 B = Isometry3::Identity();  // T_li_lj, LiDAR motion
  // false: A.translation() is a direction only (scaleless camera motion, e.g. from an essential matrix).
  bool camera_scaled = true;
  std::optional<Matrix6> cov_A;
  std::optional<Matrix6> cov_B;
};

// Identifies an input pair: its position in the input vector and its stations.
struct PairRef {
  int index = -1;
  int station_i = -1;
  int station_j = -1;
};

struct RejectedPair {
  int index = -1;
  int station_i = -1;
  int station_j = -1;
  std::string reason;
};

enum class RobustLoss { kNone, kHuber, kCauchy };

struct HandEyeSettings {
  // --- Screening of single pairs (before any solve) ---
  // The rotation angle is invariant under conjugation (R_a = R R_b R^T), so |angle(A) - angle(B)| must be
  // small: pairs beyond max_angle_difference_deg + angle_difference_fraction x the larger of the two angles
  // are rejected (the fixed part covers the noise, 10 x nominal; the part that grows with the turn covers
  // what grows with it: timing and scale errors of the motion estimates).
  double max_angle_difference_deg = 1.0;
  double angle_difference_fraction = 0.1;
  // Pairs whose camera and LiDAR angles are both below this carry no usable rotation axis (and (R_a - I)
  // vanishes, so they do not constrain t either): rejected as "no rotation".
  double min_rotation_deg = 1.0;
  // Rotation blocks must satisfy |R^T R - I|_F < tol and det R > 0.
  double orthonormality_tolerance = 1e-6;
  // Fewer usable pairs than this: observability "too_few_motions" (an estimate is still returned from two
  // pairs on; with fewer than 2 nothing can be estimated). Must be >= 2.
  int min_pairs = 3;

  // --- Robust estimation ---
  // After each initial solve, every screened pair (used, or rejected as an outlier before) is measured
  // against limits decided from all of them: outlier_factor x the median residual, but never below
  // outlier_factor x the median residual the nominal noise gives (nor outlier_min_*). The used pair that
  // exceeds its limit by the largest ratio is rejected; else a rejected pair below 0.8 x its limit comes
  // back; repeated until nothing changes. A rejection does not lower the limits (no cascade).
  bool reject_outliers = true;
  double outlier_factor = 4.0;
  double outlier_min_rotation_deg = 0.01;
  double outlier_min_translation_m = 0.001;
  // Loss of the first nonlinear solve, on the whitened residual of a pair (units: standard deviations).
  // The final solve (after outlier rejection) is plain least squares, so that the covariance is the usual one.
  RobustLoss robust_loss = RobustLoss::kHuber;
  double robust_loss_scale = 3.0;

  // --- Noise model ---
  // Used for pairs without covariances (both sensors, per axis), for whitening, and for the observability
  // verdict. When not every pair carries covariances, the two sigmas are re-estimated from the residuals
  // (variance component estimation) and the final covariance is scaled by sigma^2 = 2 cost / dof.
  double nominal_rotation_sigma_deg = 0.1;
  double nominal_translation_sigma_m = 0.01;
  bool estimate_noise_from_residuals = true;
  // With it, the re-estimated rotation noise also differs by direction: per class of motion across its
  // axis, and along it (handeye/rotation_noise.hpp). Weights and covariance use it; the verdict keeps the
  // pooled sigma. Off: on the simulated scenarios it does not yet bring every axis's coverage into band.
  bool rotation_noise_by_axis = false;

  // Errors every motion of one sensor shares (handeye/shared_error.hpp): standard deviations of the
  // entries of one unknown linear map per sensor and of its common length scale, added to the covariance
  // of the scaled solve. The camera's are the sizes fusion odometry's shared errors have in simulation
  // (docs/design.md, "Errors every motion shares"; config: handeye.shared_errors).
  SharedErrors shared_camera_errors{8e-5, 2e-4, 0.0, 5e-4};
  SharedErrors shared_lidar_errors;

  // --- Observability verdict ---
  // The verdict uses the information matrix of the used pairs under the noise the data show: per sensor
  // motion and axis the larger of the nominal noise and the noise estimated from the residuals (pairs
  // with given covariances: those, scaled by the reduced chi-square when it exceeds 1). A direction whose
  // standard deviation would exceed these thresholds (or whose singular value is zero) is unobservable.
  double max_rotation_std_deg = 1.0;
  double max_translation_std_m = 0.1;
  // A rotation std above max_rotation_std_deg is a degenerate direction only when it is more than this
  // many times the best-observed direction's: motions that lack an axis leave one direction far weaker
  // than the others (a turn about the vertical alone: tens of times), noisy motions about axes spread in
  // 3D leave all alike (a handheld rig at 1 deg per motion: within a factor of 1.5). The latter is an
  // estimate as uncertain as its std says, observed, not a degenerate one.
  double degenerate_rotation_anisotropy = 3.0;
  // Hysteresis: a verdict of the same session (previous_verdict, set by the hand-eye stage) changes only
  // when a standard deviation crosses its threshold by this fraction: a degenerate part becomes observed
  // below (1 - h) x threshold, an observed part becomes degenerate above (1 + h) x threshold.
  double verdict_hysteresis = 0.2;
  std::optional<Observability> previous_verdict;

  // --- Nonlinear solver (Ceres) ---
  int max_iterations = 100;
  double function_tolerance = 1e-12;
  double parameter_tolerance = 1e-12;
  double gradient_tolerance = 1e-12;

  // Empty string when valid, otherwise a description of the first problem found.
  std::string Validate() const;
  bool IsValid(std::string* error = nullptr) const;
};

// HandEyeResult::status and ::observability are HandEyeStatus and Observability
// (foundation/extrinsic_verdict.hpp), named by Name().

// Why a hand-eye solve made no estimate (status failed).
enum class HandEyeFailure {
  kNone,                 // usable: status converged, not_converged or degenerate
  kNotRun,               // a default-constructed result
  kInvalidSettings,      // settings.Validate() failed
  kInvalidInitialGuess,  // the initial guess is not a rigid transform
  kTooFewPairs,          // fewer than 2 usable motion pairs
  kSolverFailed,         // the nonlinear solver produced no usable solution
  kInternalError,        // an exception inside the core
};

struct HandEyeResult {
  Isometry3 T_camera_lidar = Isometry3::Identity();
  // 6x6 over [rotation (rad) ; translation (m)], perturbation R = R_hat Exp(d_rot), t = t_hat + d_trans.
  // Along unobservable directions a variance of kUnobservableVariance is added.
  Matrix6 covariance = Matrix6::Zero();
  Eigen::Vector3d std_dev_rot_deg = Eigen::Vector3d::Zero();  // sqrt of the diagonal, degrees
  Eigen::Vector3d std_dev_trans_m = Eigen::Vector3d::Zero();  // sqrt of the diagonal, metres

  // An estimate exists (status is not failed); see status and observability for what it is worth.
  bool usable() const { return failure_reason.code == HandEyeFailure::kNone; }

  bool scaled = false;     // SolveScaled (true) or SolveScaleless (false)
  bool converged = false;  // true only when status is kConverged (never for a degenerate set)
  HandEyeStatus status = HandEyeStatus::kFailed;
  Observability observability = Observability::kTooFewMotions;
  // Camera frame, unit; zero when ok. Along it the estimate keeps the initial guess's value (t along it and,
  // for rotation_degenerate, the rotation about it), or zero translation / an arbitrary angle without one.
  Eigen::Vector3d unobservable_direction = Eigen::Vector3d::Zero();

  std::vector<PairRef> used_pairs;
  std::vector<RejectedPair> rejected_pairs;
  // Scaleless: one scale per used pair (same order), s_i in R_a t + s_i t_a = R t_b + t, and its standard
  // deviation. Empty for the scaled solve.
  std::vector<double> scales;
  std::vector<double> scale_std_devs;

  // RMS over used pairs of |Log(R_b^T R^T R_a R)| (degrees) and of |R_a t + s_i t_a - R t_b - t| (metres).
  double residual_rms_rot_deg = 0.0;
  double residual_rms_trans_m = 0.0;
  // The largest standard deviations the verdict compared with max_rotation_std_deg / max_translation_std_m
  // (at the noise the data show, at least nominal; infinite along a null direction).
  double verdict_rotation_std_deg = 0.0;
  double verdict_translation_std_m = 0.0;
  // Noise per sensor motion and axis that the final solve used (estimated from residuals, or nominal).
  double noise_rot_deg = 0.0;
  double noise_trans_m = 0.0;
  // Variance inflation for pairs whose residuals are correlated in sequence (overlapping windows; 1: none),
  // applied to the verdict and the covariance (handeye/serial_correlation.hpp).
  double serial_correlation_inflation = 1.0;

  int iterations = 0;   // nonlinear iterations, all solves together
  std::string message;  // what the solve found, or why it failed
  // kNone when usable; else the code, and the message as its text.
  Failure<HandEyeFailure> failure_reason{HandEyeFailure::kNotRun, {}};

  bool IsRejected(int station_i, int station_j) const;
  bool IsUsed(int station_i, int station_j) const;
};

// Variance added along unobservable directions of the result covariance (rad^2 or m^2).
inline constexpr double kUnobservableVariance = 1e6;

}  // namespace fusecal
