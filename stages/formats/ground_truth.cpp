#include "formats/ground_truth.hpp"

#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "formats/result_file.hpp"

namespace fusecal {

std::optional<ground_truth_t> ReadGroundTruth(const std::string& log_path) {
  LogReader reader(log_path);
  std::optional<ground_truth_t> truth;
  while (auto event = reader.Next()) {
    if (event->channel != channels::kGroundTruth) continue;
    ground_truth_t message{};
    if (message.decode(event->data.data(), 0, static_cast<int>(event->data.size())) >= 0) truth = message;
  }
  return truth;
}

std::optional<int> TruthStationAt(const ground_truth_t& truth, int64_t utime) {
  for (int k = 0; k < truth.num_stations; ++k)
    if (truth.still_from_utime[k] <= utime && utime <= truth.still_to_utime[k]) return k;
  return std::nullopt;
}

Isometry3 ReadReferenceExtrinsic(const std::string& path) {
  const auto ends_with = [&](const std::string& suffix) {
    return path.size() >= suffix.size() && path.compare(path.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (ends_with(".yaml") || ends_with(".yml")) return ReadResultFile(path).T_camera_lidar;
  const auto truth = ReadGroundTruth(path);
  if (!truth) throw std::runtime_error(path + ": the log has no GROUND_TRUTH message");
  return FromRowMajor(truth->T_camera_lidar);
}

}  // namespace fusecal
