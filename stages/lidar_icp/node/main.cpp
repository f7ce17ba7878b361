#include "lidar_icp/node/lidar_icp_node.hpp"

int main(int argc, char** argv) {
  fusecal::StageDefinition stage;
  stage.name = "lidar_icp";
  stage.description = "fusecal-lidar-icp: LiDAR motion between stations by ICP with no initial guess";
  stage.make_node = [](const std::string& config_path) {
    fusecal::LidarIcpNodeSettings settings;
    if (!config_path.empty()) settings = fusecal::ReadLidarIcpNodeSettings(fusecal::StageSection(config_path, "lidar_icp"));
    return std::make_unique<fusecal::LidarIcpNode>(settings);
  };
  return fusecal::StageMain(argc, argv, stage);
}
