#include "stages/lidar_icp/node/lidar_icp_node.hpp"

int main(int argc, char** argv) {
  return fusecal::RunStage<fusecal::LidarIcpNode>(
      argc, argv, "lidar_icp", "fusecal-lidar-icp: LiDAR motion between stations by ICP with no initial guess",
      fusecal::ReadLidarIcpNodeSettings);
}
