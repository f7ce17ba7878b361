// Bad input never crashes and never throws: the result says failed and why.
#include <gtest/gtest.h>

#include <limits>

#include "runtime/sim/fixtures/fo_test_data.hpp"
#include "stages/fusion_odometry/fusion_odometry.hpp"

namespace fusecal::fusion_odometry {
namespace {

// A small valid problem: a textured panorama pair (the same image) and a sphere of points around it.
class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    CameraParams p;
    p.model = "equirectangular";
    p.width = 256;
    p.height = 128;
    camera_ = MakeCameraModel(p);
    image_ = cv::Mat(128, 256, CV_8UC1);
    cv::RNG rng(3);
    rng.fill(image_, cv::RNG::UNIFORM, 0, 255);
    for (int lat = -60; lat <= 60; lat += 2)
      for (int lon = -180; lon < 180; lon += 2) {
        const double a = lat * M_PI / 180, b = lon * M_PI / 180;
        scan_.points.emplace_back(4.0f * std::cos(a) * std::cos(b), 4.0f * std::cos(a) * std::sin(b),
                                  4.0f * std::sin(a));
      }
    X_ = MakeIsometry(RotationFromRpy(-M_PI / 2, 0, -M_PI / 2), Eigen::Vector3d::Zero());  // LiDAR x -> camera z
  }

  static void ExpectFailed(const FusionOdometryResult& r, const std::string& reason_part,
                           FusionOdometryFailure code = FusionOdometryFailure::kInvalidInput) {
    EXPECT_FALSE(r.usable());
    EXPECT_EQ(r.status, status::kFailed);
    EXPECT_EQ(r.failure_reason.code, code);
    EXPECT_NE(r.failure_reason.text.find(reason_part), std::string::npos) << "reason: " << r.failure_reason;
    EXPECT_TRUE(IsValidTransform(r.T_ci_cj));
  }

  std::unique_ptr<CameraModel> camera_;
  cv::Mat image_;
  PointCloud scan_;
  Isometry3 X_ = Isometry3::Identity();
};

TEST_F(BadInput, SanityTheValidProblemConverges) {
  const FusionOdometryResult r = EstimateScaledMotion(scan_, image_, image_, *camera_, X_);
  EXPECT_TRUE(r.usable()) << r.failure_reason;
  EXPECT_LT(r.T_ci_cj.translation().norm(), 0.01);
  EXPECT_LT(RotationAngle(r.T_ci_cj.linear()), 1e-3);
}

TEST_F(BadInput, EmptyScan) {
  ExpectFailed(EstimateScaledMotion(PointCloud(), image_, image_, *camera_, X_), "empty scan");
}

TEST_F(BadInput, ExtrinsicThatProjectsNoPoint) {
  // Pinhole camera looking away from every point (all points behind it).
  CameraParams p;
  p.width = 320;
  p.height = 240;
  p.fx = p.fy = 300;
  p.cx = 159.5;
  p.cy = 119.5;
  const auto pinhole = MakeCameraModel(p);
  PointCloud ahead;  // LiDAR x forward, camera z = LiDAR x; the extrinsic turns the camera backwards
  for (int k = 0; k < 1000; ++k) ahead.points.emplace_back(5.0f, 0.01f * (k % 40 - 20), 0.01f * (k / 40 - 12));
  const Isometry3 backwards = MakeIsometry(RotationFromRpy(-M_PI / 2, 0, M_PI / 2), Eigen::Vector3d::Zero());
  const cv::Mat img(240, 320, CV_8UC1, cv::Scalar(100));
  ExpectFailed(EstimateScaledMotion(ahead, img, img, *pinhole, backwards), "no scan point projects",
               FusionOdometryFailure::kNothingProjects);
  // The same with points far beyond the range limit, and with only non-finite points.
  PointCloud far, nan;
  far.points.assign(100, Eigen::Vector3f(1e4f, 0, 0));
  nan.points.assign(100, Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 0, 0));
  ExpectFailed(EstimateScaledMotion(far, image_, image_, *camera_, X_), "no scan point projects",
               FusionOdometryFailure::kNothingProjects);
  ExpectFailed(EstimateScaledMotion(nan, image_, image_, *camera_, X_), "no scan point projects",
               FusionOdometryFailure::kNothingProjects);
}

TEST_F(BadInput, BlackImageJFailsTracking) {
  const cv::Mat black = cv::Mat::zeros(image_.size(), CV_8UC1);
  ExpectFailed(EstimateScaledMotion(scan_, image_, black, *camera_, X_), "tracking failed",
               FusionOdometryFailure::kTrackingFailed);
}

TEST_F(BadInput, BlackImageIHasNothingToTrack) {
  const cv::Mat black = cv::Mat::zeros(image_.size(), CV_8UC1);
  ExpectFailed(EstimateScaledMotion(scan_, black, image_, *camera_, X_), "trackable",
               FusionOdometryFailure::kTooFewTrackable);
}

TEST_F(BadInput, UnrelatedImageJDoesNotConverge) {
  cv::Mat other(image_.size(), CV_8UC1);
  cv::RNG rng(99);
  rng.fill(other, cv::RNG::UNIFORM, 0, 255);
  const FusionOdometryResult r = EstimateScaledMotion(scan_, image_, other, *camera_, X_);
  EXPECT_FALSE(r.usable());
  EXPECT_FALSE(r.failure_reason.text.empty());
}

TEST_F(BadInput, ImagesOfTheWrongSizeOrType) {
  ExpectFailed(EstimateScaledMotion(scan_, cv::Mat(), image_, *camera_, X_), "image i is empty");
  ExpectFailed(EstimateScaledMotion(scan_, image_, cv::Mat(64, 64, CV_8UC1), *camera_, X_), "image j is 64x64");
  cv::Mat float_image;
  image_.convertTo(float_image, CV_32F);
  ExpectFailed(EstimateScaledMotion(scan_, float_image, image_, *camera_, X_), "8-bit");
  cv::Mat bgr;  // colour input is fine
  cv::merge(std::vector<cv::Mat>{image_, image_, image_}, bgr);
  EXPECT_TRUE(EstimateScaledMotion(scan_, bgr, bgr, *camera_, X_).usable());
}

TEST_F(BadInput, InvalidTransformsAndSettings) {
  Isometry3 nan_X = X_;
  nan_X.translation().x() = std::numeric_limits<double>::quiet_NaN();
  ExpectFailed(EstimateScaledMotion(scan_, image_, image_, *camera_, nan_X), "invalid extrinsic");
  Isometry3 sheared = X_;
  sheared.linear()(0, 1) += 0.5;
  ExpectFailed(EstimateScaledMotion(scan_, image_, image_, *camera_, sheared), "invalid extrinsic");
  MotionGuess bad_guess;
  bad_guess.T_ci_cj.translation().y() = std::numeric_limits<double>::infinity();
  ExpectFailed(EstimateScaledMotion(scan_, image_, image_, *camera_, X_, bad_guess), "invalid motion guess");
  FusionOdometrySettings settings;
  settings.tracking.window_px = 4;
  ExpectFailed(EstimateScaledMotion(scan_, image_, image_, *camera_, X_, {}, settings),
               "invalid settings: tracking.window_px", FusionOdometryFailure::kInvalidSettings);
  EXPECT_EQ(FusionOdometryResult().failure_reason.code, FusionOdometryFailure::kNotRun);
}

}  // namespace
}  // namespace fusecal::fusion_odometry
