// fusecal-stationarity: turns the raw CAMERA_IMAGE and LIDAR_SCAN streams into STATION messages (one per
// stop of the rig). Its STATUS shows the phase (moving / settling / still) and the figures it decides on.
//
// Overload (docs/design.md section 5): the handlers only queue the raw frames; the detector takes them
// in arrival order when it is free (Tick). Each stream keeps at most `raw_queue_depth` frames: a newer
// frame pushes the oldest one out (latest wins), counted in STATUS as images_skipped / scans_skipped.
// A station is built from frames the detector has taken, so a skipped frame costs a sample, never a
// station; STATION itself is published by this stage and never skipped. A replay that waits for the
// pipeline (--paced) skips nothing: the queue holds up to kPacedQueueDepth frames per stream, so that
// the stations are those `fusecal calibrate` finds, and its STATUS says every kPacedReportEvery frames
// how many it has done, so that the player keeps only a few in flight. Tick returns after kMaxTickMs with frames still
// queued, so that the bus is served meanwhile (a DDS reader keeps only `bulk_depth` raw frames).
//
// Decimation: images are taken at most `max_image_rate_hz` (default 5 Hz; 0: all). Decoding a 2048x1024
// JPEG alone costs about 4.5 ms; every scan is still taken, so each taken image has its scan within
// max_pair_dt_s as before. Decimated images are counted as images_decimated (not as skipped).
//
// A rig of several cameras (docs/design.md, "Rigs of several cameras"): the first camera and the LiDAR
// decide, as above; the rig is rigid, so when they stand still every camera does. Each station goes out
// once per camera on STATION_<camera>, with the same id, interval and cloud and the camera's own image
// taken inside the still interval, nearest the first camera's. The other cameras' images are kept
// undecoded for the last `kKeepOtherImages_s`; a station whose image of a camera has not come yet waits
// for it until that camera's images have passed the interval.
#pragma once

#include <deque>
#include <map>
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
  int raw_queue_depth = 2;                   // frames kept per stream while the detector is busy, in [1, 1000]
  double max_image_rate_hz = 5.0;            // images taken at most this often (0: every image)
  std::vector<std::string> rig_cameras{""};  // the rig's cameras (the pipeline config's `cameras`), first decides

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
                                                              : 0),
        cameras_(settings.rig_cameras) {}
  void Start(Bus& bus) override;
  // Takes the queued frames (oldest first) and publishes the stations they complete.
  void Tick(Bus& bus, int64_t now_utime) override;
  void Flush(Bus& bus) override;
  StageStatus Status() const override;
  bool HasQueuedWork() const override { return !queue_.empty(); }
  void UsePacedInput() override {
    paced_ = true;
    raw_queue_depth_ = kPacedQueueDepth;
  }
  // Paced: a STATUS every kPacedReportEvery frames done (taken, decimated or skipped), whose
  // `frames_done` the player waits for (`fusecal run`: at most a few frames in flight).
  bool WantsStatusNow() override;
  static constexpr int kPacedQueueDepth = 1000;
  static constexpr int kMaxTickMs = 50;
  static constexpr long kPacedReportEvery = 2;

 private:
  struct QueuedFrame {
    bool image = false;  // else a scan
    std::vector<uint8_t> bytes;
  };
  void Queue(bool image, const RawMessage& raw);
  void TakeImage(Bus& bus, const std::vector<uint8_t>& bytes);
  void TakeScan(Bus& bus, const std::vector<uint8_t>& bytes);
  void Emit(Bus& bus, const DetectedStation& station);
  // The rig's other cameras.
  struct OtherImage {
    int64_t utime = 0;
    std::vector<uint8_t> bytes;  // image_t, encoded
  };
  struct WaitingStation {
    station_t station;        // with the cloud; its image still to come
    int64_t image_utime = 0;  // the first camera's, to be matched
  };
  void KeepOtherImage(const std::string& camera, const RawMessage& raw);
  // The camera's image for `station` (inside its interval, nearest image_utime), or false.
  bool FillImage(const std::string& camera, int64_t image_utime, station_t* station);
  void PublishStation(Bus& bus, const std::string& camera, const station_t& station);
  // Publishes the waiting stations of `camera` that have their image; `flushing`: the input has ended, so
  // those without one are dropped. Returns what was dropped, for the stage's log (empty: nothing).
  std::string PublishWaiting(Bus& bus, const std::string& camera, bool flushing = false);
  static constexpr double kKeepOtherImages_s = 4.0;

  StationarityDetector detector_;
  int raw_queue_depth_;
  int64_t min_image_interval_us_;
  int64_t last_image_utime_ = -1;  // of the last image queued (not decimated)
  std::deque<QueuedFrame> queue_;  // both streams, arrival order
  int queued_images_ = 0, queued_scans_ = 0;
  std::vector<std::string> cameras_;                   // the rig's; cameras_[0] decides
  std::map<std::string, camera_info_t> camera_infos_;  // by camera
  std::map<std::string, std::deque<OtherImage>> other_images_;
  std::map<std::string, std::deque<WaitingStation>> waiting_;
  long stations_without_image_ = 0;
  // The frames the sensors' messages name (a ROS header's frame_id), passed on in STATION.
  std::string image_frame_id_ = "camera", scan_frame_id_ = "lidar";
  std::vector<Subscription> subscriptions_;
  int stations_ = 0, without_camera_info_ = 0;
  Bus* bus_ = nullptr;  // for the other cameras' handlers
  long images_skipped_ = 0, scans_skipped_ = 0, images_decimated_ = 0;
  long frames_received_ = 0;  // every raw frame its handlers were given, of every camera
  long FramesDone() const { return frames_received_ - static_cast<long>(queue_.size()); }
  bool paced_ = false;
  long frames_reported_ = 0;  // FramesDone() at the last STATUS asked for
  WorkStats work_;            // one item per frame taken
  WorkStats image_work_, scan_work_;
};

}  // namespace fusecal
