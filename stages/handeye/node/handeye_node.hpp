// fusecal-handeye: the bus adapter of the calibration loop (handeye/calibrator.hpp). CAMERA_MOTION,
// LIDAR_MOTION and FUSED_MOTIONS go into the Calibrator; each version it produces goes out as one EXTRINSIC
// (a REFINING one asks fusion odometry for the metric motions of the pairs it lists; docs/design.md,
// "The online alternation").
#pragma once

#include <optional>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/motion_set_t.hpp"
#include "fusecal/motion_t.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/stage_main.hpp"
#include "runtime/work_stats.hpp"
#include "stages/handeye/calibrator.hpp"

namespace fusecal {

// The `handeye` section of a pipeline config, and the camera the loop serves.
struct HandEyeNodeSettings {
  CalibratorSettings calibrator;
  std::string camera;  // its name on a rig of several (CAMERA_MOTION_<camera>, EXTRINSIC_<camera>, ...)
};
HandEyeNodeSettings ReadHandEyeNodeSettings(ConfigReader section);

// The Calibrator's view of a motion message, and its version as an EXTRINSIC message.
SensorMotion ToSensorMotion(const motion_t& motion);
extrinsic_t ToExtrinsicMessage(const CalibrationVersion& version);

class HandEyeNode : public StageNode {
 public:
  explicit HandEyeNode(HandEyeNodeSettings settings)
      : calibrator_(std::move(settings.calibrator)), camera_(std::move(settings.camera)) {}
  explicit HandEyeNode(CalibratorSettings settings) : calibrator_(std::move(settings)) {}
  void Start(Bus& bus) override;
  void Tick(Bus& bus, int64_t now_utime) override;
  StageStatus Status() const override;

  // The latest scaleless (initial) and current results, for tools that run the node in-process.
  const std::optional<HandEyeResult>& initial() const { return calibrator_.initial(); }
  const std::optional<HandEyeResult>& current() const { return calibrator_.current(); }
  bool converged() const { return calibrator_.converged(); }

 private:
  void PublishAll(Bus& bus, const std::vector<CalibrationVersion>& versions, double seconds);

  void Publish(Bus& bus, const CalibrationVersion& version);

  Calibrator calibrator_;
  std::string camera_;
  std::vector<Subscription> subscriptions_;
  WorkStats work_;
};

}  // namespace fusecal
