// The commands of fastdds_ros2_peer (fastdds_ros2_peer.cpp parses them). Each returns the exit code and
// throws std::runtime_error for what stops it before it could start.
#pragma once

#include <string>
#include <vector>

namespace fusecal::fastdds_peer {

struct PlayOptions {
  std::string log;
  int domain = 0;
  double speed = 1;  // 0: as fast as possible
  bool best_effort = false;
  bool compressed = false;
  bool livox = false;  // clouds as livox_ros_driver2/msg/CustomMsg, not PointCloud2
  std::string image_topic = "/camera/image_raw";
  std::string cloud_topic = "/lidar/points";
  std::string camera_info_topic = "/camera/camera_info";
  // A log of a rig of several cameras: each camera's CAMERA_IMAGE_<name> and CAMERA_INFO_<name> on
  // /<name>/image_raw and /<name>/camera_info (instead of image_topic and camera_info_topic).
  std::vector<std::string> rig_cameras;
  double wait_s = 20;
  double settle_s = 3;  // after every topic has a reader, before the first message
  double loop_s = 0;    // play the log forward and backward until the stream is this long (LoopedRecording)
};

// Publishes the log's CAMERA_INFO, CAMERA_IMAGE and LIDAR_SCAN as sensor_msgs topics (the scans as
// Livox's CustomMsg with `livox`) at the recorded pace, once every topic has a matched reader; prints {"published":
// {topic: n, ...}, "seconds": s, "passes": n, "start_unix_s": .., "first_utime": .., "end_unix_s": ..}
// (when the first sample with stamp first_utime left and when the last left, on the host's clock).
int Play(const PlayOptions& options);

// Prints each transform a late-joining reader of rt/tf_static receives, one JSON line each, until
// `count` transforms; 1 after `timeout_s` without them.
int TfListen(int domain, double timeout_s, int count);

// Publishes parent -> child (0.8 m along z) on rt/tf_static as tf2_ros's static broadcaster does and
// holds it for `seconds` (late joiners get it); prints {"published": {...}}.
int TfStatic(int domain, const std::string& parent, const std::string& child, double seconds);

// Counts the messages and serialized bytes on `topics` ("/name" or "/name:Type", Type one of Image,
// CompressedImage, PointCloud2, CameraInfo; without it, the type follows from the name) for `seconds`,
// or until `idle_s` after the last message; prints {"received": {topic: {"messages": n, "bytes": b}},
// "seconds": s}.
int Count(int domain, double seconds, double idle_s, bool best_effort, const std::vector<std::string>& topics);

}  // namespace fusecal::fastdds_peer
