#include "stages/handeye/node/handeye_node.hpp"

#include <chrono>

#include "runtime/channels.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/handeye/node/result_conversion.hpp"

namespace fusecal {

namespace {

static_assert(static_cast<int8_t>(VersionStatus::kInitial) == extrinsic_t::STATUS_INITIAL &&
              static_cast<int8_t>(VersionStatus::kRefining) == extrinsic_t::STATUS_REFINING &&
              static_cast<int8_t>(VersionStatus::kConverged) == extrinsic_t::STATUS_CONVERGED &&
              static_cast<int8_t>(VersionStatus::kNotConverged) == extrinsic_t::STATUS_NOT_CONVERGED &&
              static_cast<int8_t>(VersionStatus::kDegenerate) == extrinsic_t::STATUS_DEGENERATE &&
              static_cast<int8_t>(VersionStatus::kFailed) == extrinsic_t::STATUS_FAILED);

void ReadSharedErrors(ConfigReader r, SharedErrors* e) {
  r.Get("rotation_per_rotation", &e->rotation_per_rotation, NonNegative<double>());
  r.Get("translation_per_translation", &e->translation_per_translation, NonNegative<double>());
  r.Get("translation_per_rotation_m", &e->translation_per_rotation_m, NonNegative<double>());
  r.Get("translation_scale", &e->translation_scale, NonNegative<double>());
  r.Finish();
}

void SetPairs(const std::vector<StationPair>& pairs, int32_t* count, std::vector<int32_t>* i, std::vector<int32_t>* j) {
  i->clear();
  j->clear();
  for (const auto& [a, b] : pairs) {
    i->push_back(a);
    j->push_back(b);
  }
  *count = static_cast<int32_t>(i->size());
}

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

HandEyeNodeSettings ReadHandEyeNodeSettings(ConfigReader r) {
  HandEyeNodeSettings node;
  CalibratorSettings& s = node.calibrator;
  r.Get("tolerance_rotation_deg", &s.tolerance_rotation_deg);
  r.Get("tolerance_translation_m", &s.tolerance_translation_m);
  r.Get("tolerance_std_fraction", &s.tolerance_std_fraction);
  r.Get("max_iterations", &s.max_iterations);
  r.Get("retry_s", &s.retry_s);
  r.Get("scaled_refinement", &s.scaled_refinement);
  r.Get("max_motions", &s.max_motions);
  r.Get("max_angle_difference_deg", &s.solver.max_angle_difference_deg);
  r.Get("min_rotation_deg", &s.solver.min_rotation_deg);
  r.Get("min_pairs", &s.solver.min_pairs);
  ConfigReader change = r.Child("change_detection");
  change.Get("enabled", &s.change_detection.enabled);
  change.Get("off_probability", &s.change_detection.off_probability);
  change.Get("confirm_probability", &s.change_detection.confirm_probability);
  change.Get("directed_confirm_probability", &s.change_detection.directed_confirm_probability);
  change.Get("window", &s.change_detection.window);
  change.Get("noise_floor_fraction", &s.change_detection.noise_floor_fraction);
  change.Get("test_direction", &s.change_detection.test_direction);
  change.Get("min_direction_length", &s.change_detection.min_direction_length);
  change.Get("split_min_noise_dof", &s.change_detection.split_min_noise_dof);
  change.Finish();
  ConfigReader shared = r.Child("shared_errors");
  ReadSharedErrors(shared.Child("camera"), &s.solver.shared_camera_errors);
  ReadSharedErrors(shared.Child("lidar"), &s.solver.shared_lidar_errors);
  shared.Finish();
  r.Finish();
  r.FailIfInvalid(s.Validate(), {{"max_angle_difference_deg", "solver.max_angle_difference_deg"},
                                 {"min_rotation_deg", "solver.min_rotation_deg"},
                                 {"min_pairs", "solver.min_pairs"}});
  return node;
}

SensorMotion ToSensorMotion(const motion_t& m) {
  SensorMotion s;
  s.sensor = m.sensor == "camera" ? SensorMotion::Sensor::kCamera : SensorMotion::Sensor::kLidar;
  s.station_i = m.station_i;
  s.station_j = m.station_j;
  s.valid = m.valid;
  s.scaled = m.scaled;
  s.T_i_j = FromRowMajor(m.T_i_j);
  s.failure_reason = m.failure_reason;
  return s;
}

extrinsic_t ToExtrinsicMessage(const CalibrationVersion& v) {
  extrinsic_t msg = ToExtrinsicMessage(v.result, v.version, v.utime);
  SetPairs(v.used, &msg.num_used, &msg.used_station_i, &msg.used_station_j);
  SetPairs(v.not_used, &msg.num_rejected, &msg.rejected_station_i, &msg.rejected_station_j);
  msg.status = static_cast<int8_t>(v.status);
  msg.converged = v.converged();
  msg.iteration = v.iteration;
  msg.change_rotation_rad = v.change_rotation_rad;
  msg.change_translation_m = v.change_translation_m;
  for (const ExtrinsicChange& c : v.changes) {
    msg.change_after_station.push_back(c.after_station);
    msg.change_decided_at_station.push_back(c.decided_at_station);
    std::vector<double> T(16), C(36);
    ToRowMajor(c.T_before, T.data());
    Matrix6ToArray(c.covariance_before, C.data());
    msg.change_T_before.push_back(T);
    msg.change_covariance_before.push_back(C);
  }
  msg.num_changes = static_cast<int32_t>(v.changes.size());
  return msg;
}

void HandEyeNode::Start(Bus& bus) {
  const auto on_motion = [this, &bus](const motion_t& m) {
    const auto start = std::chrono::steady_clock::now();
    const std::vector<CalibrationVersion> versions = calibrator_.OnMotion(ToSensorMotion(m), NowUtime());
    PublishAll(bus, versions, Seconds(start));
  };
  subscriptions_.push_back(bus.Subscribe(ForCamera(channels::kCameraMotion, camera_), on_motion));
  subscriptions_.push_back(bus.Subscribe(channels::kLidarMotion, on_motion));
  subscriptions_.push_back(
      bus.Subscribe(ForCamera(channels::kFusedMotions, camera_), [this, &bus](const motion_set_t& set) {
        const auto start = std::chrono::steady_clock::now();
        std::vector<SensorMotion> motions;
        for (const auto& m : set.motions) motions.push_back(ToSensorMotion(m));
        const std::vector<CalibrationVersion> versions =
            calibrator_.OnFusedMotions(set.extrinsic_version, motions, NowUtime());
        PublishAll(bus, versions, Seconds(start));
      }));
}

void HandEyeNode::PublishAll(Bus& bus, const std::vector<CalibrationVersion>& versions, double seconds) {
  if (versions.empty()) return;
  work_.Add(seconds);  // a solve
  for (const auto& v : versions) Publish(bus, v);
}

void HandEyeNode::Publish(Bus& bus, const CalibrationVersion& version) {
  extrinsic_t msg = ToExtrinsicMessage(version);
  msg.camera = camera_;
  bus.Publish(ForCamera(channels::kExtrinsic, camera_), msg);
}

void HandEyeNode::Tick(Bus& bus, int64_t now_utime) {
  if (const auto repeat = calibrator_.Tick(now_utime)) Publish(bus, *repeat);
}

StageStatus HandEyeNode::Status() const {
  StageStatus s;
  s.state = calibrator_.state();
  s.counters = {{"camera_motions", double(calibrator_.camera_motions())},
                {"lidar_motions", double(calibrator_.lidar_motions())},
                {"pairs", double(calibrator_.pairs())},
                {"version", calibrator_.version()},
                {"iteration", calibrator_.iteration()},
                {"retries", calibrator_.retries()},
                {"dropped_motions", double(calibrator_.dropped_pairs())}};
  work_.AddTo(&s.counters);  // items: solves
  return s;
}

}  // namespace fusecal
