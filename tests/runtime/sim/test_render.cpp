// Rendering: determinism, realistic texture for feature detectors, consistency with the camera model
// (KLT tracks against the truth from geometry).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "runtime/sim/simulator/render.hpp"
#include "runtime/sim/simulator/simulation.hpp"
#include "tests/support/simulator_test_util.hpp"

namespace fusecal::sim {
namespace {

bool SameBytes(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

bool SameScan(const SimulatedScan& a, const SimulatedScan& b) {
  return a.points.size() == b.points.size() &&
         std::equal(a.points.begin(), a.points.end(), b.points.begin(), [](const LidarPoint& p, const LidarPoint& q) {
           return std::memcmp(&p, &q, sizeof(float) * 4 + sizeof(int32_t) + sizeof(uint16_t)) == 0;
         });
}

// The default scenario's scene and camera, shared by the (slower) full-size tests.
class SimDefaultScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scenario_ = new Scenario(LoadScenario(testing::ScenarioPath("indoor-equirect-hdl64.yaml")));
    scene_ = new Scene(BuildScene(*scenario_));
    trajectory_ = new Trajectory(BuildTrajectory(*scenario_));
    camera_ = MakeCameraModel(scenario_->camera().params).release();
  }
  static void TearDownTestSuite() {
    delete scenario_;
    delete scene_;
    delete trajectory_;
    delete camera_;
  }
  static RenderOptions Options() {
    RenderOptions o;
    o.supersample = scenario_->camera().supersample;
    o.noise_sigma = scenario_->noise.image_sigma;
    return o;
  }
  static Isometry3 CameraPose(const Isometry3& T_world_lidar) {
    return T_world_lidar * scenario_->T_camera_lidar().inverse();
  }
  static Scenario* scenario_;
  static Scene* scene_;
  static Trajectory* trajectory_;
  static CameraModel* camera_;
};
Scenario* SimDefaultScene::scenario_ = nullptr;
Scene* SimDefaultScene::scene_ = nullptr;
Trajectory* SimDefaultScene::trajectory_ = nullptr;
CameraModel* SimDefaultScene::camera_ = nullptr;

TEST_F(SimDefaultScene, AkazeFindsThousandsOfFeatures) {
  const cv::Mat image =
      RenderImage(*scene_, *camera_, CameraPose(trajectory_->stills()[0].T_world_lidar), Options(), 1);
  ASSERT_EQ(image.cols, 2048);
  ASSERT_EQ(image.rows, 1024);
  std::vector<cv::KeyPoint> keypoints;
  cv::AKAZE::create()->detect(image, keypoints);
  RecordProperty("akaze_keypoints", static_cast<int>(keypoints.size()));
  EXPECT_GE(keypoints.size(), 2000u);
  // Texture everywhere: features in every eighth of the panorama's width (the room's walls).
  std::vector<int> per_sector(8, 0);
  for (const auto& k : keypoints) per_sector[std::min(7, static_cast<int>(k.pt.x / 256))]++;
  for (int s = 0; s < 8; ++s) EXPECT_GE(per_sector[s], 100) << "sector " << s;
}

TEST_F(SimDefaultScene, KltTracksAcrossTenDegreeTurn) {
  // Rig turns 10 deg about the vertical axis through its yaw pivot (with the lever arm, so the camera
  // also translates a few cm and the flow depends on depth).
  const Isometry3 A_lidar = trajectory_->stills()[0].T_world_lidar;
  const Eigen::Vector3d pivot = A_lidar * scenario_->motions.yaw_pivot_m;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Isometry3 B_lidar = A_lidar;
  B_lidar.linear() = R * A_lidar.linear();
  B_lidar.translation() = R * (A_lidar.translation() - pivot) + pivot;
  const Isometry3 A = CameraPose(A_lidar), B = CameraPose(B_lidar);
  const cv::Mat image_a = RenderImage(*scene_, *camera_, A, Options(), 11);
  const cv::Mat image_b = RenderImage(*scene_, *camera_, B, Options(), 12);

  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(image_a, corners, 3000, 0.01, 8);
  // Leave out the poles' rows and the seam columns (KLT does not wrap around).
  corners.erase(std::remove_if(corners.begin(), corners.end(),
                               [](const cv::Point2f& p) { return p.y < 100 || p.y > 924 || p.x < 100 || p.x > 1948; }),
                corners.end());
  ASSERT_GT(corners.size(), 1000u);
  std::vector<cv::Point2f> tracked;
  std::vector<uint8_t> status;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(image_a, image_b, corners, tracked, status, err, cv::Size(21, 21), 4);

  std::vector<double> errors;
  int good = 0, seen = 0;
  for (size_t i = 0; i < corners.size(); ++i) {
    Eigen::Vector3d p_world;
    if (!CastPixel(*scene_, *camera_, A, Eigen::Vector2d(corners[i].x, corners[i].y), &p_world)) continue;
    Eigen::Vector2d truth;
    if (!camera_->Project(B.inverse() * p_world, &truth)) continue;
    ++seen;
    if (!status[i]) continue;
    const double e = (Eigen::Vector2d(tracked[i].x, tracked[i].y) - truth).norm();
    if (e < 3.0) {
      ++good;
      errors.push_back(e);
    }
  }
  ASSERT_GT(seen, 1000);
  const double fraction = static_cast<double>(good) / seen;
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  const double median = errors[errors.size() / 2];
  RecordProperty("klt_tracked_fraction", std::to_string(fraction));
  RecordProperty("klt_median_error_px", std::to_string(median));
  EXPECT_GT(fraction, 0.5);
  EXPECT_LT(median, 1.0);
}

TEST_F(SimDefaultScene, RenderMatchesCameraModelGeometry) {
  // The pixel at which a world point projects sees that point: cast a few pixels, project the hits
  // back; both directions through the renderer's own ray grid (equirectangular closed form).
  const Isometry3 A = CameraPose(trajectory_->stills()[0].T_world_lidar);
  const CameraRays rays(*camera_, 1);
  const Eigen::Matrix3d R = A.linear() * rays.grid.frame().cast<double>();
  for (int r = 10; r < 1024; r += 101) {
    for (int c = 7; c < 2048; c += 233) {
      const Eigen::Vector3d grid_dir = R * rays.grid.Direction(r, c).cast<double>();
      const Eigen::Vector3d model_dir = A.linear() * camera_->Unproject(Eigen::Vector2d(c, r));
      EXPECT_LT((grid_dir - model_dir).norm(), 1e-6) << r << " " << c;
    }
  }
}

TEST(SimRender, PinholeRayTableMatchesModel) {
  // The interpolated ray table of a distorted pinhole camera agrees with CameraModel::Unproject.
  const Scenario s = LoadScenario(testing::ScenarioPath("indoor-pinhole-hdl64.yaml"));
  const auto camera = MakeCameraModel(s.camera().params);
  const CameraRays rays(*camera, 2);
  ASSERT_EQ(rays.grid.rows(), 1440);
  ASSERT_EQ(rays.grid.cols(), 2560);
  double worst = 0;
  for (int r = 0; r < 1440; r += 37)
    for (int c = 0; c < 2560; c += 41) {
      const Eigen::Vector2d pixel((c + 0.5) / 2 - 0.5, (r + 0.5) / 2 - 0.5);
      const Eigen::Vector3d exact = camera->Unproject(pixel);
      const Eigen::Vector3d grid = (rays.grid.frame() * rays.grid.Direction(r, c)).cast<double>();
      worst = std::max(worst, std::acos(std::min(1.0, exact.dot(grid.normalized()))));
    }
  EXPECT_LT(worst / (1.0 / s.camera().params.fx), 0.01) << "worst error in pixels";
}

TEST(SimRender, SameSeedSameBytesDifferentSeedDifferent) {
  const Scenario s = LoadScenario(testing::ScenarioPath("tiny-equirect.yaml"));
  const Scene scene = BuildScene(s);
  const auto camera = MakeCameraModel(s.camera().params);
  const Isometry3 T = BuildTrajectory(s).T_world_lidar(0.0) * s.T_camera_lidar().inverse();
  RenderOptions o;
  o.noise_sigma = 2.0;
  o.threads = 1;
  const cv::Mat a = RenderImage(scene, *camera, T, o, 5);
  o.threads = 2;
  const cv::Mat b = RenderImage(scene, *camera, T, o, 5);
  o.threads = 3;
  const cv::Mat c = RenderImage(scene, *camera, T, o, 6);
  EXPECT_TRUE(SameBytes(a, b)) << "thread count changed the image";
  EXPECT_FALSE(SameBytes(a, c));
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1) / a.total(), 1.0);  // noise differs everywhere, not just somewhere
  o.color = true;
  const cv::Mat color = RenderImage(scene, *camera, T, o, 5);
  EXPECT_EQ(color.type(), CV_8UC3);

  const SimulatedScan s1 = ScanLidar(scene, s.lidar, T, 9);
  const SimulatedScan s2 = ScanLidar(scene, s.lidar, T, 9);
  const SimulatedScan s3 = ScanLidar(scene, s.lidar, T, 10);
  EXPECT_GT(s1.points.size(), 5000u);
  EXPECT_TRUE(SameScan(s1, s2));
  EXPECT_FALSE(SameScan(s1, s3));
}

TEST(SimRender, SimulationIsDeterministicAndRandomAccessMatchesSequence) {
  const Scenario s = LoadScenario(testing::ScenarioPath("tiny-equirect.yaml"));
  Simulation a(s), b(s, DefaultTextureDir(), 1);
  std::vector<cv::Mat> images;  // by camera frame index
  Event ea, eb;
  int cameras = 0, scans = 0, moving_cameras = 0;
  int64_t last_utime = 0;
  while (a.Next(&ea)) {
    ASSERT_TRUE(b.Next(&eb));
    ASSERT_EQ(ea.type, eb.type);
    ASSERT_EQ(ea.utime, eb.utime);
    EXPECT_GE(ea.utime, last_utime);
    last_utime = ea.utime;
    if (ea.type == Event::Type::kCamera) {
      ++cameras;
      moving_cameras += ea.camera.station_id < 0;
      EXPECT_EQ(ea.camera.utime, ea.utime);
      ASSERT_TRUE(SameBytes(ea.camera.image, eb.camera.image)) << "camera frame " << ea.camera.index;
      ASSERT_EQ(ea.camera.index, static_cast<int>(images.size()));
      images.push_back(ea.camera.image);
    } else {
      ++scans;
      ASSERT_TRUE(SameScan(ea.lidar.scan, eb.lidar.scan)) << "scan " << ea.lidar.index;
    }
  }
  EXPECT_FALSE(b.Next(&eb));
  EXPECT_EQ(cameras, a.num_camera_frames());
  EXPECT_EQ(scans, a.num_lidar_scans());
  EXPECT_GT(moving_cameras, 10);
  // Tiny: 5 stations x still_s + 4 moves of 1-1.5 s at 10 Hz.
  const double still_s = s.motions.still_s;
  EXPECT_GE(cameras, static_cast<int>(10 * (5 * still_s + 4 * 1.0)));
  EXPECT_LE(cameras, static_cast<int>(10 * (5 * still_s + 4 * 1.5)) + 1);

  // Frames requested out of order (cache cold, other station cached) are the same bytes.
  Simulation c(s);
  for (int k : {37, 3, 77, 4, 15}) EXPECT_TRUE(SameBytes(c.RenderCameraFrame(k).image, images[k])) << "frame " << k;
  const LidarFrame scan = c.RenderLidarFrame(20);
  EXPECT_TRUE(SameScan(scan.scan, b.RenderLidarFrame(20).scan));

  // Still frames at one station differ only by noise; consecutive ones are not identical.
  const CameraFrame f1 = c.RenderCameraFrame(1), f2 = c.RenderCameraFrame(2);
  ASSERT_EQ(f1.station_id, 0);
  ASSERT_EQ(f2.station_id, 0);
  EXPECT_FALSE(SameBytes(f1.image, f2.image));
  EXPECT_LT(cv::norm(f1.image, f2.image, cv::NORM_L1) / f1.image.total(), 8.0);
}

TEST(SimRender, StationsAreGroundTruth) {
  const Scenario s = LoadScenario(testing::ScenarioPath("tiny-equirect.yaml"));
  Simulation sim(s);
  const auto stations = sim.Stations();
  ASSERT_EQ(stations.size(), 5u);
  for (const auto& st : stations) {
    EXPECT_EQ(st.still_to_utime - st.still_from_utime, std::llround(s.motions.still_s * 1e6));
    EXPECT_TRUE(st.T_world_camera.isApprox(st.T_world_lidar * s.T_camera_lidar().inverse(), 1e-12));
  }
  EXPECT_EQ(stations[0].still_from_utime, s.start_utime);
  Event e;
  int still_scans = 0;
  while (sim.Next(&e)) {
    if (e.type != Event::Type::kLidar || e.lidar.station_id < 0) continue;
    ++still_scans;
    const auto& st = stations[e.lidar.station_id];
    EXPECT_GE(e.utime, st.still_from_utime);
    EXPECT_LE(e.utime + 100000, st.still_to_utime);  // the whole sweep is still
    EXPECT_TRUE(e.lidar.T_world_lidar.isApprox(st.T_world_lidar, 0.0));
  }
  EXPECT_GE(still_scans, 5 * 8);
}

// The camera moved on its mount after stops 1 and 2: each image is the one of an unchanged scenario
// with the extrinsic in force at its time (before, between and after the changes, still and moving);
// the LiDAR does not move.
TEST(SimRender, CameraMovedOnItsMountIsRenderedWithTheExtrinsicInForce) {
  Scenario s = LoadScenario(testing::ScenarioPath("tiny-equirect.yaml"));
  s.motions.horizontal = 1;
  s.motions.vertical = 1;
  const Isometry3 delta_a = MakeIsometry(RotationFromRpy(0.02, 0, 0), {0.02, 0, 0});
  const Isometry3 delta_b = MakeIsometry(RotationFromRpy(0, -0.03, 0.01), {0, 0, 0.05});
  s.extrinsic_changes = {{1, delta_a}, {2, delta_b}};
  Simulation sim(s);
  const auto& epochs = sim.extrinsics();
  ASSERT_EQ(epochs.size(), 3u);
  EXPECT_EQ(epochs[0].from_utime, s.start_utime);
  EXPECT_TRUE(epochs[1].T_camera_lidar.isApprox(s.T_camera_lidar() * delta_a, 1e-12));
  EXPECT_TRUE(epochs[2].T_camera_lidar.isApprox(s.T_camera_lidar() * delta_a * delta_b, 1e-12));
  const auto stations = sim.Stations();
  ASSERT_EQ(stations.size(), 3u);
  for (size_t k = 1; k < 3; ++k) {  // in the middle of the motion after stop k
    EXPECT_NEAR(epochs[k].from_utime, (stations[k - 1].still_to_utime + stations[k].still_from_utime) / 2, 1) << k;
    EXPECT_EQ(epochs[k].after_stop, static_cast<int>(k));
  }
  for (size_t k = 0; k < 3; ++k)
    EXPECT_TRUE(
        stations[k].T_world_camera.isApprox(stations[k].T_world_lidar * epochs[k].T_camera_lidar.inverse(), 1e-12));

  std::vector<std::unique_ptr<Simulation>> unchanged;  // one per extrinsic
  for (const auto& epoch : epochs) {
    Scenario fixed = s;
    fixed.extrinsic_changes.clear();
    fixed.T_camera_lidar() = epoch.T_camera_lidar;
    unchanged.push_back(std::make_unique<Simulation>(fixed));
  }
  std::vector<int> frames = {2};  // a still frame at the first station, then around each change and after it
  for (size_t k = 1; k < 3; ++k) {
    const auto& times = sim.camera_times();
    const int first = static_cast<int>(
        std::lower_bound(times.begin(), times.end(), epochs[k].from_utime - s.start_utime) - times.begin());
    ASSERT_GT(first, 0);
    frames.insert(frames.end(), {first - 1, first, first + 12});
  }
  for (int index : frames) {
    const CameraFrame f = sim.RenderCameraFrame(index);
    size_t in_force = 0;
    while (in_force + 1 < epochs.size() && epochs[in_force + 1].from_utime <= f.utime) ++in_force;
    for (size_t k = 0; k < epochs.size(); ++k)
      EXPECT_EQ(SameBytes(f.image, unchanged[k]->RenderCameraFrame(index).image), k == in_force)
          << "camera frame " << index << ", extrinsic " << k;
    EXPECT_TRUE(f.T_world_camera.isApprox(unchanged[in_force]->RenderCameraFrame(index).T_world_camera, 1e-12));
  }
  EXPECT_EQ(sim.RenderCameraFrame(frames.back()).station_id, 2);
  for (int index : {5, 20, 40})
    EXPECT_TRUE(SameScan(sim.RenderLidarFrame(index).scan, unchanged[0]->RenderLidarFrame(index).scan)) << index;
}

}  // namespace
}  // namespace fusecal::sim
