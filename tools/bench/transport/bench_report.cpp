#include "tools/bench/transport/bench_report.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace fusecal::bench {

namespace {

std::string Format(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

// Sums of delivered/sent and latency over a group of rows.
struct Tally {
  int sent = 0, delivered = 0;
  double latency_sum_ms = 0;  // mean latency x delivered, summed
  void Add(const BenchRow& row) {
    sent += row.sent;
    delivered += row.delivered;
    if (row.delivered > 0) latency_sum_ms += row.mean_ms * row.delivered;
  }
  std::string Delivery() const { return std::to_string(delivered) + "/" + std::to_string(sent); }
  std::string MeanLatency() const {
    return delivered > 0 ? Format("%.2f ms", latency_sum_ms / delivered) : std::string("-");
  }
};

}  // namespace

std::string RateLabel(int rate_hz) { return rate_hz > 0 ? std::to_string(rate_hz) + " Hz" : "flat out"; }

void WriteCsv(const std::string& path, const std::vector<BenchRow>& rows) {
  const auto parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  std::ofstream out(path);
  out << kCsvHeader << '\n';
  for (const auto& row : rows) {
    out << row.transport << ',' << row.size_bytes << ',' << row.rate_hz << ',' << row.subscriber << ',' << row.sent
        << ',' << row.delivered << ',' << (row.delivered > 0 ? Format("%.3f", row.mean_ms) : "") << ','
        << (row.delivered > 0 ? Format("%.3f", row.p99_ms) : "") << ','
        << (row.cpu_pct >= 0 ? Format("%.1f", row.cpu_pct) : "") << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

std::string MarkdownTable(const std::vector<BenchRow>& rows) {
  std::string table =
      "| transport | size_bytes | rate_hz | subscriber | delivered | mean_ms | p99_ms | cpu_pct |\n"
      "|---|---:|---|---|---:|---:|---:|---:|\n";
  for (const auto& row : rows) {
    const bool any = row.delivered > 0;
    table += "| " + row.transport + " | " + std::to_string(row.size_bytes) + " | " + RateLabel(row.rate_hz) + " | " +
             row.subscriber + " | " + std::to_string(row.delivered) + "/" + std::to_string(row.sent) + " | " +
             (any ? Format("%.2f", row.mean_ms) : "-") + " | " + (any ? Format("%.2f", row.p99_ms) : "-") + " | " +
             (row.cpu_pct >= 0 ? Format("%.0f", row.cpu_pct) : "-") + " |\n";
  }
  return table;
}

std::vector<std::string> SummaryLines(const std::vector<BenchRow>& rows) {
  std::vector<std::string> lines;
  std::vector<std::pair<std::string, size_t>> groups;  // transport and size, in row order
  for (const auto& row : rows)
    if (std::find(groups.begin(), groups.end(), std::make_pair(row.transport, row.size_bytes)) == groups.end())
      groups.emplace_back(row.transport, row.size_bytes);

  for (const auto& [transport, size] : groups) {
    Tally paced_idle, paced_busy, flat;
    std::vector<int> paced_rates;
    double cpu_min = 1e300, cpu_max = -1;
    for (const auto& row : rows) {
      if (row.transport != transport || row.size_bytes != size) continue;
      if (row.rate_hz == 0) {
        flat.Add(row);
      } else {
        (row.subscriber == "busy" ? paced_busy : paced_idle).Add(row);
        if (std::find(paced_rates.begin(), paced_rates.end(), row.rate_hz) == paced_rates.end())
          paced_rates.push_back(row.rate_hz);
      }
      if (row.cpu_pct >= 0) {
        cpu_min = std::min(cpu_min, row.cpu_pct);
        cpu_max = std::max(cpu_max, row.cpu_pct);
      }
    }
    if (paced_idle.sent + paced_busy.sent + flat.sent == 0) {
      lines.push_back(transport + ", " + std::to_string(size) +
                      " B: not measured (nothing sent; the reason is on stderr)");
      continue;
    }
    std::string rates;
    for (int rate : paced_rates) rates += (rates.empty() ? "" : "/") + std::to_string(rate);
    std::string line = transport + ", " + std::to_string(size) + " B:";
    if (!paced_rates.empty())
      line += " " + rates + " Hz delivered " + paced_idle.Delivery() + " idle, " + paced_busy.Delivery() +
              " busy (mean " + paced_idle.MeanLatency() + " idle, " + paced_busy.MeanLatency() + " busy);";
    if (flat.sent > 0 || flat.delivered > 0)
      line += " flat out " + flat.Delivery() + " (mean " + flat.MeanLatency() + ");";
    line += cpu_max >= 0 ? " CPU " + Format("%.0f", cpu_min) + "-" + Format("%.0f", cpu_max) + "%" : " CPU -";
    lines.push_back(line);
  }
  return lines;
}

std::string ProgressLine(int index, int total, const BenchRow& row) {
  std::string line = "[" + std::to_string(index) + "/" + std::to_string(total) + "] " + row.transport + " " +
                     std::to_string(row.size_bytes) + " B " + RateLabel(row.rate_hz) + " " + row.subscriber + ": " +
                     std::to_string(row.delivered) + "/" + std::to_string(row.sent);
  if (row.delivered > 0)
    line += ", mean " + Format("%.2f", row.mean_ms) + " ms, p99 " + Format("%.2f", row.p99_ms) + " ms";
  if (row.cpu_pct >= 0) line += ", CPU " + Format("%.0f", row.cpu_pct) + "%";
  return line;
}

}  // namespace fusecal::bench
