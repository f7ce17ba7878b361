// Building blocks of the registration: preprocessing, normals, rotation grid, distance field, free space.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "stages/foundation/se3.hpp"
#include "stages/lidar_icp/consistency.hpp"
#include "stages/lidar_icp/distance_field.hpp"
#include "stages/lidar_icp/global_alignment.hpp"
#include "stages/lidar_icp/preprocess.hpp"

namespace fusecal::lidar_icp {
namespace {

constexpr double kDeg = M_PI / 180.0;

TEST(Preprocess, ValidPointsDropsNonFiniteAndCropsRange) {
  PointCloud c;
  c.points = {{0.5f, 0, 0},
              {2, 0, 0},
              {std::numeric_limits<float>::quiet_NaN(), 0, 0},
              {0, std::numeric_limits<float>::infinity(), 0},
              {200, 0, 0},
              {0, 0, -3}};
  const auto v = ValidPoints(c, 1.0, 100.0);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[0], Eigen::Vector3f(2, 0, 0));
  EXPECT_EQ(v[1], Eigen::Vector3f(0, 0, -3));
}

TEST(Preprocess, VoxelDownsampleKeepsCentroids) {
  const std::vector<Eigen::Vector3f> pts = {{0.1f, 0.1f, 0.1f}, {0.3f, 0.3f, 0.3f}, {1.5f, 0.2f, 0.2f}, {-0.2f, 0, 0}};
  const auto v = VoxelDownsample(pts, 1.0);
  ASSERT_EQ(v.size(), 3u);
  bool found = false;
  for (const auto& p : v) found = found || (p - Eigen::Vector3f(0.2f, 0.2f, 0.2f)).norm() < 1e-6f;
  EXPECT_TRUE(found);
  EXPECT_EQ(VoxelDownsample(pts, 1.0), v);  // deterministic
}

// A noisy plane z = height (2 cm noise, 5 cm voxels): the mean height of the downsampled points, weighting
// each voxel alike as ICP does.
double MeanHeight(const std::vector<Eigen::Vector3f>& points) {
  double sum = 0;
  for (const auto& p : points) sum += p.z();
  return sum / double(points.size());
}

std::vector<Eigen::Vector3f> NoisyPlane(float height) {
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.02f);
  std::uniform_real_distribution<float> along(-2.0f, 2.0f);
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 200000; ++i) pts.emplace_back(along(rng), along(rng), height + noise(rng));
  return pts;
}

TEST(Preprocess, NeighbourhoodCentroidsOfANoisyPlaneLieOnItWhereverTheGridFalls) {
  double worst_voxel = 0, worst_neighbourhood = 0;
  for (float height : {0.0f, 0.01f, 0.02f, 0.0125f, 0.025f, 0.04f}) {
    const auto pts = NoisyPlane(height);
    worst_voxel = std::max(worst_voxel, std::abs(MeanHeight(VoxelDownsample(pts, 0.05)) - height));
    const auto smoothed = NeighbourhoodVoxelCentroids(pts, 0.05);
    // Voxels holding only the noise's tail off the plane are left out; a point per column remains.
    EXPECT_LE(smoothed.size(), VoxelDownsample(pts, 0.05).size());
    EXPECT_GE(smoothed.size(), 80u * 80u);
    worst_neighbourhood = std::max(worst_neighbourhood, std::abs(MeanHeight(smoothed) - height));
  }
  // The voxels' own centroids are pulled toward the grid by millimetres; the neighbourhoods' are not.
  EXPECT_GT(worst_voxel, 2e-3);
  EXPECT_LT(worst_neighbourhood, 5e-4);
}

TEST(Preprocess, NeighbourhoodCentroidsAverageTheTwentySevenVoxels) {
  const std::vector<Eigen::Vector3f> pts = {{0.5f, 0.5f, 0.5f}, {1.5f, 0.5f, 0.5f}, {3.5f, 0.5f, 0.5f}};
  const auto v = NeighbourhoodVoxelCentroids(pts, 1.0);
  ASSERT_EQ(v.size(), 3u);
  EXPECT_TRUE(v[0].isApprox(Eigen::Vector3f(1.0f, 0.5f, 0.5f)));  // itself and its neighbour at x + 1
  EXPECT_TRUE(v[1].isApprox(Eigen::Vector3f(1.0f, 0.5f, 0.5f)));
  EXPECT_TRUE(v[2].isApprox(Eigen::Vector3f(3.5f, 0.5f, 0.5f)));  // alone
}

TEST(Preprocess, SubsampleIsDeterministicAndBounded) {
  std::vector<Eigen::Vector3f> pts;
  for (int i = 0; i < 1000; ++i) pts.emplace_back(float(i), 0, 0);
  const auto a = Subsample(pts, 100), b = Subsample(pts, 100);
  EXPECT_EQ(a.size(), 100u);
  EXPECT_EQ(a, b);
  EXPECT_EQ(Subsample(pts, 5000).size(), 1000u);
}

TEST(Preprocess, NormalsOfAPlaneAndRejectionOfALine) {
  PreparedCloud plane;
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.0f, 0.002f);
  for (int x = 0; x < 30; ++x)
    for (int y = 0; y < 30; ++y) plane.points.emplace_back(0.1f * x, 0.1f * y, 2.0f + noise(rng));
  plane.BuildTarget(10, 1);
  for (size_t i = 0; i < plane.points.size(); ++i) {
    ASSERT_TRUE(plane.planar[i]);
    EXPECT_GT(std::abs(plane.normals[i].z()), 0.99f);
  }
  PreparedCloud line;
  for (int x = 0; x < 50; ++x) line.points.emplace_back(0.1f * x, noise(rng), noise(rng));
  line.BuildTarget(10, 1);
  for (uint8_t p : line.planar) EXPECT_FALSE(p);
}

TEST(GlobalAlignment, RotationGridCoversTiltedRotations) {
  const double step = 10.0 * kDeg, tilt = 60.0 * kDeg;
  const auto grid = RotationGrid(tilt, step);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int k = 0; k < 300; ++k) {
    // Random yaw, tilt of the z axis up to 60 deg about a random horizontal axis.
    const Eigen::Vector3d axis(u(rng), u(rng), 0.0);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(std::abs(u(rng)) * tilt, axis.normalized()).toRotationMatrix() *
                              Eigen::AngleAxisd(u(rng) * M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    double nearest = 1e9;
    for (const auto& G : grid) nearest = std::min(nearest, RotationErrorRad(G, R));
    worst = std::max(worst, nearest);
  }
  EXPECT_LT(worst, step) << "worst distance to the grid " << worst / kDeg << " deg";
  EXPECT_GT(RotationGrid(M_PI, step).size(), grid.size());  // 180 = all of SO(3)
}

TEST(DistanceField, SurfaceFreeSpaceAndUnknown) {
  // A wall at x = 5 seen from the origin.
  std::vector<Eigen::Vector3f> wall;
  for (int y = -20; y <= 20; ++y)
    for (int z = -10; z <= 10; ++z) wall.emplace_back(5.0f, 0.1f * y, 0.1f * z);
  const DistanceField field(wall, 0.1f, 0.4f);
  auto value = [&](float x, float y, float z) {
    return field.Score(Eigen::Matrix3f::Identity(), Eigen::Vector3f::Zero(), {Eigen::Vector3f(x, y, z)});
  };
  EXPECT_GT(value(5.0f, 0.0f, 0.0f), 0.9f);  // on the surface
  EXPECT_GT(value(4.8f, 0.0f, 0.0f), 0.3f);  // near it
  EXPECT_LT(value(2.5f, 0.0f, 0.0f), 0.0f);  // seen through: free space
  EXPECT_EQ(value(6.5f, 0.0f, 0.0f), 0.0f);  // behind the wall: unknown
}

TEST(FreeSpace, PointsInFrontOfASeenWallViolate) {
  std::vector<Eigen::Vector3f> wall;
  for (int y = -50; y <= 50; ++y)
    for (int z = -50; z <= 50; ++z) wall.emplace_back(10.0f, 0.1f * y, 0.1f * z);
  const FreeSpaceImage image(wall);
  const std::vector<Eigen::Vector3f> on = {{10.0f, 0.5f, 0.5f}}, front = {{5.0f, 0.25f, 0.25f}},
                                     behind = {{14.0f, 0.5f, 0.5f}};
  EXPECT_EQ(image.ViolationRatio(on, Isometry3::Identity(), 1.0, 0.3), 0.0);
  EXPECT_EQ(image.ViolationRatio(front, Isometry3::Identity(), 1.0, 0.3), 1.0);
  EXPECT_EQ(image.ViolationRatio(behind, Isometry3::Identity(), 1.0, 0.3), 0.0);
}

}  // namespace
}  // namespace fusecal::lidar_icp
