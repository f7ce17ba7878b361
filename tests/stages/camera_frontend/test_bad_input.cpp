// Bad input never crashes nor throws: it ends in a flag and a failure_reason saying what is wrong.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "runtime/sim/fixtures/camera_frontend_helpers.hpp"
#include "runtime/sim/fixtures/synthetic_room.hpp"
#include "stages/camera_frontend/relative_pose.hpp"

namespace fusecal {
using namespace fusecal::fixtures;  // the synthetic room and the camera helpers
namespace {

const SyntheticRoom& Room() {
  static const SyntheticRoom room(FUSECAL_CAMERA_FRONTEND_TEST_DATA);
  return room;
}

struct Fixture {
  std::unique_ptr<CameraModel> camera = MakeCameraModel(DistortedPinholeParams());
  cv::Mat textured;  // a valid image of the camera's size
  Fixture() {
    const Isometry3 pose = MakeIsometry(Eigen::AngleAxisd(Rad(40), Eigen::Vector3d::UnitY()).toRotationMatrix(),
                                        Eigen::Vector3d(1.2, -0.3, 2.0));
    textured = Room().Render(*camera, pose, 1, 1.5, 3);
  }
};

const Fixture& Data() {
  static const Fixture data;
  return data;
}

RelativePoseResult Estimate(const cv::Mat& a, const cv::Mat& b, const CameraFrontendSettings& settings = {}) {
  RelativePoseResult r;
  EXPECT_NO_THROW(r = EstimateRelativePose(a, b, *Data().camera, settings));
  return r;
}

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(CameraFrontendBadInput, EmptyImage) {
  const RelativePoseResult r = Estimate(cv::Mat(), Data().textured);
  EXPECT_FALSE(r.valid);
  EXPECT_FALSE(r.usable());
  EXPECT_EQ(r.failure_reason.code, RelativePoseFailure::kFeaturesFailed);
  EXPECT_TRUE(Contains(r.failure_reason.text, "image i: image is empty")) << r.failure_reason;
  const RelativePoseResult r2 = Estimate(Data().textured, cv::Mat());
  EXPECT_TRUE(Contains(r2.failure_reason.text, "image j: image is empty")) << r2.failure_reason;
}

TEST(CameraFrontendBadInput, WrongSizeForTheCamera) {
  cv::Mat smaller;
  cv::resize(Data().textured, smaller, cv::Size(320, 240));
  const RelativePoseResult r = Estimate(Data().textured, smaller);
  EXPECT_FALSE(r.valid);
  EXPECT_TRUE(Contains(r.failure_reason.text, "image j: image is 320x240 but the camera model expects 640x480"))
      << r.failure_reason;
}

TEST(CameraFrontendBadInput, AnImageTooSmallToTrackIsRefusedWithItsSize) {
  CameraParams params;
  params.model = "pinhole";
  params.width = params.height = 1;
  params.fx = params.fy = 1;
  const auto camera = MakeCameraModel(params);
  const cv::Mat pixel(1, 1, CV_8U, cv::Scalar(128));
  const RelativePoseResult r = EstimateRelativePose(pixel, pixel, *camera);
  EXPECT_FALSE(r.valid);
  EXPECT_EQ(r.failure_reason.text, "image i: image is 1x1, too small to track (at least 32x32 pixels)")
      << r.failure_reason;
}

TEST(CameraFrontendBadInput, UnsupportedType) {
  cv::Mat floating;
  Data().textured.convertTo(floating, CV_32F);
  const RelativePoseResult r = Estimate(floating, Data().textured);
  EXPECT_FALSE(r.valid);
  EXPECT_TRUE(Contains(r.failure_reason.text, "unsupported image type")) << r.failure_reason;
}

TEST(CameraFrontendBadInput, BlackImage) {
  const cv::Mat black = cv::Mat::zeros(480, 640, CV_8U);
  const RelativePoseResult r = Estimate(black, Data().textured);
  EXPECT_FALSE(r.valid);
  EXPECT_TRUE(Contains(r.failure_reason.text, "image i: no features")) << r.failure_reason;
  EXPECT_EQ(r.inliers, 0);
  // With the blank mask off, AKAZE itself finds nothing in a constant image.
  CameraFrontendSettings no_blank_mask;
  no_blank_mask.features.blank_value = -1;
  const RelativePoseResult r2 = Estimate(black, black, no_blank_mask);
  EXPECT_FALSE(r2.valid);
  EXPECT_TRUE(Contains(r2.failure_reason.text, "no features")) << r2.failure_reason;
}

TEST(CameraFrontendBadInput, FeaturesSayWhyTheyAreNotUsable) {
  EXPECT_TRUE(ImageFeatures().usable());  // an empty set of features is not a failure
  const ImageFeatures empty = ExtractImageFeatures(cv::Mat(), *Data().camera);
  EXPECT_FALSE(empty.usable());
  EXPECT_EQ(empty.failure_reason.code, FeatureFailure::kBadImage);
  EXPECT_EQ(empty.failure_reason.text, "image is empty");
  const ImageFeatures black = ExtractImageFeatures(cv::Mat::zeros(480, 640, CV_8U), *Data().camera);
  EXPECT_EQ(black.failure_reason.code, FeatureFailure::kNoFeatures);
  EXPECT_TRUE(black.keypoints.empty());
}

TEST(CameraFrontendBadInput, UniformGreyImage) {
  const cv::Mat grey(480, 640, CV_8U, cv::Scalar(128));
  const RelativePoseResult r = Estimate(grey, grey);
  EXPECT_FALSE(r.valid);
  EXPECT_TRUE(Contains(r.failure_reason.text, "no features")) << r.failure_reason;
}

// The same image twice: no motion at all. The rotation (identity) is valid, the translation is not.
TEST(CameraFrontendBadInput, IdenticalImages) {
  const RelativePoseResult r = Estimate(Data().textured, Data().textured);
  EXPECT_TRUE(r.valid) << r.failure_reason;
  EXPECT_TRUE(r.translation_unreliable);
  EXPECT_FALSE(r.usable());
  EXPECT_EQ(r.failure_reason.code, RelativePoseFailure::kTranslationUnreliable);
  EXPECT_TRUE(Contains(r.failure_reason.text, "translation unreliable")) << r.failure_reason;
  EXPECT_LT(RotationErrorDeg(r.R, Eigen::Matrix3d::Identity()), 1e-3);
  EXPECT_NEAR(r.median_parallax_deg, 0.0, 1e-6);
}

// Two unrelated images, both full of features: no motion explains the few matches.
TEST(CameraFrontendBadInput, UnrelatedImages) {
  cv::Mat noise(480, 640, CV_8U);
  cv::RNG(5).fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 2.0);
  cv::normalize(noise, noise, 0, 255, cv::NORM_MINMAX);
  const RelativePoseResult r = Estimate(Data().textured, noise);
  EXPECT_GT(r.features_j, 500);
  EXPECT_FALSE(r.valid);
  EXPECT_TRUE(r.too_few_inliers);
  EXPECT_TRUE(r.failure_reason.code == RelativePoseFailure::kTooFewMatches ||
              r.failure_reason.code == RelativePoseFailure::kTooFewInliers);
  EXPECT_TRUE(Contains(r.failure_reason.text, "too few")) << r.failure_reason;
}

TEST(CameraFrontendBadInput, InvalidSettings) {
  CameraFrontendSettings settings;
  settings.ransac.threshold_px = -1;
  const RelativePoseResult r = Estimate(Data().textured, Data().textured, settings);
  EXPECT_FALSE(r.valid);
  EXPECT_EQ(r.failure_reason.code, RelativePoseFailure::kInvalidSettings);
  EXPECT_TRUE(Contains(r.failure_reason.text, "invalid settings: ransac.threshold_px")) << r.failure_reason;
}

TEST(CameraFrontendBadInput, FeaturesOfAnotherCamera) {
  const auto panorama = MakeCameraModel(PanoramaParams(512));
  const ImageFeatures fi = ExtractImageFeatures(Data().textured, *Data().camera);
  ASSERT_TRUE(fi.usable()) << fi.failure_reason;
  RelativePoseResult r;
  EXPECT_NO_THROW(r = EstimateRelativePose(fi, fi, *panorama));
  EXPECT_FALSE(r.valid);
  EXPECT_EQ(r.failure_reason.code, RelativePoseFailure::kFeaturesMismatch);
  EXPECT_TRUE(Contains(r.failure_reason.text, "camera model expects 512x256")) << r.failure_reason;

  ImageFeatures broken = fi;
  broken.bearings.pop_back();
  EXPECT_NO_THROW(r = EstimateRelativePose(broken, fi, *Data().camera));
  EXPECT_FALSE(r.valid);
  EXPECT_TRUE(Contains(r.failure_reason.text, "inconsistent features")) << r.failure_reason;
}

}  // namespace
}  // namespace fusecal
