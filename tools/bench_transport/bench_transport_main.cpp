// fusecal-bench-transport: the transport benchmark of issue 10. For 2 MB and 6 MB messages at 10 Hz,
// 30 Hz and flat out, with an idle subscriber and one that is busy 80% of the time, it measures
// delivered/sent, mean and p99 latency and CPU for four transports:
//   lcm-default  LCM UDP multicast with the kernel's default receive buffer
//   lcm-tuned    LCM UDP multicast with a 64 MiB receive buffer (needs net.core.rmem_max >= 64 MiB)
//   dds-udp      Cyclone DDS over the network path (loopback UDP)
//   dds-shm      Cyclone DDS over iceoryx shared memory, with a RouDi this benchmark starts and stops
//   iox          fusecal's iceoryx bus (iox://), the handler reading the chunk in place (same RouDi)
//   iceoryx-raw  the floor: iceoryx's C API directly, loan + copy in + publish, take + read in place +
//                release (raw_iceoryx_bus.hpp; same RouDi)
// Publisher and subscriber are separate processes (this executable with --role, see transport_probe.hpp),
// so every number is cross-process. CPU is the two processes' CPU time (all their threads) summed, over
// the wall time from the first send to the later of the last send and the last delivery (the send
// phase and its drain): it can exceed 100% on a multi-core machine.
//
// Usage: fusecal-bench-transport --out FILE.csv [--quick] [--transports lcm-tuned,dds-udp] [--dds-depth 8]
// Writes the CSV, prints a Markdown table and one summary line per transport and size on stdout, and
// one progress line per configuration on stderr. A transport that fails gives rows with nothing
// delivered and the reason on stderr; the run goes on.
#include <signal.h>
#include <stdlib.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/shared_memory.hpp"
#include "tools/bench_transport/bench_report.hpp"
#include "tools/bench_transport/probe_runner.hpp"
#include "tools/bench_transport/transport_probe.hpp"

namespace {

using namespace fusecal::bench;
namespace shm = fusecal::shm;

// The largest message of the benchmark; RouDi's pools are planned for it with 1 MiB to spare.
constexpr size_t kLargestMessageBytes = 6000000;
constexpr int kBulkChunks = 32;

struct Transport {
  std::string name;
  std::string url;
  bool needs_roudi = false;
};

// `dds_depth`: the DDS readers' and writers' KEEP_LAST history (8 in the benchmark of issue 10).
std::vector<Transport> AllTransports(const shm::PoolPlan& plan, int dds_depth) {
  const std::string depth = std::to_string(dds_depth);
  const std::string largest = std::to_string(shm::LargestShmMessage(plan));
  // The iceoryx rows' subscriber queues hold `dds_depth` messages too (the DDS history's counterpart).
  return {{"lcm-default", "udpm://239.255.76.67:7670?ttl=0", false},
          {"lcm-tuned", "udpm://239.255.76.67:7671?ttl=0&recv_buf_size=67108864", false},
          {"dds-udp", "dds://?domain=40&depth=" + depth, false},
          {"dds-shm", "dds://?domain=41&shm=1&depth=" + depth + "&shm_max=" + largest, true},
#ifdef FUSECAL_WITH_IOX
          {"iox", "iox://?depth=" + depth + "&max=" + largest, true},
          {"iceoryx-raw", "iceoryx-raw://?depth=" + depth, true},
#endif
  };
}

// Messages per configuration: ~5 s at the paced rates, 100 flat out; --quick: 20 each.
int MessageCount(int rate_hz, bool quick) {
  if (quick) return 20;
  return rate_hz == 10 ? 50 : rate_hz == 30 ? 150 : 100;
}

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream stream(text);
  for (std::string item; std::getline(stream, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

std::string SelfExecutable() {
  std::error_code error;
  const auto path = std::filesystem::read_symlink("/proc/self/exe", error);
  return error ? std::string() : path.string();
}

void OnSignal(int) { RequestInterrupt(); }

// The RouDi of the shared-memory rows (dds-shm, iox, iceoryx-raw): started before a transport's first
// configuration, stopped after its last. `problem` says why they cannot run (then their rows record
// nothing delivered).
struct RoudiForBench {
  std::unique_ptr<shm::RoudiProcess> process;
  std::string problem;

  void Start(const std::string& work_dir, const shm::PoolPlan& plan) {
    if (process || !problem.empty()) return;
    if (!shm::WaitUntilRoudiGone(3)) {
      problem = "an iceoryx RouDi that this benchmark did not start is already running (socket /tmp/roudi); "
                "its pools may not fit 6 MB messages, and stopping it would end the processes attached to it. "
                "Stop it to measure the shared-memory rows.";
      return;
    }
    process = std::make_unique<shm::RoudiProcess>(work_dir, plan);
    try {
      process->Start();
      std::fprintf(stderr, "started iox-roudi (pid %d): %zu chunks of %zu bytes for messages up to %zu bytes\n",
                   process->pid(), static_cast<size_t>(plan.pools.back().count), plan.largest_chunk(),
                   shm::LargestShmMessage(plan));
    } catch (const std::exception& e) {
      problem = std::string("RouDi cannot start: ") + e.what();
      process.reset();
    }
  }
  // Empty while RouDi is up; otherwise why not.
  std::string Check() {
    if (!problem.empty()) return problem;
    if (process && !process->Alive()) problem = "iox-roudi exited during the benchmark (log: " + process->log_path() + ")";
    return problem;
  }
  void Stop() {
    if (!process) return;
    process->Stop();
    std::fprintf(stderr, "stopped iox-roudi\n");
    process.reset();
  }
};

int RunBenchmark(const std::string& out_path, bool quick, const std::string& transport_list, int dds_depth) {
  const shm::PoolPlan plan = shm::PlanPools(kLargestMessageBytes + (1u << 20), kBulkChunks);
  std::vector<Transport> transports;
  const auto all = AllTransports(plan, dds_depth);
  if (transport_list.empty()) {
    transports = all;
  } else {
    const auto wanted = SplitCommas(transport_list);
    for (const auto& name : wanted) {
      bool known = false;
      for (const auto& t : all) known = known || t.name == name;
      if (!known) {
        std::fprintf(stderr, "--transports: unknown transport '%s' (lcm-default, lcm-tuned, dds-udp, dds-shm, iox, iceoryx-raw)\n",
                     name.c_str());
        return 2;
      }
    }
    for (const auto& t : all)  // always in the canonical order
      if (std::find(wanted.begin(), wanted.end(), t.name) != wanted.end()) transports.push_back(t);
  }
  const std::vector<size_t> sizes = quick ? std::vector<size_t>{2000000} : std::vector<size_t>{2000000, 6000000};
  const std::vector<int> rates = quick ? std::vector<int>{30, 0} : std::vector<int>{10, 30, 0};
  const std::vector<std::string> subscribers = {"idle", "busy"};
  const int total = static_cast<int>(transports.size() * sizes.size() * rates.size() * subscribers.size());

  const std::string executable = SelfExecutable();
  if (executable.empty()) {
    std::fprintf(stderr, "cannot find this executable (/proc/self/exe) to start the probe processes\n");
    return 1;
  }
  char work_template[] = "/tmp/fusecal-bench-transport-XXXXXX";
  if (!mkdtemp(work_template)) {
    std::fprintf(stderr, "cannot create a work folder in /tmp\n");
    return 1;
  }
  const std::string work_dir = work_template;

  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  std::fprintf(stderr, "transport benchmark: %d configurations on %ld cores%s (work folder %s)\n", total,
               sysconf(_SC_NPROCESSORS_ONLN), quick ? ", quick" : "", work_dir.c_str());
  for (const auto& transport : transports) std::fprintf(stderr, "  %-11s %s\n", transport.name.c_str(), transport.url.c_str());
  std::mt19937_64 random(std::random_device{}());
  RoudiForBench roudi;
  std::vector<BenchRow> rows;
  std::set<std::string> printed_outputs;
  const auto start = std::chrono::steady_clock::now();
  int index = 0;
  for (const auto& transport : transports) {
    if (Interrupted()) break;
    if (transport.needs_roudi) roudi.Start(work_dir + "/roudi", plan);
    for (size_t size : sizes) {
      for (int rate : rates) {
        for (const auto& subscriber : subscribers) {
          if (Interrupted()) break;  // (the loops around end at once too)
          ++index;
          BenchRow row{transport.name, size, rate, subscriber};
          ProbeConfig config;
          config.url = transport.url;
          config.size_bytes = size;
          config.rate_hz = rate;
          config.count = MessageCount(rate, quick);
          config.busy = subscriber == "busy";
          config.run_tag = random();
          config.dir = work_dir + "/" + std::to_string(index);
          config.timeout_s = (rate > 0 ? double(config.count) / rate : 0.1 * config.count) + 30;
          std::filesystem::create_directories(config.dir);

          std::string note, child_output;
          const std::string roudi_problem = transport.needs_roudi ? roudi.Check() : std::string();
          if (!roudi_problem.empty()) {
            note = roudi_problem;
          } else {
            const Measurement m = RunConfiguration(executable, config);
            if (Interrupted()) {  // a configuration cut short is not a measurement: no row
              std::fprintf(stderr, "[%d/%d] interrupted\n", index, total);
              break;
            }
            row.sent = m.sent;
            row.delivered = m.delivered;
            row.mean_ms = m.mean_ms;
            row.p99_ms = m.p99_ms;
            row.cpu_pct = m.cpu_pct;
            note = m.note;
            child_output = m.child_output;
            if (transport.needs_roudi && !m.shared_memory && m.sent > 0)
              note += std::string(note.empty() ? "" : "; ") +
                      "WARNING: the bus did not use shared memory (network path measured instead)";
          }
          rows.push_back(row);
          std::fprintf(stderr, "%s\n", ProgressLine(index, total, row).c_str());
          if (!note.empty()) std::fprintf(stderr, "    note: %s\n", note.c_str());
          // Transport warnings, each distinct text once (LCM repeats its buffer warning every time).
          if (!child_output.empty() && printed_outputs.insert(child_output).second)
            std::fprintf(stderr, "%s", child_output.c_str());
        }
      }
    }
    if (transport.needs_roudi) roudi.Stop();
  }
  roudi.Stop();
  std::error_code ignored;
  std::filesystem::remove_all(work_dir, ignored);

  try {
    WriteCsv(out_path, rows);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("%s\n", MarkdownTable(rows).c_str());
  for (const auto& line : SummaryLines(rows)) std::printf("%s\n", line.c_str());
  std::fprintf(stderr, "wrote %s (%zu rows) in %.0f s\n", out_path.c_str(), rows.size(), seconds);
  if (Interrupted()) {
    std::fprintf(stderr, "interrupted: the CSV holds the configurations measured so far\n");
    return 130;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Transport benchmark (issue 10): LCM (default and tuned buffers) and Cyclone DDS (UDP and "
               "iceoryx shared memory), 2 and 6 MB messages at 10 Hz, 30 Hz and flat out, idle and busy "
               "subscriber. Publisher and subscriber are separate processes."};
  std::string out_path;
  bool quick = false;
  std::string transport_list;
  app.add_option("--out", out_path, "CSV file to write");
  app.add_flag("--quick", quick, "only 2 MB at 30 Hz and flat out, 20 messages each (for tests)");
  app.add_option("--transports", transport_list,
                 "comma-separated subset of lcm-default,lcm-tuned,dds-udp,dds-shm,iox,iceoryx-raw (default: all)");
  int dds_depth = 8;
  app.add_option("--dds-depth", dds_depth, "KEEP_LAST history depth of the DDS transports (default 8)")
      ->check(CLI::Range(1, 256));

  // The probe processes (started by the benchmark itself, hence hidden).
  std::string role, subscriber_mode = "idle";
  ProbeConfig probe;
  app.add_option("--role", role)->group("")->check(CLI::IsMember({"publisher", "subscriber"}));
  app.add_option("--url", probe.url)->group("");
  app.add_option("--channel", probe.channel)->group("");
  app.add_option("--size", probe.size_bytes)->group("");
  app.add_option("--rate", probe.rate_hz)->group("");
  app.add_option("--count", probe.count)->group("");
  app.add_option("--subscriber", subscriber_mode)->group("")->check(CLI::IsMember({"idle", "busy"}));
  app.add_option("--tag", probe.run_tag)->group("");
  app.add_option("--dir", probe.dir)->group("");
  app.add_option("--timeout", probe.timeout_s)->group("");
  CLI11_PARSE(app, argc, argv);

  if (!role.empty()) {
    probe.busy = subscriber_mode == "busy";
    return role == "publisher" ? RunPublisher(probe) : RunSubscriber(probe);
  }
  if (out_path.empty()) {
    std::fprintf(stderr, "--out FILE.csv is required\n%s", app.help().c_str());
    return 2;
  }
  return RunBenchmark(out_path, quick, transport_list, dds_depth);
}
