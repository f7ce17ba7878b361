// The two measures on their own: image displacement (KLT) and LiDAR change (range image).
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "stages/stationarity/image_motion.hpp"
#include "stages/stationarity/range_image.hpp"

namespace fusecal {
namespace {

// A smooth random texture (blurred uniform noise), deterministic.
cv::Mat Texture(int width, int height, uint64_t seed = 1) {
  cv::Mat m(height, width, CV_8U);
  cv::RNG rng(seed);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(m, m, cv::Size(0, 0), 2.0);
  cv::normalize(m, m, 0, 255, cv::NORM_MINMAX);
  return m;
}

cv::Mat Shift(const cv::Mat& image, double dx, double dy) {
  cv::Mat out;
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::warpAffine(image, out, M, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

TEST(ImageMotion, MeasuresASubpixelShift) {
  const ImageMotionSettings s;
  const cv::Mat a = Texture(640, 320);
  const ImageFrame fa = PrepareImage(0, a, s);
  ASSERT_TRUE(fa.textured);
  EXPECT_EQ(fa.corners.size(), static_cast<size_t>(s.max_corners));
  for (const double shift : {0.0, 0.1, 0.5, 2.0, 6.0}) {
    const ImageFrame fb = PrepareImage(1, Shift(a, shift * 0.8, shift * 0.6), s);
    const ImageFlow flow = MeasureFlow(fa, fb, s);
    ASSERT_TRUE(flow.usable()) << flow.failure_reason.text;
    EXPECT_NEAR(flow.median_px, shift, 0.02 + 0.01 * shift) << "shift " << shift;
    EXPECT_GT(flow.tracks, s.max_corners * 3 / 4);
  }
}

TEST(ImageMotion, ReportsPixelsOfTheWorkingWidth) {
  // A 2048-pixel image shifted by 3.2 px moves 1 px in an image 640 px wide.
  const ImageMotionSettings s;
  const cv::Mat a = Texture(2048, 1024, 2);
  const ImageFrame fa = PrepareImage(0, a, s), fb = PrepareImage(1, Shift(a, 3.2, 0), s);
  EXPECT_EQ(fa.grey.cols, 640);
  EXPECT_EQ(fa.grey.rows, 320);
  const ImageFlow flow = MeasureFlow(fa, fb, s);
  ASSERT_TRUE(flow.usable());
  EXPECT_NEAR(flow.median_px, 1.0, 0.03);
  // A small image is not scaled up; its pixels are converted.
  const cv::Mat c = Texture(320, 160, 3);
  const ImageFrame fc = PrepareImage(0, c, s), fd = PrepareImage(1, Shift(c, 0.5, 0), s);
  EXPECT_EQ(fc.grey.cols, 320);
  EXPECT_NEAR(MeasureFlow(fc, fd, s).median_px, 1.0, 0.04);
}

TEST(ImageMotion, ExposureChangeIsNotMotion) {
  const ImageMotionSettings s;
  const cv::Mat a = Texture(640, 320, 4);
  cv::Mat darker, brighter;
  a.convertTo(darker, CV_8U, 0.5, 10);
  a.convertTo(brighter, CV_8U, 1.2, 5);
  const ImageFrame fa = PrepareImage(0, a, s);
  for (const cv::Mat& b : {darker, brighter}) {
    const ImageFlow flow = MeasureFlow(fa, PrepareImage(1, b, s), s);
    ASSERT_TRUE(flow.usable()) << flow.failure_reason.text;
    EXPECT_LT(flow.median_px, 0.02);
  }
}

TEST(ImageMotion, MovingObjectOnAStillBackgroundIsNotMotion) {
  // A third of the corners on an object that moves by 8 px: the median stays on the background.
  const ImageMotionSettings s;
  const cv::Mat a = Texture(640, 320, 5);
  cv::Mat b = a.clone();
  const cv::Rect object(100, 80, 200, 150);
  Shift(a, 8, 0)(object).copyTo(b(object));
  const ImageFlow flow = MeasureFlow(PrepareImage(0, a, s), PrepareImage(1, b, s), s);
  ASSERT_TRUE(flow.usable());
  EXPECT_LT(flow.median_px, 0.05);
}

TEST(ImageMotion, BlackAndBlankFramesHaveNoTexture) {
  const ImageMotionSettings s;
  const ImageFrame black = PrepareImage(0, cv::Mat::zeros(256, 512, CV_8U), s);
  EXPECT_FALSE(black.textured);
  EXPECT_TRUE(black.grey.empty());
  const ImageFrame grey = PrepareImage(0, cv::Mat(256, 512, CV_8UC3, cv::Scalar(128, 128, 128)), s);
  EXPECT_FALSE(grey.textured);
  const ImageFrame textured = PrepareImage(1, Texture(512, 256), s);
  const ImageFlow flow = MeasureFlow(black, textured, s);
  EXPECT_FALSE(flow.usable());
  EXPECT_EQ(flow.failure_reason.code, ImageFlowFailure::kNoTexture);
  EXPECT_EQ(flow.failure_reason.text, "no texture to track");
}

TEST(ImageMotion, LargeMotionOrADifferentSceneLosesTracking) {
  const ImageMotionSettings s;
  const cv::Mat a = Texture(640, 320, 6);
  const ImageFrame fa = PrepareImage(0, a, s);
  const ImageFlow other = MeasureFlow(fa, PrepareImage(1, Texture(640, 320, 7), s), s);
  EXPECT_FALSE(other.usable() && other.median_px < s.still_flow_px) << other.median_px;
  const ImageFlow far = MeasureFlow(fa, PrepareImage(1, Shift(a, 150, 0), s), s);
  EXPECT_FALSE(far.usable() && far.median_px < 2.0) << far.median_px;
  // Different working sizes cannot be compared.
  EXPECT_FALSE(MeasureFlow(fa, PrepareImage(1, Texture(400, 200, 6), s), s).usable());
}

TEST(ImageMotion, SupportedImages) {
  EXPECT_TRUE(IsSupportedImage(cv::Mat(4, 4, CV_8UC1)));
  EXPECT_TRUE(IsSupportedImage(cv::Mat(4, 4, CV_8UC3)));
  EXPECT_TRUE(IsSupportedImage(cv::Mat(4, 4, CV_8UC4)));
  EXPECT_FALSE(IsSupportedImage(cv::Mat()));
  EXPECT_FALSE(IsSupportedImage(cv::Mat(4, 4, CV_16UC1)));
  EXPECT_FALSE(IsSupportedImage(cv::Mat(4, 4, CV_32FC3)));
  EXPECT_FALSE(IsSupportedImage(cv::Mat(4, 4, CV_8UC2)));
}

// A 16-beam scan of a room-like box: ranges to the walls of a 12 x 10 x 4 m box around the sensor.
PointCloud BoxScan(const Eigen::Vector3f& offset, bool with_ring, float range_bias = 0) {
  PointCloud c;
  for (int beam = 0; beam < 16; ++beam) {
    const float el = (15.0f - 2.0f * beam) * static_cast<float>(M_PI) / 180.0f;
    for (int col = 0; col < 720; ++col) {
      const float az = (col * 0.5f - 180.0f + 0.25f) * static_cast<float>(M_PI) / 180.0f;
      const Eigen::Vector3f d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      // Distance along d from `offset` to the box [-6, 6] x [-5, 5] x [-2, 2].
      float t = 1e9f;
      const Eigen::Vector3f half(6, 5, 2);
      for (int k = 0; k < 3; ++k) {
        if (std::fabs(d[k]) < 1e-6f) continue;
        const float tk = ((d[k] > 0 ? half[k] : -half[k]) - offset[k]) / d[k];
        if (tk > 0) t = std::min(t, tk);
      }
      c.points.push_back(d * (t + range_bias));
      if (with_ring) c.ring.push_back(static_cast<int16_t>(beam));
    }
  }
  return c;
}

TEST(RangeImage, RowsByRingOrElevation) {
  const LidarChangeSettings s;
  const RangeImage by_ring = BuildRangeImage(BoxScan({0, 0, 0}, true), s);
  EXPECT_TRUE(by_ring.by_ring);
  EXPECT_EQ(by_ring.rows, s.max_rings);
  EXPECT_EQ(by_ring.cols, 360);
  EXPECT_EQ(by_ring.valid_cells, 16 * 360);
  EXPECT_EQ(by_ring.valid_points, 16u * 720u);
  const RangeImage by_elevation = BuildRangeImage(BoxScan({0, 0, 0}, false), s);
  EXPECT_FALSE(by_elevation.by_ring);
  EXPECT_EQ(by_elevation.rows, 360);
  EXPECT_EQ(by_elevation.valid_cells, 16 * 360);
  // A ring out of range falls back to elevation rows.
  PointCloud odd = BoxScan({0, 0, 0}, true);
  odd.ring[5] = -1;
  EXPECT_FALSE(BuildRangeImage(odd, s).by_ring);
}

TEST(RangeImage, ChangeIsTheMedianRangeDifference) {
  const LidarChangeSettings s;
  const RangeImage a = BuildRangeImage(BoxScan({0, 0, 0}, true), s);
  const LidarChange same = CompareRangeImages(a, a, s);
  ASSERT_TRUE(same.usable());
  EXPECT_EQ(same.change_m, 0.0);
  EXPECT_EQ(same.common_cells, 16 * 360);
  const LidarChange biased = CompareRangeImages(a, BuildRangeImage(BoxScan({0, 0, 0}, true, 0.1f), s), s);
  EXPECT_NEAR(biased.change_m, 0.1, 1e-4);
  // The sensor moved 0.2 m diagonally: the ranges change on every wall.
  const LidarChange moved = CompareRangeImages(a, BuildRangeImage(BoxScan({0.2f, 0.2f, 0}, true), s), s);
  EXPECT_GT(moved.change_m, 0.1);
  // A known blind spot of the measure (why the image decides too): a translation along x leaves the ranges
  // to the walls parallel to x unchanged, and those are most of the cells here.
  const LidarChange along = CompareRangeImages(a, BuildRangeImage(BoxScan({0.3f, 0, 0}, true), s), s);
  EXPECT_LT(along.change_m, 0.01);
  // Layouts differ: not comparable.
  EXPECT_EQ(CompareRangeImages(a, BuildRangeImage(BoxScan({0, 0, 0}, false), s), s).failure_reason.code,
            LidarChangeFailure::kLayoutsDiffer);
}

TEST(RangeImage, MovingObjectsInAMinorityOfCellsDoNotCount) {
  const LidarChangeSettings s;
  PointCloud b = BoxScan({0, 0, 0}, true);
  // 30% of the points (a passing truck) come 4 m closer.
  for (size_t i = 0; i < b.size(); i += 10)
    for (size_t k = i; k < std::min(b.size(), i + 3); ++k) b.points[k] *= 0.5f;
  const LidarChange change = CompareRangeImages(BuildRangeImage(BoxScan({0, 0, 0}, true), s), BuildRangeImage(b, s), s);
  ASSERT_TRUE(change.usable());
  EXPECT_LT(change.change_m, 1e-3);
}

TEST(RangeImage, NanAndOutOfRangePointsAreSkipped) {
  const LidarChangeSettings s;
  PointCloud c = BoxScan({0, 0, 0}, true);
  for (size_t i = 0; i < c.size(); i += 2) c.points[i] = Eigen::Vector3f::Constant(NAN);
  c.points[1] = Eigen::Vector3f(0.1f, 0, 0);  // closer than min_range_m
  c.points[3] = Eigen::Vector3f(1e4f, 0, 0);  // beyond max_range_m
  const RangeImage img = BuildRangeImage(c, s);
  EXPECT_EQ(img.valid_points, c.size() / 2 - 2);
  PointCloud all_nan = c;
  for (auto& p : all_nan.points) p = Eigen::Vector3f::Constant(NAN);
  EXPECT_EQ(BuildRangeImage(all_nan, s).valid_cells, 0);
  EXPECT_EQ(BuildRangeImage(PointCloud(), s).valid_cells, 0);
  EXPECT_EQ(CompareRangeImages(img, BuildRangeImage(all_nan, s), s).failure_reason.code,
            LidarChangeFailure::kTooFewCommonCells);
}

}  // namespace
}  // namespace fusecal
