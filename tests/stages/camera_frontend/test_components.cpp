// The steps of the camera front end on their own: settings, masks, budget, matching, bearing geometry,
// chirality, 5-point RANSAC, epipolar refinement and its covariance, rotation-only fit.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <iostream>
#include <opencv2/features2d.hpp>
#include <random>

#include "runtime/sim/fixtures/camera_frontend_helpers.hpp"
#include "stages/camera_frontend/bearings.hpp"
#include "stages/camera_frontend/chirality.hpp"
#include "stages/camera_frontend/epipolar_refinement.hpp"
#include "stages/camera_frontend/features.hpp"
#include "stages/camera_frontend/five_point_ransac.hpp"
#include "stages/camera_frontend/masks.hpp"
#include "stages/camera_frontend/matching.hpp"
#include "stages/camera_frontend/rotation_only.hpp"
#include "stages/camera_frontend/settings.hpp"

namespace fusecal {
using namespace fusecal::fixtures;  // the synthetic room and the camera helpers
namespace {

using namespace fusecal::camera_frontend;

// ------------------------------------------------------------------------------------------- settings

TEST(CameraFrontendSettings, DefaultsAreValid) { EXPECT_EQ(CameraFrontendSettings().Validate(), ""); }

TEST(CameraFrontendSettings, BadFieldsAreNamed) {
  auto message = [](auto mutate) {
    CameraFrontendSettings s;
    mutate(s);
    return s.Validate();
  };
  EXPECT_EQ(message([](auto& s) { s.ransac.threshold_px = 0; }).rfind("ransac.threshold_px", 0), 0u);
  EXPECT_EQ(message([](auto& s) { s.ransac.algorithm = "eightpt"; }).rfind("ransac.algorithm", 0), 0u);
  EXPECT_EQ(message([](auto& s) { s.features.max_features = 0; }).rfind("features.max_features", 0), 0u);
  EXPECT_EQ(message([](auto& s) { s.features.blank_value = 300; }).rfind("features.blank_value", 0), 0u);
  EXPECT_EQ(message([](auto& s) { s.matching.ratio = 1.5; }).rfind("matching.ratio", 0), 0u);
  EXPECT_EQ(message([](auto& s) { s.refinement.loss_scale_px = -1; }).rfind("refinement.loss_scale_px", 0), 0u);
  EXPECT_EQ(message([](auto& s) { s.min_inliers = 3; }).rfind("min_inliers", 0), 0u);
  EXPECT_EQ(message([](auto& s) { s.max_translation_std_deg = 0; }).rfind("max_translation_std_deg", 0), 0u);
}

// ---------------------------------------------------------------------------------------------- masks

TEST(CameraFrontendMasks, BlankAreasCoverConstantFillAndMarginOnly) {
  cv::Mat grey(100, 200, CV_8U);
  cv::randu(grey, 10, 250);
  grey(cv::Rect(150, 0, 50, 100)).setTo(0);  // a blank band on the right
  grey.at<uchar>(20, 20) = 0;                // isolated black pixels of texture: not blank
  grey.at<uchar>(21, 21) = 0;
  const cv::Mat blank = BlankAreas(grey, 0, 8);
  EXPECT_EQ(blank.at<uchar>(50, 199), 255);
  EXPECT_EQ(blank.at<uchar>(50, 150), 255);
  EXPECT_EQ(blank.at<uchar>(50, 150 - 8), 255);  // within the margin
  EXPECT_EQ(blank.at<uchar>(50, 150 - 12), 0);   // beyond it
  EXPECT_EQ(blank.at<uchar>(20, 20), 0);
  EXPECT_EQ(cv::countNonZero(BlankAreas(grey, -1, 8)), 0);  // disabled
}

TEST(CameraFrontendMasks, PoleRowsOfPanoramaOnly) {
  const auto panorama = MakeCameraModel(PanoramaParams(360));  // 180 rows: one degree per row
  const cv::Mat rows = PoleRows(*panorama, 70.0);
  // Row v has latitude 90 - (v + 0.5) degrees: rows 0..19 are beyond 70 degrees, 20..159 within.
  EXPECT_EQ(rows.at<uchar>(19, 5), 255);
  EXPECT_EQ(rows.at<uchar>(20, 5), 0);
  EXPECT_EQ(rows.at<uchar>(159, 5), 0);
  EXPECT_EQ(rows.at<uchar>(160, 5), 255);
  const auto pinhole = MakeCameraModel(DistortedPinholeParams());
  EXPECT_EQ(cv::countNonZero(PoleRows(*pinhole, 10.0)), 0);
}

TEST(CameraFrontendFeatures, GridBudgetSpreadsFeatures) {
  // 400 strong keypoints crowded in the top-left cell, 1 weak keypoint in each of the other 15 cells.
  std::vector<cv::KeyPoint> keypoints;
  for (int k = 0; k < 400; ++k) keypoints.emplace_back(cv::Point2f(k % 20, k / 20), 5.f, -1.f, 1.0f + k);
  for (int cell = 1; cell < 16; ++cell)
    keypoints.emplace_back(cv::Point2f((cell % 4) * 100 + 50, (cell / 4) * 100 + 50), 5.f, -1.f, 0.001f);
  const std::vector<int> selected = SelectKeypointsByGrid(keypoints, 400, 400, 100, 4, 4);
  ASSERT_EQ(selected.size(), 100u);
  int weak = 0;
  for (int k : selected) weak += keypoints[k].response < 0.01f ? 1 : 0;
  EXPECT_EQ(weak, 15);  // every other cell keeps its keypoint
  for (size_t k = 1; k < selected.size(); ++k)
    EXPECT_GE(keypoints[selected[k - 1]].response, keypoints[selected[k]].response);
  EXPECT_EQ(SelectKeypointsByGrid(keypoints, 400, 400, 1000, 4, 4).size(), keypoints.size());
}

// ------------------------------------------------------------------------------------------- matching

// Reference: cv::BFMatcher knnMatch(k = 2) with ratio test, then match() the other way for the mutual check.
std::vector<cv::DMatch> ReferenceMatches(const cv::Mat& a, const cv::Mat& b, double ratio) {
  cv::BFMatcher matcher(cv::NORM_HAMMING);
  std::vector<std::vector<cv::DMatch>> knn;
  matcher.knnMatch(a, b, knn, 2);
  std::vector<cv::DMatch> back;
  matcher.match(b, a, back);
  std::vector<cv::DMatch> out;
  for (const auto& pair : knn)
    if (pair.size() == 2 && pair[0].distance < ratio * pair[1].distance &&
        back[pair[0].trainIdx].trainIdx == pair[0].queryIdx)
      out.push_back(pair[0]);
  return out;
}

TEST(CameraFrontendMatching, AgreesWithBFMatcher) {
  cv::RNG rng(7);
  cv::Mat b(600, 61, CV_8U);
  rng.fill(b, cv::RNG::UNIFORM, 0, 256);
  cv::Mat a(400, 61, CV_8U);
  rng.fill(a, cv::RNG::UNIFORM, 0, 256);
  for (int r = 0; r < 300; ++r) {  // 300 rows of a are noisy copies of rows of b
    b.row((r * 7) % 600).copyTo(a.row(r));
    for (int flip = 0; flip < r % 60; ++flip) a.at<uchar>(r, rng.uniform(0, 61)) ^= 1u << rng.uniform(0, 8);
  }
  const std::vector<cv::DMatch> ours = MatchDescriptors(a, b, MatchingSettings());
  const std::vector<cv::DMatch> reference = ReferenceMatches(a, b, MatchingSettings().ratio);
  ASSERT_GT(reference.size(), 150u);
  ASSERT_EQ(ours.size(), reference.size());
  for (size_t k = 0; k < ours.size(); ++k) {
    EXPECT_EQ(ours[k].queryIdx, reference[k].queryIdx);
    EXPECT_EQ(ours[k].trainIdx, reference[k].trainIdx);
    EXPECT_EQ(ours[k].distance, reference[k].distance);
  }
  MatchingSettings no_mutual;
  no_mutual.mutual_check = false;
  EXPECT_GE(MatchDescriptors(a, b, no_mutual).size(), ours.size());
  EXPECT_TRUE(MatchDescriptors(cv::Mat(), b, MatchingSettings()).empty());
}

// --------------------------------------------------------------------------------- synthetic bearings

struct Scene {
  Eigen::Matrix3d R;  // A = T_ci_cj
  Eigen::Vector3d t;
  Bearings f_i, f_j;
  std::vector<char> outlier;
};

Eigen::Vector3d Perturb(const Eigen::Vector3d& f, double sigma, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, sigma);
  return (f + Eigen::Vector3d(n(rng), n(rng), n(rng)).cross(f)).normalized();
}

// Points seen by camera j within +-half_width (x) and +-half_height (y) radians of its axis, 2 to 10 m away.
Scene MakeScene(int points, double noise_rad, double outlier_fraction, unsigned seed, double half_width = 0.6,
                double half_height = 0.4,
                const Eigen::Matrix3d& R =
                    Eigen::AngleAxisd(Rad(40), Eigen::Vector3d(0.3, 1, -0.2).normalized()).toRotationMatrix()) {
  Scene s;
  s.R = R;
  s.t = Eigen::Vector3d(0.4, -0.1, 0.3);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), depth(2, 10), unit(0, 1);
  for (int k = 0; k < points; ++k) {
    const Eigen::Vector3d p_j =
        Eigen::Vector3d(std::tan(half_width * u(rng)), std::tan(half_height * u(rng)), 1).normalized() * depth(rng);
    Eigen::Vector3d f_i = (s.R * p_j + s.t).normalized();
    const bool outlier = unit(rng) < outlier_fraction;
    if (outlier) f_i = Eigen::Vector3d(u(rng), u(rng), 1).normalized();
    s.f_i.push_back(Perturb(f_i, noise_rad, rng));
    s.f_j.push_back(Perturb(p_j.normalized(), noise_rad, rng));
    s.outlier.push_back(outlier);
  }
  return s;
}

std::vector<int> All(const Scene& s) {
  std::vector<int> all(s.f_i.size());
  for (size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
  return all;
}

TEST(CameraFrontendGeometry, EpipolarAngleMeasuresDistanceToPlane) {
  const Scene s = MakeScene(20, 0.0, 0.0, 1);
  for (size_t k = 0; k < s.f_i.size(); ++k) EXPECT_NEAR(EpipolarAngle(s.R, s.t, s.f_i[k], s.f_j[k]), 0.0, 1e-12);
  // Tilt f_i out of its epipolar plane by a known angle: about an axis inside the plane.
  const Eigen::Vector3d n = s.t.cross(s.R * s.f_j[0]).normalized();
  const Eigen::Vector3d axis = n.cross(s.f_i[0]).normalized();  // in the plane, orthogonal to f_i
  const Eigen::Vector3d tilted = Eigen::AngleAxisd(0.01, axis) * s.f_i[0];
  EXPECT_NEAR(std::abs(EpipolarAngle(s.R, s.t, tilted, s.f_j[0])), 0.01, 1e-9);
  EXPECT_NEAR(RotationOnlyAngle(s.R, s.R * s.f_j[0], s.f_j[0]), 0.0, 1e-12);
  EXPECT_NEAR(Median({3.0, 1.0, 2.0}), 2.0, 0.0);
  const auto pano = MakeCameraModel(PanoramaParams(2048));
  EXPECT_NEAR(PixelAngleRad(*pano), 2 * M_PI / 2048, 1e-9);
  const auto kitti = MakeCameraModel(KittiParams());
  EXPECT_NEAR(PixelAngleRad(*kitti), 1.0 / 721.5377, 1e-6);
}

TEST(CameraFrontendGeometry, ChiralityPicksThePhysicalMotion) {
  const Scene s = MakeScene(50, 0.0, 0.0, 2);
  const std::vector<int> all = All(s);
  double l_i = 0, l_j = 0;
  ASSERT_TRUE(TriangulateDepths(s.R, s.t, s.f_i[0], s.f_j[0], &l_i, &l_j));
  EXPECT_GT(l_i, 0);
  EXPECT_GT(l_j, 0);
  EXPECT_EQ(CountInFront(s.R, s.t, s.f_i, s.f_j, all).in_front, 50);
  EXPECT_EQ(CountInFront(s.R, -s.t, s.f_i, s.f_j, all).in_front, 0);

  Eigen::Matrix3d R = s.R;
  Eigen::Vector3d t = -s.t.normalized();  // wrong sign
  EXPECT_EQ(ResolveChirality(s.f_i, s.f_j, all, &R, &t).in_front, 50);
  EXPECT_LT((t - s.t.normalized()).norm(), 1e-12);
  EXPECT_LT((R - s.R).norm(), 1e-12);

  R = Eigen::AngleAxisd(M_PI, s.t.normalized()) * s.R;  // twisted pair
  t = s.t.normalized();
  ResolveChirality(s.f_i, s.f_j, all, &R, &t);
  EXPECT_LT(RotationErrorDeg(R, s.R), 1e-9);
  EXPECT_LT((t - s.t.normalized()).norm(), 1e-12);
}

TEST(CameraFrontendRansac, MinimalSolverFollowsTheConvention) {
  const Scene s = MakeScene(5, 0.0, 0.0, 3);
  for (const std::string algorithm : {"stewenius", "nister"}) {
    bool found = false;
    for (const auto& [R, t] : FivePointMotions(s.f_i, s.f_j, {0, 1, 2, 3, 4}, algorithm))
      found = found || (RotationErrorDeg(R, s.R) < 1e-6 && DirectionErrorDeg(t, s.t) < 1e-6);
    EXPECT_TRUE(found) << algorithm << ": p_i = R p_j + t not among the solutions";
  }
}

TEST(CameraFrontendRansac, FindsMotionAndInliersAmongOutliers) {
  const double noise = 0.0005;  // rad, about half a pixel of a 640-pixel camera
  const Scene s = MakeScene(600, noise, 0.35, 4);
  RansacSettings settings;
  const RansacResult r = FivePointRansac(s.f_i, s.f_j, settings, 3 * noise);
  ASSERT_TRUE(r.ok);
  EXPECT_LT(RotationErrorDeg(r.R, s.R), 0.3);
  EXPECT_LT(DirectionErrorDeg(r.t, s.t), 2.0);
  int true_positive = 0;
  for (int k : r.inliers) true_positive += s.outlier[k] ? 0 : 1;
  const int inliers_total = static_cast<int>(std::count(s.outlier.begin(), s.outlier.end(), 0));
  EXPECT_GT(true_positive, 0.9 * inliers_total);                           // recall
  EXPECT_GT(true_positive, 0.95 * static_cast<double>(r.inliers.size()));  // precision

  // The refinement of the angular epipolar error then improves on RANSAC's minimal-sample motion.
  const EpipolarRefinement refined = RefineEpipolar(s.f_i, s.f_j, r.inliers, r.R, r.t, noise, 50, true);
  ASSERT_TRUE(refined.ok);
  EXPECT_LT(RotationErrorDeg(refined.R, s.R), 0.02);
  EXPECT_LT(DirectionErrorDeg(refined.t, s.t), 0.5);
  EXPECT_LE(refined.final_cost, refined.initial_cost);

  const RansacResult rotation_only = RotationOnlyRansac(s.f_i, s.f_j, settings, 3 * noise);
  EXPECT_LT(rotation_only.inliers.size(), r.inliers.size() / 2) << "a translating camera is not a rotation";
}

// The covariance has the documented perturbation model: its prediction matches the scatter of the
// estimates over noise draws (whitened eigenvalues near 1). With the rotation perturbed on the wrong side
// (left instead of right: a 90-degree rotation apart) the rotation block would not match.
TEST(CameraFrontendRefinement, CovarianceMatchesScatter) {
  const double noise = 0.001;
  const int trials = 120;
  std::vector<Vector6> errors;
  Matrix6 predicted = Matrix6::Zero();
  Scene truth;
  for (int trial = 0; trial < trials; ++trial) {
    const Scene s = MakeScene(150, noise, 0.0, 100 + trial, 0.7, 0.1,
                              Eigen::AngleAxisd(Rad(90), Eigen::Vector3d::UnitY()).toRotationMatrix());
    truth = s;
    const EpipolarRefinement r = RefineEpipolar(s.f_i, s.f_j, All(s), s.R, s.t, 10 * noise, 50, true);
    ASSERT_TRUE(r.ok && r.covariance_ok);
    Vector6 e;
    e.head<3>() = LogSO3(r.R.transpose() * s.R);  // R_true = R_hat Exp(e_rot)
    e.tail<3>() = s.t.normalized() - r.t;         // t_true = t_hat + e_t
    errors.push_back(e);
    predicted += r.covariance / trials;
  }
  Matrix6 scatter = Matrix6::Zero();
  for (const Vector6& e : errors) scatter += e * e.transpose() / trials;

  auto whitened_eigenvalues = [](const Eigen::MatrixXd& C_pred, const Eigen::MatrixXd& C_emp) {
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(C_pred);
    const Eigen::MatrixXd W = eig.operatorInverseSqrt();
    return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(W * C_emp * W).eigenvalues().eval();
  };
  const Eigen::VectorXd rotation = whitened_eigenvalues(predicted.block<3, 3>(0, 0), scatter.block<3, 3>(0, 0));
  std::cout << "predicted rotation covariance eigenvalues (deg^2): "
            << Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(predicted.block<3, 3>(0, 0)).eigenvalues().transpose() *
                   std::pow(180 / M_PI, 2)
            << "; whitened scatter: rotation " << rotation.transpose();
  EXPECT_GT(rotation.minCoeff(), 0.5) << rotation.transpose();
  EXPECT_LT(rotation.maxCoeff(), 2.0) << rotation.transpose();
  // Translation: in the plane tangent to the sphere at t (the direction has no scale).
  Eigen::Matrix<double, 3, 2> B;
  const Eigen::Vector3d t = truth.t.normalized();
  B.col(0) = t.unitOrthogonal();
  B.col(1) = t.cross(B.col(0));
  const Eigen::VectorXd translation = whitened_eigenvalues(B.transpose() * predicted.block<3, 3>(3, 3) * B,
                                                           B.transpose() * scatter.block<3, 3>(3, 3) * B);
  std::cout << ", translation " << translation.transpose() << "\n";
  EXPECT_GT(translation.minCoeff(), 0.5) << translation.transpose();
  EXPECT_LT(translation.maxCoeff(), 2.0) << translation.transpose();

  // The same test fails for the left-perturbation reading of the rotation block.
  const Eigen::Matrix3d R = truth.R;
  const Eigen::VectorXd left =
      whitened_eigenvalues(R * predicted.block<3, 3>(0, 0) * R.transpose(), scatter.block<3, 3>(0, 0));
  EXPECT_TRUE(left.minCoeff() < 0.5 || left.maxCoeff() > 2.0) << left.transpose();
}

TEST(CameraFrontendRotationOnly, FitsPureRotation) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(Rad(30), Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  Bearings f_i, f_j;
  std::vector<int> all;
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d f = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    f_j.push_back(Perturb(f, 0.0005, rng));
    f_i.push_back(Perturb(R * f, 0.0005, rng));
    all.push_back(k);
  }
  const RotationOnlyFit fit = FitRotationOnly(f_i, f_j, all, 0.001, 50, true);
  ASSERT_TRUE(fit.ok);
  EXPECT_LT(RotationErrorDeg(fit.R, R), 0.01);
  EXPECT_LT(fit.median_residual_rad, 0.002);
  EXPECT_GT(fit.median_residual_rad, 0.0002);  // the noise is there
  EXPECT_TRUE(fit.covariance_ok);
  const RansacResult ransac = RotationOnlyRansac(f_i, f_j, RansacSettings(), 0.002);
  ASSERT_TRUE(ransac.ok);
  EXPECT_GT(ransac.inliers.size(), 190u);
  EXPECT_LT(RotationErrorDeg(ransac.R, R), 0.1);
}

TEST(CameraFrontendFeatures, CheckImageExplainsProblems) {
  const auto camera = MakeCameraModel(DistortedPinholeParams());
  EXPECT_EQ(CheckImage(cv::Mat(480, 640, CV_8UC1), *camera), "");
  EXPECT_EQ(CheckImage(cv::Mat(480, 640, CV_8UC3), *camera), "");
  EXPECT_NE(CheckImage(cv::Mat(), *camera).find("empty"), std::string::npos);
  EXPECT_NE(CheckImage(cv::Mat(480, 641, CV_8UC1), *camera).find("expects 640x480"), std::string::npos);
  EXPECT_NE(CheckImage(cv::Mat(480, 640, CV_32FC1), *camera).find("unsupported image type"), std::string::npos);
  EXPECT_NE(CheckImage(cv::Mat(480, 640, CV_8UC2), *camera).find("unsupported image type"), std::string::npos);
}

}  // namespace
}  // namespace fusecal
