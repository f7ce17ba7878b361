// Accuracy benchmark: fusecal's scaled hand-eye solve against OpenCV's cv::calibrateHandEye (Tsai, Park,
// Horaud, Andreff, Daniilidis) on the same noisy synthetic motions; then our scaleless solve alone.
//
// OpenCV solves A X = X B from absolute poses: with gripper poses T_base_gripper,k and target poses
// T_cam_target,k it forms A = T_gripper,i_gripper,j and B = T_cam,i_cam,j and returns X = T_gripper_cam.
// Mapping: OpenCV gripper = our camera, OpenCV camera = our LiDAR, target = base = world. Our motion chain
// gives camera poses P_c,k = A_0 ... A_(k-1) (gripper2base) and LiDAR poses P_l,k = B_0 ... B_(k-1), whose
// inverses are the target2cam poses; X_opencv then is T_camera_lidar. A noise-free run checks this.
//
// Usage: bench_handeye [--quick] [--trials N]. Exit status: 0 when our mean rotation and translation errors
// are not larger than the best OpenCV method's, 1 otherwise, 2 when the noise-free check fails.
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "stages/handeye/handeye_solver.hpp"
#include "stages/handeye/synthetic_motions.hpp"

namespace {

using fusecal::Isometry3;

struct Errors {
  explicit Errors(std::string n) : name(std::move(n)) {}
  std::string name;
  std::vector<double> rot_deg, trans_cm;
  double seconds = 0.0;
  int failures = 0;

  static double Mean(const std::vector<double>& v) {
    double s = 0.0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / v.size();
  }
  static double Median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  }
  void Add(const Isometry3& estimate, const Isometry3& truth) {
    if (!estimate.matrix().allFinite()) {
      ++failures;
      return;
    }
    rot_deg.push_back(fusecal::RotationErrorDeg(estimate.linear(), truth.linear()));
    trans_cm.push_back(100.0 * (estimate.translation() - truth.translation()).norm());
  }
  void Print() const {
    std::printf("%-22s %10.4f %10.4f %10.3f %10.3f %10.3f %5d\n", name.c_str(), Mean(rot_deg), Median(rot_deg),
                Mean(trans_cm), Median(trans_cm), 1e3 * seconds / std::max<size_t>(1, rot_deg.size() + failures),
                failures);
  }
};

struct Method {
  const char* name;
  cv::HandEyeCalibrationMethod id;
};
const Method kMethods[] = {{"opencv TSAI", cv::CALIB_HAND_EYE_TSAI},
                           {"opencv PARK", cv::CALIB_HAND_EYE_PARK},
                           {"opencv HORAUD", cv::CALIB_HAND_EYE_HORAUD},
                           {"opencv ANDREFF", cv::CALIB_HAND_EYE_ANDREFF},
                           {"opencv DANIILIDIS", cv::CALIB_HAND_EYE_DANIILIDIS}};

cv::Mat RotationToCv(const Eigen::Matrix3d& R) {
  cv::Mat m(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m.at<double>(r, c) = R(r, c);
  return m;
}
cv::Mat TranslationToCv(const Eigen::Vector3d& t) { return (cv::Mat_<double>(3, 1) << t.x(), t.y(), t.z()); }

// Absolute poses from the motion chain, in OpenCV's roles (see the header comment).
struct AbsolutePoses {
  std::vector<cv::Mat> R_gripper2base, t_gripper2base, R_target2cam, t_target2cam;
};

AbsolutePoses ChainPoses(const std::vector<fusecal::MotionPair>& pairs) {
  AbsolutePoses out;
  Isometry3 P_c = Isometry3::Identity(), P_l = Isometry3::Identity();
  for (size_t k = 0; k <= pairs.size(); ++k) {
    const Isometry3 target2cam = P_l.inverse();
    out.R_gripper2base.push_back(RotationToCv(P_c.linear()));
    out.t_gripper2base.push_back(TranslationToCv(Eigen::Vector3d(P_c.translation())));
    out.R_target2cam.push_back(RotationToCv(target2cam.linear()));
    out.t_target2cam.push_back(TranslationToCv(Eigen::Vector3d(target2cam.translation())));
    if (k < pairs.size()) {
      P_c = P_c * pairs[k].A;
      P_l = P_l * pairs[k].B;
    }
  }
  return out;
}

Isometry3 SolveOpenCv(const AbsolutePoses& p, cv::HandEyeCalibrationMethod method) {
  cv::Mat R, t;
  cv::calibrateHandEye(p.R_gripper2base, p.t_gripper2base, p.R_target2cam, p.t_target2cam, R, t, method);
  Eigen::Matrix3d Re;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Re(r, c) = R.at<double>(r, c);
  return fusecal::MakeIsometry(Re, Eigen::Vector3d(t.at<double>(0), t.at<double>(1), t.at<double>(2)));
}

fusecal::SyntheticMotionSettings Scenario(std::uint32_t seed, bool noisy, bool scaleless) {
  fusecal::SyntheticMotionSettings s;
  s.num_motions = 10;
  s.min_angle_deg = 10.0;
  s.max_angle_deg = 45.0;
  s.max_translation_m = 1.0;
  s.rotation_noise_deg = noisy ? 0.05 : 0.0;
  s.translation_noise_m = noisy ? 0.005 : 0.0;
  s.scaleless = scaleless;
  s.seed = seed;
  return s;
}

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

void PrintHeader() {
  std::printf("%-22s %10s %10s %10s %10s %10s %5s\n", "method", "rot mean", "rot med", "trans mean", "trans med",
              "ms/solve", "fail");
  std::printf("%-22s %10s %10s %10s %10s\n", "", "(deg)", "(deg)", "(cm)", "(cm)");
}

// 1. Convention check: with noise-free motions every OpenCV method must return the truth.
bool CheckConventions() {
  std::printf("Noise-free convention check (OpenCV X must equal T_camera_lidar):\n");
  bool convention_ok = true;
  const auto data = fusecal::GenerateSyntheticMotions(Scenario(1, false, false));
  const AbsolutePoses poses = ChainPoses(data.pairs);
  for (const Method& m : kMethods) {
    const Isometry3 X = SolveOpenCv(poses, m.id);
    const double rot = fusecal::RotationErrorDeg(X.linear(), data.T_camera_lidar.linear());
    const double trans = (X.translation() - data.T_camera_lidar.translation()).norm();
    const bool ok = rot < 1e-6 && trans < 1e-6;
    convention_ok = convention_ok && ok;
    std::printf("  %-20s rotation error %.3e deg, translation error %.3e m  %s\n", m.name, rot, trans,
                ok ? "ok" : "MISMATCH");
  }
  const fusecal::HandEyeResult ours = fusecal::SolveScaled(data.pairs);
  std::printf("  %-20s rotation error %.3e deg, translation error %.3e m\n", "fusecal scaled",
              fusecal::RotationErrorDeg(ours.T_camera_lidar.linear(), data.T_camera_lidar.linear()),
              (ours.T_camera_lidar.translation() - data.T_camera_lidar.translation()).norm());
  return convention_ok;
}

// The errors of every method over the noisy trials.
struct Comparison {
  std::vector<Errors> opencv;
  Errors ours{"fusecal scaled"}, ours_scaleless{"fusecal scaleless"};
  int ours_not_converged = 0;
};

// 2. Noisy comparison.
Comparison CompareNoisy(int trials) {
  Comparison c;
  for (const Method& m : kMethods) c.opencv.emplace_back(m.name);
  for (int k = 0; k < trials; ++k) {
    const std::uint32_t seed = 100 + k;
    const auto data = fusecal::GenerateSyntheticMotions(Scenario(seed, true, false));
    const AbsolutePoses poses = ChainPoses(data.pairs);
    for (size_t m = 0; m < c.opencv.size(); ++m) {
      const auto t0 = std::chrono::steady_clock::now();
      const Isometry3 X = SolveOpenCv(poses, kMethods[m].id);
      c.opencv[m].seconds += Seconds(t0);
      c.opencv[m].Add(X, data.T_camera_lidar);
    }
    auto t0 = std::chrono::steady_clock::now();
    const fusecal::HandEyeResult r = fusecal::SolveScaled(data.pairs);
    c.ours.seconds += Seconds(t0);
    c.ours.Add(r.T_camera_lidar, data.T_camera_lidar);
    c.ours_not_converged += !r.converged;

    const auto data_sl = fusecal::GenerateSyntheticMotions(Scenario(seed, true, true));
    t0 = std::chrono::steady_clock::now();
    const fusecal::HandEyeResult rs = fusecal::SolveScaleless(data_sl.pairs);
    c.ours_scaleless.seconds += Seconds(t0);
    c.ours_scaleless.Add(rs.T_camera_lidar, data_sl.T_camera_lidar);
  }
  return c;
}

void PrintComparison(const Comparison& c, int trials) {
  std::printf(
      "\nScaled motions: %d trials, 10 motions (10-45 deg about random axes, translations up to 1 m per "
      "axis), noise 0.05 deg / 5 mm per axis on both sensors\n",
      trials);
  PrintHeader();
  for (const auto& e : c.opencv) e.Print();
  c.ours.Print();
  std::printf("  (fusecal scaled: %d of %d not converged)\n", c.ours_not_converged, trials);
  std::printf("\nScaleless camera motions (unit translation), same motions: ours only\n");
  PrintHeader();
  c.ours_scaleless.Print();
}

// 0 when ours is at least as accurate as OpenCV's best method in rotation and in translation.
int Verdict(const Comparison& c) {
  const auto& opencv = c.opencv;
  const auto& ours = c.ours;
  double best_rot = 1e300, best_trans = 1e300;
  std::string best_rot_name, best_trans_name;
  for (const auto& e : opencv) {
    if (e.failures) continue;
    if (Errors::Mean(e.rot_deg) < best_rot) best_rot = Errors::Mean(e.rot_deg), best_rot_name = e.name;
    if (Errors::Mean(e.trans_cm) < best_trans) best_trans = Errors::Mean(e.trans_cm), best_trans_name = e.name;
  }
  const bool rot_ok = Errors::Mean(ours.rot_deg) <= best_rot;
  const bool trans_ok = Errors::Mean(ours.trans_cm) <= best_trans;
  std::printf("\nBest OpenCV: rotation %s (%.4f deg), translation %s (%.3f cm). Ours: %.4f deg %s, %.3f cm %s\n",
              best_rot_name.c_str(), best_rot, best_trans_name.c_str(), best_trans, Errors::Mean(ours.rot_deg),
              rot_ok ? "ok" : "WORSE", Errors::Mean(ours.trans_cm), trans_ok ? "ok" : "WORSE");
  return rot_ok && trans_ok && ours.failures == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  int trials = 50;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--quick")) {
      trials = 10;
    } else if (!std::strcmp(argv[i], "--trials") && i + 1 < argc) {
      trials = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: %s [--quick] [--trials N]\n", argv[0]);
      return 2;
    }
  }
  const bool convention_ok = CheckConventions();
  const Comparison comparison = CompareNoisy(trials);
  PrintComparison(comparison, trials);
  if (!convention_ok) {
    std::printf("\nFAIL: OpenCV convention check failed; the comparison is not meaningful\n");
    return 2;
  }
  return Verdict(comparison);
}
