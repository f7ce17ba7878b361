#include "runtime/pipeline/stage_table.hpp"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <sstream>

#include "runtime/output_file.hpp"

namespace fusecal {

double StageCounter(const std::map<std::string, double>& counters, const std::string& name) {
  const auto it = counters.find(name);
  return it == counters.end() ? 0.0 : it->second;
}

std::string StageBusyText(const StageCounters& stages) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(2);
  for (const auto& [stage, c] : stages) out << " " << stage << " " << StageCounter(c, "busy_s") << " s";
  return out.str();
}

std::string WriteStageTable(const std::string& dir, const StageCounters& stages, double span_s) {
  const std::string path = dir + "/stages.csv";
  std::ostringstream file;
  file << "stage,items,mean_ms,p95_ms,busy_s,skipped,realtime_factor\n";
  char line[256];
  for (const auto& [stage, c] : stages) {
    const double busy = StageCounter(c, "busy_s");
    std::snprintf(line, sizeof(line), "%s,%.0f,%.2f,%.2f,%.3f,%.0f,%.4f\n", stage.c_str(), StageCounter(c, "items"),
                  StageCounter(c, "item_ms_mean"), StageCounter(c, "item_ms_p95"), busy, StageCounter(c, "skipped"),
                  span_s > 0 ? busy / span_s : 0.0);
    file << line;
  }
  WriteFileChecked(path, file.str());
  return path;
}

std::string StageTableText(const StageCounters& stages, double span_s) {
  std::ostringstream out;
  char line[256];
  int width = 16;  // the longest name (a rig's per-camera stages: camera_frontend/<camera>)
  for (const auto& entry : stages) width = std::max(width, static_cast<int>(entry.first.size()));
  for (const auto& [stage, c] : stages) {
    const double busy = StageCounter(c, "busy_s");
    std::snprintf(line, sizeof(line),
                  "  %-*s %5.0f items, %8.2f ms mean, %8.2f ms p95, %7.2f s busy, %4.0f skipped, "
                  "realtime factor %.3f\n",
                  width, stage.c_str(), StageCounter(c, "items"), StageCounter(c, "item_ms_mean"),
                  StageCounter(c, "item_ms_p95"), busy, StageCounter(c, "skipped"), span_s > 0 ? busy / span_s : 0.0);
    out << line;
  }
  return out.str();
}

}  // namespace fusecal
