// Benchmark of the camera front end: time per image pair for a 2048x1024 panorama (synthetic room) and a
// 1242x375 pinhole image (KITTI snippet frames 0 -> 4 if present, else the synthetic room seen by the KITTI
// camera). Target: at most 1 s per pair on the 2-core development machine.
//
//   bench_camera_frontend [repetitions] [akaze_octave_layers]
//
// Wall time depends on what else runs on the machine; the CPU time of the process (all threads) is printed
// too: on an idle machine the wall time lies between CPU time / cores and CPU time.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>
#include <vector>

#include "runtime/sim/fixtures/camera_frontend_helpers.hpp"
#include "runtime/sim/fixtures/synthetic_room.hpp"
#include "stages/camera_frontend/relative_pose.hpp"

using namespace fusecal;
using namespace fusecal::fixtures;

namespace {

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void Bench(const std::string& name, const CameraModel& camera, const cv::Mat& image_i, const cv::Mat& image_j,
           const Isometry3* A_true, int repetitions, const CameraFrontendSettings& settings) {
  std::vector<double> total, features, matching, ransac, refinement, cached, cpu;
  RelativePoseResult r;
  for (int k = 0; k < repetitions; ++k) {
    const std::clock_t cpu_start = std::clock();
    r = EstimateRelativePose(image_i, image_j, camera, settings);
    cpu.push_back(static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC);
    total.push_back(r.seconds);
    features.push_back(r.seconds_features);
    matching.push_back(r.seconds_matching);
    ransac.push_back(r.seconds_ransac);
    refinement.push_back(r.seconds_refinement);
    // Streaming use: the features of image i were extracted for the previous pair already.
    cached.push_back(r.seconds - r.seconds_features / 2);
  }
  std::printf("%s (%dx%d): %s, %d features/image, %d matches, %d inliers\n", name.c_str(), camera.width(),
              camera.height(), r.usable() ? "valid" : ("NOT VALID: " + r.failure_reason.text).c_str(), r.features_i,
              r.matches, r.inliers);
  std::printf(
      "  per pair: median %.3f s, min %.3f s over %d runs  [features (2 images) %.3f, matching %.3f, "
      "RANSAC %.3f, refinement %.3f]\n",
      Median(total), *std::min_element(total.begin(), total.end()), repetitions, Median(features), Median(matching),
      Median(ransac), Median(refinement));
  std::printf("  per pair with features of image i cached (streaming): median %.3f s\n", Median(cached));
  std::printf("  CPU time per pair (all threads): median %.3f s\n", Median(cpu));
  if (A_true) {
    const PoseErrors e = Errors(r, *A_true);
    std::printf("  accuracy: rotation error %.4f deg, translation direction error %.3f deg (|t| = %.2f m)\n",
                e.rotation_deg, e.translation_direction_deg, A_true->translation().norm());
  }
  std::printf("  target <= 1 s per pair: %s\n", Median(total) <= 1.0 ? "met" : "MISSED");
}

}  // namespace

int main(int argc, char** argv) {
  const int repetitions = argc > 1 ? std::max(1, std::atoi(argv[1])) : 5;
  CameraFrontendSettings settings;
  if (argc > 2) settings.features.akaze_octave_layers = std::atoi(argv[2]);
  if (std::string e = settings.Validate(); !e.empty()) {
    std::fprintf(stderr, "bad settings: %s\n", e.c_str());
    return 2;
  }
  std::printf("bench_camera_frontend: OpenCV threads %d, %u hardware threads, AKAZE %d octaves x %d layers\n",
              cv::getNumThreads(), std::thread::hardware_concurrency(), settings.features.akaze_octaves,
              settings.features.akaze_octave_layers);
  const SyntheticRoom room(FUSECAL_CAMERA_FRONTEND_TEST_DATA);

  {  // Panorama 2048x1024.
    const auto camera = MakeCameraModel(PanoramaParams(2048));
    const Isometry3 T_world_ci = MakeIsometry(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.2, -0.1, 0.3));
    const Isometry3 A =
        MakeIsometry(Eigen::AngleAxisd(Rad(20), Eigen::Vector3d(0.2, 1, -0.1).normalized()).toRotationMatrix(),
                     Eigen::Vector3d(0.25, 0.05, -0.15));
    const cv::Mat image_i = room.Render(*camera, T_world_ci, 2, 1.5, 1);
    const cv::Mat image_j = room.Render(*camera, T_world_ci * A, 2, 1.5, 2);
    Bench("synthetic panorama", *camera, image_i, image_j, &A, repetitions, settings);
  }

  {  // Pinhole 1242x375.
    const auto camera = MakeCameraModel(KittiParams());
    const std::string dir = std::string(FUSECAL_KITTI_SNIPPET_DIR) + "/image_02/data/";
    if (std::filesystem::exists(dir + "0000000000.png")) {
      const cv::Mat image_i = cv::imread(dir + "0000000000.png", cv::IMREAD_UNCHANGED);
      const cv::Mat image_j = cv::imread(dir + "0000000004.png", cv::IMREAD_UNCHANGED);
      Bench("KITTI frames 0 -> 4", *camera, image_i, image_j, nullptr, repetitions, settings);
    } else {
      std::printf("KITTI snippet not found at %s: synthetic room seen by the KITTI camera instead\n", dir.c_str());
      const Isometry3 T_world_ci = MakeIsometry(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.0, 0.0, -2.0));
      const Isometry3 A = MakeIsometry(Eigen::AngleAxisd(Rad(3), Eigen::Vector3d::UnitY()).toRotationMatrix(),
                                       Eigen::Vector3d(0.05, 0.0, 0.3));
      const cv::Mat image_i = room.Render(*camera, T_world_ci, 2, 1.5, 1);
      const cv::Mat image_j = room.Render(*camera, T_world_ci * A, 2, 1.5, 2);
      Bench("synthetic pinhole", *camera, image_i, image_j, &A, repetitions, settings);
    }
  }
  return 0;
}
