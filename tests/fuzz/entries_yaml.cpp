// Fuzz entries of the YAML loaders (fuzz_entries.hpp): the bytes are a whole file.
#include <string>

#include "fuzz_entries.hpp"
#include "fuzz_support.hpp"
#include "runtime/pipeline/pipeline_config.hpp"
#include "runtime/sim/simulator/scenario.hpp"
#include "stages/formats/camera_file.hpp"
#include "stages/formats/ground_truth.hpp"
#include "stages/formats/result_file.hpp"

namespace fusecal::fuzz {

namespace {

std::string Text(const uint8_t* data, size_t size) { return std::string(reinterpret_cast<const char*>(data), size); }

}  // namespace

int FuzzOnePipelineConfig(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile("pipeline.yaml", data, size);
  IgnoringRejection([&] { LoadPipelineConfig(path); });  // every stage's settings and their checks
  return 0;
}

int FuzzOneScenario(const uint8_t* data, size_t size) {
  IgnoringRejection([&] {
    const sim::Scenario scenario = sim::ParseScenario(Text(data, size));
    scenario.lidar.ElevationsRad();
    scenario.lidar.Columns();
  });
  return 0;
}

int FuzzOneResultFile(const uint8_t* data, size_t size) {
  const std::string path = WriteScratchFile("result.yaml", data, size);
  IgnoringRejection([&] { ReadResultFile(path); });
  IgnoringRejection([&] { ReadReferenceExtrinsic(path); });  // `fusecal evaluate --reference RESULT.yaml`
  return 0;
}

int FuzzOneCameraFile(const uint8_t* data, size_t size) {
  IgnoringRejection([&] { ParseCameraYaml(Text(data, size)); });
  return 0;
}

}  // namespace fusecal::fuzz
