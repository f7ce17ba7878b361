// Real data: KITTI raw 2011-09-26 snippet (HDL-64E, every second frame of 0..76). Consecutive frames
// register with no guess, and chained motions agree with direct ones: B_ac vs B_ab * B_bc within
// 0.05 deg and 2 cm. The data lives outside the repository; without it the tests are skipped, saying so.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "runtime/io/scan_io/scan_io.hpp"
#include "stages/foundation/se3.hpp"
#include "stages/lidar_icp/registration.hpp"

namespace fusecal::lidar_icp {
namespace {

namespace fs = std::filesystem;

const std::string kVelodyneDir = std::string(KITTI_SNIPPET_DIR) + "/velodyne_points/data";

std::string FramePath(int frame) {
  char name[32];
  std::snprintf(name, sizeof(name), "%010d.bin", frame);
  return kVelodyneDir + "/" + name;
}

class KittiRegistration : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::is_directory(kVelodyneDir))
      GTEST_SKIP() << "KITTI snippet not found at " << KITTI_SNIPPET_DIR
                   << ": velodyne_points/data/ is missing (external data, see /work/shared/data)";
  }

  const PointCloud& Scan(int frame) {
    auto it = scans_.find(frame);
    if (it == scans_.end()) it = scans_.emplace(frame, ReadScan(FramePath(frame))).first;
    return it->second;
  }

  // B = T_la_lb, frame b registered to frame a.
  RegistrationResult Motion(int a, int b) {
    const RegistrationResult r = Register(Scan(a), Scan(b));
    const Eigen::Vector3d rpy = RpyFromRotation(r.T_li_lj.linear()) * 180.0 / M_PI;
    std::printf(
        "  %02d <- %02d: converged %d  t [%.3f %.3f %.3f] m  rpy [%.3f %.3f %.3f] deg  fitness %.2f  "
        "rms %.1f mm  free-space %.3f  cond %.3f  %.2f s\n",
        a, b, r.usable(), r.T_li_lj.translation().x(), r.T_li_lj.translation().y(), r.T_li_lj.translation().z(),
        rpy.x(), rpy.y(), rpy.z(), r.fitness, 1e3 * r.inlier_rms_m, r.free_space_violation, r.conditioning, r.seconds);
    return r;
  }

  std::map<int, PointCloud> scans_;
};

TEST_F(KittiRegistration, ConsecutiveFramesRegisterAndChainsAgreeWithDirectMotions) {
  // Triplets a, b = a+2, c = a+4 (consecutive files) along the drive: moving, decelerating, stopped.
  for (int a : {0, 20, 44, 64}) {
    const int b = a + 2, c = a + 4;
    const RegistrationResult ab = Motion(a, b);
    const RegistrationResult bc = Motion(b, c);
    const RegistrationResult ac = Motion(a, c);
    for (const RegistrationResult* r : {&ab, &bc, &ac}) {
      ASSERT_TRUE(r->usable()) << r->failure_reason;
      EXPECT_GT(r->fitness, 0.4);  // inlier ratio at the last threshold (0.1 m)
      // A car between frames 0.2 s apart: a few metres at most, a small turn.
      EXPECT_LT(r->T_li_lj.translation().norm(), 4.0);
      EXPECT_LT(RotationAngle(r->T_li_lj.linear()) * 180.0 / M_PI, 5.0);
    }
    const Isometry3 chained = ab.T_li_lj * bc.T_li_lj;
    const double rotation_deg = RotationErrorDeg(chained.linear(), ac.T_li_lj.linear());
    const double translation_m = (chained.translation() - ac.T_li_lj.translation()).norm();
    std::printf("  chain %02d-%02d-%02d vs direct: %.4f deg, %.1f mm\n", a, b, c, rotation_deg, 1e3 * translation_m);
    EXPECT_LT(rotation_deg, 0.05) << "frames " << a << ", " << b << ", " << c;
    EXPECT_LT(translation_m, 0.02) << "frames " << a << ", " << b << ", " << c;
  }
}

TEST_F(KittiRegistration, ReadsVelodyneScan) {
  const PointCloud& scan = Scan(0);
  EXPECT_GT(scan.size(), 100000u);
  EXPECT_EQ(scan.intensity.size(), scan.size());
  EXPECT_EQ(fs::file_size(FramePath(0)), 16 * scan.size());
}

}  // namespace
}  // namespace fusecal::lidar_icp
