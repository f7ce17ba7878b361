// fusecal-bus-bridge: forwards every message between the coordinator's bus and the stages' bus, both ways
// (runtime/bus_bridge.hpp). `fusecal run` starts it for iox:// (runtime/shm_transport.hpp); the supervisor
// restarts it with the stages when RouDi dies.
//   fusecal-bus-bridge --coordinator udpm://...?ttl=0 --stages 'iox://?max=...'
#include <signal.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include "runtime/bus.hpp"
#include "runtime/bus_bridge.hpp"
#include "runtime/bus_url.hpp"

namespace {

std::atomic<bool> g_stop{false};
void OnSignal(int) { g_stop = true; }

// After SIGTERM the bridge forwards a little longer: the stages, stopped at the same moment, send their
// last STATUS ("stopped", final counters) through it.
constexpr auto kLinger = std::chrono::milliseconds(700);

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"fusecal-bus-bridge: forwards every message between two buses of one host, both ways"};
  std::string coordinator_url, stages_url;
  app.add_option("--coordinator", coordinator_url, "the coordinator's bus (LCM)")->required();
  app.add_option("--stages", stages_url, "the stages' bus (iox://)")->required();
  CLI11_PARSE(app, argc, argv);

  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  if (stages_url == coordinator_url) {
    // Shared memory given up (RouDi does not start again): the stages are on the coordinator's bus.
    while (!g_stop) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    return 0;
  }
  try {
    auto coordinator = fusecal::MakeBus(coordinator_url);
    // The bridge must not get back what it publishes on the stages' side.
    auto stages = fusecal::MakeBus(fusecal::WithUrlParameter(stages_url, "self", "0"));
    fusecal::BusBridge bridge(*coordinator, *stages);
    std::fprintf(stderr, "fusecal-bus-bridge: %s <-> %s\n", coordinator_url.c_str(), stages->url().c_str());
    while (!g_stop) {
      try {
        bridge.Pump(50);
      } catch (const fusecal::BusError& e) {
        std::fprintf(stderr, "fusecal-bus-bridge: %s\n", e.what());  // one message lost; go on
      }
    }
    for (const auto end = std::chrono::steady_clock::now() + kLinger; std::chrono::steady_clock::now() < end;)
      bridge.Pump(20);
    std::fprintf(stderr, "fusecal-bus-bridge: forwarded %llu to the stages, %llu to the coordinator\n",
                 static_cast<unsigned long long>(bridge.forwarded_to_stages()),
                 static_cast<unsigned long long>(bridge.forwarded_to_coordinator()));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fusecal-bus-bridge: %s\n", e.what());
    return 1;
  }
  return 0;
}
