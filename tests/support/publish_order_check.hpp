// A check every transport with a reader per channel passes: messages of several channels waiting at once
// reach the handlers in the order they were published (a scan published before an image reaches the
// stationarity detector first, as in the log).
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "runtime/bus.hpp"

namespace fusecal::testing {

inline void ExpectChannelsArriveInPublishOrder(Bus& bus) {
  std::vector<std::string> received;
  auto on_message = [&](const RawMessage& m) { received.emplace_back(reinterpret_cast<const char*>(m.data), m.size); };
  auto scans = bus.SubscribeRaw("LIDAR_SCAN", on_message);
  auto images = bus.SubscribeRaw("CAMERA_IMAGE", on_message);
  const auto handle_until = [&](size_t count) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(3);
    while (received.size() < count && std::chrono::steady_clock::now() < end) bus.Handle(50);
  };
  // The writers first (a new one waits for discovery), then six of each, interleaved, with no handling.
  bus.PublishRaw("LIDAR_SCAN", "s", 1);
  bus.PublishRaw("CAMERA_IMAGE", "i", 1);
  handle_until(2);
  ASSERT_EQ(received.size(), 2u);
  received.clear();
  std::vector<std::string> published;
  for (int k = 0; k < 12; ++k) {
    published.push_back((k % 2 ? "scan " : "image ") + std::to_string(k));
    bus.PublishRaw(k % 2 ? "LIDAR_SCAN" : "CAMERA_IMAGE", published.back().data(), published.back().size());
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  handle_until(published.size());
  EXPECT_EQ(received, published);
}

}  // namespace fusecal::testing
