#include "stages/lidar_icp/global_alignment.hpp"

#include <algorithm>
#include <cmath>

namespace fusecal::lidar_icp {
namespace {

// Minimal rotation taking e_z to the unit vector u (its axis is horizontal: a pure tilt).
Eigen::Matrix3d Swing(const Eigen::Vector3d& u) {
  return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), u).toRotationMatrix();
}

bool CloseTo(const Isometry3& a, const Isometry3& b, double angle_rad, double distance_m) {
  return RotationErrorRad(a.linear(), b.linear()) < angle_rad &&
         (a.translation() - b.translation()).norm() < distance_m;
}

}  // namespace

double Objective(const DistanceField& field, const std::vector<Eigen::Vector3f>& source, const Isometry3& T) {
  if (source.empty()) return 0.0;
  const DistanceField::Tally t = field.Evaluate(T.linear().cast<float>(), T.translation().cast<float>(), source);
  return t.sum / (t.observed + 0.2 * double(source.size()));
}

std::vector<Eigen::Matrix3d> RotationGrid(double max_tilt_rad, double step_rad) {
  // Directions u = R e_z: a Fibonacci sphere with about one point per step^2 of solid angle, kept on
  // the cap of half-angle max_tilt (+ half a step, so the border is covered), plus u = e_z exactly.
  const int sphere_points = std::max(8, static_cast<int>(std::ceil(4.0 * M_PI / (step_rad * step_rad))));
  const double cap_cos = std::cos(std::min(M_PI, max_tilt_rad + 0.5 * step_rad));
  std::vector<Eigen::Vector3d> directions{Eigen::Vector3d::UnitZ()};
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < sphere_points; ++i) {
    const double z = 1.0 - (i + 0.5) * 2.0 / sphere_points;
    if (z < cap_cos) break;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d u(r * std::cos(golden * i), r * std::sin(golden * i), z);
    if (u.z() > std::cos(0.5 * step_rad)) continue;  // e_z itself is already in
    directions.push_back(u);
  }
  const int yaw_steps = std::max(1, static_cast<int>(std::lround(2.0 * M_PI / step_rad)));
  std::vector<Eigen::Matrix3d> grid;
  grid.reserve(directions.size() * yaw_steps);
  for (const Eigen::Vector3d& u : directions) {
    const Eigen::Matrix3d S = Swing(u);
    for (int k = 0; k < yaw_steps; ++k)
      grid.push_back(S * Eigen::AngleAxisd(2.0 * M_PI * k / yaw_steps, Eigen::Vector3d::UnitZ()).toRotationMatrix());
  }
  return grid;
}

PoseCandidate HillClimb(const DistanceField& field, const std::vector<Eigen::Vector3f>& source, const Isometry3& T0,
                        double rotation_step_rad, double translation_step_m) {
  PoseCandidate best{T0, Objective(field, source, T0)};
  const double min_rotation_step = 0.25 * M_PI / 180.0;
  const double min_translation_step = 0.5 * field.resolution();
  double rs = rotation_step_rad, ts = translation_step_m;
  for (int guard = 0; guard < 200; ++guard) {
    PoseCandidate step_best = best;
    for (int axis = 0; axis < 6; ++axis)
      for (int sign = -1; sign <= 1; sign += 2) {
        Isometry3 T = best.T_target_source;
        if (axis < 3) {
          // Rotation about the source origin (the sensor of scan j): right perturbation.
          T.linear() = T.linear() * Eigen::AngleAxisd(sign * rs, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
        } else {
          T.translation()(axis - 3) += sign * ts;
        }
        const double s = Objective(field, source, T);
        if (s > step_best.score) step_best = {T, s};
      }
    if (step_best.score > best.score) {
      best = step_best;
      continue;
    }
    if (rs <= min_rotation_step && ts <= min_translation_step) break;
    rs = std::max(min_rotation_step, 0.5 * rs);
    ts = std::max(min_translation_step, 0.5 * ts);
  }
  return best;
}

std::vector<PoseCandidate> GlobalCandidates(const DistanceField& field, const DistanceField& sharp,
                                            const std::vector<Eigen::Vector3f>& source,
                                            const GlobalSearchOptions& options,
                                            const std::vector<Isometry3>& extra_seeds) {
  const std::vector<Eigen::Matrix3d> grid = RotationGrid(options.max_tilt_rad, options.rotation_step_rad);
  std::vector<float> scores(grid.size());
  const int n = static_cast<int>(grid.size());
#pragma omp parallel for num_threads(options.threads) schedule(dynamic, 16)
  for (int i = 0; i < n; ++i) scores[i] = Objective(field, source, MakeIsometry(grid[i], Eigen::Vector3d::Zero()));

  std::vector<int> order(grid.size());
  for (int i = 0; i < n; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return scores[a] > scores[b]; });

  // Non-maximum suppression in rotation: seeds at least a step apart; twice as many seeds as
  // candidates wanted, since hill climbing reorders them.
  std::vector<Isometry3> seeds = extra_seeds;
  const size_t wanted_seeds = seeds.size() + 2 * static_cast<size_t>(options.candidates);
  for (int i : order) {
    if (seeds.size() >= wanted_seeds) break;
    bool distinct = true;
    for (size_t s = extra_seeds.size(); s < seeds.size() && distinct; ++s)
      distinct = RotationErrorRad(seeds[s].linear(), grid[i]) > 1.05 * options.rotation_step_rad;
    if (distinct) seeds.push_back(MakeIsometry(grid[i], Eigen::Vector3d::Zero()));
  }

  std::vector<PoseCandidate> climbed(seeds.size());
  const int m = static_cast<int>(seeds.size());
#pragma omp parallel for num_threads(options.threads) schedule(dynamic, 1)
  for (int i = 0; i < m; ++i) {
    const PoseCandidate wide =
        HillClimb(field, source, seeds[i], 0.5 * options.rotation_step_rad, 2.0 * field.resolution());
    climbed[i] = HillClimb(sharp, source, wide.T_target_source, 2.0 * M_PI / 180.0, sharp.resolution());
  }
  std::stable_sort(climbed.begin(), climbed.end(),
                   [](const PoseCandidate& a, const PoseCandidate& b) { return a.score > b.score; });

  std::vector<PoseCandidate> out;
  for (const PoseCandidate& c : climbed) {
    if (static_cast<int>(out.size()) >= options.candidates + static_cast<int>(extra_seeds.size())) break;
    bool distinct = true;
    for (const PoseCandidate& o : out)
      distinct =
          distinct && !CloseTo(c.T_target_source, o.T_target_source, 2.0 * M_PI / 180.0, 2.0 * field.resolution());
    if (distinct) out.push_back(c);
  }
  return out;
}

}  // namespace fusecal::lidar_icp
