#include "stages/ros2_input/node/ros2_sensor_input.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "stages/formats/ros_cdr.hpp"

namespace fusecal {

namespace {
constexpr size_t kStepsKept = 15;
constexpr size_t kStepsToLearn = 3;  // steps seen before gaps are judged
}  // namespace

const char* Ros2TypeOf(Ros2SensorTopic topic) {
  switch (topic) {
    case Ros2SensorTopic::kCameraInfo:
      return "sensor_msgs/msg/CameraInfo";
    case Ros2SensorTopic::kImage:
      return "sensor_msgs/msg/Image";
    case Ros2SensorTopic::kCompressedImage:
      return "sensor_msgs/msg/CompressedImage";
    case Ros2SensorTopic::kCloud:
      return "sensor_msgs/msg/PointCloud2";
    case Ros2SensorTopic::kLivoxCloud:
      return "livox_ros_driver2/msg/CustomMsg";
  }
  return "";
}

int StampGapCounter::Add(int64_t stamp_utime) {
  const int64_t last = std::exchange(last_, stamp_utime);
  if (last == INT64_MIN || stamp_utime <= last) return 0;  // the first, or a repeat or reordering
  const int64_t step = stamp_utime - last;
  int missing = 0;
  if (steps_.size() >= kStepsToLearn) {
    std::vector<int64_t> sorted(steps_.begin(), steps_.end());
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double period = static_cast<double>(sorted[sorted.size() / 2]);
    const long periods = std::lround(step / period);
    if (periods >= 2) missing = static_cast<int>(std::min<long>(periods - 1, 1000000));
  }
  if (missing == 0) {
    steps_.push_back(step);
    if (steps_.size() > kStepsKept) steps_.pop_front();
  }
  lost_ += missing;
  return missing;
}

Ros2SensorInput::Ros2SensorInput(std::optional<CameraParams> camera_from_file)
    : camera_from_file_(camera_from_file.has_value()), frames_(std::move(camera_from_file)) {}

Ros2InputFrame Ros2SensorInput::Take(Ros2SensorTopic topic, const uint8_t* data, size_t size, int64_t receive_utime) {
  Ros2TopicCounts& counts = counts_[topic];
  ++counts.received;
  counts.bytes += size;
  Ros2InputFrame frame;
  try {
    frame = Convert(topic, data, size, receive_utime);
  } catch (const std::exception& e) {
    frame = Ros2InputFrame{};
    frame.error = std::string(Ros2TypeOf(topic)) + ": " + e.what();
  }
  if (!frame.error.empty()) {
    if (counts.malformed++ == 0) counts.first_error = frame.error;
    return frame;
  }
  ++counts.used;
  const int64_t stamp = frame.image ? frame.image->utime : frame.scan ? frame.scan->utime : -1;
  if (stamp >= 0) counts.lost += gaps_[topic].Add(stamp);
  return frame;
}

Ros2InputFrame Ros2SensorInput::Convert(Ros2SensorTopic topic, const uint8_t* data, size_t size,
                                        int64_t receive_utime) {
  Ros2InputFrame frame;
  switch (topic) {
    case Ros2SensorTopic::kCameraInfo: {
      const CameraParams camera = RosCameraInfoToParams(DecodeCdrCameraInfo(data, size));
      if (const std::string problem = camera.Validate(); !problem.empty()) throw std::runtime_error(problem);
      const auto& known = frames_.camera();
      const bool same = known && known->model == camera.model && known->width == camera.width &&
                        known->height == camera.height && known->fx == camera.fx && known->fy == camera.fy &&
                        known->cx == camera.cx && known->cy == camera.cy && known->dist == camera.dist;
      if (!camera_from_file_ && !same) {
        frames_.SetCamera(camera);
        frame.camera = camera;
      }
      break;
    }
    case Ros2SensorTopic::kImage:
      frame.image = frames_.Image(DecodeCdrImage(data, size), receive_utime);
      break;
    case Ros2SensorTopic::kCompressedImage:
      frame.image = frames_.Image(DecodeCdrCompressedImage(data, size), receive_utime);
      break;
    case Ros2SensorTopic::kCloud:
      frame.scan = frames_.Cloud(DecodeCdrPointCloud2(data, size), receive_utime);
      break;
    case Ros2SensorTopic::kLivoxCloud:
      frame.scan = frames_.Cloud(DecodeCdrLivoxCustomMsg(data, size), receive_utime);
      break;
  }
  return frame;
}

}  // namespace fusecal
