#include "camera_frontend/node/camera_frontend_node.hpp"

int main(int argc, char** argv) {
  fusecal::StageDefinition stage;
  stage.name = "camera_frontend";
  stage.description = "fusecal-camera-frontend: scaleless camera motion between stations";
  stage.make_node = [](const std::string& config_path) {
    fusecal::CameraFrontendNodeSettings settings;
    if (!config_path.empty())
      settings = fusecal::ReadCameraFrontendNodeSettings(fusecal::StageSection(config_path, "camera_frontend"));
    return std::make_unique<fusecal::CameraFrontendNode>(settings);
  };
  return fusecal::StageMain(argc, argv, stage);
}
