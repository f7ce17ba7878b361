#include "stages/ros2_input/node/ros2_input_node.hpp"

int main(int argc, char** argv) {
  return fusecal::RunStage<fusecal::Ros2InputNode>(
      argc, argv, "ros2_input",
      "fusecal-ros2-input: ROS 2 sensor topics (Image or CompressedImage, PointCloud2, CameraInfo) into the pipeline",
      fusecal::ReadRos2InputSettings);
}
