#include "stationarity/node/stationarity_node.hpp"

int main(int argc, char** argv) {
  fusecal::StageDefinition stage;
  stage.name = "stationarity";
  stage.description = "fusecal-stationarity: stations from the camera and LiDAR streams";
  stage.make_node = [](const std::string& config_path) {
    fusecal::StationarityNodeSettings settings;
    if (!config_path.empty())
      settings = fusecal::ReadStationarityNodeSettings(fusecal::StageSection(config_path, "stationarity"));
    return std::make_unique<fusecal::StationarityNode>(settings);
  };
  return fusecal::StageMain(argc, argv, stage);
}
