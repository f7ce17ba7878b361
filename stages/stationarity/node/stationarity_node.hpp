// fusecal-stationarity: turns the raw CAMERA_IMAGE and LIDAR_SCAN streams into STATION messages (one per
// stop of the rig). Its STATUS shows the phase (moving / settling / still) and the figures it decides on.
//
// Overload (docs/design.md section 5): the handlers only queue the raw frames; the detector takes them
// in arrival order when it is free (Tick). Each stream keeps at most `raw_queue_depth` frames: a newer
// frame pushes the oldest one out (latest wins), counted in STATUS as images_skipped / scans_skipped.
// A station is built from frames the detector has taken, so a skipped frame costs a sample, never a
// station; STATION itself is published by this stage and never skipped.
//
// Decimation: images are taken at most `max_image_rate_hz` (default 5 Hz; 0: all). Decoding a 2048x1024
// JPEG alone costs about 4.5 ms; every scan is still taken, so each taken image has its scan within
// max_pair_dt_s as before. Decimated images are counted as images_decimated (not as skipped).
#pragma once

#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/stage_main.hpp"
#include "runtime/work_stats.hpp"
#include "stages/stationarity/stationarity_detector.hpp"

namespace fusecal {

struct StationarityNodeSettings {
  StationaritySettings detector;
  int raw_queue_depth = 2;         // frames kept per stream while the detector is busy, in [1, 1000]
  double max_image_rate_hz = 5.0;  // images taken at most this often (0: every image)

  // Empty when usable, else what is wrong: a field above, or detector.Validate()'s message.
  std::string Validate() const;
};

StationarityNodeSettings ReadStationarityNodeSettings(ConfigReader section);

class StationarityNode : public StageNode {
 public:
  explicit StationarityNode(const StationarityNodeSettings& settings)
      : detector_(settings.detector),
        raw_queue_depth_(settings.raw_queue_depth),
        min_image_interval_us_(settings.max_image_rate_hz > 0 ? static_cast<int64_t>(1e6 / settings.max_image_rate_hz)
                                                              : 0) {}
  void Start(Bus& bus) override;
  // Takes the queued frames (oldest first) and publishes the stations they complete.
  void Tick(Bus& bus, int64_t now_utime) override;
  void Flush(Bus& bus) override;
  StageStatus Status() const override;

 private:
  struct QueuedFrame {
    bool image = false;  // else a scan
    std::vector<uint8_t> bytes;
  };
  void Queue(bool image, const RawMessage& raw);
  void TakeImage(Bus& bus, const std::vector<uint8_t>& bytes);
  void TakeScan(Bus& bus, const std::vector<uint8_t>& bytes);
  void Emit(Bus& bus, const DetectedStation& station);

  StationarityDetector detector_;
  int raw_queue_depth_;
  int64_t min_image_interval_us_;
  int64_t last_image_utime_ = -1;  // of the last image queued (not decimated)
  std::deque<QueuedFrame> queue_;  // both streams, arrival order
  int queued_images_ = 0, queued_scans_ = 0;
  std::optional<camera_info_t> camera_;
  // The frames the sensors' messages name (a ROS header's frame_id), passed on in STATION.
  std::string image_frame_id_ = "camera", scan_frame_id_ = "lidar";
  std::vector<Subscription> subscriptions_;
  int stations_ = 0, without_camera_info_ = 0;
  long images_skipped_ = 0, scans_skipped_ = 0, images_decimated_ = 0;
  WorkStats work_;  // one item per frame taken
  WorkStats image_work_, scan_work_;
};

}  // namespace fusecal
