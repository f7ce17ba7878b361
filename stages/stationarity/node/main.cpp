#include "stages/stationarity/node/stationarity_node.hpp"

int main(int argc, char** argv) {
  return fusecal::RunStage<fusecal::StationarityNode>(
      argc, argv, "stationarity", "fusecal-stationarity: stations from the camera and LiDAR streams",
      fusecal::ReadStationarityNodeSettings);
}
