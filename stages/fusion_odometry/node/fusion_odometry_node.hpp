// fusecal-fusion-odometry: caches stations and LiDAR motions; on EXTRINSIC version k (one that asks for
// refinement) recomputes the metric camera motion of every station pair the extrinsic used, warm-started
// from the previous version's motion, and publishes one FUSED_MOTIONS for version k. A repeated version
// is answered again from cache; versions older than the newest answered one are ignored.
// In a long session only the stations of the pairs the hand-eye stage holds and the newest ones are kept
// (StationRetention), so memory stays bounded.
#pragma once

#include <map>
#include <memory>
#include <optional>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/motion_set_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/stage_main.hpp"
#include "runtime/work_stats.hpp"
#include "stages/fusion_odometry/fusion_odometry.hpp"
#include "stages/node_kit/station_retention.hpp"

namespace fusecal {

struct FusionOdometryNodeSettings {
  std::string
      camera;  // its name on a rig of several (STATION_<camera>, EXTRINSIC_<camera>, ...); empty: the one camera
  fusion_odometry::FusionOdometrySettings odometry;
  double input_wait_s = 2.0;  // how long a request waits for the stations and LiDAR motions it needs
  // A pair keeps its last motion when the extrinsic moved less than this since (0: always recompute);
  // the hand-eye tolerances by default ...
  double reuse_rotation_deg = 1e-3;
  double reuse_translation_m = 1e-4;
  // ... or less than this fraction of the requesting estimate's own std (rotation and translation, its
  // largest; only when everything is observable; 0: off).
  double reuse_std_fraction = 0.5;

  // Empty when usable, else what is wrong: a field above (all >= 0), or odometry.Validate()'s message.
  std::string Validate() const;
};

FusionOdometryNodeSettings ReadFusionOdometryNodeSettings(ConfigReader section);

// How far the extrinsic may have moved since a pair's fused motion was computed for the motion to be kept
// when `request` asks for it: the fixed reuse tolerances, or reuse_std_fraction of the request's largest
// std (rotation, translation) when everything is observable and the covariance is one, whichever is larger.
struct ReuseTolerance {
  double rotation_deg, translation_m;
};
ReuseTolerance FusedMotionReuseTolerance(const FusionOdometryNodeSettings& settings, const extrinsic_t& request);

class FusionOdometryNode : public StageNode {
 public:
  explicit FusionOdometryNode(FusionOdometryNodeSettings settings) : settings_(std::move(settings)) {}
  void Start(Bus& bus) override;
  void Tick(Bus& bus, int64_t now_utime) override;
  StageStatus Status() const override;

 private:
  struct CachedStation {
    cv::Mat image;
    PointCloud cloud;
    std::shared_ptr<CameraModel> camera;
  };
  using PairKey = std::pair<int, int>;
  void OnStation(const station_t& station);
  void OnExtrinsic(Bus& bus, const extrinsic_t& extrinsic);
  motion_t ComputeMotion(int i, int j, const Isometry3& X, int version,
                         fusion_odometry::FusionOdometryResult* result) const;
  std::vector<motion_t> ComputeMotions(const extrinsic_t& extrinsic);
  bool HasInputsFor(const extrinsic_t& extrinsic) const;
  bool Reusable(const PairKey& pair, const Isometry3& X, const ReuseTolerance& tolerance) const;
  void AnswerPendingIfReady(Bus& bus, bool waited_enough);
  // Drops the stations StationRetention does not keep, and what is cached for their pairs.
  void EvictStations();

  FusionOdometryNodeSettings settings_;
  std::map<int, CachedStation> stations_;
  std::map<PairKey, Isometry3> lidar_motions_;
  std::map<PairKey, Isometry3> last_camera_motions_;  // warm start of the next version
  std::map<int, motion_set_t> answered_;              // version -> answer (kept small)
  int newest_answered_ = -1;
  std::optional<extrinsic_t> pending_;  // the newest request, until its inputs are here
  int64_t pending_since_utime_ = 0;
  int answered_without_inputs_ = 0;
  struct Computed {
    Isometry3 X;  // the extrinsic it was computed with
    motion_t motion;
  };
  std::map<PairKey, Computed> last_computed_;
  long reused_ = 0;
  StationRetention retention_;
  long stations_dropped_ = 0;
  std::vector<Subscription> subscriptions_;
  int motions_ = 0, failures_ = 0, repeats_ = 0;
  WorkStats work_;
};

}  // namespace fusecal
