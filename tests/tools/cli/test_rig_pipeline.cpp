// End to end on a rig of two cameras (the stereo scenario's stations): `fusecal calibrate` calibrates
// each camera and derives the camera-to-camera transform; `fusecal run` with one process per camera's
// stage, and with one camera's stages in a second run, gives the same answer; a live replay meets the
// same bounds; a one-camera config on the same log gives that camera exactly the rig's answer.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/support/process_utils.hpp"

namespace fusecal {
namespace {

using testing::ReadAll;
using testing::RunCommand;
using testing::StartInBackground;
const std::string kFusecal = FUSECAL_BIN;
const std::string kScenarios = SCENARIO_DIR;
const std::string kConfig = CONFIG_PATH;

std::string Temp(const std::string& name) {
  return ::testing::TempDir() + "fusecal_rig_" + std::to_string(getpid()) + "_" + name;
}
std::string Bus(int port) { return "udpm://239.255.76.67:" + std::to_string(port) + "?ttl=0&recv_buf_size=67108864"; }

// A pipeline config naming the rig's cameras (`cameras`), the rest the shipped one.
std::string RigConfig(const std::string& cameras) {
  const std::string path = Temp("config-" + std::to_string(std::hash<std::string>()(cameras)) + ".yaml");
  std::ofstream(path) << "cameras: [" << cameras << "]\n" << ReadAll(kConfig);
  return path;
}

nlohmann::json Evaluate(const std::string& result, const std::string& truth) {
  const auto eval = RunCommand(kFusecal + " evaluate --result " + result + " --truth " + truth + " 2>&1");
  EXPECT_EQ(eval.exit_code, 0) << eval.output;
  return nlohmann::json::parse(eval.output);
}

class RigPipeline : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    log_ = Temp("stereo.lcmlog");
    const auto sim = RunCommand(kFusecal + " simulate --scenario " + kScenarios +
                                "/stereo-pinhole-hdl64.yaml --stations-only --out " + log_ + " 2>&1");
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
    calibrate_output_ = RunCommand(kFusecal + " calibrate --log " + log_ + " --out " + Temp("cal") + " 2>&1").output;
  }
  // Every camera's result and the rig file equal calibrate's.
  static void ExpectSameAnswerAsCalibrate(const std::string& out_dir, const std::string& context) {
    const nlohmann::json j = Evaluate(out_dir + "/extrinsic.yaml", Temp("cal") + "/extrinsic.yaml");
    ASSERT_EQ(j["cameras"].size(), 2u) << context;
    EXPECT_LT(j["max_rot_err_deg"].get<double>(), 1e-6) << context;
    EXPECT_LT(j["max_trans_err_m"].get<double>(), 1e-6) << context;
  }
  static std::string log_, calibrate_output_;
};
std::string RigPipeline::log_, RigPipeline::calibrate_output_;

TEST_F(RigPipeline, CalibrateCalibratesEveryCameraAndTheCameraToCameraAgreesWithTheTruth) {
  EXPECT_NE(calibrate_output_.find("the log's cameras: left, right"), std::string::npos) << calibrate_output_;
  const nlohmann::json j = Evaluate(Temp("cal") + "/extrinsic.yaml", log_);
  for (const std::string camera : {"left", "right"}) {
    const auto& c = j["cameras"][camera];
    EXPECT_EQ(c["status"], "converged") << camera;
    EXPECT_LT(c["rot_err_deg"].get<double>(), 0.05) << camera;
    EXPECT_LT(c["trans_err_m"].get<double>(), 0.003) << camera;
    for (const char* file : {"extrinsic.yaml", "convergence.csv", "overlay-0.png"})
      EXPECT_EQ(access((Temp("cal") + "/" + camera + "/" + file).c_str(), F_OK), 0) << camera << "/" << file;
  }
  const auto& pair = j["camera_to_camera"]["right_left"];
  EXPECT_LT(pair["max_err_in_std"].get<double>(), 3.0) << j.dump();
  EXPECT_GT(pair["trans_std_m"].get<double>(), 0.0);
  // Exported, one transform per camera; a tool that takes one camera's result says where each camera's is.
  const auto exported = RunCommand(kFusecal + " export " + Temp("cal") + "/extrinsic.yaml --format json 2>&1");
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  const auto json = nlohmann::json::parse(exported.output);
  EXPECT_EQ(json["T_right_lidar"]["status"], "converged") << exported.output;
  EXPECT_EQ(json["T_right_left"]["T"].size(), 16u) << exported.output;
  const auto one = RunCommand(kFusecal + " evaluate --result " + Temp("cal") + "/left/extrinsic.yaml --truth " +
                              Temp("cal") + "/extrinsic.yaml 2>&1");
  EXPECT_NE(one.exit_code, 0);
  EXPECT_NE(one.output.find("<camera>/extrinsic.yaml"), std::string::npos) << one.output;
}

TEST_F(RigPipeline, ACameraAloneGetsExactlyItsAnswerInTheRig) {
  const auto cal = RunCommand(kFusecal + " calibrate --config " + RigConfig("{name: right}") + " --log " + log_ +
                              " --out " + Temp("right-alone") + " 2>&1");
  ASSERT_EQ(cal.exit_code, 0) << cal.output;
  const nlohmann::json alone = Evaluate(Temp("right-alone") + "/extrinsic.yaml", Temp("cal") + "/extrinsic.yaml");
  ASSERT_EQ(alone["cameras"].size(), 1u) << alone.dump();
  EXPECT_LT(alone["cameras"]["right"]["rot_err_deg"].get<double>(), 1e-9);
  EXPECT_LT(alone["cameras"]["right"]["trans_err_m"].get<double>(), 1e-9);
}

TEST_F(RigPipeline, SeparateProcessesPerCameraAgreeWithCalibrate) {
  const std::string out = Temp("run");
  const auto run =
      RunCommand(kFusecal + " run --log " + log_ + " --speed 0 --bus '" + Bus(7697) + "' --out " + out + " 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* stage : {"fusecal-camera_frontend/left: running", "fusecal-handeye/right: running"})
    EXPECT_NE(run.output.find(stage), std::string::npos) << stage;
  ExpectSameAnswerAsCalibrate(out, run.output);
}

TEST_F(RigPipeline, OneCamerasStagesInAnotherRunAgreeWithCalibrate) {
  const std::string config = RigConfig("{name: left}, {name: right}"), out_a = Temp("split-a"), out_b = Temp("split-b");
  const pid_t b = StartInBackground(kFusecal + " run --config " + config +
                                        " --stages camera_frontend/right,fusion_odometry/right,handeye/right --bus '" +
                                        Bus(7699) + "' --out " + out_b,
                                    out_b + ".txt");
  const auto a = RunCommand(kFusecal + " run --config " + config + " --log " + log_ + " --speed 0 --bus '" + Bus(7699) +
                            "' --stages lidar_icp,camera_frontend/left,fusion_odometry/left,handeye/left --out " +
                            out_a + " 2>&1");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  EXPECT_EQ(testing::WaitOrKill(b, 30), 0) << ReadAll(out_b + ".txt");
  EXPECT_NE(a.output.find("waiting for camera_frontend/right,fusion_odometry/right,handeye/right on other hosts"),
            std::string::npos)
      << a.output;
  ExpectSameAnswerAsCalibrate(out_a, a.output);
  ExpectSameAnswerAsCalibrate(out_b, ReadAll(out_b + ".txt"));
}

TEST_F(RigPipeline, LiveReplayMeetsTheBounds) {
  const std::string out = Temp("live");
  const auto run = RunCommand(kFusecal + " run --log " + log_ + " --live --speed 4 --bus '" + Bus(7701) + "' --out " +
                              out + " 2>&1");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = Evaluate(out + "/extrinsic.yaml", log_);
  EXPECT_LT(j["max_rot_err_deg"].get<double>(), 0.05) << j.dump();
  EXPECT_LT(j["max_trans_err_m"].get<double>(), 0.003) << j.dump();
  EXPECT_LT(j["camera_to_camera"]["right_left"]["max_err_in_std"].get<double>(), 3.0) << j.dump();
}

TEST(RigPipelineBadInput, AStageOfACameraTheRigDoesNotHaveIsNamed) {
  const auto run = RunCommand(kFusecal + " run --config " + RigConfig("{name: left}") +
                              " --stages handeye/rear --bus '" + Bus(7703) + "' --out " + Temp("no-rear") + " 2>&1");
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find("--stages handeye/rear: the rig has no camera rear (its cameras: left)"), std::string::npos)
      << run.output;
  const auto stage = RunCommand(std::string(FUSECAL_BIN_DIR) + "/fusecal-handeye --config " +
                                RigConfig("{name: left}, {name: right}") + " --bus memq:// 2>&1");
  EXPECT_EQ(stage.exit_code, 2) << stage.output;
  EXPECT_NE(stage.output.find("say which this process serves with --camera NAME"), std::string::npos) << stage.output;
}

}  // namespace
}  // namespace fusecal
