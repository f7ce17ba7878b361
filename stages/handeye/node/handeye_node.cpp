#include "handeye/node/handeye_node.hpp"

#include <chrono>

#include "handeye/node/result_conversion.hpp"
#include "runtime/channels.hpp"
#include "runtime/conversions.hpp"

namespace fusecal {

namespace {

bool Observable(const HandEyeResult& r) { return r.observability == handeye_observability::kOk; }

double Seconds(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

HandEyeNodeSettings ReadHandEyeNodeSettings(ConfigReader r) {
  HandEyeNodeSettings s;
  r.Get("tolerance_rotation_deg", &s.tolerance_rotation_deg, Positive<double>());
  r.Get("tolerance_translation_m", &s.tolerance_translation_m, Positive<double>());
  r.Get("max_iterations", &s.max_iterations, InRange(1, 1000));
  r.Get("retry_s", &s.retry_s, NonNegative<double>());
  r.Get("scaled_refinement", &s.scaled_refinement);
  r.Get("max_angle_difference_deg", &s.solver.max_angle_difference_deg, Positive<double>());
  r.Get("min_rotation_deg", &s.solver.min_rotation_deg, NonNegative<double>());
  r.Get("min_pairs", &s.solver.min_pairs, InRange(2, 1000));
  r.Finish();
  const std::string error = s.solver.Validate();
  if (!error.empty()) r.FailSection(error);
  return s;
}

void HandEyeNode::Start(Bus& bus) {
  auto on_motion = std::function<void(const motion_t&)>([this, &bus](const motion_t& m) { OnMotion(bus, m); });
  subscriptions_.push_back(bus.Subscribe<motion_t>(channels::kCameraMotion, on_motion));
  subscriptions_.push_back(bus.Subscribe<motion_t>(channels::kLidarMotion, on_motion));
  subscriptions_.push_back(bus.Subscribe<motion_set_t>(
      channels::kFusedMotions,
      std::function<void(const motion_set_t&)>([this, &bus](const motion_set_t& s) { OnFusedMotions(bus, s); })));
}

void HandEyeNode::OnMotion(Bus& bus, const motion_t& motion) {
  const PairKey key{motion.station_i, motion.station_j};
  auto& store = motion.sensor == "camera" ? camera_motions_ : lidar_motions_;
  const bool known = store.count(key) > 0;
  store[key] = motion;
  if (known || !motion.valid) return;
  // A new usable pair completes a motion: start a new round of the alternation.
  const auto other = motion.sensor == "camera" ? lidar_motions_.find(key) : camera_motions_.find(key);
  const auto& others = motion.sensor == "camera" ? lidar_motions_ : camera_motions_;
  if (other != others.end() && other->second.valid) StartRound(bus);
}

std::vector<MotionPair> HandEyeNode::ScalelessPairs() const {
  std::vector<MotionPair> pairs;
  for (const auto& [key, camera] : camera_motions_) {
    const auto lidar = lidar_motions_.find(key);
    if (!camera.valid || lidar == lidar_motions_.end() || !lidar->second.valid) continue;
    MotionPair p;
    p.station_i = key.first;
    p.station_j = key.second;
    p.A = FromRowMajor(camera.T_i_j);
    p.B = FromRowMajor(lidar->second.T_i_j);
    p.camera_scaled = false;
    pairs.push_back(p);
  }
  return pairs;
}

void HandEyeNode::StartRound(Bus& bus) {
  const auto start = std::chrono::steady_clock::now();
  initial_ = SolveScaleless(ScalelessPairs(), settings_.solver, current_ ? &current_->T_camera_lidar : nullptr);
  busy_s_ += Seconds(start);
  iteration_ = 0;
  converged_ = false;
  // Online refinement resumes from the current scaled estimate when there is one.
  const HandEyeResult& start_point = (current_ && Observable(*initial_)) ? *current_ : *initial_;
  const bool usable = initial_->status != handeye_status::kFailed && Observable(*initial_);
  const bool ask = usable && settings_.scaled_refinement;
  std::string status = "initial";
  if (initial_->status == handeye_status::kFailed) status = "failed";
  else if (!Observable(*initial_)) status = "degenerate";
  else if (!settings_.scaled_refinement) status = initial_->converged ? "converged" : "initial";
  if (!current_ || !usable) current_ = *initial_;
  state_ = ask ? "refining" : "waiting for motions (" + status + ")";
  if (!settings_.scaled_refinement && status == "converged") converged_ = true;
  Publish(bus, start_point, status, 0.0, ask);
}

void HandEyeNode::OnFusedMotions(Bus& bus, const motion_set_t& set) {
  if (set.extrinsic_version != awaiting_version_) return;  // old or repeated answer
  const auto start = std::chrono::steady_clock::now();
  std::vector<MotionPair> pairs;
  for (const auto& m : set.motions) {
    const PairKey key{m.station_i, m.station_j};
    const auto lidar = lidar_motions_.find(key);
    if (!m.valid || !m.scaled || lidar == lidar_motions_.end() || !lidar->second.valid) continue;
    MotionPair p;
    p.station_i = key.first;
    p.station_j = key.second;
    p.A = FromRowMajor(m.T_i_j);
    p.B = FromRowMajor(lidar->second.T_i_j);
    p.camera_scaled = true;
    pairs.push_back(p);
  }
  HandEyeResult result = SolveScaled(pairs, settings_.solver, &current_->T_camera_lidar);
  busy_s_ += Seconds(start);
  if (result.status == handeye_status::kFailed) {
    // Keep what we had; say why and wait for more motions.
    awaiting_version_ = -1;
    state_ = "waiting for motions (scaled solve failed: " + result.message + ")";
    Publish(bus, *current_, "failed", 0.0, false);
    return;
  }
  const double change_rot = RotationErrorDeg(result.T_camera_lidar.linear(), current_->T_camera_lidar.linear());
  const double change_trans = (result.T_camera_lidar.translation() - current_->T_camera_lidar.translation()).norm();
  current_ = result;
  ++iteration_;
  const bool small = change_rot < settings_.tolerance_rotation_deg && change_trans < settings_.tolerance_translation_m;
  const bool done = small || iteration_ >= settings_.max_iterations;
  std::string status = "refining";
  if (done) status = Observable(result) && result.converged && small ? "converged" : (Observable(result) ? "not_converged" : "degenerate");
  converged_ = status == "converged";
  state_ = done ? status : "refining";
  Publish(bus, result, status, change_rot * M_PI / 180.0 + change_trans, !done);
}

void HandEyeNode::Publish(Bus& bus, const HandEyeResult& result, const std::string& status, double change,
                          bool ask) {
  extrinsic_t msg = ToExtrinsicMessage(result, ++version_, NowUtime());
  msg.status = status;
  msg.converged = status == "converged";
  msg.iteration = iteration_;
  msg.change = change;
  last_published_ = msg;
  last_sent_utime_ = NowUtime();
  awaiting_version_ = ask ? version_ : -1;
  bus.Publish(channels::kExtrinsic, msg);
}

void HandEyeNode::Tick(Bus& bus, int64_t now_utime) {
  if (awaiting_version_ < 0 || settings_.retry_s <= 0) return;
  if (now_utime - last_sent_utime_ < static_cast<int64_t>(settings_.retry_s * 1e6)) return;
  ++retries_;
  last_sent_utime_ = now_utime;
  bus.Publish(channels::kExtrinsic, last_published_);  // same version: answered from cache if seen
}

StageStatus HandEyeNode::Status() const {
  StageStatus s;
  s.state = state_;
  s.counters = {{"camera_motions", double(camera_motions_.size())},
                {"lidar_motions", double(lidar_motions_.size())},
                {"pairs", double(ScalelessPairs().size())},
                {"version", version_},
                {"iteration", iteration_},
                {"retries", retries_},
                {"busy_s", busy_s_}};
  return s;
}

}  // namespace fusecal
