// Observability of the extrinsic from a set of motions: singular values of the whitened Jacobian.
//
// The information matrix J^T J of the used pairs (whitened with the verdict noise: the larger of nominal
// and estimated noise, or the given covariances; its rotation and translation blocks times
// `variance_factor`) is pseudo-inverted. An exactly null direction, or a direction whose standard deviation exceeds
// settings.max_rotation_std_deg / max_translation_std_m, is unobservable. Typical cases:
//   * all rotation axes parallel (scaleless), or all motions screws about one line (scaled): the rotation
//     about the axis, J_rot = I - R_b^T has the axis as null vector -> rotation_degenerate;
//   * scaled motions about one axis but different lines (planar motion): stacked (R_a - I) has the axis
//     k_a as null vector -> t along k_a unobservable -> translation_partly_unobservable.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "stages/handeye/handeye_types.hpp"
#include "stages/handeye/pair_model.hpp"
#include "stages/handeye/serial_correlation.hpp"
#include "stages/handeye/translation_solver.hpp"

namespace fusecal::handeye {

struct ObservabilityReport {
  Observability verdict = Observability::kOk;           // kOk, kRotationDegenerate or kTranslationPartlyUnobservable
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // camera frame, unit; zero when ok
  double rotation_std_deg = 0.0;         // largest standard deviation of the rotation (infinite when null)
  double translation_std_m = 0.0;        // largest standard deviation of t
  std::vector<Vector6> null_directions;  // exact null vectors in [d_rot ; t] coordinates
};

ObservabilityReport AnalyzeScaled(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R,
                                  const Eigen::Vector3d& t, const NoiseModel& noise, const HandEyeSettings& settings,
                                  const VarianceFactor& variance_factor = {});

// Rotation from the rotation residuals alone; t with the scales marginalised, from `lt` (translation
// residual variance 2 sigma_trans^2 per axis), plus the rotation uncertainty propagated through lt.dt_drot.
ObservabilityReport AnalyzeScaleless(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R,
                                     const LinearTranslation& lt, const NoiseModel& noise,
                                     const HandEyeSettings& settings, const VarianceFactor& variance_factor = {});

// The noise a verdict uses: per component the larger of the nominal and the estimated noise.
NoiseModel VerdictNoise(const NoiseModel& nominal, const NoiseModel& estimated);

// Largest standard deviation (rad) of the rotation as determined by the rotations alone, and its axis in the
// LiDAR frame (the rotation perturbation coordinates). Infinite for parallel axes.
double WeakestRotationFromAxes(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const NoiseModel& noise,
                               Eigen::Vector3d* axis_b);

}  // namespace fusecal::handeye
