// Global initial alignment with no guess (the paper gives ICP no initial value: III-A-1). Stations
// differ by a turn of the rig: any yaw, a tilt of the LiDAR z axis up to max_tilt, and a small
// translation. So the rotation is searched exhaustively on a grid, R = Swing(u) * Rz(yaw) with u = R e_z
// on a spherical cap, each rotation scored against a truncated distance field of the target; the best
// distinct rotations are then hill-climbed in 6 DoF on that field and on a sharper one.
//
// Objective: sum of field values / (points in observed cells + 0.2 * all points). Dividing by the
// observed points keeps a wrong pose from winning by pushing points seen only by the source (a tilted
// multi-beam LiDAR sees the ceiling, the other the floor) into the target's observed space; the 0.2 *
// all points term keeps a pose with a tiny overlap from winning by a few well-placed points.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/foundation/se3.hpp"
#include "stages/lidar_icp/distance_field.hpp"

namespace fusecal::lidar_icp {

struct GlobalSearchOptions {
  double max_tilt_rad = 60.0 * M_PI / 180.0;
  double rotation_step_rad = 10.0 * M_PI / 180.0;
  int candidates = 6;
  int threads = 1;
};

struct PoseCandidate {
  Isometry3 T_target_source = Isometry3::Identity();
  double score = 0.0;  // objective on the sharp field
};

// Rotations of the search grid (deterministic order).
std::vector<Eigen::Matrix3d> RotationGrid(double max_tilt_rad, double step_rad);

// The objective above, in [-1, 1].
double Objective(const DistanceField& field, const std::vector<Eigen::Vector3f>& source, const Isometry3& T);

// Local 6-DoF ascent of the objective from T: rotation steps about the source origin, translation
// steps in the target frame, halved when no move improves, down to fine steps.
PoseCandidate HillClimb(const DistanceField& field, const std::vector<Eigen::Vector3f>& source, const Isometry3& T,
                        double rotation_step_rad, double translation_step_m);

// Best distinct candidates, best first, each hill-climbed on `field` then on `sharp` (same target, a
// smaller truncation). `source` are points of the source scan (a few thousand); extra_seeds (e.g. a
// caller's guess) are hill-climbed and ranked with the grid's.
std::vector<PoseCandidate> GlobalCandidates(const DistanceField& field, const DistanceField& sharp,
                                            const std::vector<Eigen::Vector3f>& source,
                                            const GlobalSearchOptions& options,
                                            const std::vector<Isometry3>& extra_seeds = {});

}  // namespace fusecal::lidar_icp
