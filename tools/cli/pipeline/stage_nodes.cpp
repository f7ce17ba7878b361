#include "pipeline/stage_nodes.hpp"

#include <stdexcept>

namespace fusecal {

std::vector<NamedNode> MakeStageNodes(const PipelineConfig& config, bool with_stationarity) {
  std::vector<NamedNode> nodes;
  if (with_stationarity) nodes.push_back({"stationarity", std::make_unique<StationarityNode>(config.stationarity)});
  nodes.push_back({"lidar_icp", std::make_unique<LidarIcpNode>(config.lidar_icp)});
  nodes.push_back({"camera_frontend", std::make_unique<CameraFrontendNode>(config.camera_frontend)});
  nodes.push_back({"fusion_odometry", std::make_unique<FusionOdometryNode>(config.fusion_odometry)});
  nodes.push_back({"handeye", std::make_unique<HandEyeNode>(config.handeye)});
  return nodes;
}

}  // namespace fusecal
