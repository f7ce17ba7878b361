// Importers (KITTI raw, folder, Ishikawa layout) on data the test generates, and on the KITTI snippet
// from ../shared when it is there.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "fusecal/station_t.hpp"
#include "runtime/channels.hpp"
#include "runtime/io/importers/folder.hpp"
#include "runtime/io/importers/ishikawa.hpp"
#include "runtime/io/importers/kitti.hpp"
#include "runtime/io/scan_io/scan_io.hpp"
#include "runtime/io/visualization/overlay.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/ground_truth.hpp"
#include "stages/formats/result_file.hpp"
#include "stages/foundation/extrinsic_error.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

namespace fs = std::filesystem;
using testing::RunCommand;

std::string FreshDir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "fusecal_import_" + std::to_string(getpid()) + "_" + name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

PointCloud SmallCloud(int n, float offset) {
  PointCloud cloud;
  for (int i = 0; i < n; ++i) {
    cloud.points.emplace_back(5.0f + offset, 0.01f * i, 0.5f);
    cloud.intensity.push_back(0.5f);
  }
  return cloud;
}

// A tiny KITTI raw drive of `frames` frames, with the snippet's calibration format.
std::string MakeKittiDrive(int frames) {
  const std::string dir = FreshDir("kitti");
  fs::create_directories(dir + "/image_02/data");
  fs::create_directories(dir + "/velodyne_points/data");
  std::ofstream(dir + "/calib_velo_to_cam.txt") << "calib_time: test\nR: 0 -1 0 0 0 -1 1 0 0\nT: 0.1 -0.2 -0.3\n";
  std::ofstream(dir + "/calib_cam_to_cam.txt")
      << "R_rect_00: 1 0 0 0 1 0 0 0 1\nP_rect_02: 100 0 32 4.5 0 100 24 0.2 0 0 1 0.003\nS_rect_02: 64 48\n";
  std::ofstream image_times(dir + "/image_02/timestamps.txt"), scan_times(dir + "/velodyne_points/timestamps.txt");
  for (int i = 0; i < frames; ++i) {
    char stem[32];
    std::snprintf(stem, sizeof(stem), "%010d", 2 * i + 4);  // need not start at 0 nor be contiguous
    cv::Mat image(48, 64, CV_8UC3, cv::Scalar(10 * i, 50, 90));
    cv::imwrite(dir + "/image_02/data/" + stem + ".png", image);
    WriteScan(dir + "/velodyne_points/data/" + stem + ".bin", SmallCloud(200, float(i)));
    image_times << "2011-09-26 13:02:" << 10 + i << ".500000000\n";
    scan_times << "2011-09-26 13:02:" << 10 + i << ".450000000\n";
  }
  return dir;
}

TEST(KittiImporter, CalibrationComposesRectificationAndProjectionOffset) {
  const std::string dir = MakeKittiDrive(1);
  const KittiCalibration calib = ReadKittiCalibration(dir);
  EXPECT_EQ(calib.camera.width, 64);
  EXPECT_EQ(calib.camera.fx, 100);
  // P_rect_02 offset: b = ((4.5 - 32 * 0.003) / 100, (0.2 - 24 * 0.003) / 100, 0.003).
  const Eigen::Vector3d expected = Eigen::Vector3d(0.1, -0.2, -0.3) + Eigen::Vector3d(0.04404, 0.00128, 0.003);
  EXPECT_LT((calib.T_camera_lidar.translation() - expected).norm(), 1e-12);
  EXPECT_EQ(ParseKittiTimestamp("1970-01-01 00:00:01.250000000"), 1250000);
}

TEST(KittiImporter, WritesEveryFrameAtItsTimeWithStationsAndReference) {
  const std::string dir = MakeKittiDrive(6), log = dir + "/out.lcmlog";
  const ImportReport report = ImportKitti(dir, log, KittiImportOptions{2});
  EXPECT_EQ(report.images, 6);
  EXPECT_EQ(report.scans, 6);
  EXPECT_EQ(report.stations, 3);
  EXPECT_TRUE(report.warnings.empty());
  const Isometry3 reference = ReadReferenceExtrinsic(log);
  EXPECT_LT((reference.translation() - ReadKittiCalibration(dir).T_camera_lidar.translation()).norm(), 1e-12);
  LogReader reader(log);
  int64_t last = 0;
  while (auto event = reader.Next()) {
    EXPECT_GE(event->utime, last) << "events out of time order";
    last = event->utime;
  }
}

TEST(KittiImporter, BadFilesAreNamedAndSkippedAndFailuresLeaveNoLog) {
  std::string dir = MakeKittiDrive(4), log = dir + "/out.lcmlog";
  std::ofstream(dir + "/image_02/data/0000000006.png", std::ios::trunc) << "not a png";
  std::ofstream(dir + "/velodyne_points/data/0000000008.bin", std::ios::trunc) << "12345";  // truncated
  PointCloud with_nan = SmallCloud(150, 0);
  with_nan.points[3].x() = std::nanf("");
  WriteScan(dir + "/velodyne_points/data/0000000010.bin", with_nan);
  const ImportReport report = ImportKitti(dir, log, {});
  EXPECT_EQ(report.images, 3);
  EXPECT_EQ(report.scans, 3);
  std::string all;
  for (const auto& w : report.warnings) all += w + "\n";
  EXPECT_NE(all.find("0000000006.png"), std::string::npos) << all;
  EXPECT_NE(all.find("0000000008.bin"), std::string::npos) << all;

  dir = MakeKittiDrive(3);
  log = dir + "/out.lcmlog";
  std::ofstream(dir + "/velodyne_points/timestamps.txt", std::ios::app) << "2011-09-26 13:03:00.0\n";
  try {
    ImportKitti(dir, log, {});
    FAIL() << "mismatched timestamps accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("timestamps.txt"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(log));
  EXPECT_FALSE(fs::exists(log + ".partial"));
  fs::remove(dir + "/calib_cam_to_cam.txt");
  EXPECT_THROW(ImportKitti(dir, log, {}), std::runtime_error);
}

TEST(FolderImporter, PairsByStemAndReportsStrays) {
  const std::string dir = FreshDir("folder"), log = dir + "/out.lcmlog";
  for (const char* stem : {"a", "b", "c"}) {
    cv::imwrite(dir + "/" + stem + ".png", cv::Mat(20, 40, CV_8UC3, cv::Scalar(1, 2, 3)));
    WriteScan(dir + "/" + stem + ".pcd", SmallCloud(120, 0));
  }
  cv::imwrite(dir + "/lonely.png", cv::Mat(20, 40, CV_8UC3));
  std::ofstream(dir + "/times.csv") << "stem,seconds\na,10.5\nb,11\nc,12.25\n";
  CameraParams camera;
  camera.model = "equirectangular";
  camera.width = 40;
  camera.height = 20;
  const ImportReport report = ImportFolder(dir, camera, log);
  EXPECT_EQ(report.stations, 3);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("lonely.png"), std::string::npos);
  LogReader reader(log);
  std::vector<int64_t> station_times;
  while (auto event = reader.Next())
    if (event->channel == channels::kStation.name) station_times.push_back(event->utime);
  EXPECT_EQ(station_times, (std::vector<int64_t>{10500000, 11000000, 12250000}));
}

// Writes position<N>.ply in the dataset's layout: binary little-endian, pose as "matrix" column lines.
void WriteIshikawaPly(const std::string& path, const Eigen::Matrix4d& pose, const PointCloud& cloud) {
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\ncomment scanner export\n";
  for (int c = 0; c < 4; ++c)
    out << "matrix " << pose(0, c) << " " << pose(1, c) << " " << pose(2, c) << " " << pose(3, c) << "\n";
  out << "element vertex " << cloud.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
      << "property float confidence\nend_header\n";
  for (size_t i = 0; i < cloud.size(); ++i) {
    const float v[4] = {cloud.points[i].x(), cloud.points[i].y(), cloud.points[i].z(), cloud.intensity[i]};
    out.write(reinterpret_cast<const char*>(v), sizeof(v));
  }
}

TEST(IshikawaImporter, ReadsPosesFromPlyHeadersAndMotionPairs) {
  const std::string dir = FreshDir("ishikawa"), log = dir + "/out.lcmlog";
  std::vector<Eigen::Matrix4d> poses;
  for (int n = 1; n <= 3; ++n) {
    Eigen::Matrix4d pose =
        MakeIsometry(RotationFromRpy(0.01 * n, 0.2 * n, 0.5 * n), {0.1 * n, -0.2, 0.05 * n}).matrix();
    poses.push_back(pose);
    WriteIshikawaPly(dir + "/position" + std::to_string(n) + ".ply", pose, SmallCloud(300, float(n)));
    cv::imwrite(dir + "/position" + std::to_string(n) + ".jpg", cv::Mat(64, 128, CV_8UC3, cv::Scalar(20, 40, 60)));
  }
  std::ofstream(dir + "/motion.txt") << "1-2\n2-3\n";
  EXPECT_EQ(ReadMotionPairs(dir + "/motion.txt"), (std::vector<std::pair<int, int>>{{0, 1}, {1, 2}}));
  const PosedScan scan = ReadPlyWithPose(dir + "/position2.ply");
  ASSERT_TRUE(scan.pose.has_value());
  EXPECT_LT((*scan.pose - poses[1]).norm(), 1e-5);
  EXPECT_EQ(scan.cloud.size(), 300u);

  const ImportReport report = ImportIshikawa(dir, log);
  EXPECT_EQ(report.stations, 3);
  EXPECT_TRUE(report.warnings.empty());
  const auto truth = ReadGroundTruth(log);
  ASSERT_TRUE(truth.has_value());
  ASSERT_EQ(truth->num_stations, 3);
  // Reference LiDAR motion 1-2 from the header poses.
  const Isometry3 T1 = FromRowMajor(truth->T_world_lidar[0].data()), T2 = FromRowMajor(truth->T_world_lidar[1].data());
  Isometry3 P1, P2;
  P1.matrix() = poses[0];
  P2.matrix() = poses[1];
  EXPECT_LT(((T1.inverse() * T2).matrix() - (P1.inverse() * P2).matrix()).norm(), 1e-5);

  // Their panorama convention maps onto ours by a fixed rotation: forward (x_t) is our z.
  EXPECT_LT((RotationTheirsFromFusecal() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 1e-12);

  std::ofstream(dir + "/position3.ply", std::ios::trunc)
      << "ply\nformat ascii 1.0\nelement vertex 10\nproperty float x\n";
  std::ofstream(dir + "/motion.txt", std::ios::trunc) << "1-2\nthree-four\n";
  EXPECT_THROW(ImportIshikawa(dir, log), std::runtime_error);
}

const std::string kKittiDir = KITTI_SNIPPET_DIR;

TEST(KittiSnippet, ImportGivesAllFramesAndTheReferenceProjectsOntoEdges) {
  if (!fs::exists(kKittiDir + "/calib_velo_to_cam.txt"))
    GTEST_SKIP() << "KITTI snippet not found at " << kKittiDir << ": real-data check not run";
  const std::string log = FreshDir("snippet") + "/kitti.lcmlog";
  const auto imported = RunCommand(std::string(FUSECAL_BIN) + " import kitti " + kKittiDir + " --out " + log +
                                   " --stations every:10 2>&1");
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const auto info = RunCommand(std::string(FUSECAL_BIN) + " log info " + log);
  EXPECT_NE(info.output.find("CAMERA_IMAGE  count=39"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("LIDAR_SCAN  count=39"), std::string::npos) << info.output;

  const Isometry3 reference = ReadReferenceExtrinsic(log);
  const Isometry3 rotated = reference * MakeIsometry(ExpSO3({0, 0, 1.5 * M_PI / 180}), Eigen::Vector3d::Zero());
  LogReader reader(log);
  int stations = 0;
  while (auto event = reader.Next()) {
    if (event->channel != channels::kStation.name) continue;
    station_t station{};
    ASSERT_GE(station.decode(event->data.data(), 0, static_cast<int>(event->data.size())), 0);
    const cv::Mat image = ImageToMat(station.image);
    const PointCloud cloud = CloudFromMsg(station.cloud);
    const auto camera = MakeCameraModel(CameraFromMsg(station.camera));
    const double right = DepthEdgeToImageEdgeDistance(image, cloud, *camera, reference);
    const double wrong = DepthEdgeToImageEdgeDistance(image, cloud, *camera, rotated);
    EXPECT_LT(right, 0.8 * wrong) << "station " << station.id << ": depth edges do not sit on image edges";
    cv::imwrite(::testing::TempDir() + "kitti_overlay_" + std::to_string(station.id) + ".png",
                RenderDepthOverlay(image, cloud, *camera, reference));
    ++stations;
  }
  EXPECT_EQ(stations, 4);
}

}  // namespace
}  // namespace fusecal

namespace fusecal {
namespace {

// The README's worked example: a straight drive observes only the direction of travel, and says so.
TEST(KittiSnippet, AStraightDriveIsNotConvergedAndNamesWhatIsUnobserved) {
  if (!fs::exists(kKittiDir + "/calib_velo_to_cam.txt"))
    GTEST_SKIP() << "KITTI snippet not found at " << kKittiDir << ": real-data check not run";
  const std::string dir = FreshDir("worked_example");
  const std::string fusecal = FUSECAL_BIN;
  ASSERT_EQ(RunCommand(fusecal + " import kitti " + kKittiDir + " --stations every:6 --out " + dir +
                       "/kitti.lcmlog > /dev/null 2>&1")
                .exit_code,
            0);
  const auto calibrate = RunCommand(fusecal + " calibrate --log " + dir + "/kitti.lcmlog --out " + dir + "/out 2>&1");
  EXPECT_EQ(calibrate.exit_code, 1) << calibrate.output;  // not converged
  EXPECT_NE(calibrate.output.find("result: failed (observability: too_few_motions)"), std::string::npos)
      << calibrate.output;
  EXPECT_NE(calibrate.output.find("rotation about the direction of travel"), std::string::npos) << calibrate.output;
  EXPECT_NE(calibrate.output.find("the whole translation"), std::string::npos) << calibrate.output;

  const CalibrationResult result = ReadResultFile(dir + "/out/extrinsic.yaml");
  EXPECT_NE(result.status, "converged");
  ASSERT_TRUE(result.unobservable_direction);
  EXPECT_GT(result.unobservable_direction->z(), 0.99);  // the car drives along the camera's optical axis
  const ObservableError observed = CompareObservablePart(
      result.T_camera_lidar, ReadReferenceExtrinsic(dir + "/kitti.lcmlog"), *result.unobservable_direction);
  EXPECT_LT(observed.direction_deg, 3.0);  // KITTI's calibration agrees with what was observed
}

}  // namespace
}  // namespace fusecal
