#include "stationarity/node/stationarity_node.hpp"

#include <chrono>

#include "runtime/channels.hpp"
#include "formats/conversions.hpp"

namespace fusecal {

StationarityNodeSettings ReadStationarityNodeSettings(ConfigReader r) {
  StationarityNodeSettings s;
  auto& d = s.detector;
  r.Get("min_still_s", &d.min_still_s, Positive<double>());
  r.Get("merge_scans", &d.merge_scans, InRange(1, 20));
  r.Get("max_pair_dt_s", &d.max_pair_dt_s, Positive<double>());
  r.Get("still_flow_px", &d.image.still_flow_px, Positive<double>());
  r.Get("still_change_m", &d.lidar.still_change_m, Positive<double>());
  r.Finish();
  const std::string error = d.Validate();
  if (!error.empty()) r.FailSection(error);
  return s;
}

void StationarityNode::Start(Bus& bus) {
  subscriptions_.push_back(bus.Subscribe<camera_info_t>(
      channels::kCameraInfo, std::function<void(const camera_info_t&)>([this](const camera_info_t& c) { camera_ = c; })));
  subscriptions_.push_back(bus.Subscribe<image_t>(
      channels::kCameraImage, std::function<void(const image_t&)>([this, &bus](const image_t& msg) {
        const auto start = std::chrono::steady_clock::now();
        const cv::Mat image = ImageToMat(msg);  // a bad encoding throws: reported, the node goes on
        for (const auto& s : detector_.AddImage(msg.utime, image)) Emit(bus, s);
        busy_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      })));
  subscriptions_.push_back(bus.Subscribe<point_cloud_t>(
      channels::kLidarScan, std::function<void(const point_cloud_t&)>([this, &bus](const point_cloud_t& msg) {
        const auto start = std::chrono::steady_clock::now();
        for (const auto& s : detector_.AddScan(msg.utime, CloudFromMsg(msg))) Emit(bus, s);
        busy_s_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      })));
}

void StationarityNode::Emit(Bus& bus, const DetectedStation& s) {
  if (!camera_) {
    ++without_camera_info_;
    throw std::runtime_error("station " + std::to_string(s.id) + " dropped: no CAMERA_INFO received yet");
  }
  station_t msg{};
  msg.utime = s.utime;
  msg.id = s.id;
  msg.still_from_utime = s.still_from;
  msg.still_to_utime = s.still_to;
  msg.image = MatToImage(s.image, s.image.channels() == 1 ? "mono8" : "bgr8", s.image_utime);
  msg.cloud = CloudToMsg(s.cloud, s.scan_utime);
  msg.camera = *camera_;
  bus.Publish(channels::kStation, msg);
  ++stations_;
}

void StationarityNode::Flush(Bus& bus) {
  if (auto s = detector_.Flush()) Emit(bus, *s);
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
                {"images_without_texture", double(c.images_without_texture)},
                {"out_of_order", double(c.images_out_of_order + c.scans_out_of_order)},
                {"without_camera_info", without_camera_info_},
                {"busy_s", busy_s_}};
  return s;
}

}  // namespace fusecal
