#include "handeye/node/handeye_node.hpp"

int main(int argc, char** argv) {
  fusecal::StageDefinition stage;
  stage.name = "handeye";
  stage.description = "fusecal-handeye: T_camera_lidar from motion pairs, alternating with fusion odometry";
  stage.make_node = [](const std::string& config_path) {
    fusecal::HandEyeNodeSettings settings;
    if (!config_path.empty()) settings = fusecal::ReadHandEyeNodeSettings(fusecal::StageSection(config_path, "handeye"));
    return std::make_unique<fusecal::HandEyeNode>(settings);
  };
  return fusecal::StageMain(argc, argv, stage);
}
