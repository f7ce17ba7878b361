// Not a test: time per motion of the fusion odometry on the default simulated scenario (2048x1024
// panorama, HDL-64E-like scan) and on the KITTI raw snippet (1242x375 pinhole, HDL-64E), with the
// accuracy of each motion. Target: at most 0.5 s per motion on the 2-core development machine.
//
//   bench_fusion_odometry [scenario.yaml] [--stations N] [--no-kitti] [--no-sim] [--set key=value ...]
// Environment: FO_GAP (KITTI frame-index gap, default 4), FO_DEBUG (tracking error against the truth),
// FO_DUMP=dir (KITTI overlays of the inliers and their residual under the LiDAR reference, x10).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "runtime/io/importers/kitti.hpp"
#include "runtime/sim/fixtures/fo_test_data.hpp"
#include "stages/fusion_odometry/fusion_odometry.hpp"
#if FUSECAL_FO_HAVE_LIDAR_ICP
#include "stages/lidar_icp/registration.hpp"
#endif
#include "runtime/io/scan_io/scan_io.hpp"

using namespace fusecal;
using namespace fusecal::fusion_odometry;
using fixtures::Deg;

namespace {

FusionOdometrySettings g_settings;

// --set key=value: a few numeric settings, for experiments.
bool SetOption(const std::string& kv) {
  const size_t eq = kv.find('=');
  if (eq == std::string::npos) return false;
  const std::string key = kv.substr(0, eq);
  const double v = std::atof(kv.c_str() + eq + 1);
  FusionOdometrySettings& s = g_settings;
  if (key == "quality")
    s.selection.min_corner_quality = v;
  else if (key == "spacing")
    s.selection.min_distance_px = v;
  else if (key == "max_points")
    s.selection.max_points = static_cast<int>(v);
  else if (key == "block")
    s.selection.corner_block_size = static_cast<int>(v);
  else if (key == "edge_radius")
    s.selection.depth_edge_radius_px = v;
  else if (key == "edge_tol")
    s.selection.depth_edge_tolerance = v;
  else if (key == "occ_radius")
    s.visibility.occlusion_radius_px = v;
  else if (key == "occ_tol")
    s.visibility.occlusion_tolerance = v;
  else if (key == "cell")
    s.visibility.cell_px = static_cast<int>(v);
  else if (key == "window")
    s.tracking.window_px = static_cast<int>(v);
  else if (key == "levels")
    s.tracking.pyramid_levels = static_cast<int>(v);
  else if (key == "fb")
    s.tracking.max_forward_backward_px = v;
  else if (key == "derotate")
    s.tracking.derotate_min_deg = v;
  else if (key == "max_residual")
    s.refinement.max_residual_px = v;
  else if (key == "loss_scale")
    s.refinement.loss_scale_px = v;
  else if (key == "ransac_px")
    s.ransac.threshold_px = v;
  else if (key == "retrack")
    s.retrack = v != 0;
  else
    return false;
  return true;
}

void PrintResult(const char* label, const FusionOdometryResult& r, double rot_err_deg, double trans_err_mm,
                 double length_err_pct) {
  std::printf(
      "  %-10s %-13s %5.3f s (select %.3f track %.3f ransac %.3f refine %.3f)  pts %d/%d/%d trk %d "
      "inl %d  res %.2f px  rot err %.4f deg  t err %.1f mm (%.2f %%)%s%s\n",
      label, r.status.c_str(), r.seconds, r.seconds_selection, r.seconds_tracking, r.seconds_ransac,
      r.seconds_refinement, r.projected_points, r.visible_points, r.selected_points, r.tracked_points, r.inliers,
      r.rms_residual_px, rot_err_deg, trans_err_mm, length_err_pct, r.failure_reason.text.empty() ? "" : "  ",
      r.failure_reason.text.c_str());
}

double RunSim(const std::string& path, int max_stations, int* count) {
  const sim::Scenario scenario = sim::LoadScenario(path);
  const fixtures::SimData data = fixtures::SimulateStations(scenario, max_stations);
  std::printf("simulated %s: %zu stations, %dx%d %s, rendered in %.1f s\n", path.c_str(), data.stations.size(),
              data.camera->width(), data.camera->height(), data.camera->params().model.c_str(), data.seconds_render);
  double total = 0;
  const Isometry3 X0 = fixtures::PerturbExtrinsic(data.T_camera_lidar, 0.03, 2.0);
  for (size_t s = 0; s + 1 < data.stations.size(); ++s) {
    const auto& i = data.stations[s];
    const auto& j = data.stations[s + 1];
    const Isometry3 A_true = fixtures::TrueCameraMotion(i, j);
    const Isometry3 B_true = fixtures::TrueLidarMotion(i, j);
    std::printf(" motion %d -> %d (%.1f deg, %.3f m)\n", i.id, j.id, Deg(RotationAngle(A_true.linear())),
                A_true.translation().norm());
    // First iteration: rough guess X0 B X0^-1, not reliable (P3P RANSAC); then the refined one as guess.
    MotionGuess guess{CameraMotionFromLidar(X0, B_true), false};
    FusionOdometryResult r =
        EstimateScaledMotion(i.scan, i.image, j.image, *data.camera, data.T_camera_lidar, guess, g_settings);
    auto report = [&](const char* label, const FusionOdometryResult& res) {
      const double t_err = (res.T_ci_cj.translation() - A_true.translation()).norm();
      PrintResult(label, res, RotationErrorDeg(res.T_ci_cj.linear(), A_true.linear()), 1e3 * t_err,
                  100.0 * t_err / A_true.translation().norm());
    };
    report("first", r);
    if (std::getenv("FO_DEBUG")) {  // tracking error against the truth, pixels
      Eigen::Vector2d mean = Eigen::Vector2d::Zero();
      double sum2 = 0;
      for (const auto& c : r.inlier_correspondences) {
        Eigen::Vector2d truth;
        data.camera->Project(A_true.inverse() * c.p_ci, &truth);
        Eigen::Vector2d d = c.pixel_j - truth;
        if (d.x() > data.camera->width() / 2) d.x() -= data.camera->width();
        if (d.x() < -data.camera->width() / 2) d.x() += data.camera->width();
        mean += d;
        sum2 += d.squaredNorm();
      }
      const double n = std::max<size_t>(1, r.inlier_correspondences.size());
      std::printf("    tracking vs truth: mean [%.3f %.3f] px, rms %.3f px\n", mean.x() / n, mean.y() / n,
                  std::sqrt(sum2 / n));
    }
    total += r.seconds;
    ++*count;
    guess = MotionGuess{r.T_ci_cj, true};
    r = EstimateScaledMotion(i.scan, i.image, j.image, *data.camera, data.T_camera_lidar, guess, g_settings);
    report("next", r);
    total += r.seconds;
    ++*count;
  }
  return total;
}

double RunKitti(int* count) {
#if !FUSECAL_FO_HAVE_LIDAR_ICP
  std::printf("KITTI skipped: the ICP stage (fusecal::lidar_icp) is not part of this build\n");
  (void)count;
  return 0;
#else
  if (!fixtures::KittiAvailable()) {
    std::printf("KITTI snippet not found at %s: skipped\n", fixtures::KittiDir().c_str());
    return 0;
  }
  const KittiCalibration calib = ReadKittiCalibration(fixtures::KittiDir());
  const auto camera = MakeCameraModel(calib.camera);
  const Isometry3 X = calib.T_camera_lidar;
  const int gap = std::getenv("FO_GAP") ? std::atoi(std::getenv("FO_GAP")) : 4;
  std::printf("KITTI %s: %dx%d, frame pairs %d frame indices (%d files) apart\n", fixtures::KittiDir().c_str(),
              camera->width(), camera->height(), gap, gap / 2);
  double total = 0;
  for (int a = 0; a <= 32; a += 8) {
    const int b = a + gap;
    const PointCloud scan_a = ReadScan(fixtures::KittiScanPath(a));
    const PointCloud scan_b = ReadScan(fixtures::KittiScanPath(b));
    const cv::Mat image_a = cv::imread(fixtures::KittiImagePath(a), cv::IMREAD_UNCHANGED);
    const cv::Mat image_b = cv::imread(fixtures::KittiImagePath(b), cv::IMREAD_UNCHANGED);
    const lidar_icp::RegistrationResult icp = lidar_icp::Register(scan_a, scan_b);
    const Isometry3 A_ref = CameraMotionFromLidar(X, icp.T_li_lj);
    std::printf(" %02d -> %02d: ICP %s %s, %.3f m, %.3f deg (%.2f s)\n", a, b, icp.usable() ? "ok" : "failed",
                icp.failure_reason.text.c_str(), icp.T_li_lj.translation().norm(),
                Deg(RotationAngle(icp.T_li_lj.linear())), icp.seconds);
    for (bool reliable : {false, true}) {
      const FusionOdometryResult r =
          EstimateScaledMotion(scan_a, image_a, image_b, *camera, X, MotionGuess{A_ref, reliable}, g_settings);
      const Eigen::Vector3d t = r.T_ci_cj.translation(), t_ref = A_ref.translation();
      const double dir_deg = Deg(std::atan2(t.cross(t_ref).norm(), t.dot(t_ref)));
      std::printf("  direction err %.3f deg  ", dir_deg);
      PrintResult(reliable ? "reliable" : "unreliable", r, RotationErrorDeg(r.T_ci_cj.linear(), A_ref.linear()),
                  1e3 * (t - t_ref).norm(), 100.0 * (t.norm() - t_ref.norm()) / t_ref.norm());
      total += r.seconds;
      ++*count;
      if (!reliable) {
        int ref_ok = 0;
        for (const auto& c : r.inlier_correspondences) {
          Eigen::Vector2d ref;
          camera->Project(A_ref.inverse() * c.p_ci, &ref);
          ref_ok += (c.pixel_j - ref).norm() < 2.0;
        }
        std::printf("    inliers within 2 px of the ICP reference: %d of %zu\n", ref_ok,
                    r.inlier_correspondences.size());
      }
      if (std::getenv("FO_DUMP") && !reliable) {  // overlay: inliers green, residual under A_ref in colour
        cv::Mat vis = image_b.clone();
        const Isometry3 inv = A_ref.inverse();
        for (const auto& c : r.inlier_correspondences) {
          Eigen::Vector2d ref;
          camera->Project(inv * c.p_ci, &ref);
          cv::line(vis, cv::Point2d(c.pixel_j.x(), c.pixel_j.y()), cv::Point2d(c.pixel_i.x(), c.pixel_i.y()),
                   cv::Scalar(255, 255, 0), 1);
          const Eigen::Vector2d d = 10.0 * (c.pixel_j - ref);  // error under A_ref, x10
          cv::line(vis, cv::Point2d(c.pixel_j.x(), c.pixel_j.y()),
                   cv::Point2d(c.pixel_j.x() + d.x(), c.pixel_j.y() + d.y()), cv::Scalar(0, 0, 255), 2);
          cv::circle(vis, cv::Point2d(c.pixel_j.x(), c.pixel_j.y()), 2, cv::Scalar(0, 255, 0), -1);
        }
        cv::imwrite(std::string(std::getenv("FO_DUMP")) + "/kitti_" + std::to_string(a) + ".png", vis);
      }
    }
  }
  return total;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  std::string scenario = fixtures::ScenarioPath("indoor-equirect-hdl64.yaml");
  int stations = 5;
  bool kitti = true, simulated = true;
  for (int k = 1; k < argc; ++k) {
    if (!std::strcmp(argv[k], "--no-kitti"))
      kitti = false;
    else if (!std::strcmp(argv[k], "--no-sim"))
      simulated = false;
    else if (!std::strcmp(argv[k], "--stations") && k + 1 < argc)
      stations = std::atoi(argv[++k]);
    else if (!std::strcmp(argv[k], "--set") && k + 1 < argc) {
      if (!SetOption(argv[++k])) return std::fprintf(stderr, "bad --set %s\n", argv[k]), 2;
    } else
      scenario = argv[k];
  }
  try {
    if (simulated) {
      int n = 0;
      const double total = RunSim(scenario, stations, &n);
      if (n) std::printf("simulated: %.3f s per motion (%d runs)\n", total / n, n);
    }
    if (kitti) {
      int n = 0;
      const double total = RunKitti(&n);
      if (n) std::printf("KITTI: %.3f s per motion (%d runs)\n", total / n, n);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
