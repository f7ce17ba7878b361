#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "stages/formats/conversions.hpp"
#include "stages/formats/extrinsic_status.hpp"

namespace fusecal {
namespace {

cv::Mat TestPattern(int channels) {
  cv::Mat image(48, 64, CV_8UC(channels));
  cv::randu(image, 0, 255);
  return image;
}

// Encodes, serialises through LCM bytes, decodes, and converts back.
cv::Mat RoundTrip(const cv::Mat& image, const std::string& encoding) {
  const image_t msg = MatToImage(image, encoding, 42);
  std::vector<uint8_t> bytes(msg.getEncodedSize());
  EXPECT_GT(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  image_t decoded;
  EXPECT_GT(decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  EXPECT_EQ(decoded.utime, 42);
  EXPECT_EQ(decoded.encoding, encoding);
  return ImageToMat(decoded);
}

double MaxAbsDiff(const cv::Mat& a, const cv::Mat& b) {
  EXPECT_EQ(a.size(), b.size());
  EXPECT_EQ(a.type(), b.type());
  return cv::norm(a, b, cv::NORM_INF);
}

TEST(ImageConversion, LosslessEncodingsRoundTripExactly) {
  const cv::Mat grey = TestPattern(1), colour = TestPattern(3);
  EXPECT_EQ(MaxAbsDiff(RoundTrip(grey, "mono8"), grey), 0);
  EXPECT_EQ(MaxAbsDiff(RoundTrip(colour, "bgr8"), colour), 0);
  EXPECT_EQ(MaxAbsDiff(RoundTrip(colour, "rgb8"), colour), 0);
  EXPECT_EQ(MaxAbsDiff(RoundTrip(colour, "png"), colour), 0);
  EXPECT_EQ(MaxAbsDiff(RoundTrip(grey, "png"), grey), 0);
}

TEST(ImageConversion, Rgb8StoresRedFirst) {
  cv::Mat bgr(1, 1, CV_8UC3, cv::Scalar(10, 20, 30));
  const image_t msg = MatToImage(bgr, "rgb8", 0);
  ASSERT_EQ(msg.data.size(), 3u);
  EXPECT_EQ(msg.data[0], 30);
  EXPECT_EQ(msg.data[2], 10);
}

TEST(ImageConversion, JpegRoundTripIsClose) {
  cv::Mat smooth(64, 64, CV_8UC1);
  for (int r = 0; r < 64; ++r)
    for (int c = 0; c < 64; ++c) smooth.at<uint8_t>(r, c) = static_cast<uint8_t>(2 * r + c);
  const cv::Mat back = RoundTrip(smooth, "jpeg");
  EXPECT_LT(cv::norm(back, smooth, cv::NORM_L1) / smooth.total(), 2.0);
}

TEST(ImageConversion, BadMessagesGiveClearErrors) {
  image_t msg = MatToImage(TestPattern(1), "mono8", 0);
  msg.encoding = "yuv422";
  try {
    ImageToMat(msg);
    FAIL() << "unknown encoding accepted";
  } catch (const ConversionError& e) {
    EXPECT_NE(std::string(e.what()).find("yuv422"), std::string::npos);
  }
  msg = MatToImage(TestPattern(3), "bgr8", 0);
  msg.data.resize(msg.data.size() / 2);
  EXPECT_THROW(ImageToMat(msg), ConversionError);
  msg = MatToImage(TestPattern(3), "png", 0);
  for (size_t i = 0; i < msg.data.size(); ++i) msg.data[i] = uint8_t(i * 7);
  EXPECT_THROW(ImageToMat(msg), ConversionError);
}

TEST(CloudConversion, RoundTripKeepsEveryField) {
  PointCloud cloud;
  for (int i = 0; i < 1000; ++i) {
    cloud.points.emplace_back(i * 0.1f, -i * 0.2f, 1.5f);
    cloud.intensity.push_back(float(i % 256));
    cloud.ring.push_back(int16_t(i % 64));
    cloud.time_offset_s.push_back(i * 1e-5f);
  }
  const point_cloud_t msg = CloudToMsg(cloud, 7);
  std::vector<uint8_t> bytes(msg.getEncodedSize());
  ASSERT_GT(msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  point_cloud_t decoded;
  ASSERT_GT(decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  const PointCloud back = CloudFromMsg(decoded);
  ASSERT_EQ(back.size(), cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(back.points[i], cloud.points[i]);
  EXPECT_EQ(back.intensity, cloud.intensity);
  EXPECT_EQ(back.ring, cloud.ring);
  EXPECT_EQ(back.time_offset_s, cloud.time_offset_s);
}

TEST(CloudConversion, OptionalFieldsMayBeEmptyButNotShort) {
  PointCloud cloud;
  cloud.points.assign(10, Eigen::Vector3f::Ones());
  EXPECT_NO_THROW(CloudFromMsg(CloudToMsg(cloud, 0)));
  cloud.intensity.assign(5, 1.0f);
  EXPECT_THROW(CloudToMsg(cloud, 0), ConversionError);
}

TEST(CameraConversion, RoundTrip) {
  CameraParams p;
  p.model = "pinhole";
  p.width = 1242;
  p.height = 375;
  p.fx = 721.5;
  p.fy = 721.5;
  p.cx = 609.6;
  p.cy = 172.9;
  p.dist = {0.1, -0.2, 0.001, 0.002, 0.03};
  const CameraParams back = CameraFromMsg(CameraToMsg(p));
  EXPECT_EQ(back.model, p.model);
  EXPECT_EQ(back.width, p.width);
  EXPECT_EQ(back.fx, p.fx);
  EXPECT_EQ(back.dist, p.dist);
  camera_info_t bad = CameraToMsg(p);
  bad.model = "fisheye";
  EXPECT_THROW(CameraFromMsg(bad), ConversionError);
}

TEST(MatrixConversion, Matrix6RoundTrip) {
  Matrix6 m = Matrix6::Random();
  double a[36];
  Matrix6ToArray(m, a);
  EXPECT_EQ(a[1], m(0, 1));
  EXPECT_EQ(Matrix6FromArray(a), m);
}

TEST(ExtrinsicStatus, VerdictsConvertToTheConstantsAndBackWithTheSameNames) {
  for (HandEyeStatus status :
       {HandEyeStatus::kConverged, HandEyeStatus::kNotConverged, HandEyeStatus::kDegenerate, HandEyeStatus::kFailed}) {
    const int8_t constant = ToExtrinsicStatus(status);
    EXPECT_EQ(HandEyeStatusOf(constant), status);
    EXPECT_STREQ(ExtrinsicStatusName(constant), Name(status));
  }
  for (Observability o : {Observability::kOk, Observability::kRotationDegenerate,
                          Observability::kTranslationPartlyUnobservable, Observability::kTooFewMotions}) {
    const int8_t constant = ToExtrinsicObservability(o);
    EXPECT_EQ(ObservabilityOf(constant), o);
    EXPECT_STREQ(ObservabilityName(constant), Name(o));
  }
  const int8_t not_converged = extrinsic_t::STATUS_NOT_CONVERGED;  // a copy: gtest binds references
  const int8_t partly = extrinsic_t::OBSERVABILITY_TRANSLATION_PARTLY_UNOBSERVABLE;
  EXPECT_EQ(ToExtrinsicStatus(HandEyeStatus::kNotConverged), not_converged);
  EXPECT_EQ(ToExtrinsicObservability(Observability::kTranslationPartlyUnobservable), partly);
  EXPECT_STREQ(ExtrinsicStatusName(extrinsic_t::STATUS_INITIAL), "initial");
  EXPECT_STREQ(ExtrinsicStatusName(extrinsic_t::STATUS_REFINING), "refining");
  EXPECT_FALSE(HandEyeStatusOf(extrinsic_t::STATUS_REFINING).has_value());
  EXPECT_STREQ(ExtrinsicStatusName(42), "unknown");
  EXPECT_STREQ(ObservabilityName(42), "unknown");
}

}  // namespace
}  // namespace fusecal
