#include "stages/fusion_odometry/fusion_odometry.hpp"

#include <chrono>
#include <cmath>
#include <exception>
#include <opencv2/imgproc.hpp>
#include <optional>

#include "stages/fusion_odometry/derotation.hpp"
#include "stages/fusion_odometry/klt_tracking.hpp"
#include "stages/fusion_odometry/p3p_ransac.hpp"
#include "stages/fusion_odometry/pose_refinement.hpp"
#include "stages/fusion_odometry/track_selection.hpp"
#include "stages/fusion_odometry/visibility.hpp"

namespace fusecal::fusion_odometry {

namespace {

using Clock = std::chrono::steady_clock;
using Code = FusionOdometryFailure;

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Empty when the image is usable (8-bit, 1, 3 or 4 channels, the camera's size), else why not.
std::string CheckImage(const cv::Mat& image, const CameraModel& camera, const char* name) {
  if (image.empty()) return std::string("image ") + name + " is empty";
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3 && image.channels() != 4))
    return std::string("image ") + name + " must be 8-bit grey, BGR or BGRA";
  if (image.cols != camera.width() || image.rows != camera.height())
    return std::string("image ") + name + " is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
           ", the camera " + std::to_string(camera.width()) + "x" + std::to_string(camera.height());
  if (std::string e = TrackableSizeProblem(image.cols, image.rows); !e.empty())
    return std::string("image ") + name + " is " + e;
  return {};
}

cv::Mat Grey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
  return grey;
}

// Image j as tracked: derotated by R_d through `map` (derotation.hpp), or as it is (R_d = I, no map).
struct TrackedImage {
  Eigen::Matrix3d R_d = Eigen::Matrix3d::Identity();
  std::optional<DerotationMap> map;
  bool derotated() const { return map.has_value(); }
};

// One tracking pass: predict where each selected point appears in (derotated) image j under `prediction`
// (the initial flow), track, and pair the bearings v'_j of the tracked pixels with the points.
Correspondences TrackPass(const std::vector<ScanPoint>& selected, const Isometry3& prediction_T_ci_cj,
                          const CameraModel& camera, const KltTracker& tracker, const TrackedImage& tracked_image,
                          int border_px) {
  const Isometry3 T_cj_ci = prediction_T_ci_cj.inverse();
  const Eigen::Matrix3d& R_d = tracked_image.R_d;
  std::vector<cv::Point2f> from, predicted;
  std::vector<int> which;
  for (size_t k = 0; k < selected.size(); ++k) {
    Eigen::Vector2d pixel;
    if (!camera.Project(R_d * (T_cj_ci * selected[k].p_ci), &pixel) || !camera.InImage(pixel)) continue;
    from.emplace_back(static_cast<float>(selected[k].pixel_i.x()), static_cast<float>(selected[k].pixel_i.y()));
    predicted.emplace_back(static_cast<float>(pixel.x()), static_cast<float>(pixel.y()));
    which.push_back(static_cast<int>(k));
  }
  std::vector<cv::Point2f> tracked;
  std::vector<unsigned char> ok;
  tracker.Track(from, predicted, &tracked, &ok);
  Correspondences out;
  const bool check_border = tracked_image.derotated() && !camera.WrapsHorizontally();
  for (size_t n = 0; n < which.size(); ++n) {
    if (!ok[n]) continue;
    const ScanPoint& s = selected[which[n]];
    Correspondence c;
    c.p_ci = s.p_ci;
    c.pixel_i = s.pixel_i;
    c.index = s.index;
    // Derotated: back into image j through the map the resampling used; a pinhole window must have come
    // from inside image j (not its replicated border).
    c.pixel_j = tracked_image.derotated() ? tracked_image.map->SourcePixel(tracked[n].x, tracked[n].y)
                                          : Eigen::Vector2d(tracked[n].x, tracked[n].y);
    if (check_border &&
        (c.pixel_j.x() < border_px || c.pixel_j.y() < border_px || c.pixel_j.x() > camera.width() - 1 - border_px ||
         c.pixel_j.y() > camera.height() - 1 - border_px))
      continue;
    c.bearing_j = camera.Unproject(c.pixel_j);
    out.push_back(c);
  }
  return out;
}

// Records the outcome: the status, and usable when `failure` is kNone.
void Conclude(const char* status, Failure<Code> failure, FusionOdometryResult* result) {
  result->status = status;
  result->failure_reason = std::move(failure);
}

void Fail(FusionOdometryResult* result, Code code, const std::string& reason) {
  Conclude(status::kFailed, {code, reason}, result);
}

// kNone when the inputs can be used, else why not (the input checks of Run, in order).
Failure<Code> InputProblem(const PointCloud& scan_i, const cv::Mat& image_i, const cv::Mat& image_j,
                           const CameraModel& camera, const Isometry3& T_camera_lidar, const MotionGuess& guess,
                           const FusionOdometrySettings& settings) {
  if (const std::string e = settings.Validate(); !e.empty()) return {Code::kInvalidSettings, "invalid settings: " + e};
  if (camera.width() <= 0 || camera.height() <= 0) return {Code::kInvalidInput, "camera has no image size"};
  if (std::string e = CheckImage(image_i, camera, "i"); !e.empty()) return {Code::kInvalidInput, e};
  if (std::string e = CheckImage(image_j, camera, "j"); !e.empty()) return {Code::kInvalidInput, e};
  if (!IsValidTransform(T_camera_lidar, 1e-6))
    return {Code::kInvalidInput, "invalid extrinsic T_camera_lidar (non-finite or not a rigid transform)"};
  if (!IsValidTransform(guess.T_ci_cj, 1e-6))
    return {Code::kInvalidInput, "invalid motion guess (non-finite or not a rigid transform)"};
  if (scan_i.empty()) return {Code::kInvalidInput, "empty scan"};
  return {};
}

// Steps 1, 2: the visible, trackable scan points in image i (timed from `started`); false (result failed)
// when none projects or too few are trackable.
bool SelectPoints(const PointCloud& scan_i, const cv::Mat& grey_i, const CameraModel& camera,
                  const Isometry3& T_camera_lidar, const FusionOdometrySettings& settings, bool wrap, int border_px,
                  Clock::time_point started, FusionOdometryResult* result, std::vector<ScanPoint>* selected) {
  const VisibleScan visible = ProjectVisible(scan_i, camera, T_camera_lidar, settings.visibility);
  result->projected_points = visible.projected;
  result->visible_points = static_cast<int>(visible.points.size());
  if (visible.projected == 0) {
    Fail(result, Code::kNothingProjects, "no scan point projects into image i (check the extrinsic T_camera_lidar)");
    return false;
  }
  const cv::Mat response = CornerResponse(grey_i, settings.selection.corner_block_size, wrap);
  *selected = SelectTrackable(visible, response, camera, border_px, settings.selection);
  result->selected_points = static_cast<int>(selected->size());
  result->seconds_selection = SecondsSince(started);
  if (result->selected_points < settings.min_inliers) {
    Fail(result, Code::kTooFewTrackable,
         "too few trackable scan points in image i (" + std::to_string(selected->size()) + " of " +
             std::to_string(visible.points.size()) + " visible; need " + std::to_string(settings.min_inliers) + ")");
    return false;
  }
  return true;
}

// Image j as the tracker sees it: resampled with camera i's orientation (R_d = the guess's rotation) when the
// guess turns the camera by more than derotate_min_deg, else grey_j as it is.
cv::Mat ImageJForTracking(const cv::Mat& grey_j, const CameraModel& camera, const MotionGuess& guess,
                          const TrackingSettings& tracking, TrackedImage* tracked_image) {
  cv::Mat grey_j_tracked = grey_j;
  if (tracking.derotate_min_deg >= 0 &&
      RotationAngle(guess.T_ci_cj.linear()) * 180.0 / M_PI > tracking.derotate_min_deg) {
    tracked_image->R_d = guess.T_ci_cj.linear();
    tracked_image->map.emplace(camera, tracked_image->R_d, tracking.derotation_grid_px);
    grey_j_tracked = tracked_image->map->Resample(grey_j);
  }
  return grey_j_tracked;
}

// The pose the refinement starts from, and the tracks consistent with it.
struct StartPose {
  Isometry3 T_ci_cj = Isometry3::Identity();
  std::vector<int> inliers;
};

// Step 4: the guess, or the P3P RANSAC pose when RANSAC runs (guess not trusted, or ransac_mode "always")
// and explains more tracks.
StartPose ChooseStart(const Correspondences& tracks, const MotionGuess& guess, double ransac_threshold,
                      const FusionOdometrySettings& settings, FusionOdometryResult* result) {
  const auto t0 = Clock::now();
  StartPose start;
  start.inliers = PoseInliers(tracks, guess.T_ci_cj, ransac_threshold);
  result->guess_inliers = static_cast<int>(start.inliers.size());
  start.T_ci_cj = guess.T_ci_cj;
  const bool guess_trusted = guess.reliable && start.inliers.size() >= settings.min_guess_inlier_ratio * tracks.size();
  result->used_ransac = settings.ransac_mode == "always" || (settings.ransac_mode == "auto" && !guess_trusted);
  if (result->used_ransac) {
    const P3pResult p3p = P3pRansac(tracks, ransac_threshold, settings.ransac);
    result->ransac_iterations = p3p.iterations;
    result->ransac_inliers = static_cast<int>(p3p.inliers.size());
    if (p3p.ok && p3p.inliers.size() > start.inliers.size()) {
      start.T_ci_cj = p3p.T_ci_cj;
      start.inliers = p3p.inliers;
    }
  }
  result->seconds_ransac = SecondsSince(t0);
  return start;
}

// After a RANSAC start: tracks again with the refined pose as the prediction and refines again; the second
// pass replaces *refined and *tracks when it keeps at least as many inliers.
void RetrackAndRefine(const std::vector<ScanPoint>& selected, const CameraModel& camera, const KltTracker& tracker,
                      const TrackedImage& tracked_image, int border_px, double ransac_threshold, double pixel_angle,
                      const FusionOdometrySettings& settings, FusionOdometryResult* result, RefinementResult* refined,
                      Correspondences* tracks) {
  auto t0 = Clock::now();
  Correspondences tracks2 = TrackPass(selected, refined->T_ci_cj, camera, tracker, tracked_image, border_px);
  result->seconds_tracking += SecondsSince(t0);
  t0 = Clock::now();
  const std::vector<int> inliers2 = PoseInliers(tracks2, refined->T_ci_cj, ransac_threshold);
  RefinementResult refined2 = RefinePose(tracks2, refined->T_ci_cj, inliers2, pixel_angle, settings.refinement);
  result->seconds_refinement += SecondsSince(t0);
  if (refined2.ok && refined2.inliers.size() >= refined->inliers.size()) {
    refined2.iterations += refined->iterations;
    *refined = std::move(refined2);
    *tracks = std::move(tracks2);
    result->passes = 2;
    result->tracked_points = static_cast<int>(tracks->size());
  }
}

// The result from the final refinement: pose, figures, inlier correspondences and the inlier verdict.
void SetResult(const RefinementResult& refined, const Correspondences& tracks, double pixel_angle,
               const FusionOdometrySettings& settings, FusionOdometryResult* result) {
  result->T_ci_cj = refined.T_ci_cj;
  result->inliers = static_cast<int>(refined.inliers.size());
  result->refinement_iterations = refined.iterations;
  result->rms_residual_px = refined.rms_rad / pixel_angle;
  result->median_residual_px = refined.median_rad / pixel_angle;
  result->covariance_valid = refined.covariance_valid;
  if (refined.covariance_valid) result->covariance = refined.covariance;
  result->inlier_correspondences.reserve(refined.inliers.size());
  for (int k : refined.inliers) result->inlier_correspondences.push_back(tracks[k]);

  if (result->inliers < settings.min_inliers) {
    Conclude(status::kNotConverged,
             {Code::kTooFewInliers, "too few inliers: " + std::to_string(result->inliers) + " (need " +
                                        std::to_string(settings.min_inliers) + ")"},
             result);
  } else if (result->inliers < settings.min_inlier_ratio * result->tracked_points) {
    Conclude(status::kNotConverged,
             {Code::kTooFewTracksAgree, "too few tracks agree: " + std::to_string(result->inliers) + " inliers of " +
                                            std::to_string(result->tracked_points) + " tracks"},
             result);
  } else {
    Conclude(status::kConverged, {}, result);
  }
}

void Run(const PointCloud& scan_i, const cv::Mat& image_i, const cv::Mat& image_j, const CameraModel& camera,
         const Isometry3& T_camera_lidar, const MotionGuess& guess, const FusionOdometrySettings& settings,
         FusionOdometryResult* result) {
  // --- input checks ---
  if (Failure<Code> e = InputProblem(scan_i, image_i, image_j, camera, T_camera_lidar, guess, settings);
      e.code != Code::kNone)
    return Fail(result, e.code, e.text);

  const bool wrap = camera.WrapsHorizontally();
  const double pixel_angle = PixelAngleRad(camera);
  const double ransac_threshold = settings.ransac.threshold_px * pixel_angle;
  const int border_px = settings.tracking.window_px / 2 + 1;

  // --- steps 1, 2: visible, trackable scan points in image i ---
  auto t0 = Clock::now();
  const cv::Mat grey_i = Grey(image_i), grey_j = Grey(image_j);
  std::vector<ScanPoint> selected;
  if (!SelectPoints(scan_i, grey_i, camera, T_camera_lidar, settings, wrap, border_px, t0, result, &selected)) return;

  // --- step 3: KLT into image j, predicted by the guess ---
  t0 = Clock::now();
  TrackedImage tracked_image;
  const cv::Mat grey_j_tracked = ImageJForTracking(grey_j, camera, guess, settings.tracking, &tracked_image);
  const KltTracker tracker(grey_i, grey_j_tracked, wrap, border_px, settings.tracking,
                           RefineWindowPx(settings.tracking, pixel_angle));
  Correspondences tracks = TrackPass(selected, guess.T_ci_cj, camera, tracker, tracked_image, border_px);
  result->passes = 1;
  result->tracked_points = static_cast<int>(tracks.size());
  result->seconds_tracking = SecondsSince(t0);
  if (result->tracked_points < settings.min_inliers)
    return Fail(result, Code::kTrackingFailed,
                "tracking failed: " + std::to_string(tracks.size()) + " of " + std::to_string(selected.size()) +
                    " points tracked into image j (need " + std::to_string(settings.min_inliers) + ")");

  // --- step 4: hypothesis: the guess, or P3P RANSAC when the guess is not trusted ---
  const StartPose start = ChooseStart(tracks, guess, ransac_threshold, settings, result);
  if (static_cast<int>(start.inliers.size()) < 4)
    return Fail(result, Code::kNoMotion,
                "no motion explains the tracks (" + std::to_string(result->ransac_inliers) + " RANSAC inliers, " +
                    std::to_string(result->guess_inliers) + " consistent with the guess, of " +
                    std::to_string(tracks.size()) + " tracks)");

  // --- step 5: robust refinement of the angular error ---
  t0 = Clock::now();
  RefinementResult refined = RefinePose(tracks, start.T_ci_cj, start.inliers, pixel_angle, settings.refinement);
  result->seconds_refinement = SecondsSince(t0);
  if (!refined.ok) return Fail(result, Code::kRefinementFailed, refined.message);

  // --- after a RANSAC start: track again with the estimate as the prediction, refine again ---
  if (result->used_ransac && settings.retrack)
    RetrackAndRefine(selected, camera, tracker, tracked_image, border_px, ransac_threshold, pixel_angle, settings,
                     result, &refined, &tracks);

  // --- result ---
  SetResult(refined, tracks, pixel_angle, settings, result);
}

}  // namespace

FusionOdometryResult EstimateScaledMotion(const PointCloud& scan_i, const cv::Mat& image_i, const cv::Mat& image_j,
                                          const CameraModel& camera, const Isometry3& T_camera_lidar,
                                          const MotionGuess& guess, const FusionOdometrySettings& settings) {
  const auto start = Clock::now();
  FusionOdometryResult result;
  try {
    Run(scan_i, image_i, image_j, camera, T_camera_lidar, guess, settings, &result);
  } catch (const std::exception& e) {
    result = FusionOdometryResult();
    Fail(&result, Code::kInternalError, std::string("unexpected error: ") + e.what());
  } catch (...) {
    result = FusionOdometryResult();
    Fail(&result, Code::kInternalError, "unexpected error");
  }
  result.seconds = SecondsSince(start);
  return result;
}

Isometry3 CameraMotionFromLidar(const Isometry3& T_camera_lidar, const Isometry3& T_li_lj) {
  return T_camera_lidar * T_li_lj * T_camera_lidar.inverse();
}

}  // namespace fusecal::fusion_odometry
