// LoopedRecording: a recording played forward and backward as one long stream (the ROS 2 benchmark's
// long runs), on a small log written here.
#include <gtest/gtest.h>

#include <filesystem>
#include <vector>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/image_t.hpp"
#include "fusecal/point_cloud_t.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "tests/support/looped_recording.hpp"

namespace fusecal::testing {
namespace {

constexpr int64_t kStart = 1700000000000000;
constexpr int kFrames = 10;  // 10 Hz: about one second

// CAMERA_INFO at the start, then images at 0.01 + 0.1 k s and scans at 0.05 + 0.1 k s whose points come
// 0, 0.03, 0.06 and 0.09 s after the scan's stamp; image k's pixel is k, scan k's points are at x = k.
std::string WriteRecording(const std::string& name) {
  const std::string path = (std::filesystem::temp_directory_path() / (name + ".lcmlog")).string();
  LogWriter log(path);
  camera_info_t info{};
  info.utime = kStart;
  log.WriteMessage(channels::kCameraInfo, kStart, info);
  log.Write("OTHER", kStart, "x", 1);  // not a sensor channel: left out
  for (int k = 0; k < kFrames; ++k) {
    image_t image{};
    image.utime = kStart + 10000 + 100000 * k;
    image.width = image.height = image.step = 1;
    image.encoding = "mono8";
    image.data = {static_cast<uint8_t>(k)};
    image.size = 1;
    log.WriteMessage(channels::kCameraImage, image.utime, image);
    point_cloud_t scan{};
    scan.utime = kStart + 50000 + 100000 * k;
    scan.num_points = 4;
    for (int i = 0; i < 4; ++i) {
      scan.x.push_back(static_cast<float>(k));
      scan.y.push_back(0);
      scan.z.push_back(0);
      scan.time_offset_s.push_back(0.03F * static_cast<float>(i));
    }
    scan.num_time_offset = 4;
    log.WriteMessage(channels::kLidarScan, scan.utime, scan);
  }
  log.Close();
  return path;
}

template <typename Message>
Message Decoded(const LogEvent& event) {
  Message message;
  EXPECT_GE(message.decode(event.data.data(), 0, static_cast<int>(event.data.size())), 0) << event.channel;
  return message;
}

int64_t MessageUtime(const LogEvent& event) {
  if (event.channel == channels::kCameraImage.name) return Decoded<image_t>(event).utime;
  if (event.channel == channels::kLidarScan.name) return Decoded<point_cloud_t>(event).utime;
  return Decoded<camera_info_t>(event).utime;
}

TEST(LoopedRecording, WithoutALoopPlaysTheSensorEventsOnceAsRecorded) {
  const std::string log = WriteRecording("looped_recording_once");
  LoopedRecording recording(log, 0);
  LogReader reader(log);
  std::vector<LogEvent> recorded;
  while (auto event = reader.Next())
    if (event->channel != "OTHER") recorded.push_back(*event);
  size_t n = 0;
  while (auto event = recording.Next()) {
    ASSERT_LT(n, recorded.size());
    EXPECT_EQ(event->channel, recorded[n].channel);
    EXPECT_EQ(event->utime, recorded[n].utime);
    EXPECT_EQ(event->data, recorded[n].data);
    ++n;
  }
  EXPECT_EQ(n, recorded.size());
  EXPECT_EQ(recording.passes(), 1);
  EXPECT_EQ(recording.stamp_gaps(), 0);
}

TEST(LoopedRecording, PlaysForwardThenBackwardWithIncreasingStampsUntilTheStreamIsLongEnough) {
  const std::string log = WriteRecording("looped_recording_loop");
  LoopedRecording recording(log, 2.5);
  // One pass runs from the CAMERA_INFO to the last scan's last point: 0.05 + 0.9 + 0.09 s.
  EXPECT_NEAR(recording.pass_seconds(), 1.04, 1e-9);
  ASSERT_EQ(recording.passes(), 3);  // 2.5 s need three passes of 1.04 s
  std::vector<LogEvent> events;
  while (auto event = recording.Next()) events.push_back(*event);
  const size_t per_pass = 1 + 2 * kFrames;
  ASSERT_EQ(events.size(), 3 * per_pass);
  for (size_t i = 0; i < events.size(); ++i) {
    EXPECT_EQ(MessageUtime(events[i]), events[i].utime) << i;
    if (i > 0) {
      EXPECT_GE(events[i].utime, events[i - 1].utime) << i;
    }
  }
  EXPECT_GE(1e-6 * static_cast<double>(events.back().utime - events.front().utime), 2.5);

  // The backward pass starts where the forward one ended, with the last scan stamped at its last
  // point and its points' times counting back from there; the images come in reverse order.
  const LogEvent& turn = events[per_pass];
  ASSERT_EQ(turn.channel, channels::kLidarScan.name);
  EXPECT_EQ(turn.utime, kStart + 1040000);
  const auto scan = Decoded<point_cloud_t>(turn);
  EXPECT_FLOAT_EQ(scan.x[0], kFrames - 1);
  EXPECT_FLOAT_EQ(scan.time_offset_s[0], 0.09F);
  EXPECT_FLOAT_EQ(scan.time_offset_s[3], 0.0F);
  std::vector<int> backward_images, third_pass_images;
  for (size_t i = per_pass; i < 2 * per_pass; ++i)
    if (events[i].channel == channels::kCameraImage.name)
      backward_images.push_back(Decoded<image_t>(events[i]).data[0]);
  for (size_t i = 2 * per_pass; i < events.size(); ++i)
    if (events[i].channel == channels::kCameraImage.name)
      third_pass_images.push_back(Decoded<image_t>(events[i]).data[0]);
  ASSERT_EQ(backward_images.size(), static_cast<size_t>(kFrames));
  EXPECT_EQ(backward_images.front(), kFrames - 1);
  EXPECT_EQ(backward_images.back(), 0);
  EXPECT_EQ(third_pass_images.front(), 0);
  EXPECT_EQ(events[per_pass - 1].channel, channels::kLidarScan.name);
  EXPECT_EQ(events.back().channel, channels::kLidarScan.name);
  // Where the stream turns, the frames nearest the turn leave steps a receiver reads as losses: the
  // images 2 x 0.13 s apart at the first turn (2 judged lost), the scans 0.19 s at the second (1).
  EXPECT_EQ(recording.stamp_gaps(), 3);
}

TEST(LoopedRecording, ALogWithoutSensorEventsIsRefused) {
  const std::string path = (std::filesystem::temp_directory_path() / "looped_recording_empty.lcmlog").string();
  {
    LogWriter log(path);
    log.Write("OTHER", kStart, "x", 1);
    log.Close();
  }
  EXPECT_THROW(LoopedRecording(path, 10), std::runtime_error);
}

}  // namespace
}  // namespace fusecal::testing
