#include "stages/handeye/node/handeye_node.hpp"

int main(int argc, char** argv) {
  return fusecal::RunStage<fusecal::HandEyeNode>(
      argc, argv, "handeye", "fusecal-handeye: T_camera_lidar from motion pairs, alternating with fusion odometry",
      fusecal::ReadHandEyeNodeSettings);
}
