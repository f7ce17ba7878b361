// The sections of the pipeline config: every stage's reader takes its ranges from the settings'
// Validate(), and an out-of-range value is an error naming the key and the range.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>

#include "runtime/pipeline/pipeline_config.hpp"
#include "runtime/pipeline/stage_nodes.hpp"
#include "runtime/stage_main.hpp"

namespace fusecal {
namespace {

using Reader = std::function<void(ConfigReader)>;

const Reader kStationarity = [](ConfigReader r) { ReadStationarityNodeSettings(r); };
const Reader kLidarIcp = [](ConfigReader r) { ReadLidarIcpNodeSettings(r); };
const Reader kCameraFrontend = [](ConfigReader r) { ReadCameraFrontendNodeSettings(r); };
const Reader kFusionOdometry = [](ConfigReader r) { ReadFusionOdometryNodeSettings(r); };
const Reader kHandEye = [](ConfigReader r) { ReadHandEyeNodeSettings(r); };
const Reader kRos2Tf = [](ConfigReader r) { ReadRos2TfSettings(r); };
const Reader kRos2Input = [](ConfigReader r) { ReadRos2InputSettings(r); };

// Reads `section: {line}` with `read`; the ConfigError message, or "" when accepted.
std::string ErrorOf(const std::string& section, const std::string& line, const Reader& read) {
  try {
    read(ConfigReader::FromString(section + ": {" + line + "}").Child(section));
    return "";
  } catch (const ConfigError& e) {
    return e.what();
  }
}

struct Case {
  std::string section, line;
  const Reader* read;
  std::string message;  // the error must contain it
};

TEST(PipelineConfig, OutOfRangeValuesNameTheKeyAndTheRange) {
  const Case cases[] = {
      {"stationarity", "merge_scans: 33", &kStationarity, "'stationarity.merge_scans' must be in [1, 32]"},
      {"stationarity", "min_still_s: 0", &kStationarity, "'stationarity.min_still_s' must be positive"},
      {"stationarity", "max_pair_dt_s: -1", &kStationarity, "'stationarity.max_pair_dt_s' must not be negative"},
      {"stationarity", "still_flow_px: 0", &kStationarity, "'stationarity.still_flow_px' must be positive"},
      {"stationarity", "still_change_m: -1", &kStationarity, "'stationarity.still_change_m' must be positive"},
      {"stationarity", "raw_queue_depth: 0", &kStationarity, "'stationarity.raw_queue_depth' must be in [1, 1000]"},
      {"stationarity", "max_image_rate_hz: -1", &kStationarity,
       "'stationarity.max_image_rate_hz' must not be negative"},
      {"lidar_icp", "previous_stations: 11", &kLidarIcp, "'lidar_icp.previous_stations' must be in [1, 10]"},
      {"lidar_icp", "min_fitness: 1.5", &kLidarIcp, "'lidar_icp.min_fitness' must be in [0, 1]"},
      {"lidar_icp", "max_tilt_deg: 200", &kLidarIcp, "'lidar_icp.max_tilt_deg' must be in [0, 180]"},
      {"lidar_icp", "max_correspondence_m: -1", &kLidarIcp,
       "'lidar_icp.max_correspondence_m' must be in [0, 100] (0 = automatic)"},
      {"lidar_icp", "voxel_size_m: 20", &kLidarIcp, "'lidar_icp.voxel_size_m' must be in [0, 10]"},
      {"lidar_icp", "num_threads: -1", &kLidarIcp, "'lidar_icp.num_threads' must be in [0, 1024]"},
      {"lidar_icp", "max_range_m: -1", &kLidarIcp, "'lidar_icp.max_range_m' must be finite and greater than"},
      {"camera_frontend", "previous_stations: 0", &kCameraFrontend,
       "'camera_frontend.previous_stations' must be in [1, 10]"},
      {"camera_frontend", "ratio: 0", &kCameraFrontend, "'camera_frontend.ratio' must be in (0, 1]"},
      {"camera_frontend", "detection_scale: 2", &kCameraFrontend,
       "'camera_frontend.detection_scale' must be in [0.1, 1]"},
      {"camera_frontend", "max_features: 4", &kCameraFrontend, "'camera_frontend.max_features' must be at least 8"},
      {"camera_frontend", "min_inliers: 4", &kCameraFrontend, "'camera_frontend.min_inliers' must be at least 8"},
      {"fusion_odometry", "input_wait_s: -1", &kFusionOdometry, "'fusion_odometry.input_wait_s' must not be negative"},
      {"fusion_odometry", "reuse_rotation_deg: -1", &kFusionOdometry,
       "'fusion_odometry.reuse_rotation_deg' must not be negative"},
      {"fusion_odometry", "reuse_std_fraction: 2", &kFusionOdometry,
       "'fusion_odometry.reuse_std_fraction' must be in [0, 1]"},
      {"handeye", "tolerance_rotation_deg: 0", &kHandEye, "'handeye.tolerance_rotation_deg' must be positive"},
      {"handeye", "max_iterations: 0", &kHandEye, "'handeye.max_iterations' must be in [1, 1000]"},
      {"handeye", "retry_s: -1", &kHandEye, "'handeye.retry_s' must not be negative"},
      {"handeye", "min_pairs: 1", &kHandEye, "'handeye.min_pairs' must be >= 2"},
      {"handeye", "min_rotation_deg: 200", &kHandEye, "'handeye.min_rotation_deg' must be in [0, 180)"},
      {"handeye", "max_angle_difference_deg: 0", &kHandEye, "'handeye.max_angle_difference_deg' must be > 0"},
      {"handeye", "shared_errors: {camera: {translation_per_translation: -1e-4}}", &kHandEye,
       "'handeye.shared_errors.camera.translation_per_translation' must not be negative"},
      {"handeye", "shared_errors: {camera: {translation_scale: -5e-4}}", &kHandEye,
       "'handeye.shared_errors.camera.translation_scale' must not be negative"},
      {"handeye", "shared_errors: {lidar: {range_scale: 1e-3}}", &kHandEye,
       "unknown key: 'handeye.shared_errors.lidar.range_scale'"},
      {"ros2_tf", "domain: 300", &kRos2Tf, "'ros2_tf.domain' must be in [0, 232]"},
      {"ros2_tf", "parent_frame: camera, child_frame: camera", &kRos2Tf,
       "'ros2_tf': parent_frame and child_frame must be two different frame ids"},
  };
  for (const Case& c : cases) {
    const std::string error = ErrorOf(c.section, c.line, *c.read);
    EXPECT_NE(error.find(c.message), std::string::npos) << c.line << ": got '" << error << "'";
  }
}

TEST(PipelineConfig, ValuesWithinTheSettingsRangesAreAccepted) {
  EXPECT_EQ(ErrorOf("stationarity", "merge_scans: 32", kStationarity), "");
  EXPECT_EQ(ErrorOf("stationarity", "max_pair_dt_s: 0", kStationarity), "");
  EXPECT_EQ(ErrorOf("lidar_icp", "max_correspondence_m: 0", kLidarIcp), "");  // automatic
  EXPECT_EQ(ErrorOf("camera_frontend", "ratio: 0.05", kCameraFrontend), "");
  EXPECT_EQ(ErrorOf("handeye", "min_pairs: 2000, max_motions: 2000", kHandEye), "");
  EXPECT_EQ(ErrorOf("handeye", "shared_errors: {camera: {rotation_per_rotation: 1e-3}, lidar: {}}", kHandEye), "");
  // More pairs for a verdict than are ever held is a contradiction, named.
  EXPECT_NE(ErrorOf("handeye", "min_pairs: 2000", kHandEye).find("max_motions"), std::string::npos);
  EXPECT_EQ(ErrorOf("ros2_tf", "domain: 232", kRos2Tf), "");
}

TEST(PipelineConfig, ChangeDetectionIsReadAndABadValueIsNamed) {
  ConfigReader config = ConfigReader::FromString(
      "handeye: {change_detection: {enabled: false, off_probability: 1.0e-4, confirm_probability: 1.0e-2, window: 5, "
      "directed_confirm_probability: 0.02, noise_floor_fraction: 0.2, test_direction: true, min_direction_length: 4, "
      "split_min_noise_dof: 9}}");
  const CalibratorSettings s = ReadHandEyeNodeSettings(config.Child("handeye")).calibrator;
  EXPECT_FALSE(s.change_detection.enabled);
  EXPECT_EQ(s.change_detection.off_probability, 1e-4);
  EXPECT_EQ(s.change_detection.confirm_probability, 1e-2);
  EXPECT_EQ(s.change_detection.directed_confirm_probability, 0.02);
  EXPECT_EQ(s.change_detection.window, 5);
  EXPECT_EQ(s.change_detection.noise_floor_fraction, 0.2);
  EXPECT_TRUE(s.change_detection.test_direction);
  EXPECT_EQ(s.change_detection.min_direction_length, 4);
  EXPECT_EQ(s.change_detection.split_min_noise_dof, 9);
  const std::string bad = ErrorOf("handeye", "change_detection: {off_probability: 0.7}", kHandEye);
  EXPECT_NE(bad.find("change_detection.off_probability"), std::string::npos) << bad;
  const std::string unknown = ErrorOf("handeye", "change_detection: {windows: 3}", kHandEye);
  EXPECT_NE(unknown.find("windows"), std::string::npos) << unknown;
}

// As every ROS 2 tool: a config without a domain takes ROS_DOMAIN_ID; one that names a domain keeps it.
TEST(PipelineConfig, Ros2DomainComesFromRosDomainIdUnlessTheConfigNamesOne) {
  const auto input = [](const std::string& yaml) {
    return ReadRos2InputSettings(ConfigReader::FromString(yaml).Child("ros2_input")).domain;
  };
  const auto tf = [](const std::string& yaml) {
    return ReadRos2TfSettings(ConfigReader::FromString(yaml).Child("ros2_tf")).domain;
  };
  unsetenv("ROS_DOMAIN_ID");
  EXPECT_EQ(input("ros2_input: {}"), 0);
  setenv("ROS_DOMAIN_ID", "150", 1);
  EXPECT_EQ(input("ros2_input: {}"), 150);
  EXPECT_EQ(tf("ros2_tf: {}"), 150);
  EXPECT_EQ(input("ros2_input: {domain: 3}"), 3);
  EXPECT_EQ(tf("ros2_tf: {domain: 0}"), 0);
  setenv("ROS_DOMAIN_ID", "", 1);
  EXPECT_EQ(tf("ros2_tf: {}"), 0) << "empty is the default domain, as in ROS 2";
  setenv("ROS_DOMAIN_ID", "15x", 1);
  const std::string bad = ErrorOf("ros2_input", "", kRos2Input);
  EXPECT_NE(bad.find("ROS_DOMAIN_ID='15x'"), std::string::npos) << bad;
  EXPECT_EQ(ErrorOf("ros2_input", "domain: 7", kRos2Input), "") << "a domain in the config does not read it";
  setenv("ROS_DOMAIN_ID", "233", 1);
  EXPECT_NE(ErrorOf("ros2_tf", "", kRos2Tf).find("[0, 232]"), std::string::npos);
  unsetenv("ROS_DOMAIN_ID");
}

TEST(PipelineConfig, WrongTypesAndNonFiniteValuesAreStillNamed) {
  const std::string nan = ErrorOf("handeye", "tolerance_rotation_deg: .nan", kHandEye);
  EXPECT_NE(nan.find("'handeye.tolerance_rotation_deg' must be finite"), std::string::npos) << nan;
  const std::string word = ErrorOf("stationarity", "merge_scans: many", kStationarity);
  EXPECT_NE(word.find("'stationarity.merge_scans' has the wrong type"), std::string::npos) << word;
}

TEST(PipelineConfig, NodeSettingsValidateTheirOwnFieldsAndTheCores) {
  EXPECT_EQ(LidarIcpNodeSettings().Validate(), "");
  EXPECT_EQ(CameraFrontendNodeSettings().Validate(), "");
  EXPECT_EQ(FusionOdometryNodeSettings().Validate(), "");
  EXPECT_EQ(CalibratorSettings().Validate(), "");
  EXPECT_EQ(StationarityNodeSettings().Validate(), "");
  EXPECT_EQ(Ros2TfSettings().Validate(), "");
  CalibratorSettings handeye;
  handeye.solver.max_iterations = 0;  // the solver's, not the node's
  EXPECT_EQ(handeye.Validate().rfind("solver.max_iterations", 0), 0u) << handeye.Validate();
}

// The rig's cameras: each per-camera stage gets its camera, stationarity all of them, LiDAR ICP the first.
TEST(PipelineConfig, TheRigsCamerasReachEveryStageThatNeedsThem) {
  const std::string path = ::testing::TempDir() + "/fusecal_rig_config.yaml";
  { std::ofstream(path) << "cameras: [{name: front}, {name: left}]\n"; }
  const PipelineConfig config = LoadPipelineConfig(path);
  EXPECT_EQ(config.cameras, (std::vector<std::string>{"front", "left"}));
  EXPECT_EQ(config.stationarity.rig_cameras, config.cameras);
  EXPECT_EQ(config.lidar_icp.station_camera, "front");
  std::vector<std::string> names;
  for (const auto& node : MakeStageNodes(config, true)) names.push_back(node.name);
  EXPECT_EQ(names, (std::vector<std::string>{"stationarity", "lidar_icp", "camera_frontend/front",
                                             "camera_frontend/left", "fusion_odometry/front", "fusion_odometry/left",
                                             "handeye/front", "handeye/left"}));
  // A process of a per-camera stage must be told which camera it serves, and only one of the rig's.
  EXPECT_EQ(StageRig(path, "left", true).camera, "left");
  EXPECT_THROW(StageRig(path, "", true), ConfigError);
  EXPECT_THROW(StageRig(path, "rear", true), ConfigError);
  EXPECT_THROW(StageRig(path, "left", false), ConfigError);
  EXPECT_EQ(StageRig("", "", true).camera, "");  // no config: one camera without a name
}

// The ROS 2 input of a rig: every camera of the rig has its topics, and no other camera.
TEST(PipelineConfig, TheRos2InputOfARigNamesEveryCameraOnce) {
  Ros2InputSettings s =
      ReadRos2InputSettings(ConfigReader::FromString("ros2_input: {cameras: [{name: left, image_topic: "
                                                     "/left/image_raw}, {name: right, image_topic: /r/compressed}]}")
                                .Child("ros2_input"));
  s.rig_cameras = {"left", "right"};
  EXPECT_EQ(s.RigProblem(), "");
  const auto topics = s.CameraTopics();
  ASSERT_EQ(topics.size(), 2u);
  EXPECT_EQ(topics[0].CameraInfoTopic(), "/left/camera_info");
  EXPECT_TRUE(topics[1].compressed());
  s.rig_cameras = {"left", "right", "rear"};
  EXPECT_NE(s.RigProblem().find("camera rear of the rig has no image_topic here"), std::string::npos) << s.RigProblem();
  s.rig_cameras = {"left"};
  EXPECT_NE(s.RigProblem().find("right is not a camera of the rig"), std::string::npos) << s.RigProblem();
  s.rig_cameras = {""};
  EXPECT_NE(s.RigProblem().find("one camera without a name"), std::string::npos) << s.RigProblem();
  EXPECT_NE(ErrorOf("ros2_input", "cameras: [{name: a, image_topic: 'no topic'}]", kRos2Input)
                .find("ros2_input.cameras[0].image_topic"),
            std::string::npos);
}

TEST(PipelineConfig, BadCameraNamesAreNamedWithTheirEntry) {
  const std::pair<std::string, std::string> cases[] = {
      {"cameras: [{name: front}, {name: front}]", "'front' names two cameras"},
      {"cameras: [{name: 'front-left'}]", "cameras[0].name"},
      {"cameras: [{name: 2front}]", "must start with a letter"},
      {"cameras: []", "must name at least one camera"},
      {"cameras: [{name: a, fx: 3}]", "cameras[0].fx"},
  };
  for (const auto& [yaml, message] : cases) {
    try {
      ConfigReader root = ConfigReader::FromString(yaml);
      ReadRigCameras(root);
      ADD_FAILURE() << yaml << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << yaml << ": " << e.what();
    }
  }
}

}  // namespace
}  // namespace fusecal
