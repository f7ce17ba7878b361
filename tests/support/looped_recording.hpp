// A recording's sensor streams (CAMERA_INFO, CAMERA_IMAGE, LIDAR_SCAN) played as one long stream, for the
// ROS 2 peers' long benchmark runs: forward, then backward in time (the rig goes back along its path, so
// every motion stays continuous), then forward again, and so on, with stamps that keep increasing, until
// the stream is at least `min_seconds` long. The stamps are rewritten in the events and in the messages.
// With min_seconds no longer than the recording, one forward pass is streamed from the file; a longer
// stream holds the recording's sensor events in memory.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "runtime/lcm_log.hpp"
#include "stages/ros2_input/node/ros2_sensor_input.hpp"

namespace fusecal::testing {

class LoopedRecording {
 public:
  // Throws LogError when the log cannot be read, std::runtime_error when it has no sensor event.
  LoopedRecording(const std::string& log, double min_seconds);

  // The next sensor event in stream order, or nullopt after the last pass.
  std::optional<LogEvent> Next();

  int passes() const { return passes_; }
  // The images and scans a receiver judging losses from stamp gaps (StampGapCounter, as
  // fusecal-ros2-input does) would count as lost in what was played so far, none being lost: where the
  // stream turns, the frames nearest the turn leave a step of up to two periods.
  long stamp_gaps() const { return image_gaps_.lost() + scan_gaps_.lost(); }
  // The length of one pass, seconds (the recording's first to last sensor event).
  double pass_seconds() const { return 1e-6 * static_cast<double>(last_utime_ - first_utime_); }

 private:
  std::optional<LogEvent> NextEvent();
  std::optional<LogEvent> NextStreamed();
  LogEvent Restamped(size_t index, bool backward, int64_t base) const;

  std::unique_ptr<LogReader> reader_;   // the single streamed pass
  std::vector<LogEvent> events_;        // the recording, in memory for more than one pass
  std::vector<int64_t> end_utimes_;     // when each event ends (a scan at its last point)
  std::vector<size_t> backward_order_;  // event indices by their backward stamps
  int64_t first_utime_ = 0, last_utime_ = 0;
  int passes_ = 1, pass_ = 0;
  StampGapCounter image_gaps_, scan_gaps_;
  size_t next_ = 0;
};

}  // namespace fusecal::testing
