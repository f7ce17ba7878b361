// Which stations a process keeps in a long session, so that its memory stops growing with the session.
//
// Kept: the newest `keep_recent` stations (motions to them may still be on their way to the hand-eye
// stage) and every station of a pair the hand-eye stage holds. Each EXTRINSIC lists all the pairs the
// hand-eye stage holds, as used or rejected; the stage holds at most handeye.max_motions of them, so
// what is kept is bounded by keep_recent + 2 max_motions stations. Fusion odometry may be asked to
// recompute any held pair; a dropped pair is never asked for again.
#pragma once

#include <set>

#include "fusecal/extrinsic_t.hpp"

namespace fusecal {

class StationRetention {
 public:
  // Room for the pairs of lidar_icp.previous_stations (at most 10) while the hand-eye stage takes them in.
  static constexpr int kDefaultKeepRecent = 24;

  explicit StationRetention(int keep_recent = kDefaultKeepRecent) : keep_recent_(keep_recent) {}

  void OnStation(int id) {
    recent_.insert(id);
    while (static_cast<int>(recent_.size()) > keep_recent_) recent_.erase(recent_.begin());
  }

  // Only a newer version than the last one seen changes what is held.
  void OnExtrinsic(const extrinsic_t& e) {
    if (e.version <= version_) return;
    version_ = e.version;
    held_.clear();
    held_.insert(e.used_station_i.begin(), e.used_station_i.end());
    held_.insert(e.used_station_j.begin(), e.used_station_j.end());
    held_.insert(e.rejected_station_i.begin(), e.rejected_station_i.end());
    held_.insert(e.rejected_station_j.begin(), e.rejected_station_j.end());
  }

  // Before the first EXTRINSIC every station is kept (nothing says yet which pairs matter), and so is one
  // newer than every station seen (its motions may come before it).
  bool Keep(int id) const {
    return version_ < 0 || recent_.count(id) || held_.count(id) || recent_.empty() || id > *recent_.rbegin();
  }

  // Erases the stations not kept from a map keyed by station id; returns how many.
  template <typename Map>
  int Evict(Map* stations) const {
    int erased = 0;
    for (auto it = stations->begin(); it != stations->end();) {
      if (Keep(it->first)) {
        ++it;
      } else {
        it = stations->erase(it);
        ++erased;
      }
    }
    return erased;
  }

 private:
  int keep_recent_;
  int version_ = -1;
  std::set<int> recent_;  // the newest station ids
  std::set<int> held_;    // the stations of the pairs the hand-eye stage holds
};

}  // namespace fusecal
