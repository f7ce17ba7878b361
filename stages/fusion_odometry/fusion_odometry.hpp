// Sensor fusion odometry: the camera motion WITH SCALE between two stations, from the LiDAR scan of station
// i, the images of stations i and j and the current extrinsic (Ishikawa, Oishi, Ikeuchi, "LiDAR and Camera
// Calibration using Motion Estimated by Sensor Fusion Odometry", IROS 2018, section III-B-1).
//
//   project scan i into image i with X, keep visible points (z-buffer; visibility.hpp)
//   -> keep trackable ones (corner response, spacing, budget; track_selection.hpp)
//   -> KLT-track them into image j, initial flow predicted by the motion guess, forward-backward check
//      (klt_tracking.hpp); image j is first resampled with camera i's orientation when the guess turns
//      the camera (derotation.hpp)  => 2D-3D correspondences (bearing v'_j in image j, point p_ci)
//   -> P3P RANSAC (Kneip 2011) on the bearings when the guess is not reliable (p3p_ransac.hpp)
//   -> minimise sum_k rho(|v'_j x Proj(A^-1 X p_li)|^2) over A (paper: |v'_j x Proj(R_a (R p_j + t) + t_a)|,
//      with (R_a, t_a) = A^-1 and (R, t) = X), robust loss, outlier tracks removed by their residual
//      under the refined pose (pose_refinement.hpp); after a RANSAC start, tracked again with the estimate
//      as the prediction and refined again.
//
// Conventions (docs/design.md section 2): X = T_camera_lidar; the result is A = T_ci_cj, the pose of camera j in
// the frame of camera i, p_ci = A p_cj. A LiDAR motion B = T_li_lj predicts A = X B X^-1 (A X = X B).
// No LCM, no file I/O. Never throws: every problem ends up in status and failure_reason.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/point_cloud.hpp"
#include "stages/foundation/se3.hpp"
#include "stages/foundation/stage_result.hpp"
#include "stages/fusion_odometry/settings.hpp"
#include "stages/fusion_odometry/types.hpp"

namespace fusecal::fusion_odometry {

// Values of FusionOdometryResult::status.
namespace status {
inline constexpr const char* kConverged = "converged";         // the motion is usable
inline constexpr const char* kNotConverged = "not_converged";  // an estimate, but too few inliers (see reason)
inline constexpr const char* kFailed = "failed";               // no estimate (bad input, no tracks, ...)
}  // namespace status

// The motion the tracking starts from. reliable = false (e.g. the first iteration, or X B X^-1 with a rough
// initial extrinsic): the P3P RANSAC decides (settings.ransac_mode "auto"); the guess still predicts the
// optical flow and competes as one more hypothesis.
struct MotionGuess {
  Isometry3 T_ci_cj = Isometry3::Identity();
  bool reliable = false;
};

// Why a scaled motion is not usable.
enum class FusionOdometryFailure {
  kNone,               // usable
  kNotRun,             // a default-constructed result
  kInvalidSettings,    // settings.Validate() failed
  kInvalidInput,       // camera without size, bad image, invalid extrinsic or guess, empty scan
  kNothingProjects,    // no scan point projects into image i
  kTooFewTrackable,    // too few trackable scan points in image i
  kTrackingFailed,     // too few points tracked into image j
  kNoMotion,           // neither the guess nor the RANSAC explains the tracks
  kRefinementFailed,   // the pose refinement failed
  kTooFewInliers,      // an estimate, but fewer inliers than min_inliers (status not_converged)
  kTooFewTracksAgree,  // an estimate, but fewer inliers than min_inlier_ratio of the tracks (not_converged)
  kInternalError,      // an exception inside the core
};

struct FusionOdometryResult {
  Isometry3 T_ci_cj = Isometry3::Identity();  // A, metric
  bool usable() const { return failure_reason.code == FusionOdometryFailure::kNone; }
  std::string status = status::kFailed;  // converged (usable), not_converged (an estimate) or failed
  Failure<FusionOdometryFailure> failure_reason{FusionOdometryFailure::kNotRun, {}};  // text empty when usable

  int inliers = 0;  // final 2D-3D correspondences (residual under A below refinement.max_residual_px)
  // 6x6 over [d_rot (rad); d_t (m)] with R = R_hat Exp(d_rot) (rotation vector in frame j) and
  // t = t_hat + d_t (frame i), the model of handeye_types.hpp (MotionPair::cov_A): sigma^2 (J^T J)^-1 over
  // the inliers, sigma^2 from the residuals.
  bool covariance_valid = false;
  Matrix6 covariance = Matrix6::Identity();
  double seconds = 0.0;

  // Diagnostics, per step.
  int projected_points = 0;  // scan points in front of / inside image i
  int visible_points = 0;    // after the z-buffer
  int selected_points = 0;   // trackable, spaced, within the budget
  int tracked_points = 0;    // tracked into image j, forward-backward consistent (last pass)
  bool used_ransac = false;
  int ransac_inliers = 0;
  int ransac_iterations = 0;
  int guess_inliers = 0;  // tracks consistent with the guess (first pass)
  int passes = 0;         // tracking passes (2 when re-tracked with the estimate)
  int refinement_iterations = 0;
  double rms_residual_px = 0.0;  // over the inliers, in pixels at the image centre
  double median_residual_px = 0.0;
  double seconds_selection = 0.0;  // projection, visibility and selection
  double seconds_tracking = 0.0;
  double seconds_ransac = 0.0;
  double seconds_refinement = 0.0;

  Correspondences inlier_correspondences;  // for overlays and debugging
};

// The metric camera motion A = T_ci_cj. scan_i: station i in the LiDAR frame; images 8-bit grey, BGR or
// BGRA of the camera's size. Never throws.
FusionOdometryResult EstimateScaledMotion(const PointCloud& scan_i, const cv::Mat& image_i, const cv::Mat& image_j,
                                          const CameraModel& camera, const Isometry3& T_camera_lidar,
                                          const MotionGuess& guess = {}, const FusionOdometrySettings& settings = {});

// A = X B X^-1: the camera motion that a LiDAR motion B = T_li_lj implies under X = T_camera_lidar.
Isometry3 CameraMotionFromLidar(const Isometry3& T_camera_lidar, const Isometry3& T_li_lj);

}  // namespace fusecal::fusion_odometry
