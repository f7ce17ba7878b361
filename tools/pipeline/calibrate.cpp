#include "pipeline/calibrate.hpp"

#include <chrono>
#include <filesystem>

#include "pipeline/stage_nodes.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"

namespace fusecal {

CalibrateReport RunCalibrate(const std::string& log_path, const std::string& out_dir, const PipelineConfig& config,
                             const std::function<void(const std::string&)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  std::filesystem::create_directories(out_dir);
  const bool use_detector =
      config.stations_from == "detector" || (config.stations_from == "auto" && !LogHasStations(log_path));
  auto bus = MakeBus("memq://");
  PipelineConfig in_process = config;
  in_process.handeye.retry_s = 0;  // memq loses nothing; retries would only make runs differ
  SessionRecord session(*bus, out_dir + "/session.lcmlog", false);
  std::vector<NamedNode> nodes = MakeStageNodes(in_process, use_detector);
  for (auto& n : nodes) n.node->Start(*bus);

  size_t stations_seen = 0, versions_seen = 0;
  auto drain = [&] {
    // A stage that fails on one message (a corrupt image, a bad scan) says why and goes on, as its
    // process would: nothing computed so far is lost.
    for (;;) {
      try {
        if (bus->Handle(0) == 0) break;
      } catch (const std::exception& e) {
        if (progress) progress(std::string("stage error (continuing): ") + e.what());
      }
    }
    if (progress && (session.stations().size() != stations_seen || session.extrinsics().size() != versions_seen)) {
      stations_seen = session.stations().size();
      versions_seen = session.extrinsics().size();
      progress(ProgressText(session));
    }
  };
  LogReader reader(log_path);
  while (auto event = reader.Next()) {
    if (!FeedsPipeline(event->channel, use_detector)) continue;
    bus->PublishRaw(event->channel, event->data.data(), event->data.size());
    drain();
  }
  for (auto& n : nodes) n.node->Flush(*bus);
  drain();
  for (const auto& problem : reader.problems()) progress ? progress("log: " + problem) : void();

  CalibrateReport report;
  for (auto& n : nodes) {
    const StageStatus status = n.node->Status();
    const auto busy = status.counters.find("busy_s");
    report.stage_seconds[n.name] = busy == status.counters.end() ? 0.0 : busy->second;
  }
  session.Close();
  report.stations = static_cast<int>(session.stations().size());
  report.outputs = WriteCalibrationOutputs(session, out_dir);
  report.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace fusecal
