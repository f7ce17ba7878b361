#include "doctor.hpp"

#include <net/if.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "runtime/bus.hpp"
#include "runtime/bus_url.hpp"
#include "runtime/shared_memory.hpp"
#include "runtime/shm_transport.hpp"

namespace fusecal {

namespace {

int64_t ReadNumber(const std::string& path) {
  std::ifstream in(path);
  int64_t value = -1;
  in >> value;
  return value;
}

// Interface of the most specific route covering 224.0.0.0/4 in /proc/net/route (destination and mask
// in little-endian hex), or empty when none does.
std::string MulticastRouteInterface() {
  std::ifstream in("/proc/net/route");
  std::string line, best;
  unsigned long best_mask = 0;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    std::string iface, dest, gateway, flags, refcnt, use, metric, mask;
    fields >> iface >> dest >> gateway >> flags >> refcnt >> use >> metric >> mask;
    const unsigned long d = std::strtoul(dest.c_str(), nullptr, 16);
    const unsigned long m = std::strtoul(mask.c_str(), nullptr, 16);
    if ((d & m) != (0xE0ul & m)) continue;
    if (best.empty() || __builtin_popcountl(m) > __builtin_popcountl(best_mask)) {
      best = iface;
      best_mask = m;
    }
  }
  return best;
}

bool LoopbackHasMulticast() {
  std::ifstream in("/sys/class/net/lo/flags");
  std::string text;
  in >> text;
  return (std::strtol(text.c_str(), nullptr, 16) & IFF_MULTICAST) != 0;
}

// ttl=0 keeps traffic on this host: a route on lo is the clean set-up. ttl>=1 spans machines and
// needs a route through a real interface.
DoctorFinding CheckRoute(const std::string& url) {
  DoctorFinding f;
  f.check = "multicast route";
  const std::string ttl = UrlParameter(url, "ttl");
  const bool host_only = ttl.empty() || ttl == "0";
  const std::string iface = MulticastRouteInterface();
  if (iface.empty()) {
    f.ok = false;
    f.loses_messages = true;
    f.detail = "no route covers 224.0.0.0/4: multicast cannot be sent";
    f.fix = host_only ? "ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo"
                      : "ip route add 224.0.0.0/4 dev <your LAN interface>";
    return f;
  }
  if (host_only && (iface != "lo" || !LoopbackHasMulticast())) {
    f.ok = false;  // works (ttl=0 never leaves the host), but the loopback route is the clean set-up
    f.detail = "multicast goes through " + iface + (iface == "lo" ? " without the MULTICAST flag" : "") +
               "; with ttl=0 a loopback route keeps it on this host";
    f.fix = "ip link set lo multicast on && ip route replace 224.0.0.0/4 dev lo";
    return f;
  }
  f.detail = "224.0.0.0/4 is routed through " + iface;
  return f;
}

DoctorFinding CheckReceiveBuffer(const std::string& url) {
  DoctorFinding f;
  f.check = "receive buffer";
  const int64_t rmem_max = ReadNumber("/proc/sys/net/core/rmem_max");
  const std::string wanted_text = UrlParameter(url, "recv_buf_size");
  if (wanted_text.empty()) {
    f.ok = false;
    f.loses_messages = true;
    f.detail =
        "the bus URL sets no recv_buf_size: with the kernel default, multi-megabyte scans and "
        "images are dropped (measured: 0 of 50 2 MB messages)";
    f.fix =
        "add recv_buf_size=67108864 to the bus URL, e.g. "
        "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=67108864";
    return f;
  }
  const int64_t wanted = std::atoll(wanted_text.c_str());
  f.ok = rmem_max >= wanted;
  f.loses_messages = !f.ok;
  f.detail = "net.core.rmem_max = " + std::to_string(rmem_max) + ", the bus asks for " + std::to_string(wanted);
  if (!f.ok)
    f.fix = "sysctl -w net.core.rmem_max=" + std::to_string(wanted) +
            " (persist: echo net.core.rmem_max=" + std::to_string(wanted) + " > /etc/sysctl.d/60-fusecal.conf)";
  return f;
}

// fusecal-ros2-input asks Cyclone for a receive buffer of 6 of its largest messages; the kernel caps it
// at rmem_max, and a smaller buffer loses best-effort clouds without counting them.
DoctorFinding CheckRos2ReceiveBuffer(size_t wanted) {
  DoctorFinding f;
  f.check = "ROS 2 receive buffer";
  const int64_t rmem_max = ReadNumber("/proc/sys/net/core/rmem_max");
  f.ok = rmem_max >= static_cast<int64_t>(wanted);
  f.loses_messages = !f.ok;
  f.detail = "net.core.rmem_max = " + std::to_string(rmem_max) + ", fusecal-ros2-input asks for " +
             std::to_string(wanted) + " (6 x ros2_input.max_message_mb)";
  if (!f.ok)
    f.fix = "sysctl -w net.core.rmem_max=" + std::to_string(wanted) +
            " (persist: echo net.core.rmem_max=" + std::to_string(wanted) + " > /etc/sysctl.d/60-fusecal.conf)";
  return f;
}

// /dev/shm must hold RouDi's pools for the default configuration (the shared-memory transport only).
DoctorFinding CheckSharedMemory() {
  DoctorFinding f;
  f.check = "/dev/shm";
  const shm::PoolPlan plan = shm::PlanPools(shm::kDefaultMaxMessageBytes, shm::kDefaultBulkChunks);
  const shm::ShmSpace space = shm::QueryShmSpace();
  const std::string problem = shm::CheckPlanFits(plan, space);
  std::ostringstream detail;
  detail.precision(2);
  detail << std::fixed << double(space.free_bytes) / double(1u << 30) << " GiB free; RouDi's pools need "
         << double(plan.total_bytes() + shm::kRoudiManagementBytes) / double(1u << 30)
         << " GiB (dds://?shm=1 and iox:// only)";
  f.ok = problem.empty();
  f.detail = f.ok ? detail.str() : problem;
  if (!f.ok) f.fix = "mount -o remount,size=2g /dev/shm";
  return f;
}

// Whether an iceoryx RouDi is up; `fusecal run` starts its own, stand-alone stages need one.
DoctorFinding CheckRoudi(const std::string& url) {
  DoctorFinding f;
  f.check = "iceoryx RouDi";
  const bool iox = IsIoxUrl(url);
  const bool wanted = IsSharedMemoryDdsUrl(url) || iox;
  const bool running = shm::RoudiRunning();
  if (shm::RoudiExecutable().empty()) {
    f.ok = !wanted;
    f.loses_messages = iox;  // iox:// has no other path
    f.detail = iox ? "iox-roudi is not installed: iox:// cannot run"
                   : "iox-roudi is not installed (shared memory is unavailable; dds://?shm=1 uses the network path)";
    if (wanted) f.fix = "apt-get install iceoryx";
    return f;
  }
  f.detail = running ? "running (socket /tmp/roudi)"
                     : std::string("not running") +
                           (iox      ? ": `fusecal run` starts its own; stand-alone stages on iox:// fail without one"
                            : wanted ? ": `fusecal run` starts its own; stand-alone stages with shm=1 would use "
                                       "the network path"
                                     : " (needed by dds://?shm=1 and iox:// only)");
  return f;
}

DoctorFinding CheckLiveRoundTrip(const std::string& url) {
  DoctorFinding f;
  f.check = "bus round trip";
  try {
    auto bus = MakeBus(url);
    const std::vector<uint8_t> payload(1 << 20, 0x5a);
    size_t received = 0;
    auto sub = bus->SubscribeRaw("FUSECAL_DOCTOR_PROBE", [&](const RawMessage& m) { received = m.size; });
    bus->PublishRaw("FUSECAL_DOCTOR_PROBE", payload.data(), payload.size());
    for (int i = 0; i < 10 && received == 0; ++i) bus->Handle(100);
    f.ok = received == payload.size();
    f.detail = f.ok ? "a 1 MB message went round " + url
                    : "a 1 MB message published on " + url + " did not come back within 1 s";
  } catch (const std::exception& e) {
    f.ok = false;
    f.detail = e.what();
  }
  f.loses_messages = !f.ok;
  if (!f.ok) f.fix = "fix the problems above, then run `fusecal doctor` again";
  return f;
}

// iox://: a 1 MB message round the shared-memory path itself, over the RouDi that runs, or else over one
// started for the check (with the pools `fusecal run` plans; it ends when the doctor does, since a process
// attached to RouDi is ended when RouDi is stopped).
DoctorFinding CheckIoxRoundTrip(const std::string& url, std::unique_ptr<shm::RoudiProcess>* roudi) {
  DoctorFinding f;
  f.check = "iox:// round trip";
  std::string checked = url;
  if (!shm::RoudiRunning() && !shm::RoudiExecutable().empty()) {
    const shm::PoolPlan plan = shm::PlanPools(shm::kDefaultMaxMessageBytes, shm::kDefaultBulkChunks);
    char dir[] = "/tmp/fusecal-doctor-XXXXXX";
    try {
      if (!mkdtemp(dir)) throw std::runtime_error("cannot create a folder in /tmp for RouDi");
      *roudi = std::make_unique<shm::RoudiProcess>(dir, plan);
      (*roudi)->Start();
      (*roudi)->LeaveUntilExit();
      std::error_code ignored;  // RouDi has read its config; its log is an open file
      std::filesystem::remove_all(dir, ignored);
      if (UrlParameter(url, "max").empty())
        checked = WithUrlParameter(url, "max", std::to_string(shm::LargestShmMessage(plan)));
    } catch (const std::exception& e) {
      f.ok = false;
      f.loses_messages = true;
      f.detail = std::string("RouDi does not start: ") + e.what();
      f.fix = "fix the problems above, then run `fusecal doctor --bus 'iox://'` again";
      return f;
    }
  }
  f = CheckLiveRoundTrip(checked);
  f.check = "iox:// round trip";
  if (f.ok) f.detail += *roudi ? " (over a RouDi started for this check)" : " (over the running RouDi)";
  return f;
}

// The URL itself, through the parser every bus uses: no scheme, an unknown one, an unknown option or one out
// of range is a problem naming it (nothing else is checked). file:// and tcpq:// have no path this doctor
// can test: it says so instead of "ready".
DoctorFinding CheckUrl(const std::string& url) {
  DoctorFinding f;
  f.check = "bus URL";
  std::string scheme;
  try {
    scheme = ParseBusUrl(url).scheme;
  } catch (const std::exception& e) {
    f.ok = false;
    f.loses_messages = true;
    f.detail = e.what();
    f.fix = "give one of udpm://GROUP:PORT?ttl=N&recv_buf_size=B, dds://?domain=N, iox://, memq://";
    return f;
  }
  if (scheme == "file" || scheme == "tcpq") {
    f.ok = false;
    f.detail = "not tested: the doctor checks udpm://, memq://, dds:// and iox:// buses, not " + scheme + "://";
    return f;
  }
  f.detail = scheme + "://, options checked; the bus itself below";
  return f;
}

}  // namespace

std::vector<DoctorFinding> RunDoctor(const std::string& bus_url, bool apply_fixes, size_t ros2_receive_buffer) {
  const std::string url = bus_url.empty() ? DefaultBusUrl() : bus_url;
  const DoctorFinding url_finding = CheckUrl(url);
  if (!url_finding.ok) return {url_finding};
  const bool multicast = url.rfind("udpm://", 0) == 0;
  // iox://: `fusecal run` keeps its coordinator on LCM multicast on this host, bridged to the stages.
  const std::string multicast_url = IsIoxUrl(url) ? kIoxCoordinatorUrl : url;
  auto run_checks = [&] {
    std::vector<DoctorFinding> findings;
    if (multicast || IsIoxUrl(url)) {
      findings.push_back(CheckRoute(multicast_url));
      findings.push_back(CheckReceiveBuffer(multicast_url));
    }
    findings.push_back(CheckSharedMemory());
    findings.push_back(CheckRoudi(url));
    if (ros2_receive_buffer > 0) findings.push_back(CheckRos2ReceiveBuffer(ros2_receive_buffer));
    return findings;
  };
  std::vector<DoctorFinding> findings = run_checks();
  if (apply_fixes) {
    for (const auto& f : findings) {
      if (f.ok || f.fix.empty() || f.fix.rfind("add ", 0) == 0) continue;
      const std::string command = f.fix.substr(0, f.fix.find(" (persist"));
      if (command.find('<') != std::string::npos) continue;  // needs the user's choice
      std::cout << "running: " << command << std::endl;
      if (std::system(("(" + command + ") >/dev/null 2>&1").c_str()) != 0)
        std::cout << "  failed (are you root?)" << std::endl;
    }
    findings = run_checks();
  }
  // Over DDS's network path even for shm=1: a process attached to RouDi is ended when RouDi stops, and
  // the doctor must not be (RouDi itself has its own line above).
  if (multicast || url.rfind("memq://", 0) == 0) findings.push_back(CheckLiveRoundTrip(url));
  if (url.rfind("dds://", 0) == 0) findings.push_back(CheckLiveRoundTrip(WithUrlParameter(url, "shm", "0")));
  if (IsIoxUrl(url)) {
    findings.push_back(CheckLiveRoundTrip(kIoxCoordinatorUrl));
    findings.back().check = "coordinator bus round trip";
    static std::unique_ptr<shm::RoudiProcess> roudi;  // (until the doctor exits)
    findings.push_back(CheckIoxRoundTrip(url, &roudi));
  }
  return findings;
}

}  // namespace fusecal
