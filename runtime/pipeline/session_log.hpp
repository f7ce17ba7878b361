// The session's own LCM log (run.record), bounded on disk for hours of scanning:
//   stations  session.lcmlog holds everything but the raw sensor frames (CAMERA_IMAGE, LIDAR_SCAN):
//             stations, motions, extrinsics, status. `fusecal calibrate --log session.lcmlog` replays the
//             stations to the same extrinsic. The default.
//   all       as `stations`, and the raw frames in raw/raw-<n>.lcmlog: segments of max_raw_mb / 8, the
//             oldest deleted while the segments together exceed max_raw_mb. Each segment starts with the
//             latest CAMERA_INFO, so that any of them replays alone (`fusecal calibrate --log raw/raw-3.lcmlog`).
//   none      no log.
// Plain LCM logs: lcm-logplayer, lcm-spy and `fusecal log` read them.
#pragma once

#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "runtime/lcm_log.hpp"

namespace fusecal {

// The latest CAMERA_INFO of each camera as it came, by channel (CAMERA_INFO, CAMERA_INFO_front, ...).
using CameraInfos = std::map<std::string, std::vector<uint8_t>>;

struct RecordSettings {
  std::string what = "stations";  // all | stations | none
  double max_raw_mb = 2048;       // cap of the raw-frame segments (all)
};

class SessionLog {
 public:
  // `dir`: the output folder. Throws LogError when a file cannot be created.
  SessionLog(const std::string& dir, const RecordSettings& settings);
  // Records one message as the policy says; `camera_infos` start a new segment.
  void Write(const std::string& channel, int64_t utime, const uint8_t* data, size_t size,
             const CameraInfos& camera_infos);
  // Flushes and closes every file; throws LogError when data could not be written.
  void Close();
  // Raw-frame segments deleted to stay under the cap.
  int segments_deleted() const { return segments_deleted_; }

 private:
  void StartSegment(int64_t utime, const CameraInfos& camera_infos);

  RecordSettings settings_;
  std::string dir_;
  std::unique_ptr<LogWriter> session_;
  std::unique_ptr<LogWriter> segment_;
  struct Segment {
    std::string path;
    double bytes = 0;
  };
  std::deque<Segment> segments_;  // oldest first; the last is being written
  int next_segment_ = 0, segments_deleted_ = 0;
};

}  // namespace fusecal
