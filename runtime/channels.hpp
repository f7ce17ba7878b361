// The channels of the pipeline (docs/design.md section 3): name, message type and how a transport carries
// each. One place, so that nodes, tools, tests and every bus agree.
//
//   bulk   raw sensor frames (CAMERA_IMAGE, LIDAR_SCAN): only the newest matter, and the stationarity
//          stage copes with a missing one; a transport may drop them under load or loss (DDS: best
//          effort, keep last `bulk_depth`).
//   state  everything the answer depends on (STATION, motions, EXTRINSIC, FUSED_MOTIONS, CAMERA_INFO,
//          ...): every message, in order (DDS: reliable, deep enough for a round; STATION keep all).
// A channel this table does not name (a user's own) is state.
//
// A rig of several cameras: each camera has its own image, camera info, station, camera motion, fused
// motion and extrinsic channel, the pipeline's name with _<camera> appended (CAMERA_IMAGE_front, STATION_front,
// EXTRINSIC_front, ...); LIDAR_SCAN, LIDAR_MOTION, STATUS and GROUND_TRUTH are the rig's. The one camera of a
// one-camera rig has no name and the plain channels.
#pragma once

#include <mutex>
#include <set>
#include <string>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/extrinsic_t.hpp"
#include "fusecal/ground_truth_t.hpp"
#include "fusecal/image_t.hpp"
#include "fusecal/motion_set_t.hpp"
#include "fusecal/motion_t.hpp"
#include "fusecal/point_cloud_t.hpp"
#include "fusecal/station_t.hpp"
#include "fusecal/status_t.hpp"

namespace fusecal {

enum class ChannelKind { kBulk, kState };

// A channel and the LCM type it carries: Bus::Publish and Bus::Subscribe check the type at compile time.
// `large`: messages of megabytes (shared-memory transports size their queues for them).
template <typename M>
struct Channel {
  using Message = M;
  const char* name;
  ChannelKind kind;
  bool large;
};

// The channels: the one spelling for publishing, subscribing and naming (`channels::kStation.name`).
namespace channels {
inline constexpr Channel<image_t> kCameraImage{"CAMERA_IMAGE", ChannelKind::kBulk, true};
inline constexpr Channel<point_cloud_t> kLidarScan{"LIDAR_SCAN", ChannelKind::kBulk, true};
inline constexpr Channel<camera_info_t> kCameraInfo{"CAMERA_INFO", ChannelKind::kState, false};
inline constexpr Channel<station_t> kStation{"STATION", ChannelKind::kState, true};
inline constexpr Channel<motion_t> kLidarMotion{"LIDAR_MOTION", ChannelKind::kState, false};        // sensor "lidar"
inline constexpr Channel<motion_t> kCameraMotion{"CAMERA_MOTION", ChannelKind::kState, false};      // scaleless
inline constexpr Channel<motion_set_t> kFusedMotions{"FUSED_MOTIONS", ChannelKind::kState, false};  // metric
inline constexpr Channel<extrinsic_t> kExtrinsic{"EXTRINSIC", ChannelKind::kState, false};
inline constexpr Channel<status_t> kStatus{"STATUS", ChannelKind::kState, false};  // 1 Hz heartbeat
inline constexpr Channel<ground_truth_t> kGroundTruth{"GROUND_TRUTH", ChannelKind::kState, false};
}  // namespace channels

// How a bus carries the channel called `name`: its kind and whether its messages are large. What every
// bus asks, instead of keeping its own list of names.
struct ChannelTraits {
  const char* name = "";
  ChannelKind kind = ChannelKind::kState;
  bool large = false;
};

template <typename M>
constexpr ChannelTraits TraitsOf(const Channel<M>& channel) {
  return ChannelTraits{channel.name, channel.kind, channel.large};
}

// Every channel of the pipeline.
inline constexpr ChannelTraits kPipelineChannels[] = {
    TraitsOf(channels::kCameraImage),  TraitsOf(channels::kLidarScan),   TraitsOf(channels::kCameraInfo),
    TraitsOf(channels::kStation),      TraitsOf(channels::kLidarMotion), TraitsOf(channels::kCameraMotion),
    TraitsOf(channels::kFusedMotions), TraitsOf(channels::kExtrinsic),   TraitsOf(channels::kStatus),
    TraitsOf(channels::kGroundTruth)};

// The channels each camera of a rig has its own of.
inline constexpr const char* kPerCameraChannels[] = {channels::kCameraImage.name,  channels::kCameraInfo.name,
                                                     channels::kStation.name,      channels::kCameraMotion.name,
                                                     channels::kFusedMotions.name, channels::kExtrinsic.name};

// `channel` of the camera `camera`: channel_camera, or channel itself for the unnamed camera.
inline std::string CameraChannelName(const std::string& channel, const std::string& camera) {
  return camera.empty() ? channel : channel + "_" + camera;
}

// The same channel of the camera `camera`. Channel names are kept for the life of the process (a rig has
// a handful of cameras).
template <typename M>
Channel<M> ForCamera(const Channel<M>& channel, const std::string& camera) {
  if (camera.empty()) return channel;
  static std::mutex mutex;
  static std::set<std::string> names;  // nodes of a set never move: their c_str() stays valid
  std::lock_guard<std::mutex> lock(mutex);
  const std::string& name = *names.insert(CameraChannelName(channel.name, camera)).first;
  return Channel<M>{name.c_str(), channel.kind, channel.large};
}

// The pipeline channel that `name` is a camera's own of (STATION for STATION_front), or nullptr.
inline const char* PerCameraChannelOf(const std::string& name) {
  for (const char* per_camera : kPerCameraChannels) {
    const size_t length = std::char_traits<char>::length(per_camera);
    if (name.size() > length + 1 && name.compare(0, length, per_camera) == 0 && name[length] == '_') return per_camera;
  }
  return nullptr;
}

// The pipeline channel called `name`, or nullptr; a camera's own channel (STATION_front) is its
// pipeline channel's (STATION).
inline const ChannelTraits* FindPipelineChannel(const std::string& name) {
  const char* per_camera = PerCameraChannelOf(name);
  const std::string pipeline_name = per_camera ? per_camera : name;
  for (const auto& channel : kPipelineChannels)
    if (pipeline_name == channel.name) return &channel;
  return nullptr;
}

// The traits of a pipeline channel; a name the pipeline does not use (a user's own) is state, small.
inline ChannelTraits TraitsOfChannel(const std::string& name) {
  const ChannelTraits* channel = FindPipelineChannel(name);
  return channel ? *channel : ChannelTraits{};
}

inline bool IsPipelineChannel(const std::string& name) { return FindPipelineChannel(name) != nullptr; }

// The camera whose own channel `name` is ("front" for STATION_front); "" for any other channel.
inline std::string CameraOfChannel(const std::string& name) {
  const char* per_camera = PerCameraChannelOf(name);
  return per_camera ? name.substr(std::char_traits<char>::length(per_camera) + 1) : "";
}

// The pipeline channel a channel is, whichever camera's: "STATION" for STATION and STATION_front; "" for a
// channel the pipeline does not use.
inline std::string PipelineChannelOf(const std::string& name) {
  const ChannelTraits* channel = FindPipelineChannel(name);
  return channel ? channel->name : "";
}

}  // namespace fusecal
