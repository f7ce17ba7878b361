// Hours of scanning in bounded memory and disk: which stations a process keeps, how many motion pairs
// the hand-eye stage holds, and how the session log caps and rotates raw frames. In-process, on memq.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <set>

#include "fusecal/extrinsic_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "runtime/pipeline/session_log.hpp"
#include "stages/formats/motion_message.hpp"
#include "stages/handeye/node/handeye_node.hpp"
#include "stages/handeye/synthetic_motions.hpp"
#include "stages/node_kit/station_retention.hpp"

namespace fusecal {
namespace {

extrinsic_t ExtrinsicUsing(int version, std::vector<std::pair<int, int>> used,
                           std::vector<std::pair<int, int>> rejected) {
  extrinsic_t e{};
  e.version = version;
  for (const auto& [i, j] : used) {
    e.used_station_i.push_back(i);
    e.used_station_j.push_back(j);
  }
  for (const auto& [i, j] : rejected) {
    e.rejected_station_i.push_back(i);
    e.rejected_station_j.push_back(j);
  }
  e.num_used = static_cast<int32_t>(e.used_station_i.size());
  e.num_rejected = static_cast<int32_t>(e.rejected_station_i.size());
  return e;
}

TEST(StationRetention, KeepsTheNewestStationsAndThoseOfTheHeldPairsOnly) {
  StationRetention retention(3);
  std::map<int, int> stations;
  for (int id = 0; id < 10; ++id) {
    stations[id] = id;
    retention.OnStation(id);
  }
  // Nothing said yet which pairs matter: everything stays.
  EXPECT_EQ(retention.Evict(&stations), 0);
  retention.OnExtrinsic(ExtrinsicUsing(5, {{1, 2}}, {{4, 5}}));
  EXPECT_EQ(retention.Evict(&stations), 3);  // 0, 3 and 6 go
  std::set<int> kept;
  for (const auto& [id, value] : stations) kept.insert(id);
  EXPECT_EQ(kept, (std::set<int>{1, 2, 4, 5, 7, 8, 9}));
  // An older version changes nothing; a station newer than all seen is kept (its motions may come first).
  retention.OnExtrinsic(ExtrinsicUsing(4, {}, {}));
  EXPECT_TRUE(retention.Keep(1));
  EXPECT_TRUE(retention.Keep(12));
  EXPECT_FALSE(retention.Keep(6));
}

// Scaleless camera motions about two axes with a few small turns: the hand-eye stage holds at most
// max_motions pairs, drops the rest for good (a repeat does not bring one back), lists every held pair in
// each EXTRINSIC, and keeps both rotation axes.
TEST(HandEyeNodeLimit, HoldsAtMostMaxMotionsAndListsEveryHeldPair) {
  SyntheticMotionSettings synthetic;
  synthetic.num_motions = 30;
  synthetic.axes = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitZ(),
                    Eigen::Vector3d::UnitX()};
  synthetic.rotation_noise_deg = 0.01;
  synthetic.translation_noise_m = 0.001;
  const SyntheticMotionSet set = GenerateSyntheticMotions(synthetic);
  CalibratorSettings settings;
  settings.scaled_refinement = false;
  settings.max_motions = 8;
  HandEyeNode node(settings);
  auto bus = MakeBus("memq://");
  node.Start(*bus);
  std::vector<extrinsic_t> published;
  auto sub = bus->Subscribe(channels::kExtrinsic, [&](const extrinsic_t& e) { published.push_back(e); });
  const auto send = [&](const MotionPair& p) {
    bus->Publish(channels::kLidarMotion,
                 MakeMotion(p.station_i, p.station_j, "lidar", p.B, true, Matrix6::Identity(), 1));
    bus->Publish(channels::kCameraMotion,
                 MakeMotion(p.station_i, p.station_j, "camera", p.A, true, Matrix6::Identity(), 1));
    while (bus->Handle(0) > 0) {
    }
  };
  for (const auto& p : set.pairs) send(p);
  send(set.pairs.front());  // a repeat of a pair that was dropped
  ASSERT_FALSE(published.empty());
  EXPECT_EQ(node.Status().counters.at("pairs"), 8);
  EXPECT_EQ(node.Status().counters.at("dropped_motions"), 22);
  // The last EXTRINSIC lists the 8 held pairs, and the one its round dropped (if any) as rejected; every
  // pair was listed by some EXTRINSIC (answered, used or rejected).
  const extrinsic_t& last = published.back();
  std::set<std::pair<int, int>> listed, ever;
  for (int k = 0; k < last.num_used; ++k) listed.insert({last.used_station_i[k], last.used_station_j[k]});
  for (int k = 0; k < last.num_rejected; ++k) listed.insert({last.rejected_station_i[k], last.rejected_station_j[k]});
  EXPECT_GE(listed.size(), 8u);
  EXPECT_LE(listed.size(), 9u);
  for (const auto& e : published) {
    for (int k = 0; k < e.num_used; ++k) ever.insert({e.used_station_i[k], e.used_station_j[k]});
    for (int k = 0; k < e.num_rejected; ++k) ever.insert({e.rejected_station_i[k], e.rejected_station_j[k]});
  }
  EXPECT_EQ(ever.size(), set.pairs.size());
  std::set<std::pair<int, int>> held;
  for (int k = 0; k < last.num_used; ++k) held.insert({last.used_station_i[k], last.used_station_j[k]});
  bool about_x = false, about_z = false;
  for (const auto& p : set.pairs) {
    if (!held.count({p.station_i, p.station_j})) continue;
    const Eigen::AngleAxisd aa(p.B.linear());
    about_x |= std::abs(aa.axis().x()) > 0.9;
    about_z |= std::abs(aa.axis().z()) > 0.9;
  }
  EXPECT_TRUE(about_x && about_z) << "both rotation axes used";
  EXPECT_EQ(node.current()->observability, Observability::kOk) << node.current()->message;
}

std::string TempDir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "fusecal_long_" + std::to_string(getpid()) + "_" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::vector<std::string> Channels(const std::string& log) {
  std::vector<std::string> out;
  LogReader reader(log);
  while (auto event = reader.Next()) out.push_back(event->channel);
  return out;
}

// `all`: raw frames go to segments of a eighth of the cap each; the oldest are deleted so that the
// segments together stay under the cap; each starts with CAMERA_INFO; session.lcmlog has no raw frame.
TEST(SessionLog, RawFramesRotateUnderTheCapAndEachSegmentReplaysAlone) {
  const std::string dir = TempDir("all");
  SessionLog log(dir, RecordSettings{"all", 8.0});
  const std::vector<uint8_t> frame(700000, 7), station(1000, 2);
  const CameraInfos info{{channels::kCameraInfo.name, std::vector<uint8_t>(100, 1)}};
  for (int k = 0; k < 40; ++k) {
    log.Write(channels::kCameraImage.name, k, frame.data(), frame.size(), info);
    log.Write(channels::kStation.name, k, station.data(), station.size(), info);
  }
  log.Close();
  uintmax_t raw_bytes = 0;
  int segments = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir + "/raw")) {
    raw_bytes += entry.file_size();
    ++segments;
    const auto channels = Channels(entry.path());
    ASSERT_FALSE(channels.empty());
    EXPECT_EQ(channels.front(), channels::kCameraInfo.name) << entry.path();
  }
  EXPECT_LE(raw_bytes, 8000000u);
  EXPECT_GE(segments, 6);
  EXPECT_GT(log.segments_deleted(), 10);
  const auto session = Channels(dir + "/session.lcmlog");
  EXPECT_EQ(session.size(), 40u);
  EXPECT_EQ(std::count(session.begin(), session.end(), channels::kCameraImage.name), 0);
}

TEST(SessionLog, StationsPolicyKeepsNoRawFrameAndNoneWritesNothing) {
  const std::string dir = TempDir("stations");
  SessionLog log(dir, RecordSettings{});
  const std::vector<uint8_t> frame(1000, 7);
  const CameraInfos info;
  log.Write(channels::kLidarScan.name, 1, frame.data(), frame.size(), info);
  log.Write(channels::kStation.name, 2, frame.data(), frame.size(), info);
  log.Close();
  EXPECT_EQ(Channels(dir + "/session.lcmlog"), std::vector<std::string>{channels::kStation.name});
  EXPECT_FALSE(std::filesystem::exists(dir + "/raw"));
  const std::string none = TempDir("none");
  SessionLog nothing(none, RecordSettings{"none", 1.0});
  nothing.Write(channels::kStation.name, 2, frame.data(), frame.size(), info);
  nothing.Close();
  EXPECT_TRUE(std::filesystem::is_empty(none));
}

}  // namespace
}  // namespace fusecal
