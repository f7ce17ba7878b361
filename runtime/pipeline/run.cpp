#include "runtime/pipeline/run.hpp"

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <thread>

#include <yaml-cpp/yaml.h>
#include "fusecal/motion_t.hpp"
#include "fusecal/station_t.hpp"
#include "fusecal/status_t.hpp"

#include "runtime/bus_url.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "runtime/output_file.hpp"
#include "runtime/pipeline/session.hpp"
#include "runtime/pipeline/stage_registry.hpp"
#include "runtime/shm_transport.hpp"
#include "runtime/stage_main.hpp"
#include "runtime/supervisor.hpp"
#include "stages/formats/extrinsic_status.hpp"
#include "stages/formats/result_file.hpp"

namespace fusecal {

namespace {

using Clock = std::chrono::steady_clock;

// The supervised process that joins the coordinator's bus to the stages' iox:// bus.
constexpr const char* kBridgeName = "bus_bridge";

// Watches the bus for what tells the player that the pipeline has dealt with a station.
struct PipelineWatch {
  std::set<std::pair<std::string, int>> motions_for;  // (sensor, station_j), valid or failed
  std::set<int> failed_for;                           // station_j of failed motions
  std::set<std::string> alive;                        // stage names that sent STATUS
  std::map<std::string, int> pids;                    // stage name -> pid of its latest STATUS
  bool player_done = false;                           // a player (another host's run) has said "done"
  static std::string CameraKey(const std::string& camera) { return camera.empty() ? "camera" : "camera/" + camera; }
  std::string player_host;
  std::vector<Subscription> subs;

  // The motions of each camera are keyed by its name ("camera/front"); the unnamed camera's by "camera".
  PipelineWatch(Bus& bus, const std::vector<std::string>& cameras) {
    // A message that does not decode is skipped here; the session record keeps it as it came.
    const auto on_error = [](const std::string&) {};
    const auto on_motion = [this](const std::string& key, const motion_t& m) {
      motions_for.insert({key, m.station_j});
      if (!m.valid) failed_for.insert(m.station_j);
    };
    subs.push_back(bus.Subscribe(
        channels::kLidarMotion, [=](const motion_t& m) { on_motion("lidar", m); }, on_error));
    for (const auto& camera : cameras)
      subs.push_back(bus.Subscribe(
          ForCamera(channels::kCameraMotion, camera), [=](const motion_t& m) { on_motion(CameraKey(camera), m); },
          on_error));
    subs.push_back(bus.Subscribe(
        channels::kStatus,
        [this](const status_t& s) {
          if (s.name == kPlayerName) {
            player_done = s.state == "done";
            player_host = s.host;
          }
          if (s.state == "stopped" || s.name == kPlayerName) return;
          alive.insert(s.name);
          pids[s.name] = s.pid;
        },
        on_error));
  }
};

// One `fusecal run`: the stage processes, the coordinator's bus, the session record, the player.
// The run's bus URL, checked before RouDi or any stage starts: a bad option is one clear error here rather
// than stages failing and being restarted.
std::string CheckedBusUrl(const std::string& url) {
  const std::string chosen = url.empty() ? DefaultBusUrl() : url;
  ParseBusUrl(chosen);
  return chosen;
}

// A live ROS 2 robot with every stage on this host and no bus named (--bus, bus.url, $LCM_DEFAULT_URL):
// the raw frames go from fusecal-ros2-input to the stages over shared memory, without the copies that
// multicast on loopback makes for every subscriber. Stages on other hosts need a network bus.
bool SharedMemoryForRos2(const PipelineConfig& config, const RunOptions& options) {
  const char* env = std::getenv("LCM_DEFAULT_URL");
  return options.ros2 && options.stages.empty() && options.bus_url.empty() && config.bus_url.empty() &&
         !(env && *env) && SharedMemoryBusBuilt();
}

std::string RunBusUrl(const PipelineConfig& config, const RunOptions& options) {
  if (SharedMemoryForRos2(config, options)) return "iox://";
  return CheckedBusUrl(options.bus_url.empty() ? config.bus_url : options.bus_url);
}

// A copy of the config at `path` with the rig's cameras, written to `out`; returns `out`.
std::string WriteConfigWithCameras(const std::string& path, const std::vector<std::string>& cameras,
                                   const std::string& out) {
  YAML::Node root = YAML::LoadFile(path);
  YAML::Node list(YAML::NodeType::Sequence);
  for (const auto& camera : cameras) {
    YAML::Node entry;
    entry["name"] = camera;
    list.push_back(entry);
  }
  root["cameras"] = list;
  YAML::Emitter emitter;
  emitter << root;
  WriteFileChecked(out, std::string(emitter.c_str()) + "\n");
  return out;
}

class PipelineRun {
 public:
  PipelineRun(const PipelineConfig& config, const RunOptions& options, const std::atomic<bool>& stop,
              const std::function<void(const std::string&)>& progress,
              const std::function<void(const std::string&)>& event)
      : config_(config),
        options_(options),
        stop_(stop),
        progress_(progress),
        event_(event),
        player_(!options.log_path.empty()),
        url_(RunBusUrl(config, options)),
        use_detector_(
            config.stations_from == "detector" ||
            (config.stations_from == "auto" && (options.log_path.empty() || !LogHasStations(options.log_path)))),
        // With shm=1 or iox://, RouDi is started here and the coordinator stays off shared memory
        // (shm_transport.hpp).
        transport_(url_, config.max_message_bytes, config.shm_chunks, options.out_dir, event),
        bus_(MakeBus(transport_.coordinator_url())),
        records_(MakeSessionRecords(*bus_, options.out_dir, config.record, config.cameras)),
        session_(*records_.front()),
        sessions_(Pointers(records_)),
        watch_(*bus_, config.cameras),
        split_(SplitStages(
            PipelineStageNames(use_detector_, config.ros2_tf.enabled || options.ros2, options.ros2, config.cameras),
            options.stages)),
        supervisor_(options.out_dir) {}

  RunReport Run() {
    const auto start = Clock::now();
    StartStages();
    if (!Pump(30, [&] { return AllAlive(names_); }))
      throw std::runtime_error("not every stage started within 30 s (see " + options_.out_dir + "/<stage>.log)");
    if (player_) WaitForStagesElsewhere();
    report_.startup_seconds = Seconds(start);
    if (player_) {
      ReplayLog();
    } else if (options_.ros2) {
      ListenToRos2();
    } else {
      event_("listening to live sensors on " + url_ + " (Ctrl-C to stop" +
             (options_.stages.empty() ? ")" : "; ends when the host playing the log is done)"));
      const auto listen_start = Clock::now();
      Pump(1e9, [&] { return !options_.stages.empty() && watch_.player_done; });
      report_.listen_seconds = Seconds(listen_start);
      if (!stop_) event_("the player on " + watch_.player_host + " is done");
    }
    const auto finish = Clock::now();
    RunReport report = Finish();
    report.outputs_seconds = Seconds(finish);
    return report;
  }

  static std::vector<const SessionRecord*> Pointers(const std::vector<std::unique_ptr<SessionRecord>>& records) {
    std::vector<const SessionRecord*> pointers;
    for (const auto& r : records) pointers.push_back(r.get());
    return pointers;
  }

  static double Seconds(Clock::time_point since) { return std::chrono::duration<double>(Clock::now() - since).count(); }

 private:
  void StartStages() {
    names_ = split_.here;  // ros2_tf, when enabled: the extrinsic on ROS 2's rt/tf_static
    for (const auto& name : split_.not_needed) {
      if (const std::string camera = StageAndCamera(name).second; !camera.empty())
        throw std::runtime_error(
            "--stages " + name + ": the rig has no camera " + camera + " (its cameras: " +
            (config_.cameras.front().empty() ? std::string("one without a name") : JoinNames(config_.cameras)) + ")");
      event_(name + " is not started: " +
             (name == "stationarity" ? "the stations come from the log" : "ros2_tf.enabled is false in the config"));
    }
    for (const auto& name : names_) {
      const auto [stage, camera] = StageAndCamera(name);
      std::vector<std::string> args{"--config", config_.path, "--bus", transport_.stage_url()};
      if (!camera.empty()) args.insert(args.end(), {"--camera", camera});
      // A replay that waits for the stages: the detector takes every frame, as in `calibrate`.
      if (PacedReplay()) args.push_back("--paced");
      supervisor_.Add({name, ExecutableDir() + "/" + FindStage(stage)->Executable(), args});
    }
    // iox://: the coordinator's bus and the stages' are joined by a bridge process, supervised like a stage
    // (it sends no heartbeat and is never given the stations).
    if (transport_.needs_bridge()) {
      supervisor_.Add({kBridgeName,
                       ExecutableDir() + "/fusecal-bus-bridge",
                       {"--coordinator", transport_.coordinator_url(), "--stages", transport_.stage_url()}});
      event_("the coordinator is on " + transport_.coordinator_url() + ", bridged to the stages' " +
             transport_.stage_url() + " by fusecal-bus-bridge");
    }
    supervisor_.StartAll();
  }

  // A live ROS 2 robot until Ctrl-C; the result file follows every converged version. Ends by itself
  // when fusecal-ros2-input says its topics did not appear (its STATUS "no_input", the reason as its error).
  void ListenToRos2() {
    const auto& in = config_.ros2_input;
    std::string topics;
    for (const Ros2CameraTopics& c : in.CameraTopics())
      topics += (c.name.empty() ? "" : "camera " + c.name + " ") + c.image_topic +
                (c.camera_file.empty() ? ", " + c.CameraInfoTopic() : ", camera " + c.camera_file) + ", ";
    event_("calibrating from ROS 2 domain " + std::to_string(in.domain) + ": " + topics + in.cloud_topic +
           (config_.cameras.front().empty()
                ? "; the extrinsic goes to rt/tf_static (domain " + std::to_string(config_.ros2_tf.domain) + ") and "
                : "; the rig's extrinsics go to ") +
           options_.out_dir + "/extrinsic.yaml (Ctrl-C to stop)");
    event_(url_ == "iox://" ? "the stages take the frames over shared memory (iox://, RouDi started by this run); "
                              "stages on other hosts need a network bus (--bus)"
                            : "the stages take the frames over " + url_);
    if (config_.ros2_tf.domain != in.domain)
      event_("note: ros2_tf.domain (" + std::to_string(config_.ros2_tf.domain) + ") differs from ros2_input.domain (" +
             std::to_string(in.domain) + ")");
    const auto listen_start = Clock::now();
    Pump(1e9, [&] {
      WriteConvergedResult();
      const auto state = session_.stage_states().find("ros2_input");
      if (state == session_.stage_states().end() || state->second.first != "no_input") return false;
      report_.failure = "fusecal-ros2-input: " + state->second.second;
      return true;
    });
    report_.listen_seconds = Seconds(listen_start);
  }

  // extrinsic.yaml for each new converged version, so that a long session always has its latest answer;
  // a rig's once every camera has converged, and again at each camera's next converged version.
  void WriteConvergedResult() {
    if (!config_.cameras.front().empty()) return WriteConvergedRig();
    const extrinsic_t* e = session_.Final();
    if (!e || e->version == written_version_ || e->status != extrinsic_t::STATUS_CONVERGED) return;
    written_version_ = e->version;
    try {
      WriteResultFile(options_.out_dir + "/extrinsic.yaml", ResultFromMessage(*e));
      event_("version " + std::to_string(e->version) + " converged: written to " + options_.out_dir +
             "/extrinsic.yaml");
    } catch (const std::exception& error) {
      event_(std::string("cannot write the result: ") + error.what());
    }
  }

  void WriteConvergedRig() {
    // Called at every pump of the bus: nothing is built unless a camera has a newer converged version.
    std::string versions;
    for (const SessionRecord* session : sessions_) {
      const extrinsic_t* e = session->Final();
      if (!e || e->status != extrinsic_t::STATUS_CONVERGED) return;
      versions += std::to_string(e->version) + ",";
    }
    if (versions == written_rig_versions_) return;
    written_rig_versions_ = versions;
    std::vector<RigCameraResult> cameras;
    for (const SessionRecord* session : sessions_) {
      const CalibrationResult result = ResultFromMessage(*session->Final());
      cameras.push_back({session->camera(), result.T_camera_lidar, result.covariance, result.status, ""});
    }
    try {
      WriteRigFile(options_.out_dir + "/extrinsic.yaml", MakeRigResult(cameras));
      event_("every camera converged: written to " + options_.out_dir + "/extrinsic.yaml");
    } catch (const std::exception& error) {
      event_(std::string("cannot write the result: ") + error.what());
    }
  }

  bool AllAlive(const std::vector<std::string>& names) const {
    for (const auto& name : names)
      if (!watch_.alive.count(name)) return false;
    return true;
  }

  // The stages this host does not start: their heartbeats from other hosts, before the first message
  // of the log (a stage that is not up yet would miss stations).
  void WaitForStagesElsewhere() {
    if (split_.elsewhere.empty()) return;
    const std::string there = "fusecal run --stages " + JoinNames(split_.elsewhere) + " --bus '" + url_ + "' --out DIR";
    event_("waiting for " + JoinNames(split_.elsewhere) + " on other hosts (there: " + there + ")");
    if (!Pump(config_.idle_timeout_s, [&] { return AllAlive(split_.elsewhere); }))
      throw std::runtime_error("no heartbeat on " + url_ + " from every one of " + JoinNames(split_.elsewhere) +
                               " within run.idle_timeout_s = " + std::to_string(config_.idle_timeout_s) +
                               " s: start `" + there + "` on another host, with the same config");
  }

  // The player's heartbeat: other hosts' runs (without a log) end when it says "done".
  void PublishPlayerStatus(const std::string& state) {
    StageStatus status;
    status.state = state;
    PublishStatus(*bus_, kPlayerName, status, "");
    last_player_status_ = Clock::now();
  }

  // Pumps the bus for up to `seconds`, restarting dead stages; returns early when `done` holds.
  bool Pump(double seconds, const std::function<bool()>& done) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (!stop_ && Clock::now() < end) {
      if (done && done()) return true;
      try {
        bus_->Handle(20);
      } catch (const std::exception& e) {
        event_(std::string("bus: ") + e.what());
      }
      RestartWhatDied();
      ResupplyRestartedStages();
      if (player_ && Clock::now() - last_player_status_ > std::chrono::seconds(1)) PublishPlayerStatus("playing");
      const std::string line = RigProgressText(sessions_);
      if (line != last_progress_) progress_(last_progress_ = line);
    }
    return done ? done() : true;
  }

  void RestartWhatDied() {
    // RouDi gone: its stages were ended with it (or are cut off from the new one): all start again.
    if (const std::string before = transport_.stage_url(); transport_.RestartIfDead()) {
      supervisor_.ReplaceArgument(before, transport_.stage_url());
      supervisor_.RestartAll();
      report_.restarts += static_cast<int>(names_.size());
      event_("every stage restarted after RouDi; they get the stations again once they are up");
    }
    for (const auto& e : supervisor_.Poll()) {
      ++report_.restarts;
      event_(e + "; it gets the stations again once it is up");
    }
  }

  // A restarted stage (new pid in its heartbeat) needs the stations (and the stationarity stage the
  // camera model); the others ignore stations they have seen and republish their motions of them,
  // which a restarted hand-eye stage needs. Stages restarted together (after RouDi) are given them once,
  // when all are up or kResupplyWait after the first: a burst per stage overflowed iox://'s queues of 8
  // stations (measured: 3 and 4 lost, missing camera motions).
  void ResupplyRestartedStages() {
    std::vector<const StageProcess*> ready;
    bool waiting = false;
    for (const auto& p : supervisor_.processes()) {
      if (p.name == kBridgeName || p.restarts == 0 || resupplied_[p.name] == p.pid) continue;
      const auto beat = watch_.pids.find(p.name);
      if (beat != watch_.pids.end() && beat->second == p.pid)
        ready.push_back(&p);
      else
        waiting = true;
    }
    if (ready.empty()) return;
    const auto now = Clock::now();
    if (first_ready_ == Clock::time_point{}) first_ready_ = now;
    if (waiting && now - first_ready_ < kResupplyWait) return;
    first_ready_ = {};
    for (const auto* p : ready) resupplied_[p->name] = p->pid;
    // Stationarity needs every camera's for every station.
    for (const auto& [channel, camera_info] : session_.camera_infos())
      bus_->PublishRaw(channel, camera_info.data(), camera_info.size());
    for (const SessionRecord* session : sessions_)
      for (const auto& [id, station] : session->kept_stations())
        bus_->Publish(ForCamera(channels::kStation, session->camera()), station);
  }

  // A restarted stage that has not been given the stations again yet: the player holds new messages back
  // until it has, so that every stage sees the stations in order.
  bool ResupplyPending() const {
    for (const auto& p : supervisor_.processes()) {
      if (p.name == kBridgeName) continue;
      const auto given = resupplied_.find(p.name);
      if (p.restarts > 0 && (given == resupplied_.end() || given->second != p.pid)) return true;
    }
    return false;
  }

  // The pipeline has dealt with station k when both motions ending at k are out and, if they are good,
  // a round that took them in (or rejected them) has ended.
  std::function<bool()> SettledAfter(int station_id, bool first) {
    return [this, station_id, first] {
      if (first) return true;
      if (!watch_.motions_for.count({"lidar", station_id})) return false;
      for (const SessionRecord* session : sessions_)
        if (!watch_.motions_for.count({PipelineWatch::CameraKey(session->camera()), station_id})) return false;
      if (watch_.failed_for.count(station_id)) return true;  // no round starts for a failed motion
      for (const SessionRecord* session : sessions_) {
        const extrinsic_t* e = session->Final();
        if (!e || RoundRunning(*e) || !session->MotionToWasTaken(station_id)) return false;
      }
      return true;
    };
  }

  // This run plays a log and waits for the stages.
  bool PacedReplay() const { return player_ && !options_.live; }
  // The detector runs here on a replay that waits for it (started with --paced).
  bool DetectorIsPaced() const {
    return PacedReplay() && use_detector_ && std::find(names_.begin(), names_.end(), "stationarity") != names_.end();
  }
  // The raw frames the detector has done, lost ones included, by its latest STATUS.
  long DetectorFramesDone() const {
    const auto it = session_.stage_counters().find("stationarity");
    if (it == session_.stage_counters().end()) return 0;
    return static_cast<long>(StageCounter(it->second, "frames_done") + StageCounter(it->second, "bus_dropped"));
  }
  // Keeps at most kFramesInFlight raw frames ahead of what the detector has done, however slow it is, so
  // that none is lost on the way (a DDS reader keeps 8 raw frames): measured on a loaded machine, the
  // detector lost 2 frames without this and the run ended 0.006 deg from `calibrate`. The replay clock
  // does not run meanwhile. A frame lost on the way counts when a later one arrives; at the end of the
  // log, the wait gives up after kDetectorWait_s.
  void WaitForDetector() {
    const auto wait_start = Clock::now();
    Pump(kDetectorWait_s, [&] {
      const auto pid = watch_.pids.find("stationarity");
      if (pid == watch_.pids.end()) return false;
      // A new detector process counts from 0: what it has not seen is not in flight.
      const long done = DetectorFramesDone();
      if (pid->second != detector_pid_) {
        detector_pid_ = pid->second;
        detector_base_ = raw_frames_played_ - done;
      }
      return raw_frames_played_ - detector_base_ - done <= kFramesInFlight;
    });
    replay_start_ += Clock::now() - wait_start;
  }

  // Waits until the pipeline has dealt with the station; the replay clock does not run meanwhile.
  void WaitForStation(int station_id) {
    const auto wait_start = Clock::now();
    Pump(config_.idle_timeout_s, SettledAfter(station_id, stations_published_++ == 0));
    replay_start_ += Clock::now() - wait_start;
  }

  void ReplayLog() {
    LogReader reader(options_.log_path);
    replay_start_ = Clock::now();  // moved later by the time spent waiting for the stages
    replay_start_wall_utime_ = NowUtime();
    while (!stop_) {
      auto ev = reader.Next();
      if (!ev) break;
      const std::string& ch = ev->channel;
      if (!FeedsPipeline(ch, use_detector_)) continue;
      if (first_utime_ < 0) first_utime_ = ev->utime;
      last_utime_ = std::max(last_utime_, ev->utime);
      if (options_.speed > 0) {
        const auto due =
            replay_start_ + std::chrono::microseconds(int64_t((ev->utime - first_utime_) / options_.speed));
        Pump(std::chrono::duration<double>(due - Clock::now()).count(), nullptr);
      }
      if (ResupplyPending()) Pump(config_.idle_timeout_s, [&] { return !ResupplyPending(); });
      const size_t stations_before = session_.stations().size();
      bus_->PublishRaw(ch, ev->data.data(), ev->data.size());
      if (TraitsOfChannel(ch).kind == ChannelKind::kBulk && DetectorIsPaced()) {
        ++raw_frames_played_;
        WaitForDetector();
      }
      // A station of the log is played when every camera's copy of it is.
      int complete_station = -1;
      if (PipelineChannelOf(ch) == channels::kStation.name) {
        station_t s{};
        s.decode(ev->data.data(), 0, static_cast<int>(ev->data.size()));
        if (++station_copies_[s.id] == static_cast<int>(config_.cameras.size())) {
          complete_station = s.id;
          ++stations_played_;
        }
      }
      if (options_.live) continue;  // sensors do not wait
      if (complete_station >= 0) {
        WaitForStation(complete_station);
      } else if (PipelineChannelOf(ch) != channels::kStation.name) {
        // Raw frames as fast as possible still leave the detector ~20 ms each (it needs ~15 ms).
        Pump(options_.speed > 0 ? 0.001 : 0.02, nullptr);
        if (session_.stations().size() > stations_before) WaitForStation(session_.stations().rbegin()->first);
      }
    }
    for (const auto& problem : reader.problems()) event_("log " + options_.log_path + ": " + problem);
    report_.replay_seconds = Seconds(replay_start_);
    const auto after_log = Clock::now();
    if (options_.live) WaitForEveryStation();
    // Let the last round of every camera finish.
    Pump(config_.idle_timeout_s, [&] {
      for (const SessionRecord* session : sessions_) {
        const extrinsic_t* e = session->Final();
        if (e && RoundRunning(*e)) return false;
      }
      return true;
    });
    report_.after_log_seconds = Seconds(after_log);
  }

  bool AllStopped() const {
    for (const auto& name : names_) {
      const auto state = session_.stage_states().find(name);
      if (state == session_.stage_states().end() || state->second.first != "stopped") return false;
    }
    return true;
  }

  // Live: the log has ended but the stages may still be working on its last stations.
  void WaitForEveryStation() {
    Pump(config_.idle_timeout_s, [&] {
      // The last stations played may not be back from the bus yet.
      if (session_.stations().size() < stations_played_) return false;
      for (const auto& [id, station] : session_.stations())
        if (!SettledAfter(id, id == session_.stations().begin()->first)()) return false;
      return true;
    });
  }

  RunReport Finish() {
    report_.bus_counts_losses = url_.rfind("dds://", 0) == 0 || url_.rfind("iox://", 0) == 0;
    if (player_) PublishPlayerStatus("done");  // the runs on other hosts stop their stages and write outputs
    supervisor_.Stop();
    transport_.Stop();  // after the stages: stopping RouDi ends whatever is still attached to it
    report_.roudi_restarts = transport_.roudi_restarts();
    // The stages' last STATUS ("stopped", with their final counters), for at most half a second.
    for (const auto end = Clock::now() + std::chrono::milliseconds(500); Clock::now() < end && !AllStopped();)
      bus_->Handle(20);
    if (player_) PublishPlayerStatus("done");  // again, in case the first was lost
    report_.stage_counters = session_.stage_counters();
    // A live ROS 2 robot: realtime factors against the span of the sensor stamps it sent.
    if (options_.ros2 && report_.stage_counters.count("ros2_input"))
      report_.span_s = StageCounter(report_.stage_counters.at("ros2_input"), "stream_span_s");
    report_.bus_dropped = static_cast<double>(bus_->dropped_messages());
    for (const auto& [name, counters] : report_.stage_counters)
      report_.bus_dropped += StageCounter(counters, "bus_dropped");
    if (player_) report_.span_s = first_utime_ < 0 ? 0.0 : (last_utime_ - first_utime_) * 1e-6;
    for (auto& record : records_) record->Close();
    if (config_.cameras.front().empty()) {
      report_.outputs = WriteCalibrationOutputs(session_, options_.out_dir);
    } else {
      report_.rig = WriteRigOutputs(sessions_, options_.out_dir);
      report_.outputs = report_.rig->cameras.front().outputs;
    }
    AddOutputFile(&report_.outputs,
                  [&] { return WriteStageTable(options_.out_dir, report_.stage_counters, report_.span_s); });
    if (options_.live && first_utime_ >= 0) {
      const double speed = options_.speed > 0 ? options_.speed : 1.0;
      report_.latencies = StationLatencies(session_, first_utime_, [&](int64_t log_utime) {
        return replay_start_wall_utime_ + static_cast<int64_t>((log_utime - first_utime_) / speed);
      });
      AddOutputFile(&report_.outputs, [&] { return WriteLatencyTable(options_.out_dir, report_.latencies); });
    }
    return report_;
  }

  const PipelineConfig& config_;
  const RunOptions& options_;
  const std::atomic<bool>& stop_;
  const std::function<void(const std::string&)>& progress_;
  const std::function<void(const std::string&)>& event_;
  const bool player_;  // this run plays a log
  static constexpr long kFramesInFlight = 4;
  static constexpr double kDetectorWait_s = 5;
  long raw_frames_played_ = 0;  // to the detector
  long detector_base_ = 0;      // raw_frames_played_ less frames done when its process first reported
  int detector_pid_ = 0;
  const std::string url_;
  const bool use_detector_;
  SharedMemoryTransport transport_;
  std::unique_ptr<Bus> bus_;
  std::vector<std::unique_ptr<SessionRecord>> records_;  // one per camera
  SessionRecord& session_;                               // the first camera's: the rig's stations, STATUS
  const std::vector<const SessionRecord*> sessions_;
  PipelineWatch watch_;
  const StageSplit split_;
  Supervisor supervisor_;
  std::vector<std::string> names_;
  RunReport report_;
  std::map<std::string, pid_t> resupplied_;  // stage -> pid that was given the stations again
  Clock::time_point first_ready_{};          // when the first restarted stage waiting for them was up
  static constexpr std::chrono::seconds kResupplyWait{5};
  std::string last_progress_;
  int stations_published_ = 0;
  size_t stations_played_ = 0;         // stations of the log published, every camera's (stations from the log)
  std::map<int, int> station_copies_;  // station id -> cameras whose STATION of it was published
  int written_version_ = -1;           // ros2: the last converged version written to extrinsic.yaml
  std::string written_rig_versions_;   // ros2, a rig: each camera's version last written
  Clock::time_point replay_start_, last_player_status_;
  int64_t replay_start_wall_utime_ = 0;
  int64_t first_utime_ = -1, last_utime_ = -1;  // of the events played
};

}  // namespace

RunReport RunPipeline(const PipelineConfig& config, const RunOptions& options, const std::atomic<bool>& stop,
                      const std::function<void(const std::string&)>& progress,
                      const std::function<void(const std::string&)>& event) {
  const auto start = Clock::now();
  std::filesystem::create_directories(options.out_dir);
  if (options.ros2)
    if (const std::string problem = config.ros2_input.RigProblem(); !problem.empty())
      throw std::runtime_error(config.path + ": ros2_input." + problem);
  PipelineConfig effective = config;
  if (!options.log_path.empty() && config.cameras.front().empty()) {
    // The stage processes read their rig from the config file: the log's cameras go into a copy of it.
    if (const std::vector<std::string> named = CamerasInLog(options.log_path); !named.empty()) {
      effective.path = WriteConfigWithCameras(config.path, named, options.out_dir + "/pipeline.yaml");
      SetRigCameras(&effective, named);
      event("the log's cameras: " + JoinNames(named) + " (each calibrated; " + named.front() +
            " decides the stations; their config: " + effective.path + ", which stages on other hosts need too)");
    }
  }
  PipelineRun run(effective, options, stop, progress, event);
  RunReport report = run.Run();
  report.total_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace fusecal
