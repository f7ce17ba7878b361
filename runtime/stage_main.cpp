#include "runtime/stage_main.hpp"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <csignal>
#include <iostream>

#include "fusecal/status_t.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/version.hpp"

namespace fusecal {

namespace {

std::atomic<bool> g_stop_requested{false};

void OnStopSignal(int) { g_stop_requested = true; }

std::string HostName() {
  char name[256] = {0};
  gethostname(name, sizeof(name) - 1);
  return name;
}

}  // namespace

ConfigReader StageSection(const std::string& config_path, const std::string& name) {
  ConfigReader root = ConfigReader::FromFile(config_path);
  return root.Child(name);
}

Rig StageRig(const std::string& config_path, const std::string& camera, bool per_camera) {
  Rig rig;
  if (!config_path.empty()) {
    ConfigReader root = ConfigReader::FromFile(config_path);
    rig.cameras = ReadRigCameras(root);
  }
  std::string names;
  for (const auto& name : rig.cameras) names += (names.empty() ? "" : ", ") + name;
  if (!camera.empty() && !per_camera)
    throw ConfigError("--camera " + camera + ": this stage serves the whole rig (leave --camera out)");
  if (!camera.empty() && !rig.Has(camera))
    throw ConfigError(
        "--camera " + camera + ": the rig of " + (config_path.empty() ? "the defaults" : config_path) +
        (rig.named() ? " has the cameras " + names : " has one camera without a name (leave --camera out)"));
  if (per_camera && camera.empty() && rig.named())
    throw ConfigError("the rig of " + config_path + " has the cameras " + names +
                      ": say which this process serves with --camera NAME");
  rig.camera = camera;
  return rig;
}

std::string StageStatusName(const std::string& stage, const std::string& camera) {
  return camera.empty() ? stage : stage + "/" + camera;
}

void PublishStatus(Bus& bus, const std::string& name, const StageStatus& status, const std::string& last_error) {
  status_t msg{};
  msg.utime = NowUtime();
  msg.name = name;
  msg.host = HostName();
  msg.pid = static_cast<int32_t>(getpid());
  msg.state = status.state;
  for (const auto& [counter, value] : status.counters) {
    msg.counter_names.push_back(counter);
    msg.counter_values.push_back(value);
  }
  // The bus's own loss count, so that an overloaded transport shows in every heartbeat.
  msg.counter_names.push_back("bus_dropped");
  msg.counter_values.push_back(static_cast<double>(bus.dropped_messages()));
  msg.num_counters = static_cast<int32_t>(msg.counter_names.size());
  msg.last_error = last_error;
  bus.Publish(channels::kStatus, msg);
}

int StageMain(int argc, char** argv, const StageDefinition& stage) {
  CLI::App app{stage.description, "fusecal-" + stage.name};
  std::string config_path = stage.default_config;
  std::string bus_url;
  app.add_option("--config", config_path, "YAML config of this stage");
  app.add_option("--bus", bus_url, "bus URL (default: $LCM_DEFAULT_URL or loopback multicast)");
  std::string camera;
  if (stage.per_camera)
    app.add_option("--camera", camera, "the camera this process serves, on a rig of several (the config's cameras)");
  bool paced = false;
  app.add_flag("--paced", paced,
               "the input is a replay that waits for the pipeline (fusecal run gives this): no raw frame is "
               "skipped to keep up");
  app.set_version_flag("--version", std::string(kFusecalVersion));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  const std::string status_name = StageStatusName(stage.name, camera);
  std::unique_ptr<StageNode> node;
  try {
    node = stage.make_node(config_path, camera);
    if (paced) node->UsePacedInput();
  } catch (const std::exception& e) {
    std::cerr << "fusecal-" << status_name << ": " << e.what() << "\n";
    return 2;
  }
  std::unique_ptr<Bus> bus;
  try {
    bus = MakeBus(bus_url);
    node->Start(*bus);
  } catch (const std::exception& e) {
    std::cerr << "fusecal-" << status_name << ": " << e.what() << "\n";
    return 1;
  }

  std::signal(SIGINT, OnStopSignal);
  std::signal(SIGTERM, OnStopSignal);
  std::string last_error;
  int64_t next_heartbeat = 0;
  std::cerr << "fusecal-" << status_name << ": running on " << bus->url() << "\n";
  while (!g_stop_requested) {
    try {
      bus->Handle(node->HasQueuedWork() ? 0 : node->TickPeriodMs());
      node->Tick(*bus, NowUtime());
    } catch (const std::exception& e) {
      if (g_stop_requested) break;  // a signal interrupted the wait: not an error
      last_error = e.what();
      std::cerr << "fusecal-" << status_name << ": error: " << last_error << " (still running)\n";
    }
    const int64_t now = NowUtime();
    if (node->WantsStatusNow() || now >= next_heartbeat) {
      try {
        PublishStatus(*bus, status_name, node->Status(), last_error);
      } catch (const std::exception& e) {
        std::cerr << "fusecal-" << status_name << ": heartbeat failed: " << e.what() << "\n";
      }
      next_heartbeat = now + 1000000;
    }
  }
  StageStatus final_status = node->Status();
  final_status.state = "stopped";
  try {
    PublishStatus(*bus, status_name, final_status, last_error);
  } catch (const std::exception&) {
  }
  std::cerr << "fusecal-" << status_name << ": stopped\n";
  return 0;
}

}  // namespace fusecal
