// The channels of the pipeline (docs/design.md section 3): name, message type and how a transport carries
// each. One place, so that nodes, tools, tests and every bus agree.
//
//   bulk   raw sensor frames (CAMERA_IMAGE, LIDAR_SCAN): only the newest matter, and the stationarity
//          stage copes with a missing one; a transport may drop them under load or loss (DDS: best
//          effort, keep last `bulk_depth`).
//   state  everything the answer depends on (STATION, motions, EXTRINSIC, FUSED_MOTIONS, CAMERA_INFO,
//          ...): every message, in order (DDS: reliable, deep enough for a round; STATION keep all).
// A channel this table does not name (a user's own) is state.
#pragma once

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

// The pipeline channel called `name`, or nullptr.
inline const ChannelTraits* FindPipelineChannel(const std::string& name) {
  for (const auto& channel : kPipelineChannels)
    if (name == channel.name) return &channel;
  return nullptr;
}

// The traits of a pipeline channel; a name the pipeline does not use (a user's own) is state, small.
inline ChannelTraits TraitsOfChannel(const std::string& name) {
  const ChannelTraits* channel = FindPipelineChannel(name);
  return channel ? *channel : ChannelTraits{};
}

inline bool IsPipelineChannel(const std::string& name) { return FindPipelineChannel(name) != nullptr; }

}  // namespace fusecal
