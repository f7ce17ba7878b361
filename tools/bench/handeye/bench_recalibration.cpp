// Recalibration benchmark of the calibration loop (handeye/calibrator.hpp, change_detection.hpp) on
// synthetic sessions: 40 motion pairs whose camera moves during pair 20 (rotation only, translation only,
// both, of several sizes), played through the loop with fusion odometry's answers. Per case over N seeds:
// how often the change is found between the right stations, the detection delay (pairs from the one
// across the change to the one that decided it, both counted), and the final error against the extrinsic
// after the change, next to a fresh loop that sees only the pairs after it (the best one can do). Then the
// false alarms: sessions without a change, and one soak of `--soak` pairs.
//
// Usage: bench_recalibration [--seeds N] [--noise DEG] [--translation-noise M] [--soak PAIRS]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "stages/foundation/se3.hpp"
#include "stages/handeye/calibrator.hpp"
#include "stages/handeye/calibrator_playback.hpp"
#include "stages/handeye/synthetic_motions.hpp"

namespace {

using namespace fusecal;

constexpr int kPairs = 40, kChangeAt = 20;

// Plays pairs[from..] through a loop that answers every request with the metric camera motions.
Calibrator Play(const std::vector<MotionPair>& pairs, int from) {
  Calibrator calibrator{CalibratorSettings{}};
  PlayMetricPairs(calibrator, pairs, from);
  return calibrator;
}

struct Options {
  int seeds = 50;
  double rotation_noise_deg = 0.05;
  double translation_noise_m = 0.001;
  int soak = 300;
};

SyntheticMotionSettings Settings(const Options& o, int pairs, uint32_t seed) {
  SyntheticMotionSettings s;
  s.num_motions = pairs;
  s.min_angle_deg = 10;
  s.max_angle_deg = 30;
  s.rotation_noise_deg = o.rotation_noise_deg;
  s.translation_noise_m = o.translation_noise_m;
  s.seed = seed;
  return s;
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// One change case over all seeds: one line of the table.
void RunCase(const Options& o, const char* kind, double rotation_deg, double translation_m) {
  int found = 0, right_place = 0, within3 = 0, converged = 0, fresh_converged = 0;
  std::vector<double> delays, rot_err, trans_err, fresh_rot, fresh_trans;
  for (int seed = 1; seed <= o.seeds; ++seed) {
    Isometry3 delta = Isometry3::Identity();
    const Eigen::Vector3d axis = Eigen::Vector3d(std::sin(seed), std::cos(seed), 0.5).normalized();
    delta.linear() = Eigen::AngleAxisd(rotation_deg * M_PI / 180.0, axis).toRotationMatrix();
    delta.translation() = translation_m * Eigen::Vector3d(std::cos(seed), 0.3, std::sin(seed)).normalized();
    const ChangingMotionSet set = GenerateChangingMotions(Settings(o, kPairs, seed), kChangeAt, delta);
    const Calibrator loop = Play(set.pairs, 0), fresh = Play(set.pairs, kChangeAt + 1);
    if (!loop.changes().empty()) {
      ++found;
      const ExtrinsicChange& c = loop.changes().front();
      right_place += c.after_station == kChangeAt && loop.changes().size() == 1;
      const double delay = c.decided_at_station - kChangeAt;  // pairs from the one across the change
      within3 += delay <= 3;
      delays.push_back(delay);
    }
    if (loop.current() && loop.converged()) {
      ++converged;
      rot_err.push_back(RotationErrorDeg(loop.current()->T_camera_lidar.linear(), set.after.linear()));
      trans_err.push_back((loop.current()->T_camera_lidar.translation() - set.after.translation()).norm());
    }
    if (fresh.current() && fresh.converged()) {
      ++fresh_converged;
      fresh_rot.push_back(RotationErrorDeg(fresh.current()->T_camera_lidar.linear(), set.after.linear()));
      fresh_trans.push_back((fresh.current()->T_camera_lidar.translation() - set.after.translation()).norm());
    }
  }
  std::printf("| %-11s | %4.1f | %4.1f | %3d/%d | %3d | %3d | %4.1f | %3d | %.3f / %.2f | %.3f / %.2f |\n", kind,
              rotation_deg, translation_m * 100, found, o.seeds, right_place, within3, Median(delays), converged,
              Median(rot_err), 1e3 * Median(trans_err), Median(fresh_rot), 1e3 * Median(fresh_trans));
  (void)fresh_converged;
}

void RunFalseAlarms(const Options& o) {
  int alarms = 0;
  for (int seed = 1; seed <= o.seeds; ++seed) {
    const ChangingMotionSet set = GenerateChangingMotions(Settings(o, kPairs, 1000 + seed), -1, Isometry3::Identity());
    alarms += !Play(set.pairs, 0).changes().empty();
  }
  const ChangingMotionSet soak = GenerateChangingMotions(Settings(o, o.soak, 7), -1, Isometry3::Identity());
  const Calibrator long_session = Play(soak.pairs, 0);
  std::printf("\nfalse alarms: %d of %d sessions of %d pairs; soak of %d pairs: %zu change(s)%s\n", alarms, o.seeds,
              kPairs, o.soak, long_session.changes().size(), long_session.converged() ? ", converged" : "");
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    if (i + 1 >= argc) {
      std::fprintf(stderr,
                   "%s needs a value\nusage: bench_recalibration [--seeds N] [--noise DEG] "
                   "[--translation-noise M] [--soak PAIRS]\n",
                   argv[i]);
      return 2;
    }
    const std::string key = argv[i];
    const double value = std::atof(argv[++i]);
    if (key == "--seeds")
      o.seeds = static_cast<int>(value);
    else if (key == "--noise")
      o.rotation_noise_deg = value;
    else if (key == "--translation-noise")
      o.translation_noise_m = value;
    else if (key == "--soak")
      o.soak = static_cast<int>(value);
    else {
      std::fprintf(stderr, "unknown option %s\n", key.c_str());
      return 2;
    }
  }
  std::printf("%d pairs, the camera moves during pair %d; noise %.3f deg / %.1f mm per axis and sensor; %d seeds\n\n",
              kPairs, kChangeAt + 1, o.rotation_noise_deg, 1e3 * o.translation_noise_m, o.seeds);
  std::printf(
      "| change | deg | cm | found | right stations | within 3 pairs | median delay | converged | "
      "median error deg / mm | fresh loop after the change deg / mm |\n|---|---|---|---|---|---|---|---|---|---|\n");
  for (const double deg : {0.2, 0.5, 1.0, 3.0}) RunCase(o, "rotation", deg, 0.0);
  for (const double m : {0.005, 0.01, 0.05}) RunCase(o, "translation", 0.0, m);
  for (const auto& [deg, m] : std::vector<std::pair<double, double>>{{0.5, 0.01}, {3.0, 0.05}})
    RunCase(o, "both", deg, m);
  RunFalseAlarms(o);
  return 0;
}
