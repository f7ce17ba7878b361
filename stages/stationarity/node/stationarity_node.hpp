// fusecal-stationarity: turns the raw CAMERA_IMAGE and LIDAR_SCAN streams into STATION messages (one per
// stop of the rig). Its STATUS shows the phase (moving / settling / still) and the figures it decides on.
#pragma once

#include <optional>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/stage_main.hpp"
#include "stationarity/stationarity_detector.hpp"

namespace fusecal {

struct StationarityNodeSettings {
  StationaritySettings detector;
};

StationarityNodeSettings ReadStationarityNodeSettings(ConfigReader section);

class StationarityNode : public StageNode {
 public:
  explicit StationarityNode(const StationarityNodeSettings& settings) : detector_(settings.detector) {}
  void Start(Bus& bus) override;
  void Flush(Bus& bus) override;
  StageStatus Status() const override;

 private:
  void Emit(Bus& bus, const DetectedStation& station);

  StationarityDetector detector_;
  std::optional<camera_info_t> camera_;
  std::vector<Subscription> subscriptions_;
  int stations_ = 0, without_camera_info_ = 0;
  double busy_s_ = 0;
};

}  // namespace fusecal
