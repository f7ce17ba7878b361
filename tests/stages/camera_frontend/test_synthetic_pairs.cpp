// Camera front end on rendered image pairs with a known motion (synthetic_room.hpp): both camera models.
// Requirements: rotation error <= 0.05 deg; translation direction error <= 2 deg where the camera moves by
// 5 cm or more; pure rotation is flagged translation_unreliable with the rotation still accurate.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <iostream>
#include <memory>
#include <opencv2/imgproc.hpp>

#include "runtime/sim/fixtures/camera_frontend_helpers.hpp"
#include "runtime/sim/fixtures/synthetic_room.hpp"
#include "stages/camera_frontend/relative_pose.hpp"

namespace fusecal {
using namespace fusecal::fixtures;  // the synthetic room and the camera helpers
namespace {

constexpr double kMaxRotationErrorDeg = 0.05;
constexpr double kMaxTranslationErrorDeg = 2.0;

const SyntheticRoom& Room() {
  static const SyntheticRoom room(FUSECAL_CAMERA_FRONTEND_TEST_DATA);
  return room;
}

Eigen::Matrix3d AxisAngle(double deg, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(Rad(deg), axis.normalized()).toRotationMatrix();
}

// Station i of the panorama tests: off-centre, slightly tilted.
Isometry3 PanoramaStation() { return MakeIsometry(AxisAngle(10, {0.1, 1, 0.2}), Eigen::Vector3d(0.2, -0.1, 0.3)); }

// Station i of the pinhole tests: about 2 m from the corner of the +x and +z walls, looking at it and
// slightly down, so that three planes are in view.
Isometry3 PinholeStation() {
  return MakeIsometry(AxisAngle(40, Eigen::Vector3d::UnitY()) * AxisAngle(-20, Eigen::Vector3d::UnitX()),
                      Eigen::Vector3d(1.2, -0.3, 2.0));
}

struct PairOutcome {
  RelativePoseResult result;
  Isometry3 A_true;
  PoseErrors errors;
  cv::Mat image_i, image_j;
};

// Renders the two stations (motion A_true = T_ci_cj) and estimates the motion.
PairOutcome RunPair(const std::string& name, const CameraParams& params, const Isometry3& T_world_ci,
                    const Isometry3& A_true, const CameraFrontendSettings& settings = {}) {
  const auto camera = MakeCameraModel(params);
  PairOutcome out;
  out.A_true = A_true;
  out.image_i = Room().Render(*camera, T_world_ci, 2, 1.5, 11);
  out.image_j = Room().Render(*camera, T_world_ci * A_true, 2, 1.5, 12);
  out.result = EstimateRelativePose(out.image_i, out.image_j, *camera, settings);
  out.errors = Errors(out.result, A_true);
  const RelativePoseResult& r = out.result;
  std::cout << "[" << name << "] " << params.model << " " << params.width << "x" << params.height
            << ": |t| = " << A_true.translation().norm() * 100 << " cm, rotation "
            << Deg(RotationAngle(A_true.linear())) << " deg -> rotation error " << out.errors.rotation_deg
            << " deg, translation direction error " << out.errors.translation_direction_deg << " deg; " << r.inliers
            << " inliers of " << r.matches << " matches, parallax " << r.median_parallax_deg << " deg, epipolar error "
            << r.median_epipolar_error_deg << " deg, " << (r.translation_unreliable ? "translation UNRELIABLE, " : "")
            << r.seconds << " s" << (r.failure_reason.text.empty() ? "" : " (" + r.failure_reason.text + ")") << "\n";
  return out;
}

void ExpectAccurateMotion(const PairOutcome& o) {
  const RelativePoseResult& r = o.result;
  EXPECT_TRUE(r.valid) << r.failure_reason;
  EXPECT_TRUE(r.usable()) << r.failure_reason;
  EXPECT_FALSE(r.too_few_inliers);
  EXPECT_FALSE(r.translation_unreliable) << r.failure_reason;
  EXPECT_TRUE(r.failure_reason.text.empty()) << r.failure_reason;
  EXPECT_GE(r.inliers, 200);
  EXPECT_LE(o.errors.rotation_deg, kMaxRotationErrorDeg);
  EXPECT_LE(o.errors.translation_direction_deg, kMaxTranslationErrorDeg);
  EXPECT_NEAR(r.t_unit.norm(), 1.0, 1e-9);
  EXPECT_LT((r.R.transpose() * r.R - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  EXPECT_EQ(r.inlier_pixels_i.size(), static_cast<size_t>(r.inliers));
  EXPECT_EQ(r.inlier_pixels_j.size(), static_cast<size_t>(r.inliers));
  // Covariance: symmetric, positive semi-definite, rotation block positive definite, translation block of
  // rank 2 with t_unit in its null space (the direction has no scale), standard deviations below 1 deg.
  ASSERT_TRUE(r.covariance_valid);
  EXPECT_LT((r.covariance - r.covariance.transpose()).norm(), 1e-12 + 1e-9 * r.covariance.norm());
  const Eigen::SelfAdjointEigenSolver<Matrix6> eig(r.covariance);
  EXPECT_GT(eig.eigenvalues().minCoeff(), -1e-12 * eig.eigenvalues().maxCoeff());
  const Eigen::Matrix3d rotation_block = r.covariance.block<3, 3>(0, 0);
  EXPECT_GT(rotation_block.determinant(), 0.0);
  EXPECT_LT((r.covariance.block<3, 3>(3, 3) * r.t_unit).norm(), 1e-9 * (1 + r.covariance.norm()));
  EXPECT_LT(Deg(std::sqrt(eig.eigenvalues().maxCoeff())), 1.0);
}

TEST(CameraFrontendSynthetic, PanoramaMotion30cm) {
  const Isometry3 A = MakeIsometry(AxisAngle(20, {0.2, 1, -0.1}), Eigen::Vector3d(0.25, 0.05, -0.15));
  ExpectAccurateMotion(RunPair("panorama 30 cm", PanoramaParams(1024), PanoramaStation(), A));
}

TEST(CameraFrontendSynthetic, PanoramaMotion5cm) {
  const Isometry3 A = MakeIsometry(AxisAngle(15, {0.3, -1, 0.2}), Eigen::Vector3d(0.03, -0.01, 0.04));
  ASSERT_GE(A.translation().norm(), 0.05);
  ExpectAccurateMotion(RunPair("panorama 5 cm", PanoramaParams(1024), PanoramaStation(), A));
}

// A pan of 150 degrees brings what is on the seam of image i to the middle of image j: features on the seam
// must be detected (wrap-around padding) and matched through their bearings.
TEST(CameraFrontendSynthetic, PanoramaMatchesAcrossTheSeam) {
  const Isometry3 A = MakeIsometry(AxisAngle(150, Eigen::Vector3d::UnitY()), Eigen::Vector3d(-0.2, 0.0, 0.2));
  const PairOutcome o = RunPair("panorama seam", PanoramaParams(1024), PanoramaStation(), A);
  ExpectAccurateMotion(o);
  int near_seam = 0;
  for (const cv::Point2f& p : o.result.inlier_pixels_i) near_seam += (p.x < 12 || p.x > 1024 - 13) ? 1 : 0;
  EXPECT_GE(near_seam, 5) << "inliers within 12 px of the seam of image i";
}

TEST(CameraFrontendSynthetic, PanoramaPureRotationFlagsTranslation) {
  const Isometry3 A = MakeIsometry(AxisAngle(25, {0.2, 1, 0.3}), Eigen::Vector3d::Zero());
  const PairOutcome o = RunPair("panorama pure rotation", PanoramaParams(1024), PanoramaStation(), A);
  const RelativePoseResult& r = o.result;
  EXPECT_TRUE(r.valid) << r.failure_reason;
  EXPECT_TRUE(r.translation_unreliable);
  EXPECT_FALSE(r.usable());
  EXPECT_FALSE(r.too_few_inliers);
  EXPECT_NE(r.failure_reason.text.find("translation unreliable"), std::string::npos) << r.failure_reason;
  EXPECT_GE(r.inliers, 200);
  EXPECT_LE(o.errors.rotation_deg, kMaxRotationErrorDeg);
  EXPECT_TRUE(r.covariance_valid);
  const Eigen::Matrix3d translation_block = r.covariance.block<3, 3>(3, 3);
  EXPECT_EQ(translation_block, Eigen::Matrix3d::Identity());  // uninformative translation
}

// Blank areas (here the bottom fifth of the panorama, as under a camera's mount) get no features.
TEST(CameraFrontendSynthetic, PanoramaWithBlankAreaIgnoresIt) {
  const Isometry3 A = MakeIsometry(AxisAngle(12, {0, 1, 0.1}), Eigen::Vector3d(0.2, 0.0, 0.1));
  const auto camera = MakeCameraModel(PanoramaParams(1024));
  cv::Mat image_i = Room().Render(*camera, PanoramaStation(), 2, 1.5, 21);
  cv::Mat image_j = Room().Render(*camera, PanoramaStation() * A, 2, 1.5, 22);
  const int blank_from = 512 * 4 / 5;
  image_i.rowRange(blank_from, 512).setTo(0);
  image_j.rowRange(blank_from, 512).setTo(0);
  const RelativePoseResult r = EstimateRelativePose(image_i, image_j, *camera);
  const PoseErrors e = Errors(r, A);
  std::cout << "[panorama blank area] rotation error " << e.rotation_deg << " deg, translation direction error "
            << e.translation_direction_deg << " deg, " << r.inliers << " inliers\n";
  EXPECT_TRUE(r.usable()) << r.failure_reason;
  EXPECT_LE(e.rotation_deg, kMaxRotationErrorDeg);
  EXPECT_LE(e.translation_direction_deg, kMaxTranslationErrorDeg);
  const int margin = CameraFrontendSettings().features.blank_margin_px;
  for (const auto* pixels : {&r.inlier_pixels_i, &r.inlier_pixels_j})
    for (const cv::Point2f& p : *pixels) ASSERT_LT(p.y, blank_from - margin) << "feature in the blank area";
}

TEST(CameraFrontendSynthetic, PinholeMotion20cm) {
  const Isometry3 A = MakeIsometry(AxisAngle(6, {0.3, 1, 0.2}), Eigen::Vector3d(0.15, 0.03, 0.13));
  ExpectAccurateMotion(RunPair("pinhole 20 cm", DistortedPinholeParams(), PinholeStation(), A));
}

TEST(CameraFrontendSynthetic, PinholeMotion5cm) {
  const Isometry3 A = MakeIsometry(AxisAngle(4, {-0.2, 1, 0.1}), Eigen::Vector3d(0.04, 0.01, 0.03));
  ASSERT_GE(A.translation().norm(), 0.05);
  ExpectAccurateMotion(RunPair("pinhole 5 cm", DistortedPinholeParams(), PinholeStation(), A));
}

TEST(CameraFrontendSynthetic, PinholePureRotationFlagsTranslation) {
  const Isometry3 A = MakeIsometry(AxisAngle(7, {0.3, 1, -0.2}), Eigen::Vector3d::Zero());
  const PairOutcome o = RunPair("pinhole pure rotation", DistortedPinholeParams(), PinholeStation(), A);
  EXPECT_TRUE(o.result.valid) << o.result.failure_reason;
  EXPECT_TRUE(o.result.translation_unreliable);
  EXPECT_GE(o.result.inliers, 200);
  EXPECT_LE(o.errors.rotation_deg, kMaxRotationErrorDeg);
}

// The motion j -> i is the inverse of i -> j: R_ji = R^T and t_ji ~ -R^T t (same direction convention).
TEST(CameraFrontendSynthetic, ReversedPairGivesInverseMotion) {
  const Isometry3 A = MakeIsometry(AxisAngle(10, {0.1, 1, 0.1}), Eigen::Vector3d(0.2, -0.05, 0.1));
  const auto camera = MakeCameraModel(DistortedPinholeParams());
  const cv::Mat image_i = Room().Render(*camera, PinholeStation(), 2, 1.5, 31);
  const cv::Mat image_j = Room().Render(*camera, PinholeStation() * A, 2, 1.5, 32);
  const RelativePoseResult forward = EstimateRelativePose(image_i, image_j, *camera);
  const RelativePoseResult backward = EstimateRelativePose(image_j, image_i, *camera);
  ASSERT_TRUE(forward.usable()) << forward.failure_reason;
  ASSERT_TRUE(backward.usable()) << backward.failure_reason;
  EXPECT_LE(RotationErrorDeg(backward.R, forward.R.transpose()), kMaxRotationErrorDeg);
  EXPECT_LE(DirectionErrorDeg(backward.t_unit, -forward.R.transpose() * forward.t_unit), kMaxTranslationErrorDeg);
  EXPECT_LE(Errors(backward, A.inverse()).translation_direction_deg, kMaxTranslationErrorDeg);
}

// Extracting features once and passing them gives exactly what the image overload gives; colour input
// (BGR, BGRA) works like grey.
TEST(CameraFrontendSynthetic, FeatureOverloadAndColourInputAgree) {
  const Isometry3 A = MakeIsometry(AxisAngle(8, {0, 1, 0.2}), Eigen::Vector3d(0.1, 0.02, 0.15));
  const auto camera = MakeCameraModel(DistortedPinholeParams());
  const cv::Mat grey_i = Room().Render(*camera, PinholeStation(), 2, 1.5, 41);
  const cv::Mat grey_j = Room().Render(*camera, PinholeStation() * A, 2, 1.5, 42);
  const CameraFrontendSettings settings;
  const RelativePoseResult from_images = EstimateRelativePose(grey_i, grey_j, *camera, settings);
  const ImageFeatures fi = ExtractImageFeatures(grey_i, *camera, settings.features);
  const ImageFeatures fj = ExtractImageFeatures(grey_j, *camera, settings.features);
  ASSERT_TRUE(fi.usable()) << fi.failure_reason;
  EXPECT_EQ(fi.keypoints.size(), fi.bearings.size());
  EXPECT_LE(static_cast<int>(fi.keypoints.size()), settings.features.max_features);
  const RelativePoseResult from_features = EstimateRelativePose(fi, fj, *camera, settings);
  ASSERT_TRUE(from_images.usable()) << from_images.failure_reason;
  EXPECT_EQ(from_features.inliers, from_images.inliers);
  EXPECT_LT((from_features.R - from_images.R).norm(), 1e-12);
  EXPECT_LT((from_features.t_unit - from_images.t_unit).norm(), 1e-12);

  cv::Mat bgr_i, bgr_j, bgra_i;
  cv::cvtColor(grey_i, bgr_i, cv::COLOR_GRAY2BGR);
  cv::cvtColor(grey_j, bgr_j, cv::COLOR_GRAY2BGR);
  cv::cvtColor(grey_i, bgra_i, cv::COLOR_GRAY2BGRA);
  const RelativePoseResult colour = EstimateRelativePose(bgra_i, bgr_j, *camera, settings);
  ASSERT_TRUE(colour.usable()) << colour.failure_reason;
  EXPECT_LE(Errors(colour, A).rotation_deg, kMaxRotationErrorDeg);
  EXPECT_LE(Errors(colour, A).translation_direction_deg, kMaxTranslationErrorDeg);
}

}  // namespace
}  // namespace fusecal
