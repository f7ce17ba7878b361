#include "runtime/sim/simulator/trajectory.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "runtime/sim/simulator/random.hpp"

namespace fusecal::sim {

namespace {

constexpr double kDegToRad = M_PI / 180.0;

// Pose after rotating `start` by angle about axis through pivot, then translating.
Isometry3 Apply(const Isometry3& start, const Eigen::Vector3d& axis, const Eigen::Vector3d& pivot, double angle,
                const Eigen::Vector3d& translation) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
  Isometry3 T = Isometry3::Identity();
  T.linear() = R * start.linear();
  T.translation() = R * (start.translation() - pivot) + pivot + translation;
  return T;
}

// The motion order: 'H' and 'V'.
std::vector<char> Order(const MotionParams& m) {
  std::vector<char> order;
  if (m.order == "grouped") {
    order.assign(m.horizontal, 'H');
    order.insert(order.end(), m.vertical, 'V');
    return order;
  }
  int h = m.horizontal, v = m.vertical;
  while (h > 0 || v > 0) {
    if (h > 0) order.push_back('H'), --h;
    if (v > 0) order.push_back('V'), --v;
  }
  return order;
}

}  // namespace

double MinimumJerk(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}

Trajectory::Trajectory(std::vector<StillInterval> stills, std::vector<Motion> motions)
    : stills_(std::move(stills)), motions_(std::move(motions)) {
  if (stills_.empty() || motions_.size() + 1 != stills_.size())
    throw std::invalid_argument("Trajectory: need one more still interval than motions");
}

double Trajectory::duration() const { return stills_.back().t_to; }

Isometry3 Trajectory::T_world_lidar(double t) const {
  // Stills and motions alternate: still 0, motion 0, still 1, ...
  for (size_t i = 0; i < motions_.size(); ++i) {
    if (t <= stills_[i].t_to) return stills_[i].T_world_lidar;
    const Motion& m = motions_[i];
    if (t < m.t_to) {
      const double s = MinimumJerk((t - m.t_from) / (m.t_to - m.t_from));
      return Apply(stills_[i].T_world_lidar, m.axis_world, m.pivot_world, s * m.angle_rad, s * m.translation_world);
    }
  }
  return stills_.back().T_world_lidar;
}

int Trajectory::StillStation(double t0, double t1) const {
  for (const auto& s : stills_)
    if (t0 >= s.t_from && t1 <= s.t_to) return s.station_id;
  return -1;
}

Trajectory BuildTrajectory(const Scenario& scenario) {
  const MotionParams& m = scenario.motions;
  Rng rng(MixSeed(scenario.seed, 0x747261ull));  // the trajectory's own stream
  Isometry3 T = MakeIsometry(RotationFromRpy(0, 0, scenario.rig_yaw_deg * kDegToRad), scenario.rig_position_m);
  const Eigen::Vector3d start = T.translation();
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();

  std::vector<StillInterval> stills;
  std::vector<Motion> motions;
  double t = 0.0;
  int vertical_count = 0;
  const std::vector<char> order = Order(m);
  for (size_t k = 0; k <= order.size(); ++k) {
    stills.push_back({static_cast<int>(k), t, t + m.still_s, T});
    t += m.still_s;
    if (k == order.size()) break;

    Motion motion;
    motion.from_station = static_cast<int>(k);
    motion.t_from = t;
    motion.t_to = t + rng.Uniform(m.move_min_s, m.move_max_s);
    motion.translation_world.setZero();
    if (order[k] == 'H') {
      motion.kind = Motion::Kind::kHorizontal;
      motion.axis_world = up;
      motion.pivot_world = T * m.yaw_pivot_m;
      motion.angle_rad =
          (rng.Uniform() < 0.5 ? -1.0 : 1.0) * rng.Uniform(m.rotation_min_deg, m.rotation_max_deg) * kDegToRad;
      const double heading = rng.Uniform(0.0, 2.0 * M_PI);
      const double length = rng.Uniform(0.0, m.translation_m);
      motion.translation_world = length * Eigen::Vector3d(std::cos(heading), std::sin(heading), 0.0);
      // Keep the rig near its start: if this move would leave the allowed area, move back towards it.
      const Eigen::Vector3d end =
          Apply(T, up, motion.pivot_world, motion.angle_rad, Eigen::Vector3d::Zero()).translation();
      Eigen::Vector3d back = start - end;
      back.z() = 0.0;
      if ((end + motion.translation_world - start).head<2>().norm() > m.max_drift_m)
        motion.translation_world = back.norm() > 1e-9
                                       ? Eigen::Vector3d(back.normalized() * std::min(length, back.norm()))
                                       : Eigen::Vector3d::Zero();
    } else {
      motion.kind = Motion::Kind::kVertical;
      // Axis: the rig's pitch (LiDAR y) or roll (LiDAR x) axis, made horizontal.
      const bool roll = m.tilt_axis == "roll" || (m.tilt_axis == "alternate" && vertical_count % 2 == 1);
      ++vertical_count;
      Eigen::Vector3d axis = T.linear() * (roll ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY());
      axis.z() = 0.0;
      if (axis.norm() < 1e-6) throw std::runtime_error("BuildTrajectory: rig tilted too far");
      axis.normalize();
      // Current tilt about this axis; tilt back across level so the tilt stays within tilt_max_deg.
      const Eigen::Vector3d rig_up = T.linear() * Eigen::Vector3d::UnitZ();
      const double tilt = std::asin(std::clamp(up.cross(rig_up).dot(axis), -1.0, 1.0));
      const double magnitude = rng.Uniform(m.tilt_min_deg, m.tilt_max_deg) * kDegToRad;
      double sign = tilt > 1e-9 ? -1.0 : (tilt < -1e-9 ? 1.0 : (rng.Uniform() < 0.5 ? -1.0 : 1.0));
      if (std::abs(tilt + sign * magnitude) > m.tilt_max_deg * kDegToRad + 1e-9) sign = -sign;
      motion.axis_world = axis;
      motion.pivot_world = T * m.tilt_pivot_m;
      motion.angle_rad = sign * magnitude;
    }
    T = Apply(T, motion.axis_world, motion.pivot_world, motion.angle_rad, motion.translation_world);
    t = motion.t_to;
    motions.push_back(motion);
  }
  return Trajectory(std::move(stills), std::move(motions));
}

}  // namespace fusecal::sim
