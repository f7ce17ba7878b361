#include "pipeline/run.hpp"

#include <chrono>
#include <filesystem>
#include <set>
#include <thread>

#include "fusecal/motion_t.hpp"
#include "fusecal/station_t.hpp"
#include "fusecal/status_t.hpp"
#include "pipeline/session.hpp"
#include "pipeline/shm_transport.hpp"
#include "pipeline/supervisor.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"

namespace fusecal {

namespace {

using Clock = std::chrono::steady_clock;

// Watches the bus for what tells the player that the pipeline has dealt with a station.
struct PipelineWatch {
  std::set<std::pair<std::string, int>> motions_for;  // (sensor, station_j), valid or failed
  std::set<int> failed_for;                           // station_j of failed motions
  std::set<std::string> alive;                        // stage names that sent STATUS
  std::map<std::string, int> pids;                    // stage name -> pid of its latest STATUS
  std::vector<Subscription> subs;

  explicit PipelineWatch(Bus& bus) {
    auto on_motion = [this](const RawMessage& raw) {
      motion_t m{};
      if (m.decode(raw.data, 0, static_cast<int>(raw.size)) < 0) return;
      motions_for.insert({m.sensor, m.station_j});
      if (!m.valid) failed_for.insert(m.station_j);
    };
    subs.push_back(bus.SubscribeRaw(channels::kLidarMotion, on_motion));
    subs.push_back(bus.SubscribeRaw(channels::kCameraMotion, on_motion));
    subs.push_back(bus.SubscribeRaw(channels::kStatus, [this](const RawMessage& raw) {
      status_t s{};
      if (s.decode(raw.data, 0, static_cast<int>(raw.size)) < 0 || s.state == "stopped") return;
      alive.insert(s.name);
      pids[s.name] = s.pid;
    }));
  }
};

// "refining" asks for fused motions; "initial" (the scaleless record) is always followed by "refining".
bool RoundRunning(const extrinsic_t& e) { return e.status == "refining" || e.status == "initial"; }

}  // namespace

RunReport RunPipeline(const PipelineConfig& config, const RunOptions& options, const std::atomic<bool>& stop,
                      const std::function<void(const std::string&)>& progress,
                      const std::function<void(const std::string&)>& event) {
  const auto start = Clock::now();
  std::filesystem::create_directories(options.out_dir);
  const std::string url = options.bus_url.empty() ? (config.bus_url.empty() ? DefaultBusUrl() : config.bus_url)
                                                   : options.bus_url;
  const bool use_detector = config.stations_from == "detector" ||
                            (config.stations_from == "auto" && (options.log_path.empty() || !LogHasStations(options.log_path)));
  // With shm=1, RouDi is started here and the coordinator stays on the network path (shm_transport.hpp).
  SharedMemoryTransport transport(url, config, options.out_dir, event);
  auto bus = MakeBus(transport.coordinator_url());
  SessionRecord session(*bus, options.out_dir + "/session.lcmlog", true);
  PipelineWatch watch(*bus);

  Supervisor supervisor(options.out_dir);
  std::vector<std::string> names = {"lidar_icp", "camera_frontend", "fusion_odometry", "handeye"};
  if (use_detector) names.insert(names.begin(), "stationarity");
  for (const auto& name : names) {
    std::string exe = name;
    std::replace(exe.begin(), exe.end(), '_', '-');
    supervisor.Add({name, ExecutableDir() + "/fusecal-" + exe, {"--config", config.path, "--bus", transport.stage_url()}});
  }
  supervisor.StartAll();
  RunReport report;

  // Pumps the bus for up to `seconds`, restarting dead stages; returns early when `done` holds.
  std::map<std::string, pid_t> resupplied;  // stage -> pid that was given the stations again
  auto pump = [&](double seconds, const std::function<bool()>& done) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    std::string last_line;
    while (!stop && Clock::now() < end) {
      if (done && done()) return true;
      try {
        bus->Handle(20);
      } catch (const std::exception& e) {
        event(std::string("bus: ") + e.what());
      }
      // RouDi gone: its stages were ended with it (or are cut off from the new one): all start again.
      if (const std::string before = transport.stage_url(); transport.RestartIfDead()) {
        supervisor.ReplaceArgument(before, transport.stage_url());
        supervisor.RestartAll();
        report.restarts += static_cast<int>(names.size());
        event("every stage restarted after RouDi; they get the stations again once they are up");
      }
      for (const auto& e : supervisor.Poll()) {
        ++report.restarts;
        event(e + "; it gets the stations again once it is up");
      }
      // A restarted stage (new pid in its heartbeat) needs the stations; the others ignore stations
      // they have seen and republish their motions of them, which a restarted hand-eye stage needs.
      for (const auto& p : supervisor.processes()) {
        const auto beat = watch.pids.find(p.name);
        if (p.restarts == 0 || beat == watch.pids.end() || beat->second != p.pid || resupplied[p.name] == p.pid)
          continue;
        resupplied[p.name] = p.pid;
        for (const auto& [id, station] : session.stations()) bus->Publish(channels::kStation, station);
      }
      const std::string line = ProgressText(session);
      if (line != last_line) progress(last_line = line);
    }
    return done ? done() : true;
  };

  if (!pump(30, [&] { return watch.alive.size() == names.size(); }))
    throw std::runtime_error("not every stage started within 30 s (see " + options.out_dir + "/<stage>.log)");

  // The pipeline has dealt with station k when both motions ending at k are out and, if they are good,
  // a round that took them in (or rejected them) has ended.
  auto mentions = [](const extrinsic_t& e, int station) {
    for (int k = 0; k < e.num_used; ++k)
      if (e.used_station_j[k] == station) return true;
    for (int k = 0; k < e.num_rejected; ++k)
      if (e.rejected_station_j[k] == station) return true;
    return false;
  };
  auto settled_after = [&](int station_id, bool first) {
    return [&, station_id, first] {
      if (first) return true;
      if (!watch.motions_for.count({"lidar", station_id}) || !watch.motions_for.count({"camera", station_id}))
        return false;
      if (watch.failed_for.count(station_id)) return true;  // no round starts for a failed motion
      const extrinsic_t* e = session.Final();
      return e && !RoundRunning(*e) && mentions(*e, station_id);
    };
  };

  if (!options.log_path.empty()) {
    LogReader reader(options.log_path);
    int64_t first_utime = -1;
    int stations_published = 0;
    auto replay_start = Clock::now();  // moved later by the time spent waiting for the stages
    while (!stop) {
      auto ev = reader.Next();
      if (!ev) break;
      const std::string& ch = ev->channel;
      const bool station = ch == channels::kStation;
      if (!FeedsPipeline(ch, use_detector)) continue;
      if (first_utime < 0) first_utime = ev->utime;
      if (options.speed > 0) {
        const auto due = replay_start + std::chrono::microseconds(int64_t((ev->utime - first_utime) / options.speed));
        pump(std::chrono::duration<double>(due - Clock::now()).count(), nullptr);
      }
      const size_t stations_before = session.stations().size();
      bus->PublishRaw(ch, ev->data.data(), ev->data.size());
      if (station) {
        station_t s{};
        s.decode(ev->data.data(), 0, static_cast<int>(ev->data.size()));
        const auto wait_start = Clock::now();
        pump(config.idle_timeout_s, settled_after(s.id, stations_published++ == 0));
        replay_start += Clock::now() - wait_start;
      } else {
        // Raw frames as fast as possible still leave the detector ~20 ms each (it needs ~15 ms).
        pump(options.speed > 0 ? 0.001 : 0.02, nullptr);
        if (session.stations().size() > stations_before) {  // the detector emitted a station
          const auto wait_start = Clock::now();
          pump(config.idle_timeout_s, settled_after(session.stations().rbegin()->first, stations_published++ == 0));
          replay_start += Clock::now() - wait_start;
        }
      }
    }
    for (const auto& problem : reader.problems()) event("log: " + problem);
    // Let the last round finish.
    pump(config.idle_timeout_s, [&] {
      const extrinsic_t* e = session.Final();
      return !e || !RoundRunning(*e);
    });
  } else {
    event("listening to live sensors on " + url + " (Ctrl-C to stop)");
    pump(1e9, nullptr);
  }
  for (const auto& [name, seconds] : session.stage_busy_s()) report.stage_seconds[name] = seconds;
  report.used_dds = url.rfind("dds://", 0) == 0;
  report.bus_dropped = static_cast<double>(bus->dropped_messages());
  for (const auto& [name, dropped] : session.stage_bus_dropped()) report.bus_dropped += dropped;
  supervisor.Stop();
  transport.Stop();  // after the stages: stopping RouDi ends whatever is still attached to it
  report.roudi_restarts = transport.roudi_restarts();
  bus->Handle(0);
  session.Close();
  report.outputs = WriteCalibrationOutputs(session, options.out_dir);
  report.total_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return report;
}

}  // namespace fusecal
