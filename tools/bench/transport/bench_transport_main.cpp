// fusecal-bench-transport: the transport benchmark. For 2 MB and 6 MB messages at 10 Hz,
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
#include "tools/bench/transport/bench_report.hpp"
#include "tools/bench/transport/probe_runner.hpp"
#include "tools/bench/transport/transport_probe.hpp"

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

// `dds_depth`: the DDS readers' and writers' KEEP_LAST history (8 by default).
std::vector<Transport> AllTransports(const shm::PoolPlan& plan, int dds_depth) {
  const std::string depth = std::to_string(dds_depth);
  const std::string largest = std::to_string(shm::LargestShmMessage(plan));
  // The iceoryx rows' subscriber queues hold `dds_depth` messages too (the DDS history's counterpart).
  return {
      {"lcm-default", "udpm://239.255.76.67:7670?ttl=0", false},
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
      problem =
          "an iceoryx RouDi that this benchmark did not start is already running (socket /tmp/roudi); "
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
    if (process && !process->Alive())
      problem = "iox-roudi exited during the benchmark (log: " + process->log_path() + ")";
    return problem;
  }
  void Stop() {
    if (!process) return;
    process->Stop();
    std::fprintf(stderr, "stopped iox-roudi\n");
    process.reset();
  }
};

// The transports named in `list` (comma-separated) in the canonical order, or all when it is empty;
// false (with a message) on an unknown name.
bool SelectTransports(const std::vector<Transport>& all, const std::string& list, std::vector<Transport>* out) {
  if (list.empty()) {
    *out = all;
    return true;
  }
  const auto wanted = SplitCommas(list);
  for (const auto& name : wanted) {
    bool known = false;
    for (const auto& t : all) known = known || t.name == name;
    if (!known) {
      std::fprintf(
          stderr, "--transports: unknown transport '%s' (lcm-default, lcm-tuned, dds-udp, dds-shm, iox, iceoryx-raw)\n",
          name.c_str());
      return false;
    }
  }
  for (const auto& t : all)  // always in the canonical order
    if (std::find(wanted.begin(), wanted.end(), t.name) != wanted.end()) out->push_back(t);
  return true;
}

// One configuration's row, with the note and the transport's output to print beside it.
struct MeasuredRow {
  BenchRow row;
  std::string note, child_output;
  bool interrupted = false;  // cut short: not a measurement
};

MeasuredRow MeasureConfiguration(const std::string& executable, const Transport& transport, const ProbeConfig& config,
                                 RoudiForBench& roudi) {
  MeasuredRow result;
  result.row = BenchRow{transport.name, config.size_bytes, config.rate_hz, config.busy ? "busy" : "idle"};
  const std::string roudi_problem = transport.needs_roudi ? roudi.Check() : std::string();
  if (!roudi_problem.empty()) {
    result.note = roudi_problem;
    return result;
  }
  const Measurement m = RunConfiguration(executable, config);
  result.interrupted = Interrupted();
  result.row.sent = m.sent;
  result.row.delivered = m.delivered;
  result.row.mean_ms = m.mean_ms;
  result.row.p99_ms = m.p99_ms;
  result.row.cpu_pct = m.cpu_pct;
  result.note = m.note;
  result.child_output = m.child_output;
  if (transport.needs_roudi && !m.shared_memory && m.sent > 0)
    result.note += std::string(result.note.empty() ? "" : "; ") +
                   "WARNING: the bus did not use shared memory (network path measured instead)";
  return result;
}

// Everything a run of the benchmark shares across its configurations.
struct BenchRun {
  bool quick = false;
  std::string executable, work_dir;
  shm::PoolPlan plan;
  std::vector<size_t> sizes;
  std::vector<int> rates;
  int total = 0;
  int index = 0;
  std::mt19937_64 random{std::random_device{}()};
  RoudiForBench roudi;
  std::vector<BenchRow> rows;
  std::set<std::string> printed_outputs;
};

// Every size, rate and subscriber of one transport; false when interrupted.
bool MeasureTransport(BenchRun& run, const Transport& transport) {
  if (transport.needs_roudi) run.roudi.Start(run.work_dir + "/roudi", run.plan);
  for (size_t size : run.sizes) {
    for (int rate : run.rates) {
      for (const char* subscriber : {"idle", "busy"}) {
        if (Interrupted()) return false;
        ++run.index;
        ProbeConfig config;
        config.url = transport.url;
        config.size_bytes = size;
        config.rate_hz = rate;
        config.count = MessageCount(rate, run.quick);
        config.busy = std::string(subscriber) == "busy";
        config.run_tag = run.random();
        config.dir = run.work_dir + "/" + std::to_string(run.index);
        config.timeout_s = (rate > 0 ? double(config.count) / rate : 0.1 * config.count) + 30;
        std::filesystem::create_directories(config.dir);
        const MeasuredRow measured = MeasureConfiguration(run.executable, transport, config, run.roudi);
        if (measured.interrupted) {
          std::fprintf(stderr, "[%d/%d] interrupted\n", run.index, run.total);
          return false;
        }
        run.rows.push_back(measured.row);
        std::fprintf(stderr, "%s\n", ProgressLine(run.index, run.total, measured.row).c_str());
        if (!measured.note.empty()) std::fprintf(stderr, "    note: %s\n", measured.note.c_str());
        // Transport warnings, each distinct text once (LCM repeats its buffer warning every time).
        if (!measured.child_output.empty() && run.printed_outputs.insert(measured.child_output).second)
          std::fprintf(stderr, "%s", measured.child_output.c_str());
      }
    }
  }
  if (transport.needs_roudi) run.roudi.Stop();
  return true;
}

// Writes the CSV, prints the table and the summary lines; the exit status.
int ReportResults(const std::string& out_path, const std::vector<BenchRow>& rows, double seconds) {
  try {
    WriteCsv(out_path, rows);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  std::printf("%s\n", MarkdownTable(rows).c_str());
  for (const auto& line : SummaryLines(rows)) std::printf("%s\n", line.c_str());
  std::fprintf(stderr, "wrote %s (%zu rows) in %.0f s\n", out_path.c_str(), rows.size(), seconds);
  if (Interrupted()) {
    std::fprintf(stderr, "interrupted: the CSV holds the configurations measured so far\n");
    return 130;
  }
  return 0;
}

int RunBenchmark(const std::string& out_path, bool quick, const std::string& transport_list, int dds_depth) {
  BenchRun run;
  run.quick = quick;
  run.plan = shm::PlanPools(kLargestMessageBytes + (1u << 20), kBulkChunks);
  std::vector<Transport> transports;
  if (!SelectTransports(AllTransports(run.plan, dds_depth), transport_list, &transports)) return 2;
  run.sizes = quick ? std::vector<size_t>{2000000} : std::vector<size_t>{2000000, 6000000};
  run.rates = quick ? std::vector<int>{30, 0} : std::vector<int>{10, 30, 0};
  run.total = static_cast<int>(transports.size() * run.sizes.size() * run.rates.size() * 2);

  run.executable = SelfExecutable();
  if (run.executable.empty()) {
    std::fprintf(stderr, "cannot find this executable (/proc/self/exe) to start the probe processes\n");
    return 1;
  }
  char work_template[] = "/tmp/fusecal-bench-transport-XXXXXX";
  if (!mkdtemp(work_template)) {
    std::fprintf(stderr, "cannot create a work folder in /tmp\n");
    return 1;
  }
  run.work_dir = work_template;

  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  std::fprintf(stderr, "transport benchmark: %d configurations on %ld cores%s (work folder %s)\n", run.total,
               sysconf(_SC_NPROCESSORS_ONLN), quick ? ", quick" : "", run.work_dir.c_str());
  for (const auto& transport : transports)
    std::fprintf(stderr, "  %-11s %s\n", transport.name.c_str(), transport.url.c_str());
  const auto start = std::chrono::steady_clock::now();
  for (const auto& transport : transports)
    if (!MeasureTransport(run, transport)) break;
  run.roudi.Stop();
  std::error_code ignored;
  std::filesystem::remove_all(run.work_dir, ignored);
  return ReportResults(out_path, run.rows,
                       std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Transport benchmark: LCM (default and tuned buffers) and Cyclone DDS (UDP and "
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
