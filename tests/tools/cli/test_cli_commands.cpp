// The `fusecal` commands that wrap the cores: simulate (determinism, bad scenarios) and handeye (CSV).
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "stages/formats/result_file.hpp"
#include "stages/handeye/handheld_motions.hpp"
#include "stages/handeye/synthetic_motions.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

using testing::ReadAll;
using testing::RunCommand;
using testing::StartInBackground;
const std::string kFusecal = FUSECAL_BIN;
const std::string kScenarios = SCENARIO_DIR;

std::string Temp(const std::string& name) {
  return ::testing::TempDir() + "fusecal_cli_" + std::to_string(getpid()) + "_" + name;
}

#ifdef FUSECAL_WITH_DDS
// For a shared-memory DDS URL the doctor reports /dev/shm against RouDi's pools and whether RouDi is up,
// and the round trip works either way (without RouDi over the network path).
TEST(DoctorCommand, ChecksDevShmAndRoudiForSharedMemory) {
  const auto doctor = RunCommand(kFusecal + " doctor --bus 'dds://?domain=27&shm=1' 2>&1");
  EXPECT_NE(doctor.output.find("/dev/shm: "), std::string::npos) << doctor.output;
  EXPECT_NE(doctor.output.find("RouDi's pools need"), std::string::npos) << doctor.output;
  EXPECT_NE(doctor.output.find("iceoryx RouDi: "), std::string::npos) << doctor.output;
  EXPECT_NE(doctor.output.find("a 1 MB message went round"), std::string::npos) << doctor.output;
}
#endif

TEST(SimulateCommand, SameSeedSameBytesOtherSeedOtherBytes) {
  const std::string a = Temp("a.lcmlog"), b = Temp("b.lcmlog"), c = Temp("c.lcmlog");
  const std::string base = kFusecal + " simulate --scenario " + kScenarios + "/tiny-equirect.yaml";
  ASSERT_EQ(RunCommand(base + " --out " + a + " 2>&1").exit_code, 0);
  ASSERT_EQ(RunCommand(base + " --out " + b + " 2>&1").exit_code, 0);
  ASSERT_EQ(RunCommand(base + " --seed 12345 --out " + c + " 2>&1").exit_code, 0);
  const std::string bytes_a = ReadAll(a);
  EXPECT_GT(bytes_a.size(), 1000000u);
  EXPECT_TRUE(bytes_a == ReadAll(b)) << "same scenario and seed gave different logs";
  EXPECT_FALSE(bytes_a == ReadAll(c)) << "a different seed gave the same log";
  const auto info = RunCommand(kFusecal + " log info " + a);
  EXPECT_NE(info.output.find("GROUND_TRUTH  count=1"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("CAMERA_IMAGE"), std::string::npos);
  EXPECT_NE(info.output.find("LIDAR_SCAN"), std::string::npos);
}

TEST(SimulateCommand, StationsOnlyWritesOneStationPerStillInterval) {
  const std::string log = Temp("stations.lcmlog");
  ASSERT_EQ(RunCommand(kFusecal + " simulate --scenario " + kScenarios + "/tiny-equirect.yaml --stations-only --out " +
                       log + " 2>&1")
                .exit_code,
            0);
  const auto dump = RunCommand(kFusecal + " log dump " + log + " --channel GROUND_TRUTH");
  const auto truth = nlohmann::json::parse(dump.output);
  const int stills = truth["msg"]["num_stations"];
  EXPECT_GE(stills, 3);
  const auto info = RunCommand(kFusecal + " log info " + log);
  EXPECT_NE(info.output.find("STATION  count=" + std::to_string(stills)), std::string::npos) << info.output;
  EXPECT_EQ(info.output.find("CAMERA_IMAGE"), std::string::npos);
}

TEST(SimulateCommand, BadScenarioNamesTheKeyAndLeavesNoLog) {
  const std::string scenario = Temp("bad.yaml"), log = Temp("bad.lcmlog");
  std::string text = ReadAll(kScenarios + "/tiny-equirect.yaml");
  text += "\nfavourite_colour: blue\n";
  std::ofstream(scenario) << text;
  const auto result = RunCommand(kFusecal + " simulate --scenario " + scenario + " --out " + log + " 2>&1");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_NE(result.output.find("favourite_colour"), std::string::npos) << result.output;
  EXPECT_NE(access(log.c_str(), F_OK), 0);
}

// One log dump line per event of the channels matching `channels`.
std::vector<nlohmann::json> Dump(const std::string& log, const std::string& channels) {
  const auto dump = RunCommand(kFusecal + " log dump " + log + " --channel '" + channels + "'");
  std::vector<nlohmann::json> events;
  std::istringstream lines(dump.output);
  for (std::string line; std::getline(lines, line);) events.push_back(nlohmann::json::parse(line));
  return events;
}

Eigen::Matrix4d RowMajor(const nlohmann::json& values) {
  Eigen::Matrix4d M;
  for (int i = 0; i < 16; ++i) M(i / 4, i % 4) = values[i].get<double>();
  return M;
}

// The camera moved on its mount after stop 2 (of 3): GROUND_TRUTH gives both extrinsics, the second
// from the middle of the motion after stop 2, written there among the frames; evaluate compares with the
// one in force at the log's end unless --at-utime says otherwise.
TEST(SimulateCommand, CameraMovedOnItsMountGivesEachExtrinsicAndEvaluatePicksTheOneInForce) {
  const std::string scenario = Temp("moved.yaml"), log = Temp("moved.lcmlog");
  std::string text = ReadAll(kScenarios + "/tiny-equirect.yaml");
  for (const char* key : {"  horizontal: 2\n", "  vertical: 2\n"}) {
    const auto at = text.find(key);
    ASSERT_NE(at, std::string::npos) << key;
    text.replace(at + std::string(key).find('2'), 1, "1");
  }
  text += "extrinsic_changes:\n  - after_stop: 2\n    delta_rpy_deg: [1.0, 0, 0]\n    delta_xyz_m: [0.02, 0, 0]\n";
  std::ofstream(scenario) << text;
  const auto simulated = RunCommand(kFusecal + " simulate --scenario " + scenario + " --out " + log + " 2>&1");
  ASSERT_EQ(simulated.exit_code, 0) << simulated.output;

  const auto truths = Dump(log, "GROUND_TRUTH");
  ASSERT_EQ(truths.size(), 2u);
  const auto& first = truths[0]["msg"];
  const auto& second = truths[1]["msg"];
  ASSERT_EQ(first["num_stations"], 3);
  const int64_t start = first["utime"], changed = second["utime"];
  EXPECT_EQ(start, first["still_from_utime"][0].get<int64_t>());
  EXPECT_EQ(truths[1]["utime"].get<int64_t>(), changed);
  const int64_t stop2_end = first["still_to_utime"][1], stop3_start = first["still_from_utime"][2];
  EXPECT_NEAR(changed, (stop2_end + stop3_start) / 2, 1);
  EXPECT_EQ(second["still_from_utime"], first["still_from_utime"]);
  const Eigen::Matrix4d delta = MakeIsometry(RotationFromRpy(M_PI / 180, 0, 0), {0.02, 0, 0}).matrix();
  EXPECT_LT((RowMajor(second["T_camera_lidar"]) - RowMajor(first["T_camera_lidar"]) * delta).norm(), 1e-12);
  // Written when it takes effect: every frame before it is older, every frame after it is not.
  int64_t previous = 0;
  for (const auto& event : Dump(log, "CAMERA_IMAGE|LIDAR_SCAN|GROUND_TRUTH")) {
    const int64_t utime = event["utime"];
    EXPECT_GE(utime, previous) << event["channel"];
    previous = utime;
  }

  const std::string result = Temp("moved-result.yaml");
  CalibrationResult r;
  r.T_camera_lidar.matrix() = RowMajor(second["T_camera_lidar"]);
  WriteResultFile(result, r);
  const std::string evaluate = kFusecal + " evaluate --result " + result + " --truth " + log;
  const auto at_end = RunCommand(evaluate);
  ASSERT_EQ(at_end.exit_code, 0) << at_end.output;
  const auto end = nlohmann::json::parse(at_end.output);
  EXPECT_LT(end["rot_err_deg"].get<double>(), 1e-6);
  EXPECT_LT(end["trans_err_m"].get<double>(), 1e-9);
  EXPECT_EQ(end["truth_from_utime"].get<int64_t>(), changed);
  const auto at_start = RunCommand(evaluate + " --at-utime " + std::to_string(stop2_end));
  ASSERT_EQ(at_start.exit_code, 0) << at_start.output;
  const auto before = nlohmann::json::parse(at_start.output);
  EXPECT_NEAR(before["rot_err_deg"].get<double>(), 1.0, 1e-6);
  EXPECT_NEAR(before["trans_err_m"].get<double>(), 0.02, 1e-9);
  EXPECT_EQ(before["truth_from_utime"].get<int64_t>(), start);
}

void WriteCsv(const std::string& path, const std::vector<MotionPair>& pairs, const std::string& extra_lines = "") {
  std::ofstream out(path);
  out.precision(17);
  out << "a_qw,a_qx,a_qy,a_qz,a_tx,a_ty,a_tz,b_qw,b_qx,b_qy,b_qz,b_tx,b_ty,b_tz\n";
  for (const auto& p : pairs) {
    const Eigen::Quaterniond qa(p.A.linear()), qb(p.B.linear());
    out << qa.w() << "," << qa.x() << "," << qa.y() << "," << qa.z() << "," << p.A.translation().x() << ","
        << p.A.translation().y() << "," << p.A.translation().z() << "," << qb.w() << "," << qb.x() << "," << qb.y()
        << "," << qb.z() << "," << p.B.translation().x() << "," << p.B.translation().y() << "," << p.B.translation().z()
        << "\n";
  }
  out << extra_lines;
}

TEST(HandEyeCommand, SolvesScaledAndScalelessCsvAndReportsBadLines) {
  for (const bool scaled : {true, false}) {
    SyntheticMotionSettings settings;
    settings.num_motions = 8;
    settings.scaleless = !scaled;
    settings.seed = 5;
    const SyntheticMotionSet set = GenerateSyntheticMotions(settings);
    const std::string csv = Temp(scaled ? "scaled.csv" : "scaleless.csv"), out = Temp("result.yaml");
    WriteCsv(csv, set.pairs, "1,2,3\n0.5,0.5,0.5,0.5,0,0,0,nan,0,0,0,0,0,0\n2,0,0,0,0,0,0,1,0,0,0,0,0,0\n");
    const auto result = RunCommand(kFusecal + " handeye --motions " + csv + (scaled ? " --camera-scaled" : "") +
                                   " --out " + out + " 2>&1");
    EXPECT_EQ(result.exit_code, 0) << result.output;
    EXPECT_NE(result.output.find("line 10: needs 14 numbers"), std::string::npos) << result.output;
    EXPECT_NE(result.output.find("line 11: holds NaN"), std::string::npos) << result.output;
    EXPECT_NE(result.output.find("line 12: quaternion is not unit"), std::string::npos) << result.output;
    const CalibrationResult r = ReadResultFile(out);
    EXPECT_LT(RotationErrorDeg(r.T_camera_lidar.linear(), set.T_camera_lidar.linear()), 1e-6);
    EXPECT_LT((r.T_camera_lidar.translation() - set.T_camera_lidar.translation()).norm(), 1e-6);
    EXPECT_EQ(r.status, "converged");
  }
}

// A camera trajectory with one unknown scale (structure from motion, SLAM): `--camera-scale global` gives
// the extrinsic and the scale; an unknown mode is refused by name.
TEST(HandEyeCommand, OneGlobalScaleForTheCameraTrajectory) {
  SyntheticMotionSettings settings;
  settings.num_motions = 10;
  settings.seed = 6;
  SyntheticMotionSet set = GenerateSyntheticMotions(settings);
  for (auto& p : set.pairs) p.A.translation() *= 2.5;
  const std::string csv = Temp("global.csv"), out = Temp("global.yaml");
  WriteCsv(csv, set.pairs);
  const auto result =
      RunCommand(kFusecal + " handeye --motions " + csv + " --camera-scale global --out " + out + " 2>&1");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("global camera scale 0.4"), std::string::npos) << result.output;
  const CalibrationResult r = ReadResultFile(out);
  EXPECT_LT(RotationErrorDeg(r.T_camera_lidar.linear(), set.T_camera_lidar.linear()), 1e-6);
  EXPECT_LT((r.T_camera_lidar.translation() - set.T_camera_lidar.translation()).norm(), 1e-6);
  const auto bad = RunCommand(kFusecal + " handeye --motions " + csv + " --camera-scale banana --out " + out + " 2>&1");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("--camera-scale"), std::string::npos) << bad.output;
}

// Handheld pairs as a user brings them (about 1 deg of error per motion, correlated along the trajectory,
// a camera trajectory in the units of structure from motion): observed, with a rotation std of the size of
// the error, in both scale modes; `global` solves with its one scale and differs from `per-motion`.
TEST(HandEyeCommand, HandheldPairsAreObservedInBothScaleModes) {
  HandheldMotionSettings settings;
  settings.seed = 3;
  const HandheldMotionSet set = GenerateHandheldMotions(settings);
  const std::string csv = Temp("handheld.csv");
  WriteCsv(csv, set.pairs);
  std::vector<CalibrationResult> results;
  for (const std::string mode : {"per-motion", "global"}) {
    SCOPED_TRACE(mode);
    const std::string out = Temp("handheld-" + mode + ".yaml");
    const auto run =
        RunCommand(kFusecal + " handeye --motions " + csv + " --camera-scale " + mode + " --out " + out + " 2>&1");
    EXPECT_EQ(run.exit_code, 0) << run.output;
    const CalibrationResult r = ReadResultFile(out);
    EXPECT_EQ(r.status, "converged") << run.output;
    EXPECT_EQ(r.observability, "ok") << run.output;
    EXPECT_LT(RotationErrorDeg(r.T_camera_lidar.linear(), set.T_camera_lidar.linear()), 2.0);
    ASSERT_TRUE(r.covariance.has_value());
    const Eigen::Vector3d std_deg = RotationStdDevDeg(*r.covariance);
    for (int k = 0; k < 3; ++k) {
      EXPECT_GT(std_deg(k), 0.2) << run.output;
      EXPECT_LT(std_deg(k), 1.0) << run.output;
    }
    results.push_back(r);
  }
  EXPECT_GT((results[0].T_camera_lidar.translation() - results[1].T_camera_lidar.translation()).norm(), 1e-4);
}

// Metric pairs whose extrinsic changes after row 20 (the camera moved by 2 deg and 3 cm): the change is
// found in the row that spans it, each part is solved alone, and the result is the part after it.
TEST(HandEyeCommand, FindsTheRowWhereTheExtrinsicChangedAndSolvesThePartAfterIt) {
  SyntheticMotionSettings settings;
  settings.num_motions = 40;
  settings.min_angle_deg = 10;
  settings.max_angle_deg = 30;
  settings.rotation_noise_deg = 0.05;
  settings.translation_noise_m = 0.001;
  settings.seed = 11;
  Isometry3 delta = Isometry3::Identity();
  delta.linear() = Eigen::AngleAxisd(2.0 * M_PI / 180, Eigen::Vector3d(0.3, 1, 0).normalized()).toRotationMatrix();
  delta.translation() = Eigen::Vector3d(0.03, 0, 0);
  const ChangingMotionSet moved = GenerateChangingMotions(settings, 20, delta);  // row 21 spans the change
  const std::vector<MotionPair>& pairs = moved.pairs;
  const SyntheticMotionSet before = GenerateSyntheticMotions(settings);
  const std::string csv = Temp("moved.csv"), out = Temp("moved.yaml");
  WriteCsv(csv, pairs);
  const auto run =
      RunCommand(kFusecal + " handeye --motions " + csv + " --camera-scale metric --all-parts --out " + out + " 2>&1");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("CHANGED in row 21 (after station 20"), std::string::npos) << run.output;
  const YAML::Node file = YAML::LoadFile(out);
  ASSERT_EQ(file["changes"].size(), 1u) << run.output;
  EXPECT_EQ(file["changes"][0]["after_station"].as<int>(), 20);
  EXPECT_LE(file["changes"][0]["decided_at_station"].as<int>(), 21 + 3);
  EXPECT_NEAR(file["changes"][0]["rotation_deg"].as<double>(), 2.0, 0.1);
  EXPECT_NEAR(file["changes"][0]["translation_m"].as<double>(), 0.03, 0.003);
  const CalibrationResult last = ReadResultFile(out), first = ReadResultFile(Temp("moved-part1.yaml"));
  EXPECT_LT(RotationErrorDeg(last.T_camera_lidar.linear(), moved.after.linear()), 0.1);
  EXPECT_LT((last.T_camera_lidar.translation() - moved.after.translation()).norm(), 0.003);
  EXPECT_LT(RotationErrorDeg(first.T_camera_lidar.linear(), before.T_camera_lidar.linear()), 0.1);
  // The same rows without the change: no change, one part; --no-changes blends both parts.
  WriteCsv(csv, before.pairs);
  const auto unchanged =
      RunCommand(kFusecal + " handeye --motions " + csv + " --camera-scale metric --out " + out + " 2>&1");
  EXPECT_EQ(unchanged.output.find("CHANGED"), std::string::npos) << unchanged.output;
  EXPECT_EQ(YAML::LoadFile(out)["changes"].size(), 0u);
  WriteCsv(csv, pairs);
  const auto blind =
      RunCommand(kFusecal + " handeye --motions " + csv + " --camera-scale metric --no-changes --out " + out + " 2>&1");
  EXPECT_EQ(blind.output.find("CHANGED"), std::string::npos) << blind.output;
  EXPECT_GT(RotationErrorDeg(ReadResultFile(out).T_camera_lidar.linear(), moved.after.linear()), 0.3);
}

TEST(HandEyeCommand, TooFewMotionsAndBadFilesFailClearly) {
  SyntheticMotionSettings settings;
  settings.num_motions = 1;
  const std::string csv = Temp("one.csv"), out = Temp("one.yaml");
  WriteCsv(csv, GenerateSyntheticMotions(settings).pairs);
  const auto one = RunCommand(kFusecal + " handeye --motions " + csv + " --camera-scaled --out " + out + " 2>&1");
  EXPECT_EQ(one.exit_code, 1);
  EXPECT_NE(one.output.find("too_few_motions"), std::string::npos) << one.output;
  std::ofstream(csv, std::ios::trunc) << "qw,qx\n1,0\n";
  const auto bad = RunCommand(kFusecal + " handeye --motions " + csv + " --out " + out + " 2>&1");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("header"), std::string::npos) << bad.output;
  EXPECT_EQ(RunCommand(kFusecal + " handeye --motions /nonexistent.csv --out " + out + " 2>&1").exit_code, 1);
}

const std::string kKitti = KITTI_SNIPPET_DIR;

TEST(StageCommands, RegisterCameraMotionAndStationsOnKitti) {
  if (access((kKitti + "/calib_velo_to_cam.txt").c_str(), F_OK) != 0)
    GTEST_SKIP() << "KITTI snippet not found at " << kKitti << ": real-data check not run";
  const std::string scans = kKitti + "/velodyne_points/data/", images = kKitti + "/image_02/data/";
  const auto reg = RunCommand(kFusecal + " register " + scans + "0000000000.bin " + scans + "0000000004.bin");
  ASSERT_EQ(reg.exit_code, 0) << reg.output;
  const auto r = nlohmann::json::parse(reg.output);
  EXPECT_EQ(r["T_a_b"].size(), 16u);
  EXPECT_TRUE(r["converged"].get<bool>());
  EXPECT_NEAR(r["T_a_b"][3].get<double>(), 0.98, 0.1) << "the car drove about 1 m forward (LiDAR x)";

  const std::string camera = Temp("kitti-camera.yaml");
  std::ofstream(camera) << "model: pinhole\nwidth: 1242\nheight: 375\nfx: 721.5377\nfy: 721.5377\n"
                        << "cx: 609.5593\ncy: 172.854\n";
  const auto cam = RunCommand(kFusecal + " camera-motion " + images + "0000000000.png " + images +
                              "0000000004.png --camera " + camera);
  ASSERT_EQ(cam.exit_code, 0) << cam.output;
  const auto c = nlohmann::json::parse(cam.output);
  EXPECT_GT(c["t_unit"][2].get<double>(), 0.99) << "forward along the camera's z axis";
  EXPECT_GT(c["inliers"].get<int>(), 100);

  const std::string log = Temp("kitti.lcmlog");
  ASSERT_EQ(RunCommand(kFusecal + " import kitti " + kKitti + " --out " + log + " 2>&1").exit_code, 0);
  const auto stations = RunCommand(kFusecal + " stations " + log + " 2>/dev/null");
  ASSERT_EQ(stations.exit_code, 0);
  std::istringstream lines(stations.output);
  std::string line;
  std::vector<nlohmann::json> found;
  while (std::getline(lines, line)) found.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(found.size(), 1u) << stations.output << " (one stop, at the end of the drive)";
  EXPECT_GE(found[0]["image_utime"].get<int64_t>(), found[0]["still_from"].get<int64_t>());
}

TEST(StageCommands, MissingFilesFailWithTheirName) {
  const auto reg = RunCommand(kFusecal + " register /nonexistent/a.bin /nonexistent/b.bin 2>&1");
  EXPECT_EQ(reg.exit_code, 1);
  EXPECT_NE(reg.output.find("/nonexistent/a.bin"), std::string::npos) << reg.output;
  const auto cam = RunCommand(kFusecal + " camera-motion /nonexistent/a.png /nonexistent/b.png --camera " + kScenarios +
                              "/../pipeline.yaml 2>&1");
  EXPECT_EQ(cam.exit_code, 1);
  const auto st = RunCommand(kFusecal + " stations /nonexistent.lcmlog 2>&1");
  EXPECT_EQ(st.exit_code, 1);
  EXPECT_NE(st.output.find("cannot open"), std::string::npos) << st.output;
}

}  // namespace
}  // namespace fusecal
