#include "runtime/pipeline/latency.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "runtime/output_file.hpp"
#include "stages/formats/extrinsic_status.hpp"
#include "stages/formats/ground_truth.hpp"

namespace fusecal {

namespace {

// The end of the still interval the station was taken in.
int64_t StationEnd(const SessionRecord& session, const StationTimes& station) {
  if (const auto& truth = session.ground_truth())
    if (const auto k = TruthStationAt(*truth, station.utime)) return truth->still_to_utime[*k];
  return station.still_to_utime;
}

}  // namespace

std::vector<StationLatency> StationLatencies(const SessionRecord& session, int64_t first_log_utime,
                                             const std::function<int64_t(int64_t)>& wall_utime_of_log) {
  std::vector<StationLatency> out;
  const auto& versions = session.extrinsics();
  const auto& received = session.extrinsic_receive_utimes();
  for (const auto& [id, station] : session.stations()) {
    if (id == session.stations().begin()->first) continue;  // no motion ends at the first station
    StationLatency l;
    l.station = id;
    const int64_t end = StationEnd(session, station);
    l.end_s = (end - first_log_utime) * 1e-6;
    const int64_t end_wall = wall_utime_of_log(end);
    for (size_t k = 0; k < versions.size(); ++k) {
      if (l.version < 0 && TookMotionTo(versions[k], id)) {
        l.version = versions[k].version;
        l.latency_s = (received[k] - end_wall) * 1e-6;
        if (versions[k].num_changes > 0) l.changed_after_station = versions[k].change_after_station.back();
      }
      if (l.scaled_version < 0 && versions[k].scaled && UsesMotionTo(versions[k], id)) {
        l.scaled_version = versions[k].version;
        l.scaled_latency_s = (received[k] - end_wall) * 1e-6;
      }
    }
    out.push_back(l);
  }
  return out;
}

std::string LatencyText(const std::vector<StationLatency>& latencies) {
  if (latencies.empty()) return {};
  int answered = 0, scaled = 0;
  double sum = 0, worst = -1e9, scaled_sum = 0, scaled_worst = -1e9;
  for (const auto& l : latencies) {
    if (l.version >= 0) {
      ++answered;
      sum += l.latency_s;
      worst = std::max(worst, l.latency_s);
    }
    if (l.scaled_version >= 0) {
      ++scaled;
      scaled_sum += l.scaled_latency_s;
      scaled_worst = std::max(scaled_worst, l.scaled_latency_s);
    }
  }
  char line[300];
  std::snprintf(line, sizeof(line),
                "station-to-extrinsic latency: %d of %zu stations answered, mean %.2f s, max %.2f s; first scaled "
                "estimate: %d, mean %.2f s, max %.2f s (latency.csv)\n",
                answered, latencies.size(), answered ? sum / answered : 0.0, answered ? worst : 0.0, scaled,
                scaled ? scaled_sum / scaled : 0.0, scaled ? scaled_worst : 0.0);
  return line;
}

std::string WriteLatencyTable(const std::string& dir, const std::vector<StationLatency>& latencies) {
  const std::string path = dir + "/latency.csv";
  std::ostringstream file;
  file << "station,end_s,extrinsic_version,latency_s,scaled_version,scaled_latency_s,changed_after_station\n";
  char line[160];
  for (const auto& l : latencies) {
    std::snprintf(line, sizeof(line), "%d,%.3f,", l.station, l.end_s);
    file << line;
    auto write = [&](int version, double latency) {
      if (version >= 0)
        std::snprintf(line, sizeof(line), "%d,%.3f", version, latency);
      else
        std::snprintf(line, sizeof(line), "-1,");
      file << line;
    };
    write(l.version, l.latency_s);
    file << ",";
    write(l.scaled_version, l.scaled_latency_s);
    file << "," << l.changed_after_station << "\n";
  }
  WriteFileChecked(path, file.str());
  return path;
}

}  // namespace fusecal
