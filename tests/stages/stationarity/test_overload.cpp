// The stationarity node under overload (docs/design.md section 5): raw frames beyond its queue are
// skipped (latest wins) and counted; the stations are built from the frames it took, so none is lost;
// STATION is published for every one of them.
#include <gtest/gtest.h>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/channels.hpp"
#include "runtime/sim/fixtures/stationarity_test_util.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/stationarity/node/stationarity_node.hpp"

using namespace fusecal;
using namespace fusecal::fixtures;

namespace {

struct Outcome {
  int stations = 0;  // STATION messages on the bus
  std::map<std::string, double> counters;
};

// Plays the tiny recording into a node on memq, letting the node work only after every `burst` frames
// (a detector slower than the stream); burst 1 is a node that keeps up. `paced`: a replay that waits for
// the pipeline (--paced).
Outcome Play(int burst, int queue_depth, bool paced = false) {
  StationarityNodeSettings settings;
  settings.detector = TinySettings();
  settings.raw_queue_depth = queue_depth;
  settings.max_image_rate_hz = 0;  // every image (no decimation), so only overload skips
  StationarityNode node(settings);
  if (paced) node.UsePacedInput();
  auto bus = MakeBus("memq://");
  Outcome out;
  auto sub = bus->Subscribe<station_t>(
      channels::kStation.name, std::function<void(const station_t&)>([&](const station_t&) { ++out.stations; }));
  node.Start(*bus);
  const Recording& r = TinyRecording();
  bus->Publish(channels::kCameraInfo, CameraToMsg(r.scenario.camera().params, r.frames.front().utime));
  auto settle = [&] {
    while (bus->Handle(0) > 0) {
    }
    do node.Tick(*bus, 0);
    while (node.HasQueuedWork());
    while (bus->Handle(0) > 0) {
    }
  };
  int since_work = 0;
  for (const Frame& f : r.frames) {
    if (f.camera)
      bus->Publish(channels::kCameraImage, MatToImage(f.image, "bgr8", f.utime));
    else
      bus->Publish(channels::kLidarScan, CloudToMsg(f.cloud, f.utime));
    while (bus->Handle(0) > 0) {  // the handlers only queue
    }
    if (++since_work >= burst) {
      settle();
      since_work = 0;
    }
  }
  settle();
  node.Flush(*bus);
  settle();
  out.counters = node.Status().counters;
  return out;
}

}  // namespace

TEST(StationarityOverload, AStageThatKeepsUpSkipsNothing) {
  const Outcome o = Play(1, 2);
  EXPECT_EQ(o.counters.at("skipped"), 0);
  EXPECT_EQ(o.counters.at("images_skipped") + o.counters.at("scans_skipped"), 0);
  EXPECT_EQ(o.stations, static_cast<int>(TinyRecording().truth.size()));
}

TEST(StationarityOverload, FramesBeyondTheQueueAreSkippedAndCountedButNoStationIsLost) {
  const Outcome kept_up = Play(1, 2);
  // Works only after every 6 frames (3 images, 3 scans) with room for 2 per stream: 1 of 3 is skipped.
  const Outcome slow = Play(6, 2);
  const double frames = static_cast<double>(TinyRecording().frames.size());
  const double skipped = slow.counters.at("images_skipped") + slow.counters.at("scans_skipped");
  EXPECT_EQ(slow.counters.at("skipped"), skipped);
  EXPECT_GT(skipped, 0.25 * frames) << "the queue must have dropped frames";
  EXPECT_EQ(slow.counters.at("items") + skipped, frames) << "every frame is either taken or counted as skipped";
  EXPECT_GT(kept_up.stations, 0);
  EXPECT_EQ(slow.stations, kept_up.stations) << "a skipped frame costs a sample, never a station";
  EXPECT_EQ(slow.stations, static_cast<double>(slow.counters.at("stations")));
}

TEST(StationarityOverload, APacedReplaySkipsNoFrameWhenTheDetectorFallsBehind) {
  const Outcome kept_up = Play(1, 2);
  // The detector works only after every 40 frames, far beyond a queue of 2 per stream.
  const Outcome paced = Play(40, 2, true);
  EXPECT_EQ(paced.counters.at("skipped"), 0);
  EXPECT_EQ(paced.counters.at("items"), static_cast<double>(TinyRecording().frames.size()));
  EXPECT_EQ(paced.stations, kept_up.stations);
  EXPECT_GT(Play(40, 2).counters.at("skipped"), 0) << "without --paced the same burst skips frames";
}

// Paced, the node asks for a STATUS every two frames done, whose frames_done the player waits for.
TEST(StationarityOverload, APacedNodeReportsTheFramesItHasDone) {
  for (const bool paced : {false, true}) {
    StationarityNodeSettings settings;
    settings.detector = TinySettings();
    settings.max_image_rate_hz = 0;
    StationarityNode node(settings);
    if (paced) node.UsePacedInput();
    auto bus = MakeBus("memq://");
    node.Start(*bus);
    const Recording& r = TinyRecording();
    int reports = 0, frames = 0;
    for (int k = 0; k < 6; ++k, ++frames) {
      const Frame& f = r.frames[static_cast<size_t>(k)];
      f.camera ? bus->Publish(channels::kCameraImage, MatToImage(f.image, "bgr8", f.utime))
               : bus->Publish(channels::kLidarScan, CloudToMsg(f.cloud, f.utime));
      while (bus->Handle(0) > 0) {
      }
      EXPECT_FALSE(node.WantsStatusNow()) << "a queued frame is not done";
      node.Tick(*bus, 0);
      if (node.WantsStatusNow()) {
        ++reports;
        EXPECT_EQ(node.Status().counters.at("frames_done"), frames + 1);
      }
    }
    EXPECT_EQ(reports, paced ? 3 : 0) << (paced ? "paced" : "not paced");
  }
}

TEST(StationarityOverload, DecimationTakesImagesAtTheConfiguredRate) {
  StationarityNodeSettings settings;
  settings.max_image_rate_hz = 5;  // the recording has 10 Hz images: every other one is taken
  StationarityNode node(settings);
  auto bus = MakeBus("memq://");
  node.Start(*bus);
  const Recording& r = TinyRecording();
  int images = 0;
  for (const Frame& f : r.frames) {
    if (!f.camera) continue;
    ++images;
    bus->Publish(channels::kCameraImage, MatToImage(f.image, "bgr8", f.utime));
    while (bus->Handle(0) > 0) {
    }
    node.Tick(*bus, 0);
  }
  const auto counters = node.Status().counters;
  EXPECT_NEAR(counters.at("images_decimated"), images / 2, 1);
  EXPECT_NEAR(counters.at("images"), images / 2, 1);
}
