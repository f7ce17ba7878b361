#include <gtest/gtest.h>

#include "stages/lidar_icp/registration.hpp"

namespace fusecal::lidar_icp {
namespace {

TEST(RegistrationSettings, DefaultsAreValid) { EXPECT_EQ(RegistrationSettings().Validate(), ""); }

TEST(RegistrationSettings, InvalidValuesAreNamed) {
  RegistrationSettings s;
  s.max_range_m = 0.5;  // below min_range_m
  s.threshold_shrink = 1.5;
  s.normal_neighbors = 2;
  const std::string e = s.Validate();
  EXPECT_NE(e.find("max_range_m"), std::string::npos) << e;
  EXPECT_NE(e.find("threshold_shrink"), std::string::npos) << e;
  EXPECT_NE(e.find("normal_neighbors"), std::string::npos) << e;

  RegistrationSettings t;
  t.max_correspondence_m = 0.5;
  t.min_correspondence_m = 1.0;
  EXPECT_NE(t.Validate().find("min_correspondence_m"), std::string::npos);
  t = RegistrationSettings();
  t.voxel_size_m = std::nan("");
  EXPECT_NE(t.Validate().find("voxel_size_m"), std::string::npos);
}

TEST(RegistrationSettings, InvalidSettingsFailRegistrationWithoutThrowing) {
  RegistrationSettings s;
  s.min_fitness = 2.0;
  PointCloud cloud;
  const RegistrationResult r = Register(cloud, cloud, s);
  EXPECT_FALSE(r.usable());
  EXPECT_EQ(r.failure_reason.code, RegistrationFailure::kInvalidSettings);
  EXPECT_NE(r.failure_reason.text.find("min_fitness"), std::string::npos) << r.failure_reason;
  EXPECT_FALSE(RegistrationResult().usable());
  EXPECT_EQ(RegistrationResult().failure_reason.code, RegistrationFailure::kNotRun);
}

}  // namespace
}  // namespace fusecal::lidar_icp
