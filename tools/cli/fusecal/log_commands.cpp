// `fusecal log info LOG` and `fusecal log dump LOG [--channel C] [--full]`.
#include <CLI/CLI.hpp>
#include <iostream>
#include <map>

#include "commands.hpp"
#include "runtime/channel_pattern.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/message_json.hpp"

namespace fusecal {

namespace {

struct ChannelSummary {
  int64_t count = 0;
  int64_t bytes = 0;
  std::string type;
};

// Prints the problems of a log to stderr; returns the exit status they call for.
int ReportProblems(const LogReader& reader) {
  for (const auto& problem : reader.problems())
    std::cerr << "fusecal log: " << reader.path() << ": " << problem << "\n";
  return reader.problems().empty() ? 0 : 1;
}

int LogInfo(const std::string& path) {
  LogReader reader(path);
  std::map<std::string, ChannelSummary> channels;
  int64_t first = 0, last = 0, events = 0, bytes = 0;
  while (auto event = reader.Next()) {
    if (events == 0) first = event->utime;
    last = event->utime;
    ++events;
    bytes += int64_t(event->data.size());
    auto& summary = channels[event->channel];
    ++summary.count;
    summary.bytes += int64_t(event->data.size());
    if (summary.type.empty()) {
      std::string error;
      const auto decoded = DecodeToJson(event->data.data(), event->data.size(), false, &error);
      summary.type = decoded ? decoded->type : "unknown";
    }
  }
  std::cout << "log:       " << path << "\n";
  std::cout << "events:    " << events << "\n";
  std::cout << "bytes:     " << bytes << "\n";
  std::cout << "time span: " << (events ? double(last - first) * 1e-6 : 0.0) << " s (utime " << first << " .. " << last
            << ")\n";
  std::cout << "channels:\n";
  for (const auto& [name, s] : channels)
    std::cout << "  " << name << "  count=" << s.count << "  type=" << s.type << "  bytes=" << s.bytes << "\n";
  if (events == 0) {
    std::cerr << "fusecal log: " << path << ": no events (an empty file, or not an LCM event log)\n";
    ReportProblems(reader);
    return 1;
  }
  return ReportProblems(reader);
}

int LogDump(const std::string& path, const std::string& channel_pattern, bool full) {
  const ChannelPattern pattern(channel_pattern.empty() ? ".*" : channel_pattern, "--channel");
  LogReader reader(path);
  while (auto event = reader.Next()) {
    if (!pattern.Matches(event->channel)) continue;
    OrderedJson line{{"channel", event->channel}, {"utime", event->utime}};
    std::string error;
    auto decoded = DecodeToJson(event->data.data(), event->data.size(), full, &error);
    if (decoded) {
      line["type"] = decoded->type;
      line["msg"] = std::move(decoded->json);
    } else {
      line["type"] = nullptr;
      line["error"] = error;
      line["bytes"] = event->data.size();
    }
    std::cout << line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) << "\n";
  }
  return ReportProblems(reader);
}

int Guarded(const std::function<int()>& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    std::cerr << "fusecal log: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

void AddLogCommands(CLI::App& app, int* exit_code) {
  auto* log = app.add_subcommand("log", "inspect LCM event logs");
  log->require_subcommand(1);

  auto* info = log->add_subcommand("info", "channels, message counts, types, time span, bytes");
  static std::string info_path;
  info->add_option("LOG", info_path, "LCM log file")->required();
  info->callback([exit_code] { *exit_code = Guarded([] { return LogInfo(info_path); }); });

  auto* dump = log->add_subcommand("dump", "one JSON object per event and line");
  static std::string dump_path, channel;
  static bool full = false;
  dump->add_option("LOG", dump_path, "LCM log file")->required();
  dump->add_option("--channel", channel, "only channels matching this regular expression");
  dump->add_flag("--full", full, "print bulk arrays (pixels, points) in full");
  dump->callback([exit_code] { *exit_code = Guarded([] { return LogDump(dump_path, channel, full); }); });
}

}  // namespace fusecal
