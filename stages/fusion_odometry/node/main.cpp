#include "fusion_odometry/node/fusion_odometry_node.hpp"

int main(int argc, char** argv) {
  fusecal::StageDefinition stage;
  stage.name = "fusion_odometry";
  stage.description = "fusecal-fusion-odometry: metric camera motion from LiDAR depth + KLT + P3P";
  stage.make_node = [](const std::string& config_path) {
    fusecal::FusionOdometryNodeSettings settings;
    if (!config_path.empty())
      settings = fusecal::ReadFusionOdometryNodeSettings(fusecal::StageSection(config_path, "fusion_odometry"));
    return std::make_unique<fusecal::FusionOdometryNode>(settings);
  };
  return fusecal::StageMain(argc, argv, stage);
}
