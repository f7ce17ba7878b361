// The pipeline config (configs/pipeline.yaml): every section is checked, unknown keys are errors.
#pragma once

#include <string>

#include "camera_frontend/node/camera_frontend_node.hpp"
#include "fusion_odometry/node/fusion_odometry_node.hpp"
#include "handeye/node/handeye_node.hpp"
#include "lidar_icp/node/lidar_icp_node.hpp"
#include "pipeline/session_log.hpp"
#include "ros2_input/node/ros2_input_settings.hpp"
#include "ros2_tf/node/ros2_tf_settings.hpp"
#include "stationarity/node/stationarity_node.hpp"

namespace fusecal {

struct PipelineConfig {
  std::string path;  // the file it came from (stage processes are given the same file)
  std::string bus_url;
  // Shared memory (dds://?shm=1, iox://): RouDi's pools hold `shm_chunks` messages of up to max_message_bytes.
  size_t max_message_bytes = 12u << 20;
  int shm_chunks = 32;
  std::string stations_from = "auto";  // detector | log | auto
  StationarityNodeSettings stationarity;
  LidarIcpNodeSettings lidar_icp;
  CameraFrontendNodeSettings camera_frontend;
  FusionOdometryNodeSettings fusion_odometry;
  CalibratorSettings handeye;
  Ros2TfSettings ros2_tf;
  Ros2InputSettings ros2_input;  // `fusecal run --ros2`
  double idle_timeout_s = 60;
  RecordSettings record;  // run.record, run.record_max_raw_mb
};

// Throws ConfigError naming the file and key.
PipelineConfig LoadPipelineConfig(const std::string& path);

// configs/pipeline.yaml of the source tree.
std::string DefaultPipelineConfigPath();

}  // namespace fusecal
