// fusecal-ros2-input: a running ROS 2 robot's sensor topics into the pipeline. Cyclone DDS readers of
// the configured topics (DDS names rt/<topic>, types sensor_msgs::msg::dds_::Image_ and so on, in
// rosidl's form) take each sample as serialized CDR; the core (ros2_sensor_input.hpp) decodes and
// converts it as `fusecal import rosbag` does; CAMERA_INFO, CAMERA_IMAGE and LIDAR_SCAN go out on the bus
// with the header stamps.
//
// QoS: best effort, volatile, keep last `depth`. A best-effort reader matches both reliable publishers
// and best-effort (sensor data) ones. The socket receive buffer is asked to hold 6 of the largest
// messages (`max_message_mb`; the kernel's net.core.rmem_max caps it, `fusecal doctor` checks).
// A topic that has had no message `topic_timeout_s` after the start is an error that lists the topics
// and types seen on the domain (DDS discovery); STATUS then says "no_input".
#pragma once

#include <dds/dds.h>

#include <memory>
#include <string>
#include <vector>

#include "runtime/stage_main.hpp"
#include "runtime/work_stats.hpp"
#include "stages/ros2_input/node/ros2_input_settings.hpp"
#include "stages/ros2_input/node/ros2_sensor_input.hpp"

namespace fusecal {

class Ros2Discovery;

class Ros2InputNode : public StageNode {
 public:
  // Throws std::runtime_error when the domain, topics or readers cannot be made, or the camera file
  // cannot be read.
  explicit Ros2InputNode(const Ros2InputSettings& settings);
  ~Ros2InputNode() override;
  void Start(Bus& bus) override;
  void Tick(Bus& bus, int64_t now_utime) override;
  // The DDS readers are polled in Tick: every 5 ms, so that a frame waits at most that long.
  int TickPeriodMs() const override { return 5; }
  StageStatus Status() const override;

 private:
  // One camera's image and camera info, converted by its own Ros2SensorInput.
  struct CameraInput {
    std::string name;  // the rig's name of it ("" for the one camera): its channels
    std::unique_ptr<Ros2SensorInput> input;
    int64_t last_camera_info_utime = 0;
  };
  struct Reader {
    Ros2SensorTopic kind;
    std::string topic;  // ROS name
    int camera = -1;    // into cameras_; -1: the cloud
    dds_entity_t reader = 0;
    double latency_sum_s = 0, latency_max_s = 0;  // DDS source timestamp to here
    long latency_count = 0;
    bool warned = false;  // the first malformed message was reported
  };
  void TakeAll(Bus& bus, Reader& reader, int64_t now_utime);
  void Publish(Bus& bus, const Ros2InputFrame& frame, int camera);
  Ros2SensorInput& InputOf(const Reader& reader) const;
  std::string CounterKey(const Reader& reader) const;  // image, camera_info, cloud; image_<camera>, ...
  void CheckTopicsArrived(int64_t now_utime);
  std::string MissingTopicsMessage(const std::vector<const Reader*>& missing) const;

  Ros2InputSettings settings_;
  std::vector<CameraInput> cameras_;
  std::unique_ptr<Ros2SensorInput> cloud_input_;
  dds_entity_t participant_ = 0;
  std::unique_ptr<Ros2Discovery> discovery_;
  std::vector<Reader> readers_;
  std::vector<uint8_t> buffer_;  // one serialized sample, reused
  int64_t start_utime_ = 0;
  bool no_input_ = false;
  long published_images_ = 0, published_scans_ = 0;
  int64_t first_stamp_ = INT64_MAX, last_stamp_ = INT64_MIN;  // of the frames published: the stream's span
  WorkStats work_;  // one item per message taken: decoding, converting, publishing
};

}  // namespace fusecal
