// The steps of the fusion odometry one by one: settings, visibility (z-buffer), track selection, KLT across
// the panorama seam, derotation, P3P RANSAC and the robust refinement with tracks on a moving vehicle,
// the covariance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>
#include <random>

#include "runtime/sim/fixtures/fo_test_data.hpp"
#include "stages/fusion_odometry/derotation.hpp"
#include "stages/fusion_odometry/fusion_odometry.hpp"
#include "stages/fusion_odometry/klt_tracking.hpp"
#include "stages/fusion_odometry/p3p_ransac.hpp"
#include "stages/fusion_odometry/pose_refinement.hpp"
#include "stages/fusion_odometry/track_selection.hpp"
#include "stages/fusion_odometry/visibility.hpp"

namespace fusecal::fusion_odometry {
namespace {

using fixtures::Rad;

CameraParams Pinhole() {
  CameraParams p;
  p.width = 640;
  p.height = 480;
  p.fx = p.fy = 400;
  p.cx = 319.5;
  p.cy = 239.5;
  return p;
}

CameraParams Panorama(int width) {
  CameraParams p;
  p.model = "equirectangular";
  p.width = width;
  p.height = width / 2;
  return p;
}

// Smooth random texture (blurred noise), 8-bit, wrapping horizontally when `wrap`.
cv::Mat Texture(int width, int height, int seed, bool wrap) {
  cv::Mat noise(height, width, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat padded, blurred;
  const int pad = wrap ? 16 : 0;
  cv::copyMakeBorder(noise, padded, 0, 0, pad, pad, wrap ? cv::BORDER_WRAP : cv::BORDER_REFLECT);
  cv::GaussianBlur(padded, blurred, cv::Size(0, 0), 1.5);
  cv::Mat out;
  cv::normalize(blurred.colRange(pad, pad + width), out, 0, 255, cv::NORM_MINMAX);
  return out.clone();
}

// Identity extrinsic: the "LiDAR" frame is the camera frame.
const Isometry3 kIdentity = Isometry3::Identity();

TEST(Settings, DefaultsAreValidAndErrorsNameTheField) {
  FusionOdometrySettings s;
  EXPECT_EQ(s.Validate(), "");
  s.selection.max_points = 0;
  EXPECT_EQ(s.Validate().rfind("selection.max_points", 0), 0u) << s.Validate();
  s = {};
  s.tracking.window_px = 16;
  EXPECT_EQ(s.Validate().rfind("tracking.window_px", 0), 0u) << s.Validate();
  s = {};
  s.refinement.loss = "tukey";
  EXPECT_EQ(s.Validate().rfind("refinement.loss", 0), 0u) << s.Validate();
  s = {};
  s.ransac.probability = 1.0;
  EXPECT_EQ(s.Validate().rfind("ransac.probability", 0), 0u) << s.Validate();
  s = {};
  s.visibility.occlusion_tolerance = 0;
  EXPECT_EQ(s.Validate().rfind("visibility.occlusion_tolerance", 0), 0u) << s.Validate();
  s = {};
  s.ransac_mode = "sometimes";
  EXPECT_EQ(s.Validate().rfind("ransac_mode", 0), 0u) << s.Validate();
  s = {};
  s.min_inliers = 2;
  EXPECT_EQ(s.Validate().rfind("min_inliers", 0), 0u) << s.Validate();
}

TEST(Motion, CameraMotionFromLidarSatisfiesAXEqualsXB) {
  const Isometry3 X = MakeIsometry(RotationFromRpy(0.3, -1.2, 2.0), Eigen::Vector3d(0.1, -0.2, 0.05));
  const Isometry3 B = MakeIsometry(RotationFromRpy(0.05, 0.1, -0.3), Eigen::Vector3d(0.4, 0.1, -0.02));
  const Isometry3 A = CameraMotionFromLidar(X, B);
  EXPECT_LT(((A * X).matrix() - (X * B).matrix()).norm(), 1e-12);
}

// A wall at 10 m seen by the LiDAR also behind a board at 3 m (the LiDAR looks from elsewhere, and between
// its beams); the camera must not see those wall points. A floor seen at a grazing angle stays visible.
TEST(Visibility, HidesPointsBehindForegroundKeepsSlantedFloor) {
  const auto camera = MakeCameraModel(Pinhole());
  PointCloud scan;
  for (double x = -6; x <= 6; x += 0.05)
    for (double y = -4; y <= 1.4; y += 0.05) scan.points.emplace_back(x, y, 10.0);  // wall
  const size_t wall = scan.size();
  for (double x = -0.6; x <= 0.6; x += 0.03)
    for (double y = -0.6; y <= 0.6; y += 0.03) scan.points.emplace_back(x, y, 3.0);  // board
  const size_t board = scan.size();
  for (double z = 2; z <= 9.9; z += 0.05)
    for (double x = -3; x <= 3; x += 0.1) scan.points.emplace_back(x, 1.5, z);  // floor, 1.5 m below
  const VisibleScan visible = ProjectVisible(scan, *camera, kIdentity, VisibilitySettings{});
  size_t wall_behind = 0, wall_behind_seen = 0, board_seen = 0, floor_total = 0, floor_seen = 0;
  std::vector<char> seen(scan.size(), 0);
  for (const ScanPoint& s : visible.points) seen[s.index] = 1;
  for (size_t k = 0; k < scan.size(); ++k) {
    const Eigen::Vector3f& p = scan.points[k];
    if (k < wall) {
      // Wall points whose pixel lies well inside the board's image (board spans +-0.6 m at 3 m).
      if (std::abs(p.x() / p.z()) < 0.15 && std::abs(p.y() / p.z()) < 0.15) {
        ++wall_behind;
        wall_behind_seen += seen[k];
      }
    } else if (k < board) {
      board_seen += seen[k];
    } else {
      Eigen::Vector2d pixel;
      if (!camera->Project(p.cast<double>(), &pixel)) continue;
      // Not behind the board (its image plus the occlusion radius), not at the foot of the wall.
      if (std::abs(p.x() / p.z()) < 0.2 + 0.02 && p.y() / p.z() < 0.2 + 0.02) continue;
      if (p.z() > 9.0) continue;
      ++floor_total;
      floor_seen += seen[k];
    }
  }
  EXPECT_GT(wall_behind, 100u);
  EXPECT_EQ(wall_behind_seen, 0u) << "seen through the board";
  EXPECT_GT(board_seen, 0.95 * (board - wall));
  EXPECT_GT(floor_total, 1000u);
  EXPECT_GT(floor_seen, 0.9 * floor_total) << "a slanted floor is not an occlusion";
}

TEST(Visibility, DepthGridWrapsColumnsOfPanoramas) {
  DepthGrid grid(512, 256, 4, /*wrap=*/true);
  grid.Insert(Eigen::Vector2d(510.0, 100.0), 2.0);  // left of the seam
  grid.Insert(Eigen::Vector2d(6.0, 100.0), 2.0);    // right of it
  // A point on the seam between them at 5 m lies behind its surroundings.
  const DepthGrid::Contrast c = grid.SecondDifference(Eigen::Vector2d(1.0, 100.0), 5.0, 6.0);
  EXPECT_LT(c.most_negative, -2.9);
  DepthGrid flat(512, 256, 4, /*wrap=*/false);
  flat.Insert(Eigen::Vector2d(510.0, 100.0), 2.0);
  flat.Insert(Eigen::Vector2d(6.0, 100.0), 2.0);
  EXPECT_EQ(flat.SecondDifference(Eigen::Vector2d(1.0, 100.0), 5.0, 6.0).most_negative, 0.0);
}

TEST(TrackSelection, KeepsTexturedSpacedPointsWithinBudget) {
  const auto camera = MakeCameraModel(Pinhole());
  // Texture on the left half only.
  cv::Mat image(480, 640, CV_8UC1, cv::Scalar(128));
  Texture(320, 480, 5, false).copyTo(image.colRange(0, 320));
  PointCloud scan;
  for (double x = -7.9; x <= 7.9; x += 0.02)
    for (double y = -5.9; y <= 5.9; y += 0.02) scan.points.emplace_back(x, y, 10.0);
  const VisibleScan visible = ProjectVisible(scan, *camera, kIdentity, VisibilitySettings{});
  SelectionSettings settings;
  settings.max_points = 300;
  settings.min_distance_px = 10;
  const std::vector<ScanPoint> selected =
      SelectTrackable(visible, CornerResponse(image, 7, false), *camera, 8, settings);
  EXPECT_EQ(selected.size(), 300u);
  for (size_t a = 0; a < selected.size(); ++a) {
    EXPECT_LT(selected[a].pixel_i.x(), 320 + 4) << "only textured places";
    EXPECT_GE(selected[a].pixel_i.x(), 8);
    for (size_t b = a + 1; b < selected.size(); ++b)
      ASSERT_GE((selected[a].pixel_i - selected[b].pixel_i).norm(), 10.0 - 1e-9);
  }
}

// Panorama turned about its vertical axis: every column moves 9 px to the right, across the seam.
TEST(KltTracking, TracksAcrossThePanoramaSeam) {
  const int w = 512, h = 256;
  const cv::Mat image_i = Texture(w, h, 11, true);
  cv::Mat image_j;
  cv::hconcat(image_i.colRange(w - 9, w), image_i.colRange(0, w - 9), image_j);  // j(u + 9) = i(u)
  const KltTracker tracker(image_i, image_j, /*wrap=*/true, 8, TrackingSettings{});
  std::vector<cv::Point2f> from, predicted, tracked;
  for (float u : {0.3f, 3.7f, 250.2f, 500.5f, 505.1f, 509.9f, 511.2f})
    for (float v : {40.0f, 128.4f, 200.0f}) {
      from.emplace_back(u, v);
      predicted.emplace_back(std::fmod(u + 7.5f, static_cast<float>(w)), v + 0.6f);  // a guess 1.5 px off
    }
  std::vector<unsigned char> ok;
  tracker.Track(from, predicted, &tracked, &ok);
  for (size_t k = 0; k < from.size(); ++k) {
    ASSERT_TRUE(ok[k]) << from[k];
    float expected = from[k].x + 9.0f;
    if (expected >= w - 0.5f) expected -= w;
    EXPECT_NEAR(tracked[k].x, expected, 0.05) << from[k];
    EXPECT_NEAR(tracked[k].y, from[k].y, 0.05) << from[k];
    EXPECT_GE(tracked[k].x, -0.5f);
    EXPECT_LT(tracked[k].x, w - 0.5f);
  }
}

// Where the flow curves (here: d(x) = 3 + k (x - centre)^2 px in every 64-column period), a
// translation-only window lands where the flow averaged over it points, beyond the flow at its centre
// by k times the window's second moment: the refinement with a smaller window (refine_window_deg)
// shrinks that bias (settings.hpp).
TEST(KltTracking, TheSmallWindowRefinementRemovesMostOfTheCurvedFlowBias) {
  const int w = 512, h = 160, period = 64;
  const double k = 0.005;
  const auto flow = [&](double x) {
    const double c = std::fmod(x, period) - period / 2.0;
    return 3.0 + k * c * c;
  };
  const cv::Mat image_i = Texture(w, h, 21, false);
  cv::Mat map_x(h, w, CV_32FC1), map_y(h, w, CV_32FC1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      map_x.at<float>(y, x) = static_cast<float>(x - flow(x));  // j(x) = i(x - d(x))
      map_y.at<float>(y, x) = static_cast<float>(y);
    }
  cv::Mat image_j;
  cv::remap(image_i, image_j, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REFLECT);
  std::vector<cv::Point2f> from, predicted;
  std::vector<double> expected;
  for (int centre = period * 2 + period / 2; centre < w - period; centre += period)
    for (int dx = -8; dx <= 8; dx += 4)
      for (int y = 20; y < h - 20; y += 6) {
        double x = centre + dx + 3.0;  // where u = centre + dx lands: x - d(x) = u (Newton)
        for (int it = 0; it < 20; ++it)
          x -= (x - flow(x) - (centre + dx)) / (1.0 - 2.0 * k * (std::fmod(x, period) - period / 2.0));
        from.emplace_back(static_cast<float>(centre + dx), static_cast<float>(y));
        predicted.emplace_back(static_cast<float>(x + 0.8), static_cast<float>(y - 0.5));
        expected.push_back(x);
      }
  const auto mean_error = [&](int refine_window_px) {
    TrackingSettings settings;
    settings.pyramid_levels = 0;
    settings.epsilon_px = 0.001;
    const KltTracker tracker(image_i, image_j, false, 8, settings, refine_window_px);
    std::vector<cv::Point2f> tracked;
    std::vector<unsigned char> ok;
    tracker.Track(from, predicted, &tracked, &ok);
    double sum = 0;
    int n = 0;
    for (size_t i = 0; i < from.size(); ++i)
      if (ok[i]) sum += tracked[i].x - expected[i], ++n;
    EXPECT_GT(n, int(from.size()) * 3 / 4);
    return sum / std::max(n, 1);
  };
  const double plain = mean_error(0), refined = mean_error(7);
  EXPECT_GT(plain, 0.04) << "the 15 px window should overshoot a flow that curves upwards";
  EXPECT_LT(std::abs(refined), plain / 2) << "plain " << plain << " px, refined " << refined << " px";
}

TEST(KltTracking, TheRefinementWindowFollowsThePixelAngle) {
  TrackingSettings settings;                                // window_px 15, refine_window_deg 2.5
  EXPECT_EQ(RefineWindowPx(settings, 2 * M_PI / 1024), 7);  // 0.35 deg per pixel
  EXPECT_EQ(RefineWindowPx(settings, 2 * M_PI / 2048), 0);  // 15 px is 2.6 deg already
  EXPECT_EQ(RefineWindowPx(settings, 1.0 / 721.5), 0);      // KITTI's camera: 2.5 deg is 31 px
  EXPECT_EQ(RefineWindowPx(settings, 2 * M_PI / 256), 5);   // never below 5 px
  settings.refine_window_deg = 0;
  EXPECT_EQ(RefineWindowPx(settings, 2 * M_PI / 1024), 0);
}

TEST(Derotation, UndoesATurnOfAPanorama) {
  const int w = 512, h = 256;
  const auto camera = MakeCameraModel(Panorama(w));
  const cv::Mat image_i = Texture(w, h, 12, true);
  cv::Mat image_j;
  cv::hconcat(image_i.colRange(w - 9, w), image_i.colRange(0, w - 9), image_j);  // longitude + 9 px
  // Camera j sees longitude lon + delta where camera i sees lon: R_a^T = R_y(delta), R_a = R_y(-delta).
  const double delta = 9.0 * 2.0 * M_PI / w;
  const Eigen::Matrix3d R_a = Eigen::AngleAxisd(-delta, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const cv::Mat derotated = DerotateImage(image_j, *camera, R_a);
  cv::Mat diff;
  cv::absdiff(derotated.rowRange(16, h - 16), image_i.rowRange(16, h - 16), diff);
  EXPECT_LT(cv::mean(diff)[0], 1.0);
  // The wrong direction does not.
  const cv::Mat wrong = DerotateImage(image_j, *camera, R_a.transpose());
  cv::absdiff(wrong.rowRange(16, h - 16), image_i.rowRange(16, h - 16), diff);
  EXPECT_GT(cv::mean(diff)[0], 10.0);
}

TEST(Derotation, RoundTripOfATiltKeepsTheImage) {
  const auto camera = MakeCameraModel(Pinhole());
  const cv::Mat image = Texture(640, 480, 13, false);
  const Eigen::Matrix3d R = RotationFromRpy(Rad(4), Rad(-3), Rad(2));
  const cv::Mat back = DerotateImage(DerotateImage(image, *camera, R), *camera, R.transpose());
  cv::Mat diff;
  cv::absdiff(back(cv::Rect(80, 80, 480, 320)), image(cv::Rect(80, 80, 480, 320)), diff);
  EXPECT_LT(cv::mean(diff)[0], 3.0);  // bilinear resampling twice blurs a little
}

// A pixel tracked in the derotated image is read back through the map the resampling used, not through the
// exact projection: the two differ by the grid's interpolation error, which would bias every tilt's bearings.
TEST(Derotation, TrackedPixelsGoBackThroughTheSampledMap) {
  const int w = 1024, h = 512;
  const auto camera = MakeCameraModel(Panorama(w));
  const cv::Mat image_j = Texture(w, h, 14, true);
  const Eigen::Matrix3d R_a = Eigen::AngleAxisd(Rad(13), Eigen::Vector3d::UnitX()).toRotationMatrix();
  const DerotationMap map(*camera, R_a, 8);
  const cv::Mat derotated = map.Resample(image_j);
  auto sample_j = [&](const Eigen::Vector2d& p) {  // bilinear, columns wrap
    const int x0 = static_cast<int>(std::floor(p.x())), y0 = static_cast<int>(std::floor(p.y()));
    const double fx = p.x() - x0, fy = p.y() - y0;
    auto at = [&](int x, int y) {
      return static_cast<double>(image_j.at<uint8_t>(std::clamp(y, 0, h - 1), ((x % w) + w) % w));
    };
    return (1 - fx) * (1 - fy) * at(x0, y0) + fx * (1 - fy) * at(x0 + 1, y0) + (1 - fx) * fy * at(x0, y0 + 1) +
           fx * fy * at(x0 + 1, y0 + 1);
  };
  double largest_grid_error_px = 0.0, sum_difference = 0.0;
  int samples = 0;
  for (int y = 20; y < h - 20; y += 7)
    for (int x = 3; x < w; x += 11) {
      const Eigen::Vector2d source = map.SourcePixel(x, y);
      ASSERT_GE(source.x(), 0.0);
      ASSERT_LT(source.x(), w);
      // cv::remap places its samples to 1/32 px and rounds to grey levels.
      const double difference = std::abs(derotated.at<uint8_t>(y, x) - sample_j(source));
      ASSERT_LT(difference, 2.0) << "at " << x << ", " << y;
      sum_difference += difference;
      ++samples;
      Eigen::Vector2d exact;
      ASSERT_TRUE(camera->Project(R_a.transpose() * camera->Unproject(Eigen::Vector2d(x, y)), &exact));
      double dx = std::abs(exact.x() - source.x());
      dx = std::min(dx, w - dx);
      if (std::abs(y - h / 2) < h / 3)  // within 60 deg of the horizon: near a pole the map folds over it
        largest_grid_error_px = std::max(largest_grid_error_px, std::hypot(dx, exact.y() - source.y()));
    }
  EXPECT_LT(sum_difference / samples, 0.5) << "grey levels";
  EXPECT_GT(largest_grid_error_px, 0.02) << "the 8 px grid interpolates: the map is not the exact projection";
  EXPECT_LT(largest_grid_error_px, 2.0);
  std::printf("largest interpolation error of the 8 px grid, 13 deg tilt, within 60 deg of the horizon: %.3f px\n",
              largest_grid_error_px);
}

// Synthetic 2D-3D correspondences: static points, plus 30 % on a "vehicle" that moved 0.4 m with the car.
struct Synthetic {
  Correspondences correspondences;
  std::vector<bool> on_vehicle;
  Isometry3 A = Isometry3::Identity();
};

Synthetic MakeCorrespondences(double noise_rad, unsigned seed, double vehicle_share = 0.3) {
  Synthetic s;
  s.A = MakeIsometry(RotationFromRpy(Rad(2), Rad(-12), Rad(5)), Eigen::Vector3d(0.3, -0.05, 0.8));
  const Isometry3 vehicle_motion = MakeIsometry(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.05, 0.0, 0.4));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1), depth(3, 30);
  std::normal_distribution<double> n(0, noise_rad);
  for (int k = 0; k < 600; ++k) {
    Correspondence c;
    c.p_ci = Eigen::Vector3d(u(rng), 0.6 * u(rng), 1.0).normalized() * depth(rng);
    const bool vehicle = k < vehicle_share * 600;
    const Isometry3 A_seen = vehicle ? vehicle_motion.inverse() * s.A : s.A;  // the vehicle moved with the car
    Eigen::Vector3d v = A_seen.inverse() * c.p_ci;
    v = (v.normalized() + Eigen::Vector3d(n(rng), n(rng), n(rng))).normalized();
    c.bearing_j = v;
    c.index = k;
    s.correspondences.push_back(c);
    s.on_vehicle.push_back(vehicle);
  }
  return s;
}

TEST(PoseEstimation, RansacAndRobustRefinementIgnoreAVehicleMovingWithTheCar) {
  const double pixel = 1.0 / 500.0;
  const Synthetic s = MakeCorrespondences(0.3 * pixel, 1);
  const P3pResult p3p = P3pRansac(s.correspondences, 2.0 * pixel, RansacSettings{});
  ASSERT_TRUE(p3p.ok);
  EXPECT_LT(RotationErrorDeg(p3p.T_ci_cj.linear(), s.A.linear()), 0.2);
  const RefinementResult r = RefinePose(s.correspondences, p3p.T_ci_cj, p3p.inliers, pixel, RefinementSettings{});
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_LT(RotationErrorDeg(r.T_ci_cj.linear(), s.A.linear()), 0.01);
  EXPECT_LT((r.T_ci_cj.translation() - s.A.translation()).norm(), 0.002);
  // No vehicle track that the static motion cannot explain is an inlier (a few vehicle points near the
  // focus of expansion move like static ones and may be); nearly all static tracks are.
  int static_inliers = 0;
  for (int k : r.inliers) {
    const Correspondence& c = s.correspondences[k];
    if (!s.on_vehicle[k]) {
      ++static_inliers;
      continue;
    }
    EXPECT_LT(BearingAngle(c.bearing_j, s.A.inverse() * c.p_ci), 3.0 * pixel) << "vehicle track " << k;
  }
  EXPECT_GE(static_inliers, 0.95 * 420);
  ASSERT_TRUE(r.covariance_valid);
  // The estimate lies within a few sigma of the truth.
  EXPECT_LT((r.T_ci_cj.translation() - s.A.translation()).norm(),
            5.0 * std::sqrt(r.covariance.bottomRightCorner<3, 3>().trace()));
}

TEST(PoseEstimation, RefinementFromAnApproximateGuessWithoutRansac) {
  const double pixel = 1.0 / 500.0;
  const Synthetic s = MakeCorrespondences(0.3 * pixel, 2, 0.2);
  const Isometry3 guess =
      s.A * MakeIsometry(ExpSO3(Eigen::Vector3d(0.001, -0.001, 0.0005)), Eigen::Vector3d(0.005, 0, -0.004));
  const std::vector<int> start = PoseInliers(s.correspondences, guess, 3.0 * pixel);
  const RefinementResult r = RefinePose(s.correspondences, guess, start, pixel, RefinementSettings{});
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_LT(RotationErrorDeg(r.T_ci_cj.linear(), s.A.linear()), 0.01);
  EXPECT_LT((r.T_ci_cj.translation() - s.A.translation()).norm(), 0.002);
}

TEST(PoseEstimation, CovarianceScalesWithTheNoise) {
  const double pixel = 1.0 / 500.0;
  Matrix6 c1, c4;
  for (auto [noise, out] : {std::pair{0.25, &c1}, std::pair{1.0, &c4}}) {
    const Synthetic s = MakeCorrespondences(noise * pixel, 3, 0.0);
    std::vector<int> all(s.correspondences.size());
    for (size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int>(k);
    ASSERT_TRUE(PoseCovariance(s.correspondences, all, s.A, out));
  }
  // Four times the noise: sixteen times the variance (within the scatter of the estimate of sigma).
  const double ratio = c4.trace() / c1.trace();
  EXPECT_GT(ratio, 10.0);
  EXPECT_LT(ratio, 25.0);
  EXPECT_LT((c1 - c1.transpose()).norm(), 1e-12 * c1.norm());
}

}  // namespace
}  // namespace fusecal::fusion_odometry
