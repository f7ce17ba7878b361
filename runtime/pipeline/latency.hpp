// Latency of the online answer, per station: from the end of the station (the rig starts moving again)
// to the receipt of the first EXTRINSIC that took the station's motion into account (used or rejected
// it; with fewer than min_pairs motions that answer is "too few motions"), and to the first scaled
// EXTRINSIC that used it. The end is the ground truth's still interval containing the station when the
// log has one, else the station's own still_to. A negative latency: answered before the stop ended.
// Measured in live runs (`fusecal run --live`), where log time maps onto the wall clock.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "runtime/pipeline/session.hpp"

namespace fusecal {

struct StationLatency {
  int station = -1;
  double end_s = 0;         // end of the station, seconds from the start of the recording
  int version = -1;         // the first EXTRINSIC that used or rejected a motion ending there; -1: none
  double latency_s = 0;     // receipt of that version - end of the station (wall clock)
  int scaled_version = -1;  // the first scaled EXTRINSIC that used such a motion; -1: none
  double scaled_latency_s = 0;
  int changed_after_station = -1;  // the newest change of the extrinsic that version knew of; -1: none
};

// `wall_utime_of_log`: the wall-clock utime at which the player reached a log utime. Stations without a
// motion to an earlier station (the first) are left out.
std::vector<StationLatency> StationLatencies(const SessionRecord& session, int64_t first_log_utime,
                                             const std::function<int64_t(int64_t)>& wall_utime_of_log);

// One line: stations answered, mean and max latency (empty when there are none).
std::string LatencyText(const std::vector<StationLatency>& latencies);

// <dir>/latency.csv: station,end_s,extrinsic_version,latency_s,scaled_version,scaled_latency_s,
// changed_after_station (empty latencies when never answered; -1: no change of the extrinsic known).
std::string WriteLatencyTable(const std::string& dir, const std::vector<StationLatency>& latencies);

}  // namespace fusecal
