// Camera front end: the scaleless camera motion between two images (paper section III-A-1, "Camera").
//
//   AKAZE features (features.hpp) -> matching with ratio test and mutual check (matching.hpp)
//   -> 5-point RANSAC on bearing vectors (five_point_ransac.hpp)
//   -> refinement of the angular error with respect to the epipolar plane (epipolar_refinement.hpp)
//   -> chirality (chirality.hpp) and the pure-rotation check (rotation_only.hpp).
//
// Ishikawa, Oishi, Ikeuchi, "LiDAR and Camera Calibration using Motion Estimated by Sensor Fusion Odometry",
// IROS 2018. Works on unit bearing vectors, so pinhole (with distortion) and equirectangular cameras alike.
//
// Convention (docs/design.md section 2): the result is A = T_ci_cj, the pose of camera j in the frame of camera i:
// p_i = R p_j + t. t_unit is the direction of t, the position of camera j seen from camera i (for a camera
// that moves forward along its optical axis, t_unit is about +z). Translation has no scale.
//
// No LCM, no file I/O. Never throws: every problem ends up in the result's flags and failure_reason.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "stages/camera_frontend/features.hpp"
#include "stages/camera_frontend/settings.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/se3.hpp"
#include "stages/foundation/stage_result.hpp"

namespace fusecal {

// Why a relative pose is not usable (rotation and translation direction both).
enum class RelativePoseFailure {
  kNone,                   // usable
  kNotRun,                 // a default-constructed result
  kInvalidSettings,        // settings.Validate() failed
  kFeaturesFailed,         // the features of image i or j are not usable (their reason follows "image i: ")
  kFeaturesMismatch,       // features of another camera size, or keypoints, descriptors and bearings differ
  kTooFewMatches,          // fewer matches than min_inliers (too_few_inliers)
  kTooFewInliers,          // no model with min_inliers inliers (too_few_inliers)
  kTranslationUnreliable,  // near-pure rotation: R is valid, the translation direction is not
  kInternalError,          // an exception inside the core
};

struct RelativePoseResult {
  // Rotation and translation direction are both usable: A() is the motion.
  bool usable() const { return failure_reason.code == RelativePoseFailure::kNone; }
  // The same as usable().

  // valid: R is usable. The translation direction is usable too unless translation_unreliable.
  bool valid = false;
  // Fewer inliers than settings.min_inliers (or fewer matches): the motion is not valid.
  bool too_few_inliers = false;
  // Near-pure rotation (parallax at noise level): R stays valid (the refined essential-matrix rotation, or
  // the rotation-only fit f_i = R f_j when there is no consistent essential matrix); t_unit is the
  // essential-matrix direction if there is one (else zero) and must not be used.
  bool translation_unreliable = false;
  // kNone (empty text) when usable; otherwise why not (bad input, too few inliers, no parallax, ...).
  Failure<RelativePoseFailure> failure_reason{RelativePoseFailure::kNotRun, {}};

  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();   // rotation of A = T_ci_cj
  Eigen::Vector3d t_unit = Eigen::Vector3d::Zero();  // direction of the translation of A (unit, or zero)

  // 6x6 over [d_rot (rad); d_t] with R = R_hat Exp(d_rot) (right perturbation, frame j) and
  // t_unit = t_hat + d_t (frame i), the model of handeye_types.hpp (MotionPair::cov_A). The translation
  // block is that of the unit direction (rank 2, tangent to the sphere). With translation_unreliable the
  // translation block is the identity (uninformative) and the cross terms are zero.
  // Scaled by the robustly estimated residual variance (Ceres' covariance assumes unit variance).
  bool covariance_valid = false;
  Matrix6 covariance = Matrix6::Identity();

  int features_i = 0;  // keypoints kept in image i (after the budget)
  int features_j = 0;
  int matches = 0;         // after ratio test and mutual check
  int ransac_inliers = 0;  // of the 5-point RANSAC
  int ransac_iterations = 0;
  int rotation_only_inliers = 0;           // of the rotation-only RANSAC
  int inliers = 0;                         // of the final model
  double median_epipolar_error_deg = 0.0;  // median |angle to the epipolar plane| over the inliers
  double median_parallax_deg = 0.0;        // median residual of the rotation-only model over the inliers
  int refinement_iterations = 0;
  bool refinement_converged = false;

  double seconds = 0.0;  // the whole call (feature extraction included when given images)
  double seconds_features = 0.0;
  double seconds_matching = 0.0;
  double seconds_ransac = 0.0;
  double seconds_refinement = 0.0;

  // Pixels of the inlier correspondences (for overlays and debugging).
  std::vector<cv::Point2f> inlier_pixels_i;
  std::vector<cv::Point2f> inlier_pixels_j;

  // [R | t_unit] as a transform (translation of unit length, no scale).
  Isometry3 A() const { return MakeIsometry(R, t_unit); }
};

// Motion between two images of the same camera (8-bit grey, BGR or BGRA, the camera's size).
RelativePoseResult EstimateRelativePose(const cv::Mat& image_i, const cv::Mat& image_j, const CameraModel& camera,
                                        const CameraFrontendSettings& settings = {});

// Same from features extracted beforehand with ExtractImageFeatures (lets a caller extract each image once).
RelativePoseResult EstimateRelativePose(const ImageFeatures& features_i, const ImageFeatures& features_j,
                                        const CameraModel& camera, const CameraFrontendSettings& settings = {});

}  // namespace fusecal
