#include "stages/stationarity/node/stationarity_node.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

#include "runtime/channels.hpp"
#include "stages/formats/conversions.hpp"

namespace fusecal {

std::string StationarityNodeSettings::Validate() const {
  if (raw_queue_depth < 1 || raw_queue_depth > 1000) return "raw_queue_depth: must be in [1, 1000]";
  if (!(std::isfinite(max_image_rate_hz) && max_image_rate_hz >= 0)) return "max_image_rate_hz: must not be negative";
  return detector.Validate();
}

StationarityNodeSettings ReadStationarityNodeSettings(ConfigReader r) {
  StationarityNodeSettings s;
  auto& d = s.detector;
  r.Get("min_still_s", &d.min_still_s);
  r.Get("merge_scans", &d.merge_scans);
  r.Get("accumulate_s", &d.accumulate_s);
  r.Get("max_station_points", &d.max_station_points);
  r.Get("max_pair_dt_s", &d.max_pair_dt_s);
  r.Get("still_flow_px", &d.image.still_flow_px);
  r.Get("still_change_m", &d.lidar.still_change_m);
  r.Get("raw_queue_depth", &s.raw_queue_depth);
  r.Get("max_image_rate_hz", &s.max_image_rate_hz);
  r.Finish();
  r.FailIfInvalid(s.Validate(), {{"still_flow_px", "image.still_flow_px"}, {"still_change_m", "lidar.still_change_m"}});
  return s;
}

void StationarityNode::Start(Bus& bus) {
  bus_ = &bus;
  for (const std::string& camera : cameras_) {
    subscriptions_.push_back(
        bus.Subscribe(ForCamera(channels::kCameraInfo, camera), [this, camera](const camera_info_t& c) {
          camera_infos_[camera] = c;
          camera_infos_[camera].name = camera;
        }));
    if (camera == cameras_.front()) continue;
    subscriptions_.push_back(bus.SubscribeRaw(ForCamera(channels::kCameraImage, camera).name,
                                              [this, camera](const RawMessage& raw) { KeepOtherImage(camera, raw); }));
  }
  subscriptions_.push_back(bus.SubscribeRaw(ForCamera(channels::kCameraImage, cameras_.front()).name,
                                            [this](const RawMessage& raw) { Queue(true, raw); }));
  subscriptions_.push_back(
      bus.SubscribeRaw(channels::kLidarScan.name, [this](const RawMessage& raw) { Queue(false, raw); }));
}

// Latest wins per stream: a full stream drops its oldest queued frame.
void StationarityNode::Queue(bool image, const RawMessage& raw) {
  ++frames_received_;
  if (image && min_image_interval_us_ > 0) {
    const int64_t utime = PeekUtime(raw.data, raw.size);
    // (A clock that went back starts over rather than stalling the camera.)
    if (last_image_utime_ >= 0 && utime >= last_image_utime_ &&
        utime - last_image_utime_ < min_image_interval_us_ - 1000) {
      ++images_decimated_;
      return;
    }
    last_image_utime_ = utime;
  }
  int& queued = image ? queued_images_ : queued_scans_;
  if (queued >= raw_queue_depth_) {
    for (auto it = queue_.begin(); it != queue_.end(); ++it) {
      if (it->image != image) continue;
      queue_.erase(it);
      --queued;
      ++(image ? images_skipped_ : scans_skipped_);
      work_.AddSkipped();
      break;
    }
  }
  queue_.push_back({image, std::vector<uint8_t>(raw.data, raw.data + raw.size)});
  ++queued;
}

void StationarityNode::Tick(Bus& bus, int64_t) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(kMaxTickMs);
  while (!queue_.empty() && std::chrono::steady_clock::now() < end) {
    QueuedFrame frame = std::move(queue_.front());
    queue_.pop_front();
    --(frame.image ? queued_images_ : queued_scans_);
    WorkStats::Timer timer(&work_);
    WorkStats::Timer per_stream(frame.image ? &image_work_ : &scan_work_);
    // A bad frame throws: reported by the stage's main loop, the frames after it are taken next time.
    frame.image ? TakeImage(bus, frame.bytes) : TakeScan(bus, frame.bytes);
  }
}

// The motion is measured on a quick reduced grey decode; the full image is decoded only for a station.
void StationarityNode::TakeImage(Bus& bus, const std::vector<uint8_t>& bytes) {
  auto msg = std::make_shared<image_t>();
  DecodeMessage(bytes.data(), bytes.size(), ForCamera(channels::kCameraImage, cameras_.front()).name, msg.get());
  if (!msg->frame_id.empty()) image_frame_id_ = msg->frame_id;
  const cv::Mat motion_image = ImageToMatReduced(*msg, detector_.settings().image.working_width_px);
  StationarityDetector::StationImage station_image;
  if (msg->encoding == "jpeg")
    station_image = [msg] { return ImageToMat(*msg); };
  else
    station_image = [motion_image] { return motion_image; };  // already a private full-size copy
  for (const auto& s : detector_.AddImage(msg->utime, motion_image, station_image)) Emit(bus, s);
}

void StationarityNode::TakeScan(Bus& bus, const std::vector<uint8_t>& bytes) {
  point_cloud_t msg;
  DecodeMessage(bytes.data(), bytes.size(), channels::kLidarScan.name, &msg);
  if (!msg.frame_id.empty()) scan_frame_id_ = msg.frame_id;
  for (const auto& s : detector_.AddScan(msg.utime, CloudFromMsg(msg))) Emit(bus, s);
}

void StationarityNode::Emit(Bus& bus, const DetectedStation& s) {
  std::string missing;
  for (const std::string& camera : cameras_)
    if (!camera_infos_.count(camera))
      missing += std::string(missing.empty() ? "" : ", ") + ForCamera(channels::kCameraInfo, camera).name;
  if (!missing.empty()) {
    ++without_camera_info_;
    throw std::runtime_error("station " + std::to_string(s.id) + " dropped: no " + missing + " received yet");
  }
  std::string problems;
  station_t msg{};
  msg.id = s.id;
  msg.still_from_utime = s.still_from;
  msg.still_to_utime = s.still_to;
  msg.cloud = CloudToMsg(s.cloud, s.scan_utime, scan_frame_id_);
  for (const std::string& camera : cameras_) {
    msg.camera = camera_infos_.at(camera);
    if (camera == cameras_.front()) {
      msg.utime = s.utime;
      msg.image = MatToImage(s.image, s.image.channels() == 1 ? "mono8" : "bgr8", s.image_utime, image_frame_id_);
      PublishStation(bus, camera, msg);
      continue;
    }
    waiting_[camera].push_back({msg, s.image_utime});
    if (const std::string p = PublishWaiting(bus, camera); !p.empty())
      problems += std::string(problems.empty() ? "" : "; ") + p;
  }
  ++stations_;
  if (!problems.empty()) throw std::runtime_error(problems);
}

void StationarityNode::PublishStation(Bus& bus, const std::string& camera, const station_t& station) {
  bus.Publish(ForCamera(channels::kStation, camera), station);
}

void StationarityNode::KeepOtherImage(const std::string& camera, const RawMessage& raw) {
  ++frames_received_;
  auto& images = other_images_[camera];
  const int64_t utime = PeekUtime(raw.data, raw.size);
  images.push_back({utime, std::vector<uint8_t>(raw.data, raw.data + raw.size)});
  while (!images.empty() && images.front().utime < utime - static_cast<int64_t>(kKeepOtherImages_s * 1e6))
    images.pop_front();
  if (waiting_[camera].empty()) return;
  if (const std::string problem = PublishWaiting(*bus_, camera); !problem.empty()) throw std::runtime_error(problem);
}

bool StationarityNode::FillImage(const std::string& camera, int64_t image_utime, station_t* station) {
  const OtherImage* best = nullptr;
  for (const auto& image : other_images_[camera]) {
    if (image.utime < station->still_from_utime || image.utime > station->still_to_utime) continue;
    if (!best || std::llabs(image.utime - image_utime) < std::llabs(best->utime - image_utime)) best = &image;
  }
  if (!best) return false;
  DecodeMessage(best->bytes.data(), best->bytes.size(), ForCamera(channels::kCameraImage, camera).name,
                &station->image);
  if (station->image.frame_id.empty()) station->image.frame_id = camera;
  // The image as the first camera's is passed on: decoded to raw pixels (JPEG decoded once, here).
  const cv::Mat mat = ImageToMat(station->image);
  station->image = MatToImage(mat, mat.channels() == 1 ? "mono8" : "bgr8", best->utime, station->image.frame_id);
  station->utime = std::max(best->utime, station->cloud.utime);
  return true;
}

// The waiting stations of `camera` whose image has come go out; those whose interval the camera's images
// have passed without one (or all of them, when flushing) are dropped, with the reason.
std::string StationarityNode::PublishWaiting(Bus& bus, const std::string& camera, bool flushing) {
  auto& waiting = waiting_[camera];
  const auto& images = other_images_[camera];
  const int64_t newest = images.empty() ? std::numeric_limits<int64_t>::min() : images.back().utime;
  std::string dropped;
  while (!waiting.empty()) {
    WaitingStation& w = waiting.front();
    if (FillImage(camera, w.image_utime, &w.station)) {
      PublishStation(bus, camera, w.station);
    } else if (flushing || newest > w.station.still_to_utime) {
      ++stations_without_image_;
      dropped += std::string(dropped.empty() ? "" : ", ") + std::to_string(w.station.id);
    } else {
      break;  // its image may still come
    }
    waiting.pop_front();
  }
  if (dropped.empty()) return "";
  return "camera " + camera + ": no image inside the still interval of station " + dropped + " (its STATION_" + camera +
         " is left out; the other cameras have theirs)";
}

void StationarityNode::Flush(Bus& bus) {
  while (!queue_.empty()) Tick(bus, NowUtime());
  if (auto s = detector_.Flush()) Emit(bus, *s);
  std::string problems;  // the input has ended: what waits for an image now has all it will get
  for (const std::string& camera : cameras_)
    if (const std::string p = PublishWaiting(bus, camera, true); !p.empty())
      problems += std::string(problems.empty() ? "" : "; ") + p;
  if (!problems.empty()) throw std::runtime_error(problems);
}

bool StationarityNode::WantsStatusNow() {
  if (!paced_ || FramesDone() < frames_reported_ + kPacedReportEvery) return false;
  frames_reported_ = FramesDone();
  return true;
}

StageStatus StationarityNode::Status() const {
  const StationarityState state = detector_.State();
  StageStatus s;
  s.state = std::string(ToString(state.phase)) + (state.reason.empty() ? "" : ": " + state.reason);
  const auto& c = state.counters;
  s.counters = {{"stations", stations_},
                {"image_flow_px", state.image_flow_px},
                {"lidar_change_m", state.lidar_change_m},
                {"still_for_s", state.still_for_s},
                {"images", double(c.images_received)},
                {"scans", double(c.scans_received)},
                {"images_skipped", double(images_skipped_)},
                {"scans_skipped", double(scans_skipped_)},
                {"images_decimated", double(images_decimated_)},
                {"images_without_texture", double(c.images_without_texture)},
                {"out_of_order", double(c.images_out_of_order + c.scans_out_of_order)},
                {"without_camera_info", without_camera_info_},
                {"stations_without_image", double(stations_without_image_)},
                {"frames_done", double(FramesDone())}};
  work_.AddTo(&s.counters);
  s.counters["image_ms_mean"] = image_work_.mean_ms();
  s.counters["scan_ms_mean"] = scan_work_.mean_ms();
  return s;
}

}  // namespace fusecal
