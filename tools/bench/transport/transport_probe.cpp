#include "tools/bench/transport/transport_probe.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

#include "runtime/bus.hpp"
#ifdef FUSECAL_WITH_DDS
#include "runtime/dds/dds_bus.hpp"
#endif
#ifdef FUSECAL_WITH_IOX
#include "runtime/iox/iox_bus.hpp"
#include "tools/bench/transport/raw_iceoryx_bus.hpp"
#endif

namespace fusecal::bench {

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// How long the publisher waits for the subscriber to subscribe, and to confirm a warm-up message
// (after that it sends anyway and the result says the warm-up was not confirmed).
constexpr double kReadyTimeoutS = 20;
constexpr double kWarmupTimeoutS = 10;
constexpr auto kWarmupInterval = milliseconds(50);
// Pause between the confirmed warm-up and the first measured message, so that late warm-up copies are
// out of the way.
constexpr auto kSettle = milliseconds(200);
// The busy subscriber's cycle: away for 80 ms, then reading for 20 ms.
constexpr auto kBusyAway = milliseconds(80);
constexpr auto kBusyReading = milliseconds(20);
// A failed send (iceoryx out of chunks: at once; a blocked reliable writer: after 1 s) is counted and
// the publisher goes on, until failed sends have taken this long in all.
constexpr double kMaxFailingSendS = 3;

// User + system CPU seconds of this process, all threads (the transport's receive and send threads too).
double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

// Samples this process's CPU time every 10 ms on a thread of its own, so that the benchmark can take
// both processes' CPU over the same window (the send phase up to the last delivery), whatever each
// process was doing at its ends.
class CpuSampler {
 public:
  CpuSampler() = default;
  CpuSampler(const CpuSampler&) = delete;
  CpuSampler& operator=(const CpuSampler&) = delete;
  ~CpuSampler() { Stop(); }

  void Start() {
    if (thread_.joinable()) return;
    Sample();
    running_ = true;
    thread_ = std::thread([this] {
      while (running_) {
        std::this_thread::sleep_for(milliseconds(10));
        Sample();
      }
    });
  }
  // Stops sampling (after a last sample) and returns the timeline.
  CpuTimeline Stop() {
    if (thread_.joinable()) {
      running_ = false;
      thread_.join();
      Sample();
    }
    std::lock_guard<std::mutex> lock(mutex_);
    return timeline_;
  }

 private:
  void Sample() {
    const CpuSample sample{NowUtime(), CpuSeconds()};
    std::lock_guard<std::mutex> lock(mutex_);
    timeline_.push_back(sample);
  }
  std::thread thread_;
  std::atomic<bool> running_{false};
  std::mutex mutex_;
  CpuTimeline timeline_;
};

std::string SerializeTimeline(const CpuTimeline& timeline) {
  std::ostringstream text;
  text.precision(9);
  for (const auto& sample : timeline) text << sample.utime << ':' << sample.cpu_s << ' ';
  return text.str();
}

CpuTimeline ParseTimeline(const std::string& text) {
  CpuTimeline timeline;
  std::istringstream in(text);
  for (std::string item; in >> item;) {
    const auto colon = item.find(':');
    if (colon == std::string::npos) continue;
    timeline.push_back({std::stoll(item.substr(0, colon)), std::stod(item.substr(colon + 1))});
  }
  return timeline;
}

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Whether the bus really uses shared memory: a DDS bus may fall back to the network path without RouDi
// (and says so only on stderr); iox:// and the raw floor have no other path.
bool UsesSharedMemory(Bus& bus, const std::string& url) {
#ifdef FUSECAL_WITH_DDS
  if (auto* dds = dynamic_cast<DdsBus*>(&bus)) return dds->shared_memory();
#endif
#ifdef FUSECAL_WITH_IOX
  if (dynamic_cast<IoxBus*>(&bus) || IsRawIceoryxUrl(url)) return true;
#endif
  return false;
}

// The bus under test: MakeBus, or the raw-iceoryx floor (iceoryx-raw://, not a fusecal bus URL).
std::unique_ptr<Bus> MakeProbeBus(const std::string& url) {
#ifdef FUSECAL_WITH_IOX
  if (IsRawIceoryxUrl(url)) return MakeRawIceoryxBus(url);
#endif
  return MakeBus(url);
}

// Waits until `path` exists; false when `abort_path` appears first or after `timeout_s`.
bool WaitForFile(const std::string& path, const std::string& abort_path, double timeout_s) {
  const auto start = Clock::now();
  while (!FileExists(path)) {
    if ((!abort_path.empty() && FileExists(abort_path)) || SecondsSince(start) > timeout_s) return false;
    std::this_thread::sleep_for(milliseconds(5));
  }
  return true;
}

// Result files: one `key=value` per line; errors are flattened to one line.
std::string OneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  return text;
}

void WriteKeyValues(const std::string& path, const std::vector<std::pair<std::string, std::string>>& values) {
  const std::string partial = path + ".partial";
  {
    std::ofstream out(partial);
    for (const auto& [key, value] : values) out << key << '=' << value << '\n';
  }
  std::rename(partial.c_str(), path.c_str());  // the reader never sees half a file
}

std::map<std::string, std::string> ReadKeyValues(const std::string& path, bool* found) {
  std::map<std::string, std::string> values;
  std::ifstream in(path);
  *found = static_cast<bool>(in);
  std::string line;
  while (std::getline(in, line)) {
    const auto eq = line.find('=');
    if (eq != std::string::npos) values[line.substr(0, eq)] = line.substr(eq + 1);
  }
  return values;
}

double Number(const std::map<std::string, std::string>& values, const std::string& key) {
  auto it = values.find(key);
  return it == values.end() || it->second.empty() ? 0.0 : std::stod(it->second);
}

int64_t Integer(const std::map<std::string, std::string>& values, const std::string& key) {
  auto it = values.find(key);
  return it == values.end() || it->second.empty() ? 0 : std::stoll(it->second);
}

std::string Text(const std::map<std::string, std::string>& values, const std::string& key) {
  auto it = values.find(key);
  return it == values.end() ? std::string() : it->second;
}

std::string Str(double value) {
  std::ostringstream text;
  text.precision(17);
  text << value;
  return text.str();
}

// Handles messages for `duration` (Handle returns after the first batch, so it is called again until
// the time is up).
void HandleFor(Bus& bus, milliseconds duration) {
  const auto end = Clock::now() + duration;
  for (auto now = Clock::now(); now < end; now = Clock::now())
    bus.Handle(static_cast<int>(std::chrono::duration_cast<milliseconds>(end - now).count()) + 1);
}

}  // namespace

double CpuBetween(const CpuTimeline& timeline, int64_t from_utime, int64_t to_utime) {
  if (timeline.empty()) return 0;
  // CPU at `utime`, linear between samples, clamped to the ends of the timeline.
  auto at = [&](int64_t utime) {
    if (utime <= timeline.front().utime) return timeline.front().cpu_s;
    if (utime >= timeline.back().utime) return timeline.back().cpu_s;
    auto after = std::lower_bound(timeline.begin(), timeline.end(), utime,
                                  [](const CpuSample& s, int64_t t) { return s.utime < t; });
    auto before = after - 1;
    const double span = static_cast<double>(after->utime - before->utime);
    const double f = span > 0 ? static_cast<double>(utime - before->utime) / span : 1.0;
    return before->cpu_s + f * (after->cpu_s - before->cpu_s);
  };
  return std::max(0.0, at(to_utime) - at(from_utime));
}

bool FileExists(const std::string& path) { return access(path.c_str(), F_OK) == 0; }

void TouchFile(const std::string& path) { std::ofstream(path).put('\n'); }

int RunSubscriber(const ProbeConfig& config) {
  const ProbeFiles files{config.dir};
  SubscriberResult result;
  std::vector<double> latencies_ms;
  latencies_ms.reserve(static_cast<size_t>(config.count));
  CpuSampler cpu;
  try {
    auto bus = MakeProbeBus(config.url);
    result.shared_memory = UsesSharedMemory(*bus, config.url);
    std::vector<char> seen(static_cast<size_t>(config.count), 0);
    bool warm = false;
    Subscription subscription = bus->SubscribeRaw(config.channel, [&](const RawMessage& message) {
      const int64_t receive_utime = NowUtime();  // in the handler: includes any time spent queued
      if (message.size < kProbeHeaderBytes) return;
      ProbeHeader header;
      std::memcpy(&header, message.data, sizeof header);
      if (header.run_tag != config.run_tag) return;
      if (header.sequence == kWarmupSequence) {
        warm = true;
        return;
      }
      if (header.sequence < 0 || header.sequence >= config.count || message.size != config.size_bytes ||
          seen[static_cast<size_t>(header.sequence)])
        return;
      seen[static_cast<size_t>(header.sequence)] = 1;
      latencies_ms.push_back(1e-3 * static_cast<double>(receive_utime - header.send_utime));
      result.last_receive_utime = receive_utime;
    });
    TouchFile(files.ready());

    const auto ready_time = Clock::now();
    bool measuring = false;
    while (static_cast<int>(latencies_ms.size()) < config.count && !FileExists(files.stop()) &&
           SecondsSince(ready_time) < config.timeout_s) {
      // Measuring (CPU, busy cycle) starts with the warm-up message, or when the publisher stops
      // waiting for one.
      if (!measuring && (warm || !latencies_ms.empty() || SecondsSince(ready_time) > kWarmupTimeoutS)) {
        measuring = true;
        result.warm = warm;
        cpu.Start();
        if (warm) TouchFile(files.warm());
      }
      if (measuring && config.busy) {
        // Busy: this thread is away 80 ms of every 100 ms and reads only 20% of the time. It sleeps
        // rather than spins, so that the CPU column stays the transport's own cost.
        std::this_thread::sleep_for(kBusyAway);
        HandleFor(*bus, kBusyReading);
      } else {
        bus->Handle(50);
      }
    }
    result.bus_dropped = bus->dropped_messages();
  } catch (const std::exception& e) {
    result.error = e.what();
  }
  result.cpu = cpu.Stop();
  result.delivered = static_cast<int>(latencies_ms.size());
  if (!latencies_ms.empty()) {
    double sum = 0;
    for (double latency : latencies_ms) sum += latency;
    result.mean_ms = sum / static_cast<double>(latencies_ms.size());
    std::sort(latencies_ms.begin(), latencies_ms.end());
    // Nearest rank: the smallest latency that at least 99% of the messages did not exceed.
    const size_t rank = static_cast<size_t>(std::ceil(0.99 * static_cast<double>(latencies_ms.size())));
    result.p99_ms = latencies_ms[std::max<size_t>(rank, 1) - 1];
  }
  WriteKeyValues(files.subscriber_result(), {{"delivered", std::to_string(result.delivered)},
                                             {"mean_ms", Str(result.mean_ms)},
                                             {"p99_ms", Str(result.p99_ms)},
                                             {"cpu_timeline", SerializeTimeline(result.cpu)},
                                             {"last_receive_utime", std::to_string(result.last_receive_utime)},
                                             {"warm", result.warm ? "1" : "0"},
                                             {"shared_memory", result.shared_memory ? "1" : "0"},
                                             {"bus_dropped", std::to_string(result.bus_dropped)},
                                             {"error", OneLine(result.error)}});
  return 0;
}

int RunPublisher(const ProbeConfig& config) {
  const ProbeFiles files{config.dir};
  PublisherResult result;
  CpuSampler cpu;
  try {
    auto bus = MakeProbeBus(config.url);
    result.shared_memory = UsesSharedMemory(*bus, config.url);
    if (!WaitForFile(files.ready(), files.stop(), kReadyTimeoutS))
      throw std::runtime_error("the subscriber did not subscribe within " + std::to_string(int(kReadyTimeoutS)) + " s");

    // Warm-up: small messages on the measured channel until the subscriber has one.
    ProbeHeader warmup{config.run_tag, kWarmupSequence, 0};
    const auto warmup_start = Clock::now();
    while (!FileExists(files.warm()) && !FileExists(files.stop()) && SecondsSince(warmup_start) < kWarmupTimeoutS) {
      warmup.send_utime = NowUtime();
      bus->PublishRaw(config.channel, &warmup, sizeof warmup);
      std::this_thread::sleep_for(kWarmupInterval);
    }
    result.warmed = FileExists(files.warm());
    std::this_thread::sleep_for(kSettle);

    std::vector<uint8_t> payload(std::max(config.size_bytes, kProbeHeaderBytes), 0x5a);
    cpu.Start();
    result.send_start_utime = NowUtime();
    const auto start = Clock::now();
    int failures = 0;
    double failing_s = 0;
    std::string first_error;
    for (int i = 0; i < config.count && failing_s < kMaxFailingSendS; ++i) {
      if (config.rate_hz > 0)
        std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                                  std::chrono::duration<double>(double(i) / config.rate_hz)));
      const ProbeHeader header{config.run_tag, i, NowUtime()};
      std::memcpy(payload.data(), &header, sizeof header);
      const auto attempt = Clock::now();
      try {
        bus->PublishRaw(config.channel, payload.data(), payload.size());
        ++result.sent;  // `sent` counts the messages the transport accepted
      } catch (const BusError& e) {
        if (first_error.empty()) first_error = e.what();
        ++failures;
        failing_s += SecondsSince(attempt);
      }
    }
    if (failures > 0)
      result.error = std::to_string(failures) + " of " + std::to_string(result.sent + failures) +
                     " sends failed (not counted as sent), first: " + first_error;
    result.send_end_utime = NowUtime();
    TouchFile(files.sent());
    // Keep the bus until the subscriber is done: a reliable transport may still be resending.
    WaitForFile(files.stop(), "", config.timeout_s);
  } catch (const std::exception& e) {
    result.error = e.what();
  }
  result.cpu = cpu.Stop();
  WriteKeyValues(files.publisher_result(), {{"sent", std::to_string(result.sent)},
                                            {"cpu_timeline", SerializeTimeline(result.cpu)},
                                            {"send_start_utime", std::to_string(result.send_start_utime)},
                                            {"send_end_utime", std::to_string(result.send_end_utime)},
                                            {"warmed", result.warmed ? "1" : "0"},
                                            {"shared_memory", result.shared_memory ? "1" : "0"},
                                            {"error", OneLine(result.error)}});
  return 0;
}

SubscriberResult ReadSubscriberResult(const std::string& path) {
  SubscriberResult result;
  const auto values = ReadKeyValues(path, &result.found);
  result.delivered = static_cast<int>(Integer(values, "delivered"));
  result.mean_ms = Number(values, "mean_ms");
  result.p99_ms = Number(values, "p99_ms");
  result.cpu = ParseTimeline(Text(values, "cpu_timeline"));
  result.last_receive_utime = Integer(values, "last_receive_utime");
  result.warm = Text(values, "warm") == "1";
  result.shared_memory = Text(values, "shared_memory") == "1";
  result.bus_dropped = static_cast<uint64_t>(Integer(values, "bus_dropped"));
  result.error = Text(values, "error");
  return result;
}

PublisherResult ReadPublisherResult(const std::string& path) {
  PublisherResult result;
  const auto values = ReadKeyValues(path, &result.found);
  result.sent = static_cast<int>(Integer(values, "sent"));
  result.cpu = ParseTimeline(Text(values, "cpu_timeline"));
  result.send_start_utime = Integer(values, "send_start_utime");
  result.send_end_utime = Integer(values, "send_end_utime");
  result.warmed = Text(values, "warmed") == "1";
  result.shared_memory = Text(values, "shared_memory") == "1";
  result.error = Text(values, "error");
  return result;
}

}  // namespace fusecal::bench
