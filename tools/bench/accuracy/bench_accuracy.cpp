// The paper's Fig. 5/6 on our simulator: for 1..5 motion pairs (each one horizontal + one vertical
// motion), 10 random subsets each, the error of "Scaleless" (the initial estimate, III-A-2) and "Ours"
// (after alternating with sensor fusion odometry, III-B) against the ground truth.
// Usage: bench_accuracy STATIONS_LOG OUT.csv [subsets=10] [max_pairs=5]
#include <chrono>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <random>

#include "fusecal/station_t.hpp"
#include "runtime/channels.hpp"
#include "runtime/lcm_log.hpp"
#include "stages/camera_frontend/relative_pose.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/ground_truth.hpp"
#include "stages/foundation/extrinsic_error.hpp"
#include "stages/fusion_odometry/fusion_odometry.hpp"
#include "stages/handeye/handeye_solver.hpp"
#include "stages/lidar_icp/registration.hpp"

using namespace fusecal;

namespace {

struct Station {
  cv::Mat image;
  PointCloud cloud;
};

struct Motion {
  int i, j;
  bool horizontal;  // about the vertical axis
  Isometry3 B, A_scaleless;
};

struct Stats {
  double mean = 0, std = 0;
};

Stats MeanStd(const std::vector<double>& v) {
  Stats s;
  for (double x : v) s.mean += x / v.size();
  for (double x : v) s.std += (x - s.mean) * (x - s.mean) / v.size();
  s.std = std::sqrt(s.std);
  return s;
}

// The stations of a stations-only log (image and cloud by id) and the camera model of the first one.
std::map<int, Station> ReadStations(const std::string& log, std::unique_ptr<CameraModel>* camera) {
  std::map<int, Station> stations;
  LogReader reader(log);
  while (auto event = reader.Next()) {
    if (event->channel != channels::kStation.name) continue;
    station_t s{};
    s.decode(event->data.data(), 0, static_cast<int>(event->data.size()));
    stations[s.id] = {ImageToMat(s.image), CloudFromMsg(s.cloud)};
    if (!*camera) *camera = MakeCameraModel(CameraFromMsg(s.camera));
  }
  return stations;
}

// Motions between consecutive stations, measured once by the stage cores; `horizontal` from the truth.
std::vector<Motion> MeasureMotions(const std::map<int, Station>& stations, const CameraModel& camera,
                                   std::map<int, Isometry3>& world_lidar) {
  std::vector<Motion> motions;
  for (auto it = stations.begin(); std::next(it) != stations.end(); ++it) {
    const auto next = std::next(it);
    const auto icp = lidar_icp::Register(it->second.cloud, next->second.cloud);
    const auto cam = EstimateRelativePose(it->second.image, next->second.image, camera);
    if (!icp.usable() || !cam.usable()) {
      std::cerr << "motion " << it->first << "-" << next->first << " skipped: " << icp.failure_reason.text
                << cam.failure_reason.text << "\n";
      continue;
    }
    const Isometry3 B_true = world_lidar[it->first].inverse() * world_lidar[next->first];
    const Eigen::Vector3d axis_world = world_lidar[it->first].linear() * LogSO3(B_true.linear()).normalized();
    motions.push_back({it->first, next->first, std::abs(axis_world.z()) > 0.7, icp.T_li_lj, cam.A()});
  }
  return motions;
}

struct Recording {
  std::map<int, Station> stations;
  std::unique_ptr<CameraModel> camera;
  std::vector<Motion> motions;
};

// The alternation (III-B-2) from the scaleless estimate X: metric camera motions with the current X, then
// X again, until X stops changing.
Isometry3 Alternate(const Recording& rec, const std::vector<int>& chosen, const HandEyeSettings& settings,
                    Isometry3 X) {
  std::map<int, Isometry3> previous;
  for (int iteration = 0; iteration < 8; ++iteration) {
    std::vector<MotionPair> scaled;
    for (int k : chosen) {
      const Motion& m = rec.motions[k];
      fusion_odometry::MotionGuess guess;
      guess.T_ci_cj = previous.count(k) ? previous[k] : fusion_odometry::CameraMotionFromLidar(X, m.B);
      guess.reliable = previous.count(k) > 0;
      const auto fo = fusion_odometry::EstimateScaledMotion(rec.stations.at(m.i).cloud, rec.stations.at(m.i).image,
                                                            rec.stations.at(m.j).image, *rec.camera, X, guess);
      if (!fo.usable()) continue;
      previous[k] = fo.T_ci_cj;
      MotionPair p;
      p.station_i = m.i;
      p.station_j = m.j;
      p.A = fo.T_ci_cj;
      p.B = m.B;
      scaled.push_back(p);
    }
    const HandEyeResult result = SolveScaled(scaled, settings, &X);
    if (!result.usable()) break;
    const double change = RotationErrorDeg(result.T_camera_lidar.linear(), X.linear()) +
                          (result.T_camera_lidar.translation() - X.translation()).norm() * 100;
    X = result.T_camera_lidar;
    if (change < 1e-4) break;
  }
  return X;
}

// Errors of "Scaleless" and "Ours" over the trials of one subset size.
struct TrialErrors {
  std::vector<double> rot_s, trans_s, rot_o, trans_o;
};

// One random subset: the scaleless estimate and the alternation from it, compared with the truth.
void RunTrial(const Recording& rec, const std::vector<int>& chosen, const Isometry3& X_true, TrialErrors* errors) {
  std::vector<MotionPair> pairs;
  for (int k : chosen) {
    MotionPair p;
    p.station_i = rec.motions[k].i;
    p.station_j = rec.motions[k].j;
    p.A = rec.motions[k].A_scaleless;
    p.B = rec.motions[k].B;
    p.camera_scaled = false;
    pairs.push_back(p);
  }
  HandEyeSettings settings;
  settings.min_pairs = 2;
  const HandEyeResult initial = SolveScaleless(pairs, settings);
  if (!initial.usable()) return;
  const Isometry3 X = Alternate(rec, chosen, settings, initial.T_camera_lidar);
  const ExtrinsicError e_s = CompareExtrinsics(initial.T_camera_lidar, X_true);
  const ExtrinsicError e_o = CompareExtrinsics(X, X_true);
  errors->rot_s.push_back(e_s.rotation_deg);
  errors->trans_s.push_back(e_s.translation_m);
  errors->rot_o.push_back(e_o.rotation_deg);
  errors->trans_o.push_back(e_o.translation_m);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: bench_accuracy STATIONS_LOG OUT.csv [subsets=10] [max_pairs=5]\n";
    return 2;
  }
  const std::string log = argv[1], csv_path = argv[2];
  const int subsets = argc > 3 ? std::atoi(argv[3]) : 10;
  const int max_pairs = argc > 4 ? std::atoi(argv[4]) : 5;
  const auto truths = ReadGroundTruths(log);
  if (truths.size() != 1) {
    std::cerr << log
              << (truths.empty() ? ": no GROUND_TRUTH (make it with `fusecal simulate --stations-only`)\n"
                                 : ": the camera moves on its mount in this log; the bench needs one extrinsic\n");
    return 1;
  }
  const ground_truth_t* truth = &truths.front();
  const Isometry3 X_true = CheckedTruthExtrinsic(*truth).T_camera_lidar;
  std::map<int, Isometry3> world_lidar;
  for (int k = 0; k < truth->num_stations; ++k)
    world_lidar[truth->station_id[k]] = FromRowMajor(truth->T_world_lidar[k].data());

  Recording rec;
  rec.stations = ReadStations(log, &rec.camera);
  rec.motions = MeasureMotions(rec.stations, *rec.camera, world_lidar);
  std::vector<int> horizontal, vertical;
  for (size_t k = 0; k < rec.motions.size(); ++k) (rec.motions[k].horizontal ? horizontal : vertical).push_back(int(k));
  std::cerr << rec.motions.size() << " motions: " << horizontal.size() << " horizontal, " << vertical.size()
            << " vertical\n";

  std::ofstream csv(csv_path);
  csv << "pairs,method,rot_err_deg_mean,rot_err_deg_std,trans_err_m_mean,trans_err_m_std,trials\n";
  std::mt19937 rng(2018);
  std::cout << std::fixed << std::setprecision(4);
  std::cout << "pairs  method     rot mean  rot std   trans mean (cm)  trans std (cm)\n";
  for (int n = 1; n <= max_pairs && n <= int(std::min(horizontal.size(), vertical.size())); ++n) {
    TrialErrors errors;
    for (int trial = 0; trial < subsets; ++trial) {
      std::shuffle(horizontal.begin(), horizontal.end(), rng);
      std::shuffle(vertical.begin(), vertical.end(), rng);
      std::vector<int> chosen(horizontal.begin(), horizontal.begin() + n);
      chosen.insert(chosen.end(), vertical.begin(), vertical.begin() + n);
      RunTrial(rec, chosen, X_true, &errors);
    }
    for (const auto& [name, rot, trans] :
         {std::tuple{"scaleless", errors.rot_s, errors.trans_s}, std::tuple{"ours", errors.rot_o, errors.trans_o}}) {
      const Stats r = MeanStd(rot), t = MeanStd(trans);
      csv << n << "," << name << "," << r.mean << "," << r.std << "," << t.mean << "," << t.std << "," << rot.size()
          << "\n";
      std::cout << std::setw(5) << n << "  " << std::setw(9) << name << "  " << r.mean << "    " << r.std << "    "
                << t.mean * 100 << "           " << t.std * 100 << "\n";
    }
  }
  return 0;
}
