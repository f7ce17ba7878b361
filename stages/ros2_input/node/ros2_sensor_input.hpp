// The core of fusecal-ros2-input, free of DDS and of the bus: one serialized ROS 2 message (CDR, as DDS
// delivers it) of a configured topic in, the frame fusecal's streams carry out, through the same CDR
// decoding (formats/ros_cdr.hpp) and conversions (formats/ros_sensor_frames.hpp) as `fusecal import
// rosbag`. A message that does not decode or convert is counted and its reason kept; nothing throws.
// Losses are counted from gaps in each stream's header stamps (StampGapCounter): DDS delivers best-effort
// samples without telling the reader what it missed.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>

#include "stages/formats/ros_sensor_frames.hpp"

namespace fusecal {

// kCloud is sensor_msgs/msg/PointCloud2, kLivoxCloud livox_ros_driver2/msg/CustomMsg.
enum class Ros2SensorTopic { kCameraInfo, kImage, kCompressedImage, kCloud, kLivoxCloud };
const char* Ros2TypeOf(Ros2SensorTopic topic);  // "sensor_msgs/msg/Image", ...

// Messages missing from a periodic stream, judged from its stamps: a step of k periods (k >= 2, the
// period being the median of the last steps) means k - 1 messages were lost.
class StampGapCounter {
 public:
  // The messages judged lost just before this one (0 for the first few, while the period is learnt).
  int Add(int64_t stamp_utime);
  long lost() const { return lost_; }

 private:
  int64_t last_ = INT64_MIN;
  std::deque<int64_t> steps_;  // the last steps (microseconds) of messages that were not gaps
  long lost_ = 0;
};

struct Ros2TopicCounts {
  long received = 0;   // messages taken from DDS
  long used = 0;       // became a frame
  long malformed = 0;  // did not decode or convert (skipped)
  long lost = 0;       // judged missing from stamp gaps
  uint64_t bytes = 0;
  std::string first_error;  // why the first malformed message was skipped
};

// What one message became: at most one of these is set.
struct Ros2InputFrame {
  std::optional<CameraParams> camera;  // a camera model, new or changed
  std::optional<SensorImage> image;
  std::optional<SensorScan> scan;
  std::string error;  // set when the message was skipped
};

class Ros2SensorInput {
 public:
  // With a camera from a file, CameraInfo messages are counted but not used.
  explicit Ros2SensorInput(std::optional<CameraParams> camera_from_file = std::nullopt);

  Ros2InputFrame Take(Ros2SensorTopic topic, const uint8_t* data, size_t size, int64_t receive_utime);

  const Ros2TopicCounts& counts(Ros2SensorTopic topic) { return counts_[topic]; }
  const std::optional<CameraParams>& camera() const { return frames_.camera(); }
  int unstamped() const { return frames_.unstamped(); }

 private:
  Ros2InputFrame Convert(Ros2SensorTopic topic, const uint8_t* data, size_t size, int64_t receive_utime);

  const bool camera_from_file_;
  RosSensorFrames frames_;
  std::map<Ros2SensorTopic, Ros2TopicCounts> counts_;
  std::map<Ros2SensorTopic, StampGapCounter> gaps_;
};

}  // namespace fusecal
