#include "stages/ros2_tf/node/ros2_tf_node.hpp"

int main(int argc, char** argv) {
  return fusecal::RunStage<fusecal::Ros2TfNode>(
      argc, argv, "ros2_tf", "fusecal-ros2-tf: every EXTRINSIC as a ROS 2 tf2_msgs/TFMessage on rt/tf_static",
      fusecal::ReadRos2TfSettings);
}
