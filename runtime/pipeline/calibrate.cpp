#include "runtime/pipeline/calibrate.hpp"

#include <chrono>
#include <filesystem>

#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "runtime/pipeline/stage_nodes.hpp"

namespace fusecal {

namespace {

// Each node's work from its last status: every counter (stages.csv).
void RecordStageWork(const std::vector<NamedNode>& nodes, CalibrateReport* report) {
  for (const auto& n : nodes) report->stage_counters[n.name] = n.node->Status().counters;
}

// The five nodes on one memq bus: every message is handled and every node's queued work done before
// the next event of the log (deterministic).
class InProcessPipeline {
 public:
  InProcessPipeline(Bus& bus, std::vector<NamedNode>& nodes, const std::vector<const SessionRecord*>& sessions,
                    const std::function<void(const std::string&)>& progress)
      : bus_(bus), nodes_(nodes), sessions_(sessions), progress_(progress) {}

  // Until nothing moves: every message handled, every node's queued work done.
  void Drain() {
    for (;;) {
      while (HandleOnce() > 0) {
      }
      if (TickAll() || AnyQueuedWork()) continue;
      if (HandleOnce() == 0) break;
    }
    size_t stations = 0, versions = 0;
    for (const SessionRecord* session : sessions_) {
      stations += session->stations().size();
      versions += session->extrinsics().size();
    }
    if (progress_ && (stations != stations_seen_ || versions != versions_seen_)) {
      stations_seen_ = stations;
      versions_seen_ = versions;
      progress_(RigProgressText(sessions_));
    }
  }

 private:
  // A stage that fails on one message (a corrupt image, a bad scan) says why and goes on, as its process
  // would: nothing computed so far is lost.
  void ReportError(const std::exception& e) {
    if (progress_) progress_(std::string("stage error (continuing): ") + e.what());
  }
  int HandleOnce() {
    try {
      return bus_.Handle(0);
    } catch (const std::exception& e) {
      ReportError(e);
      return 1;
    }
  }
  // Each node's Tick does its queued work (the detector takes its frames); true when one failed.
  bool TickAll() {
    bool failed = false;
    for (auto& n : nodes_) {
      try {
        n.node->Tick(bus_, NowUtime());
      } catch (const std::exception& e) {
        ReportError(e);
        failed = true;
      }
    }
    return failed;
  }

  bool AnyQueuedWork() const {
    for (const auto& n : nodes_)
      if (n.node->HasQueuedWork()) return true;
    return false;
  }

  Bus& bus_;
  std::vector<NamedNode>& nodes_;
  const std::vector<const SessionRecord*>& sessions_;
  const std::function<void(const std::string&)>& progress_;
  size_t stations_seen_ = 0, versions_seen_ = 0;
};

}  // namespace

CalibrateReport RunCalibrate(const std::string& log_path, const std::string& out_dir, const PipelineConfig& config,
                             const std::function<void(const std::string&)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  std::filesystem::create_directories(out_dir);
  const bool use_detector =
      config.stations_from == "detector" || (config.stations_from == "auto" && !LogHasStations(log_path));
  auto bus = MakeBus("memq://");
  PipelineConfig in_process = config;
  in_process.handeye.calibrator.retry_s = 0;    // memq loses nothing; retries would only make runs differ
  in_process.fusion_odometry.input_wait_s = 0;  // memq keeps the order: what is missing never comes
  if (const std::vector<std::string> named = CamerasInLog(log_path);
      !named.empty() && config.cameras == std::vector<std::string>{""}) {
    SetRigCameras(&in_process, named);
    std::string names;
    for (const auto& name : named) names += (names.empty() ? "" : ", ") + name;
    if (progress)
      progress("the log's cameras: " + names + " (each calibrated; " + named.front() + " decides the stations)");
  }
  // One record per camera; the first writes the session log (the stations: the input log has the raw frames).
  std::vector<std::unique_ptr<SessionRecord>> records =
      MakeSessionRecords(*bus, out_dir, RecordSettings{}, in_process.cameras);
  std::vector<const SessionRecord*> sessions;
  for (const auto& record : records) sessions.push_back(record.get());
  const SessionRecord& session = *records.front();
  std::vector<NamedNode> nodes = MakeStageNodes(in_process, use_detector);
  for (auto& n : nodes) n.node->Start(*bus);
  InProcessPipeline pipeline(*bus, nodes, sessions, progress);

  LogReader reader(log_path);
  int64_t first_utime = -1, last_utime = -1;
  while (auto event = reader.Next()) {
    if (!FeedsPipeline(event->channel, use_detector)) continue;
    if (first_utime < 0) first_utime = event->utime;
    last_utime = std::max(last_utime, event->utime);
    bus->PublishRaw(event->channel, event->data.data(), event->data.size());
    pipeline.Drain();
  }
  for (auto& n : nodes) n.node->Flush(*bus);
  pipeline.Drain();
  for (const auto& problem : reader.problems()) progress ? progress("log " + log_path + ": " + problem) : void();
  if (first_utime < 0 && progress)
    progress("log " + log_path + ": no event that feeds the pipeline (an empty log, not an LCM event log, or " +
             (use_detector ? "no CAMERA_IMAGE / LIDAR_SCAN)" : "no STATION)"));

  CalibrateReport report;
  RecordStageWork(nodes, &report);
  for (auto& record : records) record->Close();
  report.stations = static_cast<int>(session.stations().size());
  report.span_s = first_utime < 0 ? 0.0 : (last_utime - first_utime) * 1e-6;
  const auto outputs_start = std::chrono::steady_clock::now();
  if (in_process.cameras.front().empty()) {
    report.outputs = WriteCalibrationOutputs(session, out_dir);
  } else {
    report.rig = WriteRigOutputs(sessions, out_dir);
    report.outputs = report.rig->cameras.front().outputs;
  }
  AddOutputFile(&report.outputs, [&] { return WriteStageTable(out_dir, report.stage_counters, report.span_s); });
  report.outputs_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - outputs_start).count();
  report.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace fusecal
