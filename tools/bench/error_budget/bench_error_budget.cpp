// Not a test: where the error of a simulated calibration comes from. Reads the session log of
// `fusecal calibrate` on a simulated log (it carries GROUND_TRUTH, the stations, the LiDAR motions and the
// EXTRINSIC messages) and, for the pairs the final result used:
//   - each motion against the truth: the LiDAR motions as logged, the fused camera motions recomputed at
//     the TRUE extrinsic (so that their errors are their own, not the extrinsic's): rotation angle error
//     and translation length error (relative);
//   - one scaled hand-eye solve from those motions (the alternation's step at the truth; the final result
//     is its fixed point), and the same with either side replaced by the truth: which sensor's motions
//     make the error of the extrinsic;
//   - with --feedback, the alternation's feedback J = d step / d X by finite differences at the truth
//     (a fixed point of a step with feedback J has (I - J)^-1 times the step's error).
// One CSV line per finding (tools/checks/error_budget_summary.py adds up many sessions):
//   motion,<camera|lidar>,i,j,angle_deg,angle_error_deg,length_m,length_error (relative),
//          d_rot x y z (rad),d_t x y z (m) (estimate against truth, MotionPair's model),
//          w x y z (rad),t x y z (m) (the true motion: rotation vector, translation)
//   extrinsic,<both|camera|lidar|shared>,d_rot x y z (rad),d_t x y z (m),std of the 6 (same units)
//     (std from the residuals alone; "shared": the solve from both with the default shared errors added)
//   feedback,<|eigenvalue| of J, 6, largest first>
// d = estimate - truth, R = R_true Exp(d_rot), t = t_true + d_t (docs/design.md section 2).
//   final,logged,<the same 12>: the pipeline's last result; final,<model>: its std with other sizes of the
//     camera's shared errors (--calibrated-with: the sizes the session used; default: the shipped ones)
//   with --resolve, final,resolved-pooled / final,resolved-by-class: the final pairs solved again (PrintResolved)
// Usage: bench_error_budget SESSION.lcmlog [--feedback] [--resolve] [--model NAME=G,H,K,S ...]
//          [--calibrated-with G,H,K,S]
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusecal/extrinsic_t.hpp"
#include "fusecal/ground_truth_t.hpp"
#include "fusecal/motion_t.hpp"
#include "fusecal/station_t.hpp"
#include "runtime/bus.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/ground_truth.hpp"
#include "stages/fusion_odometry/fusion_odometry.hpp"
#include "stages/handeye/handeye_solver.hpp"

using namespace fusecal;

namespace {

using PairKey = std::pair<int, int>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

struct Station {
  int64_t utime = 0;
  PointCloud cloud;
  cv::Mat image;
  std::unique_ptr<CameraModel> camera;
};

struct Session {
  std::map<int, Station> stations;
  std::map<PairKey, Isometry3> lidar_motions;
  std::optional<ground_truth_t> truth;
  Isometry3 X_true = Isometry3::Identity();
  std::vector<PairKey> used;  // by the last EXTRINSIC
  Isometry3 X_final = Isometry3::Identity();
  Matrix6 covariance_final = Matrix6::Zero();
};

template <class M>
M Decode(const LogEvent& e) {
  M m;
  DecodeMessage(e.data.data(), e.data.size(), e.channel, &m);
  return m;
}

Session ReadSession(const std::string& path) {
  Session s;
  LogReader reader(path);
  std::optional<extrinsic_t> last;
  while (auto e = reader.Next()) {
    if (e->channel == channels::kStation.name) {
      const auto m = Decode<station_t>(*e);
      Station& st = s.stations[m.id];
      st.utime = m.utime;
      st.cloud = CloudFromMsg(m.cloud);
      st.image = ImageToMat(m.image);
      st.camera = MakeCameraModel(CameraFromMsg(m.camera));
    } else if (e->channel == channels::kLidarMotion.name) {
      const auto m = Decode<motion_t>(*e);
      if (m.valid) s.lidar_motions[{m.station_i, m.station_j}] = FromRowMajor(m.T_i_j);
    } else if (e->channel == channels::kGroundTruth.name) {
      const auto truth = Decode<ground_truth_t>(*e);
      if (s.truth && !std::equal(truth.T_camera_lidar, truth.T_camera_lidar + 16, s.truth->T_camera_lidar))
        throw LogError(path + ": the camera moves on its mount in this log; the budget needs one extrinsic");
      s.truth = truth;
      s.X_true = CheckedTruthExtrinsic(truth).T_camera_lidar;
    } else if (e->channel == channels::kExtrinsic.name) {
      last = Decode<extrinsic_t>(*e);
    }
  }
  if (!s.truth) throw LogError(path + ": no GROUND_TRUTH (a session of `fusecal calibrate` on a simulated log?)");
  if (!last) throw LogError(path + ": no EXTRINSIC");
  for (int k = 0; k < last->num_used; ++k) s.used.push_back({last->used_station_i[k], last->used_station_j[k]});
  s.X_final = FromRowMajor(last->T_camera_lidar);
  s.covariance_final = Matrix6FromArray(last->covariance);
  return s;
}

// The true LiDAR motion between two stations: each station is matched to the still interval of the truth
// that holds its time (detected stations need not be numbered as the truth's).
std::optional<Isometry3> TrueLidarMotion(const Session& s, const PairKey& pair) {
  const auto pose = [&s](int id) -> std::optional<Isometry3> {
    const auto k = TruthStationAt(*s.truth, s.stations.at(id).utime);
    if (!k) return std::nullopt;
    return FromRowMajor(s.truth->T_world_lidar[*k].data());
  };
  const auto Pi = pose(pair.first), Pj = pose(pair.second);
  if (!Pi || !Pj) return std::nullopt;
  return Isometry3(Pi->inverse() * *Pj);
}

Vector6d Difference(const Isometry3& truth, const Isometry3& estimate) {
  Vector6d d;
  d.head<3>() = LogSO3(truth.linear().transpose() * estimate.linear());
  d.tail<3>() = estimate.translation() - truth.translation();
  return d;
}

Isometry3 Perturbed(const Isometry3& X, const Vector6d& d) {
  Isometry3 Y = X;
  Y.linear() = X.linear() * ExpSO3(d.head<3>());
  Y.translation() += d.tail<3>();
  return Y;
}

// The used pairs whose camera motion fuses at X: that motion, the LiDAR motion as logged, and the truth.
struct Motions {
  std::vector<PairKey> keys;
  std::vector<Isometry3> camera, lidar, lidar_true;
};

Motions Fuse(const Session& s, const Isometry3& X) {
  Motions m;
  for (const PairKey& key : s.used) {
    const auto lidar = s.lidar_motions.find(key);
    const auto truth = TrueLidarMotion(s, key);
    if (lidar == s.lidar_motions.end() || !truth) continue;
    const Station& si = s.stations.at(key.first);
    fusion_odometry::MotionGuess guess;
    guess.T_ci_cj = fusion_odometry::CameraMotionFromLidar(X, lidar->second);
    guess.reliable = true;  // as in the alternation's later rounds (warm start)
    const auto fused = fusion_odometry::EstimateScaledMotion(si.cloud, si.image, s.stations.at(key.second).image,
                                                             *si.camera, X, guess);
    if (!fused.usable()) continue;
    m.keys.push_back(key);
    m.camera.push_back(fused.T_ci_cj);
    m.lidar.push_back(lidar->second);
    m.lidar_true.push_back(*truth);
  }
  return m;
}

enum class Side { kBoth, kCameraOnly, kLidarOnly };

// One scaled solve from `initial` (X_true when not given); its covariance from the residuals alone unless
// `camera_shared` is given (the camera's shared errors added as handeye/shared_error.hpp does).
HandEyeResult Step(const Session& s, const Motions& m, Side side, const SharedErrors* camera_shared = nullptr,
                   const Isometry3* initial = nullptr,
                   bool rotation_noise_by_axis = HandEyeSettings{}.rotation_noise_by_axis) {
  std::vector<MotionPair> pairs;
  for (size_t k = 0; k < m.keys.size(); ++k) {
    MotionPair p;
    p.station_i = m.keys[k].first;
    p.station_j = m.keys[k].second;
    p.A = side == Side::kLidarOnly ? Isometry3(s.X_true * m.lidar_true[k] * s.X_true.inverse()) : m.camera[k];
    p.B = side == Side::kCameraOnly ? m.lidar_true[k] : m.lidar[k];
    pairs.push_back(p);
  }
  HandEyeSettings settings;
  settings.shared_lidar_errors = SharedErrors{};
  settings.shared_camera_errors = camera_shared ? *camera_shared : SharedErrors{};
  settings.rotation_noise_by_axis = rotation_noise_by_axis;
  return SolveScaled(pairs, settings, initial ? initial : &s.X_true);
}

void PrintMotionErrors(const char* kind, const PairKey& key, const Isometry3& estimate, const Isometry3& truth) {
  const double angle = LogSO3(truth.linear()).norm(), angle_estimate = LogSO3(estimate.linear()).norm();
  const double length2 = truth.translation().squaredNorm();
  const double length_error = length2 > 0 ? estimate.translation().dot(truth.translation()) / length2 - 1.0 : 0.0;
  std::printf("motion,%s,%d,%d,%.6f,%.6g,%.6f,%.6g", kind, key.first, key.second, angle * 180 / M_PI,
              (angle_estimate - angle) * 180 / M_PI, std::sqrt(length2), length_error);
  const Vector6d d = Difference(truth, estimate);
  const Eigen::Vector3d w = LogSO3(truth.linear()), t = truth.translation();
  for (int k = 0; k < 6; ++k) std::printf(",%.6g", d[k]);
  std::printf(",%.6g,%.6g,%.6g,%.6g,%.6g,%.6g\n", w.x(), w.y(), w.z(), t.x(), t.y(), t.z());
}

void PrintErrorAndStd(const char* kind, const std::string& name, const Vector6d& d, const Matrix6& covariance) {
  std::printf("%s,%s", kind, name.c_str());
  for (int k = 0; k < 6; ++k) std::printf(",%.6g", d[k]);
  for (int k = 0; k < 6; ++k) std::printf(",%.6g", std::sqrt(std::max(covariance(k, k), 0.0)));
  std::printf("\n");
}

void PrintExtrinsic(const char* name, const Session& s, const HandEyeResult& r) {
  if (!r.usable()) {
    std::fprintf(stderr, "%s: solve failed: %s\n", name, r.message.c_str());
    return;
  }
  PrintErrorAndStd("extrinsic", name, Difference(s.X_true, r.T_camera_lidar), r.covariance);
}

// The pipeline's final result as logged, and its std under other sizes of the camera's shared errors: the
// camera motions fused at the final estimate, solved once per model; the logged std scaled per axis by the
// ratio of that model's std to the std of the sizes the session was calibrated with (`own`; the shared
// errors change the covariance, not the estimate). `final,<name>` lines carry the logged error.
void PrintFinal(const Session& s, const SharedErrors& own,
                const std::vector<std::pair<std::string, SharedErrors>>& models) {
  const Vector6d error = Difference(s.X_true, s.X_final);
  PrintErrorAndStd("final", "logged", error, s.covariance_final);
  if (models.empty()) return;
  const Motions m = Fuse(s, s.X_final);
  const HandEyeResult reference = Step(s, m, Side::kBoth, &own, &s.X_final);
  if (!reference.usable()) return;
  for (const auto& [name, shared] : models) {
    const HandEyeResult r = Step(s, m, Side::kBoth, &shared, &s.X_final);
    if (!r.usable()) continue;
    Matrix6 scaled = s.covariance_final;
    for (int k = 0; k < 6; ++k) scaled(k, k) *= r.covariance(k, k) / reference.covariance(k, k);
    PrintErrorAndStd("final", name, error, scaled);
  }
}

// The final pairs solved once more from the final estimate (the alternation's fixed point) with the rotation
// noise pooled over all directions and by class of motion (handeye/rotation_noise.hpp), the shipped
// settings otherwise: `final,resolved-pooled` and `final,resolved-by-class` carry their own error.
void PrintResolved(const Session& s) {
  const Motions m = Fuse(s, s.X_final);
  const SharedErrors shipped = HandEyeSettings{}.shared_camera_errors;
  for (const bool by_axis : {false, true}) {
    const HandEyeResult r = Step(s, m, Side::kBoth, &shipped, &s.X_final, by_axis);
    if (r.usable())
      PrintErrorAndStd("final", by_axis ? "resolved-by-class" : "resolved-pooled",
                       Difference(s.X_true, r.T_camera_lidar), r.covariance);
  }
}

// G,H,K,S: sizes of the camera's shared errors (handeye/shared_error.hpp).
SharedErrors ParseSizes(const std::string& option, const std::string& text) {
  SharedErrors e;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf,%lf", &e.rotation_per_rotation, &e.translation_per_translation,
                  &e.translation_per_rotation_m, &e.translation_scale) != 4 ||
      !e.Valid())
    throw std::invalid_argument(option + " " + text + ": expected G,H,K,S (four numbers >= 0)");
  return e;
}

// NAME=G,H,K,S: sizes under a name.
std::pair<std::string, SharedErrors> ParseModel(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("--model " + text + ": expected NAME=G,H,K,S");
  return {text.substr(0, eq), ParseSizes("--model", text.substr(eq + 1))};
}

// J = d Difference(X_true, Step(Fuse(X))) / d X at the truth, one column per perturbed axis.
void PrintFeedback(const Session& s, const HandEyeResult& at_truth) {
  const Vector6d base = Difference(s.X_true, at_truth.T_camera_lidar);
  const double h[6] = {3.5e-4, 3.5e-4, 3.5e-4, 5e-4, 5e-4, 5e-4};  // 0.02 deg, 0.5 mm: a few std of the result
  Eigen::Matrix<double, 6, 6> J;
  for (int k = 0; k < 6; ++k) {
    Vector6d d = Vector6d::Zero();
    d[k] = h[k];
    const Isometry3 X = Perturbed(s.X_true, d);
    const HandEyeResult r = Step(s, Fuse(s, X), Side::kBoth);
    J.col(k) = r.usable() ? Vector6d((Difference(s.X_true, r.T_camera_lidar) - base) / h[k]) : Vector6d::Zero();
  }
  const Eigen::EigenSolver<Eigen::Matrix<double, 6, 6>> eig(J);
  std::vector<double> magnitudes;
  for (int k = 0; k < 6; ++k) magnitudes.push_back(std::abs(eig.eigenvalues()[k]));
  std::sort(magnitudes.rbegin(), magnitudes.rend());
  std::printf("feedback");
  for (double v : magnitudes) std::printf(",%.4f", v);
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  bool feedback = false, resolve = false;
  std::vector<std::pair<std::string, SharedErrors>> models;
  SharedErrors own = HandEyeSettings{}.shared_camera_errors;
  try {
    for (int k = 2; k < argc; ++k) {
      if (!std::strcmp(argv[k], "--feedback"))
        feedback = true;
      else if (!std::strcmp(argv[k], "--resolve"))
        resolve = true;
      else if (!std::strcmp(argv[k], "--model") && k + 1 < argc)
        models.push_back(ParseModel(argv[++k]));
      else if (!std::strcmp(argv[k], "--calibrated-with") && k + 1 < argc)
        own = ParseSizes("--calibrated-with", argv[++k]);
      else
        throw std::invalid_argument(std::string("unknown argument ") + argv[k]);
    }
    if (argc < 2) throw std::invalid_argument("no session log");
  } catch (const std::exception& e) {
    std::fprintf(stderr,
                 "%s\nusage: bench_error_budget SESSION.lcmlog [--feedback] [--resolve] [--model NAME=G,H,K,S ...] "
                 "[--calibrated-with G,H,K,S]\n",
                 e.what());
    return 2;
  }
  try {
    const Session s = ReadSession(argv[1]);
    PrintFinal(s, own, models);
    if (resolve) PrintResolved(s);
    const Motions m = Fuse(s, s.X_true);
    if (m.keys.size() < 3) {
      std::fprintf(stderr, "%s: %zu usable pairs at the truth, too few\n", argv[1], m.keys.size());
      return 1;
    }
    for (size_t k = 0; k < m.keys.size(); ++k) {
      PrintMotionErrors("camera", m.keys[k], m.camera[k], s.X_true * m.lidar_true[k] * s.X_true.inverse());
      PrintMotionErrors("lidar", m.keys[k], m.lidar[k], m.lidar_true[k]);
    }
    const HandEyeResult both = Step(s, m, Side::kBoth);
    PrintExtrinsic("both", s, both);
    const SharedErrors shipped = HandEyeSettings{}.shared_camera_errors;
    PrintExtrinsic("shared", s, Step(s, m, Side::kBoth, &shipped));
    PrintExtrinsic("camera", s, Step(s, m, Side::kCameraOnly));
    PrintExtrinsic("lidar", s, Step(s, m, Side::kLidarOnly));
    if (feedback && both.usable()) PrintFeedback(s, both);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
