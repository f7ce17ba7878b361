// The two ends of one transport-benchmark configuration. Each runs in its own process (the benchmark
// re-executes itself with `--role publisher` / `--role subscriber`), so every number is cross-process.
//
// The processes of one configuration talk through files in one folder (ProbeFiles), never through the
// bus under test:
//   1. the subscriber subscribes and writes `subscriber.ready`;
//   2. the publisher sends small warm-up messages (sequence -1) on the same channel until the subscriber
//      has one and writes `subscriber.warm` (DDS discovery is then done both ways, so the first measured
//      message is not lost to discovery);
//   3. the publisher sends `count` messages of `size_bytes` at `rate_hz` (0: as fast as PublishRaw
//      returns) and writes `publisher.sent`;
//   4. the subscriber stops when it has every message, or when the benchmark writes `stop` (after a
//      drain of up to 2 s); the publisher keeps its bus open until `stop` (a reliable transport may still
//      be resending), then both write their result files and exit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace fusecal::bench {

// The first bytes of every probe message (the rest is filler up to the configured size). Publisher and
// subscriber share the host, so the wall-clock send time can be compared with the receive time.
struct ProbeHeader {
  uint64_t run_tag = 0;    // random per configuration: stray messages of another run are ignored
  int64_t sequence = 0;    // 0..count-1; kWarmupSequence for warm-up messages
  int64_t send_utime = 0;  // system clock, microseconds, taken just before PublishRaw
};
inline constexpr size_t kProbeHeaderBytes = sizeof(ProbeHeader);
inline constexpr int64_t kWarmupSequence = -1;

// What one configuration runs (the same for both processes).
struct ProbeConfig {
  std::string url;
  std::string channel = "BENCH_TRANSPORT";
  size_t size_bytes = 0;
  int rate_hz = 0;    // 0: flat out
  int count = 0;      // measured messages
  bool busy = false;  // subscriber away 80 ms of every 100 ms
  uint64_t run_tag = 0;
  std::string dir;        // folder of the marker and result files
  double timeout_s = 60;  // each process gives up after this long
};

// The files one configuration's processes exchange.
struct ProbeFiles {
  std::string dir;
  std::string ready() const { return dir + "/subscriber.ready"; }
  std::string warm() const { return dir + "/subscriber.warm"; }
  std::string sent() const { return dir + "/publisher.sent"; }
  std::string stop() const { return dir + "/stop"; }
  std::string subscriber_result() const { return dir + "/subscriber.result"; }
  std::string publisher_result() const { return dir + "/publisher.result"; }
};

// This process's CPU time (user + system, all threads) at one moment.
struct CpuSample {
  int64_t utime = 0;  // system clock, microseconds
  double cpu_s = 0;
};
using CpuTimeline = std::vector<CpuSample>;  // every 10 ms while measuring, in time order

// CPU seconds used between `from_utime` and `to_utime`, interpolated in the timeline (0 when empty).
double CpuBetween(const CpuTimeline& timeline, int64_t from_utime, int64_t to_utime);

struct SubscriberResult {
  bool found = false;  // the result file was there
  int delivered = 0;   // distinct measured messages received
  double mean_ms = 0, p99_ms = 0;
  CpuTimeline cpu;  // from the warm-up message until the end
  int64_t last_receive_utime = 0;
  bool warm = false;           // a warm-up message arrived before the measured ones
  bool shared_memory = false;  // DDS: the bus really uses iceoryx
  uint64_t bus_dropped = 0;    // the losses the bus itself noticed (Bus::dropped_messages(); 0 for LCM)
  std::string error;
};

struct PublisherResult {
  bool found = false;
  int sent = 0;     // messages PublishRaw accepted
  CpuTimeline cpu;  // from the first send until `stop` (covers any resending after the last send)
  int64_t send_start_utime = 0, send_end_utime = 0;
  bool warmed = false;  // the subscriber confirmed a warm-up message
  bool shared_memory = false;
  std::string error;
};

// The process roles; both return the process exit status (0 also when the transport failed: the
// failure is in the result file).
int RunSubscriber(const ProbeConfig& config);
int RunPublisher(const ProbeConfig& config);

SubscriberResult ReadSubscriberResult(const std::string& path);
PublisherResult ReadPublisherResult(const std::string& path);

// Small file helpers shared with the benchmark driver.
bool FileExists(const std::string& path);
void TouchFile(const std::string& path);

}  // namespace fusecal::bench
