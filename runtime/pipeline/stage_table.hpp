// The work of every stage in one table, from the counters of its last STATUS (runtime/work_stats.hpp):
// `stages.csv` in the output folder of `calibrate` and `run`, read by tools/bench-realtime.
//   stage,items,mean_ms,p95_ms,busy_s,skipped,realtime_factor
// realtime_factor = busy_s / the recording's span: below 1 the stage keeps up with the sensors.
#pragma once

#include <map>
#include <string>

namespace fusecal {

using StageCounters = std::map<std::string, std::map<std::string, double>>;

// Writes <dir>/stages.csv and returns its path.
std::string WriteStageTable(const std::string& dir, const StageCounters& stages, double span_s);

// A counter of one stage's STATUS, 0 when it has none.
double StageCounter(const std::map<std::string, double>& counters, const std::string& name);

// " <stage> <busy_s> s" for each stage, for the time line of `calibrate` and `run`.
std::string StageBusyText(const StageCounters& stages);

// One line per stage for the terminal.
std::string StageTableText(const StageCounters& stages, double span_s);

}  // namespace fusecal
