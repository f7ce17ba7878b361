// Coverage benchmark of the hand-eye covariance on realistic handheld motion pairs
// (handeye/handheld_motions.hpp: about 1 deg of error per motion, correlated along the trajectory, camera
// translations per motion or with one unknown scale). Per scale mode over N seeds: how many verdicts are
// ok, the per-axis coverage of the truth within one reported std, and the rms error against the mean std.
//
// Usage: bench_handheld [--seeds N] [--motions M] [--noise DEG] [--correlation RHO]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "stages/handeye/global_scale.hpp"
#include "stages/handeye/handeye_solver.hpp"
#include "stages/handeye/handheld_motions.hpp"
#include "stages/handeye/synthetic_motions.hpp"

namespace {

using namespace fusecal;

struct Tally {
  int ok = 0;
  Eigen::Array<double, 6, 1> covered = Eigen::Array<double, 6, 1>::Zero();
  Eigen::Array<double, 6, 1> squared_error = Eigen::Array<double, 6, 1>::Zero();
  Eigen::Array<double, 6, 1> std_sum = Eigen::Array<double, 6, 1>::Zero();

  void Add(const HandEyeResult& r, const Isometry3& truth) {
    ok += r.observability == Observability::kOk;
    Eigen::Array<double, 6, 1> error = ExtrinsicError(r.T_camera_lidar, truth).array().abs();
    Eigen::Array<double, 6, 1> std;
    std << r.std_dev_rot_deg.array(), r.std_dev_trans_m.array();
    error.head<3>() *= 180.0 / M_PI;
    covered += (error <= std).cast<double>();
    squared_error += error.square();
    std_sum += std;
  }
  void Print(const char* mode, int n) const {
    const Eigen::Array<double, 6, 1> coverage = 100.0 * covered / n;
    const Eigen::Array<double, 6, 1> ratio = (squared_error / n).sqrt() / (std_sum / n);
    std::printf(
        "%-11s %3d/%-3d  rot %3.0f %3.0f %3.0f %%  rms/std %.2f %.2f %.2f  mean std %.3f deg   "
        "t %3.0f %3.0f %3.0f %%  rms/std %.2f %.2f %.2f  mean std %.1f mm\n",
        mode, ok, n, coverage(0), coverage(1), coverage(2), ratio(0), ratio(1), ratio(2), std_sum.head<3>().mean() / n,
        coverage(3), coverage(4), coverage(5), ratio(3), ratio(4), ratio(5), 1e3 * std_sum.tail<3>().mean() / n);
  }
};

}  // namespace

int main(int argc, char** argv) {
  int seeds = 200;
  HandheldMotionSettings base;
  for (int i = 1; i < argc; ++i) {
    const auto value = [&] {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", argv[i]);
        std::exit(2);
      }
      return std::atof(argv[++i]);
    };
    if (!std::strcmp(argv[i], "--seeds"))
      seeds = static_cast<int>(value());
    else if (!std::strcmp(argv[i], "--motions"))
      base.num_motions = static_cast<int>(value());
    else if (!std::strcmp(argv[i], "--noise"))
      base.rotation_noise_deg = value();
    else if (!std::strcmp(argv[i], "--correlation"))
      base.noise_correlation = value();
    else {
      std::fprintf(stderr, "usage: bench_handheld [--seeds N] [--motions M] [--noise DEG] [--correlation RHO]\n");
      return 2;
    }
  }
  std::printf("%d seeds, %d motions, %.2f deg per axis and sensor motion, correlation %.2f\n", seeds, base.num_motions,
              base.rotation_noise_deg, base.noise_correlation);
  std::printf("mode        ok       coverage within 1 std (x y z), rms error / mean std\n");
  Tally per_motion, global, metric;
  for (int seed = 1; seed <= seeds; ++seed) {
    HandheldMotionSettings s = base;
    s.seed = static_cast<std::uint32_t>(seed);
    s.camera_units = CameraUnits::kPerMotion;
    const HandheldMotionSet a = GenerateHandheldMotions(s);
    per_motion.Add(SolveScaleless(a.pairs), a.T_camera_lidar);
    s.camera_units = CameraUnits::kGlobalScale;
    HandheldMotionSet b = GenerateHandheldMotions(s);
    global.Add(SolveGlobalScale(b.pairs), b.T_camera_lidar);
    for (auto& p : b.pairs) {
      p.A.translation() /= s.camera_units_per_m;
      p.camera_scaled = true;
    }
    metric.Add(SolveScaled(b.pairs), b.T_camera_lidar);
  }
  per_motion.Print("per-motion", seeds);
  global.Print("global", seeds);
  metric.Print("metric", seeds);
  return 0;
}
