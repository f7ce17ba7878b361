// The skeleton of a stage that answers every STATION with the motions from the k previous stations to it
// (LiDAR ICP, camera front end). It owns the protocol; the stage supplies two steps:
//   Prepare(station)          what pairing needs of one station (a scan, image features); throws on bad input
//   Pair(previous, current)   one motion_t from the previous station to the current one
// Each station is prepared once. When a station comes again (the supervisor gives a restarted stage the
// stations again, and a restarted stage downstream needs the motions), its motions are published again
// from cache and nothing is recomputed. A station that cannot be prepared is answered with failed motions
// (so that nobody waits for them) and is not kept for pairing; the error is rethrown for the stage's log.
#pragma once

#include <deque>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "fusecal/motion_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/channels.hpp"
#include "runtime/stage_main.hpp"
#include "runtime/work_stats.hpp"
#include "stages/formats/motion_message.hpp"

namespace fusecal {

template <typename Prepared>
class StationPairNode : public StageNode {
 public:
  // `sensor` names the motions ("lidar", "camera"); the stations come on `stations`, the motions are
  // published on `channel`.
  StationPairNode(std::string sensor, Channel<station_t> stations, Channel<motion_t> channel, int previous_stations)
      : sensor_(std::move(sensor)),
        stations_channel_(stations),
        channel_(channel),
        previous_stations_(previous_stations) {}

  void Start(Bus& bus) override {
    subscriptions_.push_back(bus.Subscribe(stations_channel_, [this, &bus](const station_t& s) { OnStation(bus, s); }));
  }

  StageStatus Status() const override {
    StageStatus s;
    s.state = state_;
    s.counters = {{"stations", stations_}, {"motions", motions_}, {"failures", failures_}};
    work_.AddTo(&s.counters);  // items: stations prepared and paired
    return s;
  }

 protected:
  virtual Prepared Prepare(const station_t& station) = 0;
  virtual motion_t Pair(int previous_id, const Prepared& previous, const station_t& station,
                        const Prepared& current) = 0;

 private:
  void OnStation(Bus& bus, const station_t& station) {
    if (const auto seen = published_.find(station.id); seen != published_.end()) {
      for (const auto& motion : seen->second) bus.Publish(channel_, motion);
      return;
    }
    published_[station.id];
    ++stations_;
    WorkStats::Timer timer(&work_);
    state_ = "working on station " + std::to_string(station.id);
    Prepared current;
    try {
      current = Prepare(station);
    } catch (const std::exception& e) {
      AnswerBadStation(bus, station, e.what());
      // On a rig of several cameras, which camera's image it was.
      const std::string camera =
          sensor_ == "camera" && !station.camera.name.empty() ? "camera " + station.camera.name + ", " : "";
      throw std::runtime_error(camera + "station " + std::to_string(station.id) + ": " + e.what());
    }
    // Motions go from lower to higher ids, whatever the order of arrival (after a restart a station may
    // come before the ones it follows); the k highest ids are kept for pairing.
    for (const auto& [previous_id, previous] : previous_)
      if (previous_id < station.id) Publish(bus, station.id, Pair(previous_id, previous, station, current));
    auto at = previous_.begin();
    while (at != previous_.end() && at->first < station.id) ++at;
    previous_.emplace(at, station.id, std::move(current));
    while (static_cast<int>(previous_.size()) > previous_stations_) previous_.pop_front();
    state_ = "waiting";
  }

  void AnswerBadStation(Bus& bus, const station_t& station, const std::string& why) {
    ++failures_;
    state_ = "waiting";
    for (const auto& previous : previous_)
      if (previous.first < station.id)
        Publish(bus, station.id, MakeFailedMotion(previous.first, station.id, sensor_, why, station.utime));
  }

  void Publish(Bus& bus, int station_id, const motion_t& motion) {
    motion.valid ? ++motions_ : ++failures_;
    bus.Publish(channel_, motion);
    published_[station_id].push_back(motion);
  }

  std::string sensor_;
  Channel<station_t> stations_channel_;
  Channel<motion_t> channel_;
  int previous_stations_;
  std::deque<std::pair<int, Prepared>> previous_;   // (station id, prepared), by id, highest last
  std::map<int, std::vector<motion_t>> published_;  // per station, for repeats
  std::vector<Subscription> subscriptions_;
  int stations_ = 0, motions_ = 0, failures_ = 0;
  WorkStats work_;
  std::string state_ = "waiting";
};

}  // namespace fusecal
