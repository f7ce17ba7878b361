#include "stages/camera_frontend/node/camera_frontend_node.hpp"

int main(int argc, char** argv) {
  return fusecal::RunStage<fusecal::CameraFrontendNode>(
      argc, argv, "camera_frontend", "fusecal-camera-frontend: scaleless camera motion between stations",
      fusecal::ReadCameraFrontendNodeSettings);
}
