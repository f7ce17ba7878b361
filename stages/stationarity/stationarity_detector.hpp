// Stationarity detector: picks the stop-and-scan stations (paper section III: "the sensors stand still
// while a scan and an image are taken") automatically from a camera stream and a LiDAR stream, so that
// calibration can run during mobile scanning. No LCM, no I/O.
//
// Each stream is judged on its own, frame by frame (arrival order, own timestamps):
//   image: median KLT displacement between consecutive frames <= still_flow_px, and from the first frame
//          of the still run (the anchor) <= max_drift_px; a frame without texture is undecidable;
//   LiDAR: median |range difference| between consecutive coarse range images <= still_change_m, and from
//          the anchor scan <= max_drift_m.
// A sensor's still run starts at its anchor frame (the last frame judged moving, or the first after a
// gap) and lasts while every new frame is judged still. The rig is still over the intersection
// [still_from, still_to] of the two runs (still_to: the last frame of the sensor that lags). Once it lasts
// min_still_s the detector emits one station: the image and the scan inside the interval closest to each
// other in time; the next station only comes from a later still run at a place the rig has moved away
// from (image displacement or LiDAR change between the two stations above moved_*).
//
// Memory is bounded: per sensor the frames of the current still run (pruned to the other sensor's run and
// to max_buffered_frames), the previous and anchor frames, and the previous station's reference.
#pragma once

#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "stages/foundation/point_cloud.hpp"
#include "stages/stationarity/image_motion.hpp"
#include "stages/stationarity/range_image.hpp"
#include "stages/stationarity/settings.hpp"

namespace fusecal {

struct DetectedStation {
  int id = 0;         // 0, 1, 2, ...
  int64_t utime = 0;  // the later of image_utime and scan_utime
  int64_t image_utime = 0;
  int64_t scan_utime = 0;  // the chosen scan (the newest of the merged ones)
  int64_t still_from = 0;  // still interval known at emission
  int64_t still_to = 0;
  cv::Mat image;     // as received (a private copy)
  PointCloud cloud;  // as received, or still scans concatenated (merge_scans, or accumulate_s without beams)
  std::vector<int64_t> merged_scan_utimes;  // the scans in `cloud`, oldest first
  // Figures at emission: displacement / change from the first frame of the still run to the chosen one.
  double image_drift_px = 0;
  double lidar_change_m = 0;
};

enum class StationarityPhase {
  kMoving,    // not known to be still: moving, or a sensor undecided or missing
  kSettling,  // both sensors still, for less than min_still_s so far
  kStill,     // both still for at least min_still_s (a station was emitted for this run, or suppressed)
};
const char* ToString(StationarityPhase phase);

struct StationarityCounters {
  int64_t images_received = 0, images_used = 0;
  int64_t images_invalid = 0;          // empty, not 8-bit, unsupported channel count
  int64_t images_duplicate = 0;        // utime equal to the previous image's
  int64_t images_out_of_order = 0;     // utime before the previous image's
  int64_t images_without_texture = 0;  // black / blank frames: stillness undecidable
  int64_t images_untracked = 0;        // tracking lost (too few tracks)
  int64_t image_gaps = 0;              // consecutive images further apart than max_frame_gap_s
  int64_t scans_received = 0, scans_used = 0;
  int64_t scans_empty = 0;  // no valid points (empty, all NaN, all out of range)
  int64_t scans_duplicate = 0;
  int64_t scans_out_of_order = 0;
  int64_t scan_gaps = 0;
  int64_t stations_emitted = 0;
  int64_t stations_same_place = 0;  // still runs not emitted: the rig had not moved from the last station
  int64_t still_runs_unpaired = 0;  // still runs with no image and scan within max_pair_dt_s (so far)
};

struct StationarityState {
  StationarityPhase phase = StationarityPhase::kMoving;
  std::string reason;  // why not still (moving) or what it waits for; empty when nothing to say

  bool image_still = false, lidar_still = false;
  double image_flow_px = NAN;   // last consecutive image displacement (NaN: undecidable)
  double image_drift_px = NAN;  // last displacement from the anchor frame
  int image_tracks = 0;
  double lidar_change_m = NAN;  // last consecutive LiDAR change (NaN: undecidable)
  double lidar_drift_m = NAN;   // last change from the anchor scan
  int lidar_common_cells = 0;

  double still_for_s = 0;        // both still, so far (0 unless settling or still)
  int64_t still_from_utime = 0;  // valid while settling or still
  bool camera_missing = false;   // no image for sensor_timeout_s while the LiDAR streams (or never)
  bool lidar_missing = false;
  int64_t last_image_utime = 0, last_scan_utime = 0;  // 0: none yet
  int next_station_id = 0;

  StationarityCounters counters;
  std::string last_rejection;  // the reason the last ignored input was ignored
};

class StationarityDetector {
 public:
  // Throws std::invalid_argument with the message of settings.Validate() when the settings are invalid.
  explicit StationarityDetector(const StationaritySettings& settings);

  // Feed the frames in arrival order; each returns the stations it completes (none or one). An input that
  // cannot be used (see StationarityCounters) is ignored and counted, never thrown on.
  std::vector<DetectedStation> AddImage(int64_t utime, const cv::Mat& image);
  // The same, with the motion measured on `motion_image` (any resolution down to working_width_px, grey
  // or colour: e.g. a JPEG decoded at a reduced scale) and the station's image made by `station_image`,
  // which is called only for the frame a station takes (e.g. the full decode of the kept JPEG bytes).
  using StationImage = std::function<cv::Mat()>;
  std::vector<DetectedStation> AddImage(int64_t utime, const cv::Mat& motion_image, StationImage station_image);
  std::vector<DetectedStation> AddScan(int64_t utime, const PointCloud& cloud);

  // End of the streams: emits the pending still run if it has lasted min_still_s up to the newest frame of
  // either sensor (the sensor that ended first showed no motion until its end), then forgets the streams
  // (timestamps may start over; counters, station ids and the last station's reference are kept).
  std::optional<DetectedStation> Flush();

  StationarityState State() const;
  const StationaritySettings& settings() const { return settings_; }

 private:
  struct BufferedImage {
    int64_t utime;
    StationImage image;  // the image a station would carry
    std::shared_ptr<const ImageFrame> frame;
  };
  struct BufferedScan {
    int64_t utime;
    std::shared_ptr<const PointCloud> cloud;
    std::shared_ptr<const RangeImage> range;
  };
  // Still-run bookkeeping shared by both sensors.
  struct Run {
    bool seen = false;
    int64_t first_utime = 0, last_utime = 0;
    bool still = false;
    int64_t still_since = 0;  // utime of the anchor frame, valid while still
    std::string reason;       // why the last frame was not still
  };
  struct Reference {  // the previous station
    std::shared_ptr<const ImageFrame> frame;
    std::shared_ptr<const RangeImage> range;
  };

  // Ordering check shared by both sensors; returns false (and counts) when the input is to be ignored.
  bool AcceptTime(const char* sensor, int64_t utime, const Run& run, int64_t* duplicates, int64_t* out_of_order);
  void Prune();
  std::vector<DetectedStation> Evaluate(bool flushing);
  std::optional<DetectedStation> TryEmit(int64_t from, int64_t to);
  // Steps of AddImage and TryEmit (see the .cpp).
  void JudgeImageMotion(int64_t utime, const StationImage& image, const std::shared_ptr<const ImageFrame>& frame);
  int64_t ClosestPairDt(int64_t from, int64_t to) const;
  std::pair<const BufferedImage*, const BufferedScan*> LatestPairNearClosest(int64_t from, int64_t to, int64_t best_dt,
                                                                             int64_t tie) const;
  DetectedStation BuildStation(const BufferedImage& best_image, const BufferedScan& best_scan, int64_t from,
                               int64_t to);
  std::vector<const BufferedScan*> ScansToMerge(const BufferedScan& best_scan, int64_t from) const;
  static void MergeScanClouds(const std::vector<const BufferedScan*>& merged, const BufferedScan& best_scan,
                              PointCloud* cloud);
  void MarkRunHandled(const std::string& outcome);
  bool MovedSinceLastStation(const BufferedImage& image, const BufferedScan& scan) const;
  void Reject(const std::string& reason) { last_rejection_ = reason; }

  StationaritySettings settings_;
  StationarityCounters counters_;
  std::string last_rejection_;

  Run camera_, lidar_;
  std::shared_ptr<const ImageFrame> prev_image_, anchor_image_;
  std::shared_ptr<const RangeImage> prev_range_, anchor_range_;
  std::deque<BufferedImage> images_;
  std::deque<BufferedScan> scans_;

  int64_t anchor_scan_utime_ = 0;
  double image_flow_px_ = NAN, image_drift_px_ = NAN, lidar_change_m_ = NAN, lidar_drift_m_ = NAN;
  int image_tracks_ = 0, lidar_common_cells_ = 0;

  // Combined still run.
  bool run_active_ = false;
  int64_t run_from_ = 0;
  bool run_handled_ = false;  // emitted or suppressed
  bool run_unpaired_counted_ = false;
  std::string run_outcome_;  // what became of the run, for State().reason

  std::optional<Reference> reference_;
  int next_id_ = 0;
};

}  // namespace fusecal
