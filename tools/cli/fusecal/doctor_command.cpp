// `fusecal doctor [--bus URL] [--fix]`.
#include <CLI/CLI.hpp>
#include <iostream>

#include "commands.hpp"
#include "doctor.hpp"
#include "runtime/bus.hpp"
#include "runtime/pipeline/pipeline_config.hpp"

namespace fusecal {

void AddDoctorCommand(CLI::App& app, int* exit_code) {
  auto* doctor = app.add_subcommand("doctor", "check that this machine can carry the bus without loss");
  static std::string bus_url;
  static bool fix = false, ros2 = false;
  static std::string config = DefaultPipelineConfigPath();
  doctor->add_option("--bus", bus_url, "bus URL to check (default: $LCM_DEFAULT_URL or loopback multicast)");
  doctor->add_flag("--fix", fix, "run the fixes (needs root), then check again");
  doctor->add_flag("--ros2", ros2, "also check what `fusecal run --ros2` needs (its receive buffer)");
  doctor->add_option("--config", config, "pipeline config (--ros2: section ros2_input)");
  doctor->callback([exit_code] {
    size_t ros2_buffer = 0;
    if (ros2) {
      try {
        ros2_buffer = ReceiveBufferBytes(LoadPipelineConfig(config).ros2_input);
      } catch (const std::exception& e) {
        std::cerr << "fusecal doctor: " << e.what() << "\n";
        *exit_code = 2;
        return;
      }
    }
    const auto findings = RunDoctor(bus_url, fix, ros2_buffer);
    bool loses = false, warned = false;
    std::cout << "bus: " << (bus_url.empty() ? DefaultBusUrl() : bus_url) << "\n";
    for (const auto& f : findings) {
      std::cout << (f.ok ? "  ok       " : (f.loses_messages ? "  PROBLEM  " : "  warning  ")) << f.check << ": "
                << f.detail << "\n";
      if (!f.ok && !f.fix.empty()) std::cout << "           fix: " << f.fix << "\n";
      loses = loses || (!f.ok && f.loses_messages);
      warned = warned || !f.ok;
    }
    std::cout << (loses    ? "messages would be lost: fix the problems above\n"
                  : warned ? "no problem found in what was checked; see the warnings above\n"
                           : "the bus is ready\n");
    *exit_code = loses ? 1 : 0;
  });
}

}  // namespace fusecal
