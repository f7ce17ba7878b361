// The common result file, the export formats (round trips), and `fusecal evaluate`/`export`.
#include <gtest/gtest.h>
#include <unistd.h>

#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/extrinsic_formats.hpp"
#include "stages/formats/ground_truth.hpp"
#include "stages/formats/result_file.hpp"
#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

using testing::RunCommand;

CalibrationResult SampleResult() {
  CalibrationResult r;
  r.T_camera_lidar = MakeIsometry(RotationFromRpy(-1.55, 0.02, -1.58), {0.06, -0.12, -0.08});
  Matrix6 c = Matrix6::Zero();
  c.diagonal() << 1e-6, 4e-6, 9e-6, 1e-4, 4e-4, 9e-4;
  r.covariance = c;
  r.status = "converged";
  r.observability = "ok";
  r.motions_used = {"0-1", "1-2"};
  r.motions_rejected = {"2-3: rotation angles differ by 2.0 deg"};
  r.residual_rms = 0.0012;
  return r;
}

std::string TempFile(const std::string& name) {
  return ::testing::TempDir() + "fusecal_" + std::to_string(getpid()) + "_" + name;
}

TEST(ResultFile, WriteThenReadKeepsTheTransform) {
  const std::string path = TempFile("result.yaml");
  const CalibrationResult r = SampleResult();
  CalibrationResult initial = r;
  initial.status = "initial";
  WriteResultFile(path, r, &initial);
  const CalibrationResult back = ReadResultFile(path);
  EXPECT_LT((back.T_camera_lidar.matrix() - r.T_camera_lidar.matrix()).norm(), 1e-9);
  EXPECT_EQ(back.status, "converged");
  ASSERT_TRUE(back.covariance.has_value());
  EXPECT_NEAR(TranslationStdDevM(*back.covariance).z(), 0.03, 1e-12);
  const std::string text = ResultToYaml(r, &initial);
  for (const char* key : {"translation_m:", "rotation_quaternion_wxyz:", "rotation_rpy_deg:", "std_dev:",
                          "observability:", "motions_used:", "motions_rejected:", "residual_rms:", "initial:"})
    EXPECT_NE(text.find(key), std::string::npos) << key;
}

TEST(ResultFile, OnlyTheMatrixIsRequiredAndBadMatricesAreNamed) {
  const std::string path = TempFile("minimal.yaml");
  std::ofstream(path) << "T_camera_lidar: [1,0,0,0.1, 0,1,0,0.2, 0,0,1,0.3, 0,0,0,1]\n";
  EXPECT_NEAR(ReadResultFile(path).T_camera_lidar.translation().y(), 0.2, 1e-12);
  std::ofstream(path, std::ios::trunc) << "T_camera_lidar: [1,2,3]\n";
  try {
    ReadResultFile(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("T_camera_lidar"), std::string::npos);
  }
  std::ofstream(path, std::ios::trunc) << "T_camera_lidar: [2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n";
  EXPECT_THROW(ReadResultFile(path), std::runtime_error);
  EXPECT_THROW(ReadResultFile(TempFile("missing.yaml")), std::runtime_error);
}

TEST(ExportFormats, EveryFormatRoundTrips) {
  const CalibrationResult r = SampleResult();
  for (const auto& format : ExportFormats()) {
    const std::string text = ExportExtrinsic(r, format);
    const Isometry3 back = ParseExportedExtrinsic(text, format);
    EXPECT_LT(RotationErrorDeg(back.linear(), r.T_camera_lidar.linear()), 1e-7) << format << "\n" << text;
    EXPECT_LT((back.translation() - r.T_camera_lidar.translation()).norm(), 1e-9) << format;
  }
  EXPECT_THROW(ExportExtrinsic(r, "xacro"), std::invalid_argument);
  EXPECT_THROW(ExportExtrinsic(r, "urdf", {"camera", "velo dyne"}), std::invalid_argument);
  EXPECT_THROW(ParseExportedExtrinsic("R: 1 2 3\n", "kitti"), std::runtime_error);
  EXPECT_THROW(ParseExportedExtrinsic("<robot><joint/></robot>", "urdf"), std::runtime_error);
}

// The URDF as urdfdom (ROS's URDF parser) reads it: the joint from the camera's optical frame to the
// LiDAR's, whose origin composes to T_camera_lidar, also near pitch -90 deg, where rpy is sensitive.
TEST(ExportFormats, UrdfdomReadsTheJointAsTheExtrinsic) {
  CalibrationResult r = SampleResult();
  for (const double pitch : {0.02, -1.527}) {
    r.T_camera_lidar.linear() = RotationFromRpy(-2.2, pitch, -2.5);
    const std::string text = ExportExtrinsic(r, "urdf", {"cam_front_optical", "velodyne"});
    const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text);
    ASSERT_TRUE(model) << text;
    const urdf::JointConstSharedPtr joint = model->getJoint("cam_front_optical_to_velodyne");
    ASSERT_TRUE(joint) << text;
    EXPECT_EQ(joint->type, urdf::Joint::FIXED);
    EXPECT_EQ(joint->parent_link_name, "cam_front_optical");
    EXPECT_EQ(joint->child_link_name, "velodyne");
    const urdf::Pose& pose = joint->parent_to_joint_origin_transform;
    double x, y, z, w;
    pose.rotation.getQuaternion(x, y, z, w);
    const Eigen::Matrix3d R = Eigen::Quaterniond(w, x, y, z).toRotationMatrix();
    EXPECT_LT(RotationErrorDeg(R, r.T_camera_lidar.linear()), 1e-7) << text;
    const Eigen::Vector3d t(pose.position.x, pose.position.y, pose.position.z);
    EXPECT_LT((t - r.T_camera_lidar.translation()).norm(), 1e-12);
    EXPECT_EQ(model->getRoot()->name, "cam_front_optical");
  }
}

// A rig: the LiDAR is the root and each camera a child, its joint the camera's pose in the LiDAR frame.
TEST(ExportFormats, ARigIsOneTreeWithAJointPerCamera) {
  std::vector<RigCameraResult> cameras(2);
  cameras[0].camera = "left";
  cameras[0].T_camera_lidar = MakeIsometry(RotationFromRpy(-2.2, -1.52, -2.5), {0.06, 0.1, -0.07});
  cameras[1].camera = "right";
  cameras[1].T_camera_lidar = MakeIsometry(RotationFromRpy(-2.3, -1.53, -2.4), {-0.06, 0.1, -0.07});
  const RigResult rig = MakeRigResult(cameras);
  const std::string text = ExportRig(rig, "urdf", {"unused", "velodyne"});
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(text);
  ASSERT_TRUE(model) << text;
  EXPECT_EQ(model->getRoot()->name, "velodyne");
  for (const auto& c : rig.cameras) {
    const urdf::JointConstSharedPtr joint = model->getJoint("velodyne_to_" + c.camera);
    ASSERT_TRUE(joint) << text;
    EXPECT_EQ(joint->child_link_name, c.camera);
    const urdf::Pose& pose = joint->parent_to_joint_origin_transform;
    double x, y, z, w;
    pose.rotation.getQuaternion(x, y, z, w);
    const Isometry3 T_lidar_camera = c.T_camera_lidar.inverse();
    EXPECT_LT(RotationErrorDeg(Eigen::Quaterniond(w, x, y, z).toRotationMatrix(), T_lidar_camera.linear()), 1e-7);
    EXPECT_LT(
        (Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z) - T_lidar_camera.translation()).norm(),
        1e-12);
  }
  const std::string tf = ExportRig(rig, "ros-static-tf", {"unused", "velodyne"});
  EXPECT_EQ(std::count(tf.begin(), tf.end(), '\n'), 2) << tf;
  EXPECT_NE(tf.find(" velodyne right\n"), std::string::npos) << tf;
  const std::string kitti = ExportRig(rig, "kitti");
  EXPECT_NE(kitti.find("\nR_left:"), std::string::npos) << kitti;
  EXPECT_NE(kitti.find("\nT_right:"), std::string::npos) << kitti;
  for (const std::string format : {"json", "opencv-yaml"})
    EXPECT_NE(ExportRig(rig, format).find("T_right_left"), std::string::npos) << format;
  EXPECT_THROW(ExportRig(rig, "csv"), std::invalid_argument);
}

TEST(Commands, EvaluateAndExport) {
  const std::string result = TempFile("est.yaml"), truth = TempFile("truth.yaml");
  CalibrationResult r = SampleResult();
  WriteResultFile(truth, r);
  r.T_camera_lidar = r.T_camera_lidar * MakeIsometry(ExpSO3({0, 0, 0.5 * M_PI / 180}), {0, 0, 0});
  r.T_camera_lidar.translation() += Eigen::Vector3d(0.03, 0, -0.04);
  WriteResultFile(result, r);
  const auto eval = RunCommand(std::string(FUSECAL_BIN) + " evaluate --result " + result + " --truth " + truth);
  ASSERT_EQ(eval.exit_code, 0);
  const auto j = nlohmann::json::parse(eval.output);
  EXPECT_NEAR(j["rot_err_deg"].get<double>(), 0.5, 1e-6);
  EXPECT_NEAR(j["trans_err_m"].get<double>(), 0.05, 1e-9);
  EXPECT_EQ(j["trans_err_xyz_m"].size(), 3u);

  const std::string out = TempFile("tf.txt");
  const auto exported =
      RunCommand(std::string(FUSECAL_BIN) + " export " + result + " --format ros-static-tf --out " + out);
  ASSERT_EQ(exported.exit_code, 0);
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("camera lidar"), std::string::npos);
  EXPECT_NE(RunCommand(std::string(FUSECAL_BIN) + " export " + result + " --format xacro 2>&1").exit_code, 0);
  // The URDF passes urdfdom's own check (check_urdf, liburdfdom-tools) with the frames given.
  const std::string urdf = TempFile("extrinsic.urdf");
  ASSERT_EQ(RunCommand(std::string(FUSECAL_BIN) + " export " + result +
                       " --format urdf --parent-frame cam0_optical --child-frame os_sensor --out " + urdf)
                .exit_code,
            0);
  const auto check = RunCommand("check_urdf " + urdf + " 2>&1");
  EXPECT_EQ(check.exit_code, 0) << check.output;
  EXPECT_NE(check.output.find("root Link: cam0_optical has 1 child(ren)"), std::string::npos) << check.output;
  EXPECT_NE(check.output.find("child(1):  os_sensor"), std::string::npos) << check.output;
  EXPECT_EQ(RunCommand(std::string(FUSECAL_BIN) + " evaluate --result /nonexistent.yaml --truth " + truth + " 2>&1")
                .exit_code,
            1);
}

// A log with one GROUND_TRUTH message per extrinsic, each holding from its utime, written when it takes
// effect among some other traffic (as `fusecal simulate` writes a camera moved on its mount).
void WriteTruthLog(const std::string& path, const std::vector<std::pair<int64_t, Eigen::Matrix4d>>& extrinsics,
                   int64_t end_utime) {
  LogWriter writer(path);
  for (const auto& [utime, M] : extrinsics) {
    ground_truth_t truth{};
    truth.utime = utime;
    truth.source = "test";
    for (int i = 0; i < 16; ++i) truth.T_camera_lidar[i] = M(i / 4, i % 4);
    writer.WriteMessage(channels::kGroundTruth, utime, truth);
    writer.Write("OTHER", utime + 1, "x", 1);
  }
  writer.Write("OTHER", end_utime, "x", 1);
  writer.Close();
}

nlohmann::json Evaluate(const std::string& args, int expected_exit = 0) {
  const auto run = RunCommand(std::string(FUSECAL_BIN) + " evaluate " + args + " 2>&1");
  EXPECT_EQ(run.exit_code, expected_exit) << run.output;
  if (run.exit_code != 0) return nlohmann::json{{"output", run.output}};
  return nlohmann::json::parse(run.output);
}

TEST(Commands, EvaluateAgainstTheExtrinsicInForceAtTheLogsEndOrAtAGivenTime) {
  const std::string result = TempFile("moved-est.yaml"), log = TempFile("moved.lcmlog");
  const Isometry3 before = SampleResult().T_camera_lidar;
  const Isometry3 after = before * MakeIsometry(RotationFromRpy(1.0 * M_PI / 180, 0, 0), {0.02, 0, 0});
  WriteTruthLog(log, {{1000, before.matrix()}, {5000, after.matrix()}}, 9000);
  CalibrationResult r = SampleResult();
  r.T_camera_lidar = after;
  WriteResultFile(result, r);

  const auto at_end = Evaluate("--result " + result + " --truth " + log);
  EXPECT_LT(at_end["rot_err_deg"].get<double>(), 1e-9);
  EXPECT_LT(at_end["trans_err_m"].get<double>(), 1e-12);
  EXPECT_EQ(at_end["truth_from_utime"].get<int64_t>(), 5000);

  for (const int64_t utime : {int64_t{1000}, int64_t{4999}}) {
    const auto early = Evaluate("--result " + result + " --truth " + log + " --at-utime " + std::to_string(utime));
    EXPECT_NEAR(early["rot_err_deg"].get<double>(), 1.0, 1e-6) << utime;
    EXPECT_NEAR(early["trans_err_m"].get<double>(), 0.02, 1e-9) << utime;
    EXPECT_EQ(early["truth_from_utime"].get<int64_t>(), 1000) << utime;
  }
  EXPECT_EQ(Evaluate("--result " + result + " --truth " + log + " --at-utime 5000")["truth_from_utime"], 5000);

  // A result file as the truth has no time: no truth_from_utime, and --at-utime is refused.
  const auto from_yaml = Evaluate("--result " + result + " --truth " + result);
  EXPECT_FALSE(from_yaml.contains("truth_from_utime"));
  EXPECT_NE(
      Evaluate("--result " + result + " --truth " + result + " --at-utime 5000", 1)["output"].get<std::string>().find(
          "needs a log"),
      std::string::npos);

  // The helpers behind it.
  const auto truths = ReadGroundTruths(log);
  ASSERT_EQ(truths.size(), 2u);
  EXPECT_EQ(TruthExtrinsicAtEnd(truths).from_utime, 5000);
  EXPECT_EQ(TruthExtrinsicAt(truths, 4999).from_utime, 1000);
  EXPECT_EQ(TruthExtrinsicAt(truths, 0).from_utime, 1000);  // before the first: the first
  EXPECT_LT((TruthExtrinsicAt(truths, 7000).T_camera_lidar.matrix() - after.matrix()).norm(), 1e-12);
}

TEST(Commands, EvaluateRefusesATruthThatIsNotARigidTransform) {
  const std::string result = TempFile("rigid-est.yaml");
  WriteResultFile(result, SampleResult());
  const Eigen::Matrix4d good = SampleResult().T_camera_lidar.matrix();
  Eigen::Matrix4d scaled = good, nan = good, last_row = good;
  scaled.topLeftCorner<3, 3>() *= 2.0;
  nan(1, 2) = std::numeric_limits<double>::quiet_NaN();
  last_row(3, 0) = 0.5;
  const std::vector<std::pair<std::string, Eigen::Matrix4d>> bad = {
      {"zeros", Eigen::Matrix4d::Zero()}, {"scaled", scaled}, {"nan", nan}, {"last_row", last_row}};
  for (const auto& [name, M] : bad) {
    SCOPED_TRACE(name);
    // Bad at the start (the extrinsic compared is the later, good one) and bad at the end: refused both ways.
    for (const bool bad_first : {true, false}) {
      const std::string log = TempFile(name + ".lcmlog");
      WriteTruthLog(log, {{1000, bad_first ? M : good}, {5000, bad_first ? good : M}}, 9000);
      const std::string out = Evaluate("--result " + result + " --truth " + log, 1)["output"];
      EXPECT_NE(out.find("not a rigid transform"), std::string::npos) << out;
      EXPECT_NE(out.find(bad_first ? "utime 1000" : "utime 5000"), std::string::npos) << out;
      EXPECT_THROW(ReadReferenceExtrinsic(log), std::runtime_error);
    }
  }
}

}  // namespace
}  // namespace fusecal
