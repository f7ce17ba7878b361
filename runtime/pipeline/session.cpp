#include "runtime/pipeline/session.hpp"

#include "runtime/pipeline/outputs.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "fusecal/motion_set_t.hpp"
#include "fusecal/motion_t.hpp"
#include "fusecal/status_t.hpp"
#include "runtime/channels.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/extrinsic_status.hpp"
#include "stages/formats/result_file.hpp"
#include "stages/foundation/observed_covariance.hpp"

namespace fusecal {

template <typename M>
static bool Decode(const RawMessage& raw, M* message) {
  return message->decode(raw.data, 0, static_cast<int>(raw.size)) >= 0;
}

SessionRecord::SessionRecord(Bus& bus, const std::string& dir, const RecordSettings& record, const std::string& camera)
    : camera_(camera) {
  if (record.what != "none") log_ = std::make_unique<SessionLog>(dir, record);
  const std::string station = ForCamera(channels::kStation, camera).name;
  const std::string extrinsic = ForCamera(channels::kExtrinsic, camera).name;
  const std::string camera_motion = ForCamera(channels::kCameraMotion, camera).name;
  subscriptions_.push_back(bus.SubscribeRaw(".*", [=](const RawMessage& raw) {
    const std::string& ch = raw.channel;
    if (PipelineChannelOf(ch) == channels::kCameraInfo.name) camera_infos_[ch].assign(raw.data, raw.data + raw.size);
    if (log_) log_->Write(ch, raw.receive_utime, raw.data, raw.size, camera_infos_);
    if (ch == station) {
      OnStation(raw);
    } else if (ch == extrinsic) {
      OnExtrinsic(raw);
    } else if (ch == channels::kGroundTruth.name) {
      ground_truth_t g{};
      if (Decode(raw, &g) && g.camera.name == camera_) ground_truth_ = g;
    } else if (ch == channels::kLidarMotion.name || ch == camera_motion) {
      OnMotion(raw);
    } else if (ch == channels::kStatus.name) {
      status_t s{};
      if (!Decode(raw, &s) || s.name == kPlayerName) return;
      stage_states_[s.name] = {s.state, s.last_error};
      auto& counters = stage_counters_[s.name];
      for (int i = 0; i < s.num_counters; ++i) counters[s.counter_names[i]] = s.counter_values[i];
    }
  }));
}

void SessionRecord::OnStation(const RawMessage& raw) {
  last_news_utime_ = raw.receive_utime;
  station_t s{};
  if (!Decode(raw, &s)) return;
  stations_[s.id] = {s.utime, s.still_from_utime, s.still_to_utime};
  retention_.OnStation(s.id);
  kept_stations_[s.id] = std::move(s);
  retention_.Evict(&kept_stations_);
}

void SessionRecord::OnExtrinsic(const RawMessage& raw) {
  last_news_utime_ = raw.receive_utime;
  extrinsic_t e{};
  if (!Decode(raw, &e) || (!extrinsics_.empty() && e.version <= extrinsics_.back().version)) return;
  retention_.OnExtrinsic(e);
  retention_.Evict(&kept_stations_);
  taken_motions_to_.insert(e.used_station_j.begin(), e.used_station_j.end());
  taken_motions_to_.insert(e.rejected_station_j.begin(), e.rejected_station_j.end());
  extrinsics_.push_back(std::move(e));
  extrinsic_receive_utimes_.push_back(raw.receive_utime);
}

void SessionRecord::OnMotion(const RawMessage& raw) {
  motion_t m{};
  if (!Decode(raw, &m)) return;
  if (!m.valid) {
    ++failed_motions_;
    const std::string reason = raw.channel + ": " + m.failure_reason.substr(0, 200);
    if (failure_reasons_.count(reason) || failure_reasons_.size() < kMaxFailureReasons) ++failure_reasons_[reason];
  } else if (raw.channel == channels::kLidarMotion.name) {
    ++lidar_motions_;
  } else {
    ++camera_motions_;
  }
  last_news_utime_ = raw.receive_utime;
}

SessionRecord::~SessionRecord() {
  for (auto& s : subscriptions_) s.Unsubscribe();
}

void SessionRecord::Close() {
  if (log_) log_->Close();
}

const extrinsic_t* SessionRecord::Final() const { return extrinsics_.empty() ? nullptr : &extrinsics_.back(); }

const extrinsic_t* SessionRecord::Initial() const {
  for (auto it = extrinsics_.rbegin(); it != extrinsics_.rend(); ++it)
    if (!it->scaled && it->status != extrinsic_t::STATUS_FAILED) return &*it;
  return nullptr;
}

std::vector<std::unique_ptr<SessionRecord>> MakeSessionRecords(Bus& bus, const std::string& dir,
                                                               const RecordSettings& record,
                                                               const std::vector<std::string>& cameras) {
  std::vector<std::unique_ptr<SessionRecord>> records;
  for (const auto& camera : cameras)
    records.push_back(
        std::make_unique<SessionRecord>(bus, dir, records.empty() ? record : RecordSettings{"none"}, camera));
  return records;
}

bool LogHasStations(const std::string& log_path) {
  LogReader reader(log_path);
  for (int i = 0; i < 500; ++i) {
    auto event = reader.Next();
    if (!event) return false;
    if (PipelineChannelOf(event->channel) == channels::kStation.name) return true;
  }
  return false;
}

std::vector<std::string> CamerasInLog(const std::string& log_path) {
  std::vector<std::string> cameras;
  LogReader reader(log_path);
  for (int i = 0; i < 5000; ++i) {
    auto event = reader.Next();
    if (!event) break;
    const std::string base = PipelineChannelOf(event->channel);
    if (base != channels::kCameraImage.name && base != channels::kStation.name) continue;
    const std::string camera = CameraOfChannel(event->channel);
    if (!camera.empty() && std::find(cameras.begin(), cameras.end(), camera) == cameras.end())
      cameras.push_back(camera);
  }
  return cameras;
}

bool FeedsPipeline(const std::string& channel, bool use_detector) {
  const std::string ch = PipelineChannelOf(channel);  // any camera's
  if (ch == channels::kGroundTruth.name) return true;
  if (ch == channels::kStation.name) return !use_detector;
  const bool raw =
      ch == channels::kCameraImage.name || ch == channels::kLidarScan.name || ch == channels::kCameraInfo.name;
  return raw && use_detector;
}

std::string ProgressText(const SessionRecord& session) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3);
  out << "stations " << session.stations().size() << ", motions lidar " << session.lidar_motions() << " camera "
      << session.camera_motions() << " failed " << session.failed_motions();
  if (const extrinsic_t* e = session.Final()) {
    const Isometry3 T = FromRowMajor(e->T_camera_lidar);
    const Matrix6 cov = Matrix6FromArray(e->covariance);
    const Eigen::Vector3d d(e->unobservable_direction[0], e->unobservable_direction[1], e->unobservable_direction[2]);
    // With an unobservable direction: the std of what the motions observe (the direction projected out).
    const ObservedUncertainty observed = ObservedPart(cov, T.linear(), d);
    const Eigen::Vector3d t = T.translation(), st = observed.translation_std_m, sr = observed.rotation_std_deg;
    const Eigen::Vector3d rpy = RpyFromRotation(T.linear()) * 180.0 / M_PI;
    out << " | v" << e->version << " it" << e->iteration << " " << ExtrinsicStatusName(e->status) << " ("
        << ObservabilityName(e->observability) << ")"
        << " t=[" << t.x() << " " << t.y() << " " << t.z() << "]+-" << std::setprecision(4) << st.maxCoeff()
        << " m rpy=[" << std::setprecision(2) << rpy.x() << " " << rpy.y() << " " << rpy.z() << "]+-"
        << std::setprecision(4) << sr.maxCoeff() << " deg";
    if (d.norm() > 0.5)
      out << " (observed part; unobservable: [" << std::setprecision(2) << d.x() << " " << d.y() << " " << d.z()
          << "])";
    const std::vector<ExtrinsicChangeRecord> changes = ChangeRecords(*e);
    if (!changes.empty()) {
      const ExtrinsicChangeRecord& c = changes.back();
      out << " | CHANGED after station " << c.after_station << " (decided at " << c.decided_at_station << "): ";
      if (std::isnan(c.rotation_deg))
        out << "size not known until the motions after it are solved";
      else
        out << std::setprecision(3) << c.rotation_deg << "+-" << c.rotation_std_deg << " deg, " << c.translation_m
            << "+-" << c.translation_std_m << " m";
    }
  }
  return out.str();
}

}  // namespace fusecal
