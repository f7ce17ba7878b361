#include "runtime/bus_bridge.hpp"

#include <algorithm>
#include <set>
#include <string_view>

#include "runtime/channels.hpp"

namespace fusecal {

namespace {

constexpr auto kEchoWindow = std::chrono::seconds(5);

uint64_t Hash(const RawMessage& message) {
  return std::hash<std::string_view>()(std::string_view(reinterpret_cast<const char*>(message.data), message.size));
}

}  // namespace

BusBridge::BusBridge(Bus& coordinator, Bus& stages) : coordinator_(coordinator), stages_(stages) {
  for (const auto& channel : kPipelineChannels) {
    subscriptions_.push_back(
        coordinator_.SubscribeRaw(channel.name, [this](const RawMessage& m) { FromCoordinator(m); }));
    subscriptions_.push_back(stages_.SubscribeRaw(channel.name, [this](const RawMessage& m) { FromStages(m); }));
  }
  // Everything else (the pattern would match the pipeline's channels too: those are served above).
  subscriptions_.push_back(coordinator_.SubscribeRaw(".*", [this](const RawMessage& m) {
    if (!IsPipelineChannel(m.channel)) FromCoordinator(m);
  }));
  subscriptions_.push_back(stages_.SubscribeRaw(".*", [this](const RawMessage& m) {
    if (!IsPipelineChannel(m.channel)) FromStages(m);
  }));
}

void BusBridge::FromStages(const RawMessage& message) {
  echoes_.push_back({message.channel, message.size, Hash(message), std::chrono::steady_clock::now()});
  coordinator_.PublishRaw(message.channel, message.data, message.size);
  ++to_coordinator_;
}

void BusBridge::FromCoordinator(const RawMessage& message) {
  const auto now = std::chrono::steady_clock::now();
  while (!echoes_.empty() && now - echoes_.front().at > kEchoWindow) echoes_.pop_front();
  const uint64_t hash = Hash(message);
  const auto echo = std::find_if(echoes_.begin(), echoes_.end(), [&](const Sent& s) {
    return s.size == message.size && s.hash == hash && s.channel == message.channel;
  });
  if (echo != echoes_.end()) {  // our own forward, back from the multicast loop
    echoes_.erase(echo);
    return;
  }
  stages_.PublishRaw(message.channel, message.data, message.size);
  ++to_stages_;
}

int BusBridge::Pump(int timeout_ms) {
  const uint64_t before = to_stages_ + to_coordinator_;
  // Each side in turn, neither waiting long, so that one busy side does not hold up the other.
  const int slice = std::max(1, std::min(timeout_ms, 5));
  for (int spent = 0; spent < std::max(timeout_ms, 1); spent += 2 * slice) {
    const int n = coordinator_.Handle(slice) + stages_.Handle(slice);
    if (n > 0) break;
  }
  return static_cast<int>(to_stages_ + to_coordinator_ - before);
}

}  // namespace fusecal
