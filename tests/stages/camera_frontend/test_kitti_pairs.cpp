// Camera front end on real images: the KITTI raw snippet of 2011-09-26 (shared/data, see its README.md).
// image_02 is rectified (pinhole without distortion, P_rect_02). The car drives slowly and almost straight,
// then stops: between moving frames the camera translates forward (+z) and barely rotates.
//
// The full check against the LiDAR (A = X B X^-1 with the official extrinsic and ICP motions, rotation
// within 0.1 deg, translation direction within 3 deg) belongs to the integration tests once the ICP stage
// exists; these tests check what the images alone can tell.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "runtime/sim/fixtures/camera_frontend_helpers.hpp"
#include "stages/camera_frontend/relative_pose.hpp"

namespace fusecal {
using namespace fusecal::fixtures;  // the synthetic room and the camera helpers
namespace {

const std::string kSnippet = FUSECAL_KITTI_SNIPPET_DIR;

std::string ImagePath(int frame) {
  char name[64];
  std::snprintf(name, sizeof name, "/image_02/data/%010d.png", frame);
  return kSnippet + name;
}

#define SKIP_WITHOUT_KITTI()                  \
  if (!std::filesystem::exists(ImagePath(0))) \
  GTEST_SKIP() << "KITTI snippet not found at " << kSnippet << " (expected image_02/data/*.png)"

RelativePoseResult RunFrames(int i, int j) {
  const auto camera = MakeCameraModel(KittiParams());
  const cv::Mat image_i = cv::imread(ImagePath(i), cv::IMREAD_UNCHANGED);
  const cv::Mat image_j = cv::imread(ImagePath(j), cv::IMREAD_UNCHANGED);
  EXPECT_FALSE(image_i.empty()) << ImagePath(i);
  EXPECT_FALSE(image_j.empty()) << ImagePath(j);
  const RelativePoseResult r = EstimateRelativePose(image_i, image_j, *camera);
  std::cout << "[KITTI " << i << " -> " << j << "] rotation " << Deg(RotationAngle(r.R)) << " deg, t_unit "
            << r.t_unit.transpose() << " (" << DirectionErrorDeg(r.t_unit, Eigen::Vector3d::UnitZ())
            << " deg from +z), " << r.inliers << " inliers of " << r.matches << " matches, parallax "
            << r.median_parallax_deg << " deg, " << r.seconds << " s"
            << (r.failure_reason.text.empty() ? "" : " (" + r.failure_reason.text + ")") << "\n";
  return r;
}

class KittiMovingPairs : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(KittiMovingPairs, ForwardMotionSmallRotation) {
  SKIP_WITHOUT_KITTI();
  const auto [i, j] = GetParam();
  const RelativePoseResult r = RunFrames(i, j);
  ASSERT_TRUE(r.usable()) << r.failure_reason;
  EXPECT_GE(r.inliers, 300);
  EXPECT_LT(DirectionErrorDeg(r.t_unit, Eigen::Vector3d::UnitZ()), 10.0) << "the car drives forward";
  EXPECT_LT(Deg(RotationAngle(r.R)), 2.0);
  EXPECT_TRUE(r.covariance_valid);
}

INSTANTIATE_TEST_SUITE_P(Frames, KittiMovingPairs,
                         ::testing::Values(std::make_pair(0, 4), std::make_pair(10, 14), std::make_pair(20, 24)));

// Motions compose: R_04 = R_02 R_24, and the car goes straight, so t_02, t_24 and t_04 point the same way.
TEST(KittiPairs, MotionsCompose) {
  SKIP_WITHOUT_KITTI();
  const RelativePoseResult r02 = RunFrames(0, 2), r24 = RunFrames(2, 4), r04 = RunFrames(0, 4);
  ASSERT_TRUE(r02.usable() && r24.usable() && r04.usable());
  const double composition_deg = RotationErrorDeg(r02.R * r24.R, r04.R);
  std::cout << "[KITTI 0 -> 2 -> 4] rotation composition error " << composition_deg << " deg\n";
  EXPECT_LT(composition_deg, 0.05);
  EXPECT_LT(DirectionErrorDeg(r02.t_unit, r04.t_unit), 2.0);
  EXPECT_LT(DirectionErrorDeg(r02.R * r24.t_unit, r04.t_unit), 2.0);
}

// From about frame 54 the car stands still: no parallax, the translation direction is flagged.
TEST(KittiPairs, StandingCarFlagsTranslation) {
  SKIP_WITHOUT_KITTI();
  const RelativePoseResult r = RunFrames(60, 64);
  EXPECT_TRUE(r.valid) << r.failure_reason;
  EXPECT_TRUE(r.translation_unreliable);
  EXPECT_LT(Deg(RotationAngle(r.R)), 0.1);
}

}  // namespace
}  // namespace fusecal
