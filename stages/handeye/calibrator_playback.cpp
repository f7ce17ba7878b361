#include "stages/handeye/calibrator_playback.hpp"

#include <map>

namespace fusecal {

namespace {

SensorMotion Motion(SensorMotion::Sensor sensor, const StationPair& key, const Isometry3& T, bool scaled) {
  SensorMotion m;
  m.sensor = sensor;
  m.station_i = key.first;
  m.station_j = key.second;
  m.valid = true;
  m.scaled = scaled;
  m.T_i_j = T;
  return m;
}

}  // namespace

void PlayMetricPairs(Calibrator& calibrator, const std::vector<MotionPair>& pairs, int from, int to,
                     const FusedAnswer& answer) {
  std::map<StationPair, const MotionPair*> metric;
  for (const auto& p : pairs) metric[{p.station_i, p.station_j}] = &p;
  if (to < 0) to = static_cast<int>(pairs.size());
  for (int k = from; k < to; ++k) {
    const StationPair key{pairs[k].station_i, pairs[k].station_j};
    Isometry3 direction = pairs[k].A;
    direction.translation().normalize();
    calibrator.OnMotion(Motion(SensorMotion::Sensor::kLidar, key, pairs[k].B, false), 0);
    std::vector<CalibrationVersion> versions =
        calibrator.OnMotion(Motion(SensorMotion::Sensor::kCamera, key, direction, false), 0);
    while (!versions.empty() && versions.back().asks()) {
      std::vector<SensorMotion> fused;
      for (const StationPair& asked : versions.back().used) {
        const MotionPair& pair = *metric.at(asked);
        const Isometry3 A = answer ? answer(versions.back(), pair) : pair.A;
        fused.push_back(Motion(SensorMotion::Sensor::kCamera, asked, A, true));
      }
      versions = calibrator.OnFusedMotions(versions.back().version, fused, 0);
    }
  }
}

}  // namespace fusecal
