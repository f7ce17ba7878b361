#include "stages/fusion_odometry/node/fusion_odometry_node.hpp"

int main(int argc, char** argv) {
  return fusecal::RunStage<fusecal::FusionOdometryNode>(
      argc, argv, "fusion_odometry", "fusecal-fusion-odometry: metric camera motion from LiDAR depth + KLT + P3P",
      fusecal::ReadFusionOdometryNodeSettings);
}
