// The transport benchmark's outputs: the CSV, the Markdown table of
// docs/transport.md, one summary line per transport and message size, and the progress line per configuration.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace fusecal::bench {

// One configuration's result: one CSV row.
struct BenchRow {
  std::string transport;  // lcm-default, lcm-tuned, dds-udp or dds-shm
  size_t size_bytes = 0;
  int rate_hz = 0;         // 0: flat out
  std::string subscriber;  // idle or busy
  int sent = 0;
  int delivered = 0;
  double mean_ms = 0, p99_ms = 0;  // only when delivered > 0
  double cpu_pct = -1;             // negative: not measured (nothing sent)
};

// The CSV header, exactly.
inline constexpr const char* kCsvHeader =
    "transport,size_bytes,rate_hz,subscriber,sent,delivered,mean_ms,p99_ms,cpu_pct";

// Writes the CSV (latencies empty when nothing was delivered, cpu_pct empty when not measured). Creates
// the parent folder. Throws std::runtime_error when the file cannot be written.
void WriteCsv(const std::string& path, const std::vector<BenchRow>& rows);

// The table of docs/transport.md: delivered as `delivered/sent`, latencies with 2 decimals, `-` without a message.
std::string MarkdownTable(const std::vector<BenchRow>& rows);

// One line per transport and size: delivery at the paced rates (idle and busy) and flat out, mean
// latencies, CPU range.
std::vector<std::string> SummaryLines(const std::vector<BenchRow>& rows);

// "[12/48] dds-shm 6000000 B 30 Hz busy: 150/150, mean 1.2 ms"
std::string ProgressLine(int index, int total, const BenchRow& row);

// "30 Hz", or "flat out" for 0.
std::string RateLabel(int rate_hz);

}  // namespace fusecal::bench
