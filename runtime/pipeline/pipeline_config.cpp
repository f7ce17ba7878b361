#include "runtime/pipeline/pipeline_config.hpp"

#include "runtime/bus_url.hpp"

namespace fusecal {

PipelineConfig LoadPipelineConfig(const std::string& path) {
  PipelineConfig c;
  c.path = path;
  ConfigReader root = ConfigReader::FromFile(path);
  ConfigReader bus = root.Child("bus");
  bus.Get<std::string>("url", &c.bus_url, [](const std::string& url) {
    try {
      ParseBusUrl(url);
      return std::string();
    } catch (const BusError& e) {
      return std::string(e.what());
    }
  });
  double max_message_mb = double(c.max_message_bytes) / 1e6;
  bus.Get("max_message_mb", &max_message_mb, Positive<double>());
  c.max_message_bytes = static_cast<size_t>(max_message_mb * 1e6);
  bus.Get("shm_chunks", &c.shm_chunks, Positive<int>());
  bus.Finish();
  root.Get("stations_from", &c.stations_from, OneOf({"auto", "detector", "log"}));
  c.cameras = ReadRigCameras(root);
  // One section per stage of the registry, read by the stage's own reader.
#define FUSECAL_STAGE(name, header, Settings, read, Node, in, out) c.name = read(root.Child(#name));
#include "stages/stages.def"
#undef FUSECAL_STAGE
  SetRigCameras(&c, c.cameras);
  ConfigReader run = root.Child("run");
  run.Get("idle_timeout_s", &c.idle_timeout_s, Positive<double>());
  run.Get("record", &c.record.what, OneOf({"all", "stations", "none"}));
  run.Get("record_max_raw_mb", &c.record.max_raw_mb, Positive<double>());
  run.Finish();
  root.Finish();
  if (c.lidar_icp.previous_stations != c.camera_frontend.previous_stations)
    root.Fail("camera_frontend.previous_stations", "must equal lidar_icp.previous_stations (the same pairs)");
  return c;
}

void SetRigCameras(PipelineConfig* c, const std::vector<std::string>& cameras) {
  c->cameras = cameras;
  Rig rig;
  rig.cameras = cameras;
#define FUSECAL_STAGE(name, header, Settings, read, Node, in, out) ApplyRig(rig, &c->name);
#include "stages/stages.def"
#undef FUSECAL_STAGE
}

std::string DefaultPipelineConfigPath() { return std::string(FUSECAL_SOURCE_DIR) + "/configs/pipeline.yaml"; }

}  // namespace fusecal
