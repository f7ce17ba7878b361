// What a calibration session saw on the bus: stations, motions, every EXTRINSIC version, the ground
// truth when the log has one. Filled by a subscriber on any bus, so `calibrate` (in-process) and `run`
// (separate processes) write the same outputs. Optionally records the traffic as an LCM log (SessionLog).
// Memory stays bounded over hours: every station is remembered by its times, but its image and cloud
// only while StationRetention keeps it (the newest ones and those of the pairs the hand-eye stage holds).
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/ground_truth_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/pipeline/session_log.hpp"
#include "stages/node_kit/station_retention.hpp"

namespace fusecal {

// The STATUS name of the `fusecal run` that plays a log: 1 Hz, state "playing", and "done" once the
// pipeline has dealt with the whole log, which ends a `fusecal run` without a log on another host
// (`--stages`). Not a stage: SessionRecord leaves it out of stage_states() and stage_counters().
inline constexpr const char* kPlayerName = "player";

// A station's times, kept for every station of the session.
struct StationTimes {
  int64_t utime = 0;
  int64_t still_from_utime = 0;
  int64_t still_to_utime = 0;
};

class SessionRecord {
 public:
  // The session log goes to `dir`/session.lcmlog as `record` says. On a rig of several cameras, one
  // record per camera: its stations, camera motions, extrinsics and ground truth, and the rig's LiDAR
  // motions and STATUS.
  SessionRecord(Bus& bus, const std::string& dir, const RecordSettings& record, const std::string& camera = "");
  ~SessionRecord();

  // Every station seen, by id.
  const std::map<int, StationTimes>& stations() const { return stations_; }
  // The stations whose image and cloud are still held (all of them in a short session).
  const std::map<int, station_t>& kept_stations() const { return kept_stations_; }
  const std::vector<extrinsic_t>& extrinsics() const { return extrinsics_; }
  // When each of extrinsics() was received (utime, the bus's clock).
  const std::vector<int64_t>& extrinsic_receive_utimes() const { return extrinsic_receive_utimes_; }
  const std::optional<ground_truth_t>& ground_truth() const { return ground_truth_; }
  int lidar_motions() const { return lidar_motions_; }
  int camera_motions() const { return camera_motions_; }
  int failed_motions() const { return failed_motions_; }
  // Why motions failed: "LIDAR_MOTION: <reason>" -> how often (at most kMaxFailureReasons distinct ones).
  const std::map<std::string, int>& failure_reasons() const { return failure_reasons_; }
  static constexpr size_t kMaxFailureReasons = 16;
  int64_t last_news_utime() const { return last_news_utime_; }
  // Latest STATUS per stage name: state and last error.
  const std::map<std::string, std::pair<std::string, std::string>>& stage_states() const { return stage_states_; }
  // The latest CAMERA_INFO of every camera as it came, given again to a restarted stationarity stage.
  const CameraInfos& camera_infos() const { return camera_infos_; }
  const std::string& camera() const { return camera_; }
  // Every counter of each stage's latest STATUS (busy_s; bus_dropped: messages its bus knows it lost, DDS).
  const std::map<std::string, std::map<std::string, double>>& stage_counters() const { return stage_counters_; }

  // Whether some EXTRINSIC used or rejected a motion ending at `station_j` (the latest one may no longer
  // list it: handeye.max_motions drops pairs).
  bool MotionToWasTaken(int station_j) const { return taken_motions_to_.count(station_j) > 0; }
  // The latest EXTRINSIC, and the latest scaleless ("initial") one.
  const extrinsic_t* Final() const;
  const extrinsic_t* Initial() const;
  void Close();

 private:
  std::vector<Subscription> subscriptions_;
  void OnStation(const RawMessage& raw);
  void OnExtrinsic(const RawMessage& raw);
  void OnMotion(const RawMessage& raw);

  std::unique_ptr<SessionLog> log_;
  std::map<int, StationTimes> stations_;
  std::map<int, station_t> kept_stations_;
  StationRetention retention_;
  std::set<int> taken_motions_to_;
  std::vector<extrinsic_t> extrinsics_;
  std::vector<int64_t> extrinsic_receive_utimes_;
  std::string camera_;
  CameraInfos camera_infos_;
  std::optional<ground_truth_t> ground_truth_;
  int lidar_motions_ = 0, camera_motions_ = 0, failed_motions_ = 0;
  std::map<std::string, int> failure_reasons_;
  int64_t last_news_utime_ = 0;
  std::map<std::string, std::pair<std::string, std::string>> stage_states_;
  std::map<std::string, std::map<std::string, double>> stage_counters_;
};

// One record per camera of the rig, the first writing the session log as `record` says.
std::vector<std::unique_ptr<SessionRecord>> MakeSessionRecords(Bus& bus, const std::string& dir,
                                                               const RecordSettings& record,
                                                               const std::vector<std::string>& cameras);

// True when the log carries STATION messages among its first 500 events (a stop-and-scan dataset or
// `simulate --stations-only`); then the pipeline takes them instead of running the detector.
bool LogHasStations(const std::string& log_path);

// The cameras a log names on their own channels (CAMERA_IMAGE_front, STATION_front, ...), in the order
// they first appear among its first 5000 events; empty when it names none (one camera, plain channels).
std::vector<std::string> CamerasInLog(const std::string& log_path);

// Whether a logged channel goes into the pipeline: the ground truth always; STATION when the stations
// come from the log; the raw streams and CAMERA_INFO when the detector makes the stations.
bool FeedsPipeline(const std::string& channel, bool use_detector);

// One progress line: stations, motions, version, current estimate with standard deviations, verdict.
std::string ProgressText(const SessionRecord& session);

}  // namespace fusecal
