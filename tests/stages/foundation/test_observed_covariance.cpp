// The observed part of a covariance: the unobservable direction's huge variance projected out.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "stages/foundation/observed_covariance.hpp"

namespace fusecal {
namespace {

// A small covariance, plus 1e6 along a translation direction that is no axis: the per-axis std of the
// whole covariance are hundreds of metres on every axis, those of the observed part millimetres.
TEST(ObservedPart, ProjectsOutATranslationDirectionThatIsNoAxis) {
  Matrix6 C = Matrix6::Zero();
  C.diagonal() << 1e-6, 2e-6, 3e-6, 1e-6, 4e-6, 9e-6;  // rad^2, m^2
  const Eigen::Vector3d d = Eigen::Vector3d(0.47, -0.87, 0.13).normalized();
  C.bottomRightCorner<3, 3>() += 1e6 * d * d.transpose();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const ObservedUncertainty observed = ObservedPart(C, R, d);
  EXPECT_TRUE(observed.translation_projected);
  EXPECT_FALSE(observed.rotation_projected);  // the rotation about d has its small variance: observed
  EXPECT_LT(observed.max_translation_std_m, 0.0031);
  EXPECT_GT(observed.max_translation_std_m, 0.0009);
  EXPECT_NEAR(observed.rotation_std_deg(2), std::sqrt(3e-6) * 180 / M_PI, 1e-9);
  EXPECT_NEAR((observed.covariance.bottomRightCorner<3, 3>() * d).norm(), 0.0, 1e-12);
}

// Rotation degenerate: the rotation about the direction is unobserved in the LiDAR perturbation
// coordinates (R^T d), the translation along d too; both are projected out.
TEST(ObservedPart, ProjectsOutTheRotationAboutTheDirectionInLidarCoordinates) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  const Eigen::Vector3d d = Eigen::Vector3d::UnitZ();  // camera frame
  const Eigen::Vector3d d_lidar = R.transpose() * d;
  Matrix6 C = 1e-6 * Matrix6::Identity();
  C.topLeftCorner<3, 3>() += 1e6 * d_lidar * d_lidar.transpose();
  C.bottomRightCorner<3, 3>() += 1e6 * d * d.transpose();
  const ObservedUncertainty observed = ObservedPart(C, R, d);
  EXPECT_TRUE(observed.rotation_projected && observed.translation_projected);
  EXPECT_NEAR(observed.max_rotation_std_deg, 1e-3 * 180 / M_PI, 1e-5);  // 1e6 + 1e-6 in doubles: 1e-10 apart
  EXPECT_NEAR(observed.max_translation_std_m, 1e-3, 1e-7);
}

TEST(ObservedPart, NoDirectionOrAnObservedOneLeavesTheCovarianceAsItIs) {
  Matrix6 C = 4e-6 * Matrix6::Identity();
  const ObservedUncertainty none = ObservedPart(C, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const ObservedUncertainty small = ObservedPart(C, Eigen::Matrix3d::Identity(), Eigen::Vector3d::UnitX());
  EXPECT_EQ(none.covariance, C);
  EXPECT_EQ(small.covariance, C);
  EXPECT_FALSE(small.rotation_projected || small.translation_projected);
  EXPECT_NEAR(none.max_translation_std_m, 2e-3, 1e-12);
}

}  // namespace
}  // namespace fusecal
