// The camera front end against the LiDAR on real data (KITTI snippet): the camera motion must agree with
// the LiDAR motion carried through the official extrinsic, A = X B X^-1 (B from the ICP stage).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "runtime/io/importers/kitti.hpp"
#include "runtime/io/scan_io/scan_io.hpp"
#include "stages/camera_frontend/relative_pose.hpp"
#include "stages/lidar_icp/registration.hpp"

namespace fusecal {
namespace {

const std::string kSnippet = FUSECAL_KITTI_SNIPPET_DIR;

std::string FramePath(const char* folder, int frame, const char* ext) {
  char name[96];
  std::snprintf(name, sizeof name, "/%s/data/%010d.%s", folder, frame, ext);
  return kSnippet + name;
}

double DirectionDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

class KittiCameraVsLidar : public ::testing::TestWithParam<std::pair<int, int>> {};

TEST_P(KittiCameraVsLidar, RotationAndDirectionAgreeWithTheLidarThroughTheOfficialExtrinsic) {
  if (!std::filesystem::exists(kSnippet + "/calib_velo_to_cam.txt"))
    GTEST_SKIP() << "KITTI snippet not found at " << kSnippet << ": real-data check not run";
  const auto [i, j] = GetParam();
  const KittiCalibration calib = ReadKittiCalibration(kSnippet);
  const auto camera = MakeCameraModel(calib.camera);
  const auto lidar = lidar_icp::Register(ReadScan(FramePath("velodyne_points", i, "bin")),
                                         ReadScan(FramePath("velodyne_points", j, "bin")));
  ASSERT_TRUE(lidar.usable()) << lidar.failure_reason;
  const Isometry3& X = calib.T_camera_lidar;
  const Isometry3 predicted = X * lidar.T_li_lj * X.inverse();
  const RelativePoseResult cam = EstimateRelativePose(cv::imread(FramePath("image_02", i, "png")),
                                                      cv::imread(FramePath("image_02", j, "png")), *camera);
  ASSERT_TRUE(cam.usable()) << cam.failure_reason;
  const double rotation_deg = RotationErrorDeg(cam.R, predicted.linear());
  const double direction_deg = DirectionDeg(cam.t_unit, predicted.translation());
  std::cout << "[KITTI " << i << " -> " << j << "] car moved " << lidar.T_li_lj.translation().norm()
            << " m; camera vs X B X^-1: rotation " << rotation_deg << " deg, direction " << direction_deg << " deg\n";
  EXPECT_LT(rotation_deg, 0.1);
  EXPECT_LT(direction_deg, 3.0);
}

// Frame pairs where the car moves (the files are every second frame of 0..76).
INSTANTIATE_TEST_SUITE_P(Frames, KittiCameraVsLidar,
                         ::testing::Values(std::pair{0, 4}, std::pair{10, 14}, std::pair{20, 24}, std::pair{30, 34}));

}  // namespace
}  // namespace fusecal
