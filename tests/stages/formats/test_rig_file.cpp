// The result file of a rig of several cameras: every T_<camera>_lidar with its std, the camera-to-camera
// transforms derived from them with a covariance that matches the spread of the two estimates.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "stages/formats/result_file.hpp"
#include "stages/formats/rig_file.hpp"

using namespace fusecal;

namespace {

Matrix6 SomeCovariance(double rotation_rad, double translation_m, double correlation) {
  Matrix6 c = Matrix6::Zero();
  c.topLeftCorner<3, 3>() = Eigen::Vector3d(1.0, 2.0, 0.5).asDiagonal() * rotation_rad * rotation_rad;
  c.bottomRightCorner<3, 3>() = Eigen::Vector3d(1.0, 0.7, 3.0).asDiagonal() * translation_m * translation_m;
  c(0, 3) = c(3, 0) = correlation * rotation_rad * translation_m;
  return c;
}

RigCameraResult Camera(const std::string& name, const Eigen::Vector3d& rpy, const Eigen::Vector3d& t,
                       const Matrix6& c) {
  RigCameraResult r;
  r.camera = name;
  r.T_camera_lidar = MakeIsometry(RotationFromRpy(rpy.x(), rpy.y(), rpy.z()), t);
  r.covariance = c;
  r.status = "converged";
  return r;
}

Isometry3 Sample(const RigCameraResult& r, std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  Eigen::Matrix<double, 6, 1> z;
  for (int i = 0; i < 6; ++i) z(i) = n(rng);
  const Eigen::Matrix<double, 6, 1> d = Eigen::LLT<Matrix6>(*r.covariance).matrixL() * z;
  return MakeIsometry(r.T_camera_lidar.linear() * ExpSO3(d.head<3>()), r.T_camera_lidar.translation() + d.tail<3>());
}

}  // namespace

// The propagated covariance against the sample covariance of T_to_lidar T_from_lidar^-1 over draws of both.
TEST(RigFile, TheCameraToCameraCovarianceMatchesTheSpreadOfBothEstimates) {
  const RigCameraResult front =
      Camera("front", {-2.2, -1.5, -2.1}, {0.03, 0.12, -0.05}, SomeCovariance(2e-3, 3e-3, 0.3));
  const RigCameraResult left =
      Camera("left", {-2.1, 0.02, -0.05}, {-0.1, 0.11, 0.02}, SomeCovariance(1e-3, 5e-3, -0.2));
  const CameraToCamera c = DeriveCameraToCamera(left, front);
  ASSERT_TRUE(c.covariance);
  EXPECT_TRUE(c.T.isApprox(left.T_camera_lidar * front.T_camera_lidar.inverse(), 1e-12));
  std::mt19937 rng(7);
  const int n = 20000;
  Matrix6 sample = Matrix6::Zero();
  for (int k = 0; k < n; ++k) {
    const Isometry3 T = Sample(left, rng) * Sample(front, rng).inverse();
    Eigen::Matrix<double, 6, 1> d;
    d.head<3>() = LogSO3(c.T.linear().transpose() * T.linear());
    d.tail<3>() = T.translation() - c.T.translation();
    sample += d * d.transpose() / n;
  }
  const Eigen::Matrix<double, 6, 1> s = c.covariance->diagonal().cwiseSqrt();
  const Matrix6 relative = (sample - *c.covariance).cwiseQuotient(s * s.transpose());
  EXPECT_LT(relative.cwiseAbs().maxCoeff(), 0.05) << "sample\n" << sample << "\npropagated\n" << *c.covariance;
}

TEST(RigFile, WrittenAndReadBackWithEveryCameraAndTheDerivedTransforms) {
  const std::string path = (std::filesystem::temp_directory_path() / "fusecal_rig_file_test.yaml").string();
  const RigResult rig =
      MakeRigResult({Camera("left", {0.1, -1.5, 0.2}, {0.06, 0.1, 0}, SomeCovariance(1e-3, 2e-3, 0)),
                     Camera("right", {0.1, -1.5, 0.21}, {-0.06, 0.1, 0}, SomeCovariance(1e-3, 2e-3, 0))});
  WriteRigFile(path, rig);
  ASSERT_TRUE(IsRigFile(path));
  const RigResult back = ReadRigFile(path);
  ASSERT_EQ(back.cameras.size(), 2u);
  EXPECT_EQ(back.cameras[1].camera, "right");
  EXPECT_TRUE(back.cameras[1].T_camera_lidar.isApprox(rig.cameras[1].T_camera_lidar, 1e-9));
  ASSERT_EQ(back.camera_to_camera.size(), 1u);
  EXPECT_EQ(back.camera_to_camera[0].to, "right");
  EXPECT_EQ(back.camera_to_camera[0].from, "left");
  EXPECT_TRUE(back.camera_to_camera[0].T.isApprox(rig.camera_to_camera[0].T, 1e-9));
  EXPECT_NEAR(back.camera_to_camera[0].T.translation().norm(), 0.12, 2e-3);  // the baseline, about
  const std::string yaml = RigToYaml(rig);
  for (const char* key :
       {"T_left_lidar:", "T_left_lidar_std_dev:", "T_right_lidar_status:", "T_right_left:", "T_right_left_std_dev:"})
    EXPECT_NE(yaml.find(key), std::string::npos) << key;
  // One camera's tools say where that camera's result is.
  try {
    ReadResultFile(path);
    FAIL() << "a rig's file read as one camera's";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("<camera>/extrinsic.yaml"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(RigFile, ACameraWithoutItsTransformIsNamed) {
  const std::string path = (std::filesystem::temp_directory_path() / "fusecal_rig_file_bad.yaml").string();
  std::string yaml = RigToYaml(MakeRigResult({Camera("a", {0, 0, 0}, {0, 0, 0}, SomeCovariance(1e-3, 1e-3, 0))}));
  yaml.replace(yaml.find("T_a_lidar:"), 10, "T_x_lidar:");
  { std::ofstream(path) << yaml; }
  try {
    ReadRigFile(path);
    FAIL() << "read without T_a_lidar";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("'T_a_lidar'"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}
