#include "stages/camera_frontend/relative_pose.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <sstream>

#include "stages/camera_frontend/bearings.hpp"
#include "stages/camera_frontend/chirality.hpp"
#include "stages/camera_frontend/epipolar_refinement.hpp"
#include "stages/camera_frontend/five_point_ransac.hpp"
#include "stages/camera_frontend/matching.hpp"
#include "stages/camera_frontend/rotation_only.hpp"

namespace fusecal {

namespace {

using camera_frontend::Bearings;
using Clock = std::chrono::steady_clock;
using Code = RelativePoseFailure;

double SecondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

constexpr double kDeg = 180.0 / M_PI;
// Under near-pure rotation, the essential-matrix rotation is used when it lies within this angle of the
// rotation-only fit (their difference is of the order of the parallax; a twisted pair is 180 degrees off).
constexpr double kMaxRotationDisagreementDeg = 5.0;

std::string Fixed(double value, int digits = 3) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << value;
  return s.str();
}

struct EssentialModel {
  bool ok = false;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  std::vector<int> inliers;
  camera_frontend::EpipolarRefinement refinement;
};

// RANSAC model -> rounds of (refine on inliers, fix chirality, re-select inliers).
EssentialModel RefineEssential(const Bearings& f_i, const Bearings& f_j, const camera_frontend::RansacResult& ransac,
                               const CameraFrontendSettings& s, double threshold_rad, double loss_rad) {
  EssentialModel m;
  m.R = ransac.R;
  m.t = ransac.t;
  m.inliers = ransac.inliers;
  for (int round = 0; round < s.refinement.rounds; ++round) {
    const bool last = round + 1 == s.refinement.rounds;
    auto refined = camera_frontend::RefineEpipolar(f_i, f_j, m.inliers, m.R, m.t, loss_rad, s.refinement.max_iterations,
                                                   last && s.refinement.compute_covariance);
    if (!refined.ok) return m;  // m.ok stays false
    m.R = refined.R;
    m.t = refined.t;
    camera_frontend::ResolveChirality(f_i, f_j, m.inliers, &m.R, &m.t);
    m.refinement = refined;
    m.inliers = camera_frontend::EpipolarInliers(f_i, f_j, m.R, m.t, threshold_rad);
    if (static_cast<int>(m.inliers.size()) < s.min_inliers) return m;
  }
  m.ok = true;
  return m;
}

// kNone when the features can be used with this camera, else why not.
Failure<Code> CheckFeatures(const ImageFeatures& fi, const ImageFeatures& fj, const CameraModel& camera) {
  if (!fi.usable()) return {Code::kFeaturesFailed, "image i: " + fi.failure_reason.text};
  if (!fj.usable()) return {Code::kFeaturesFailed, "image j: " + fj.failure_reason.text};
  for (const ImageFeatures* f : {&fi, &fj}) {
    if (f->width != camera.width() || f->height != camera.height())
      return {Code::kFeaturesMismatch, "features come from a " + std::to_string(f->width) + "x" +
                                           std::to_string(f->height) + " image but the camera model expects " +
                                           std::to_string(camera.width()) + "x" + std::to_string(camera.height())};
    if (f->bearings.size() != f->keypoints.size() || f->descriptors.rows != static_cast<int>(f->keypoints.size()))
      return {Code::kFeaturesMismatch, "inconsistent features: keypoints, descriptors and bearings differ in number"};
  }
  return {};
}

// Largest standard deviation (degrees) of a 3x3 covariance in radians^2.
double MaxStdDeg(const Eigen::Matrix3d& covariance) {
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance).eigenvalues().maxCoeff();
  return std::sqrt(std::max(0.0, largest)) * kDeg;
}

// Why the translation direction cannot be trusted (near-pure rotation), or empty when it can. The parallax
// is the median residual of the rotation-only model over the inliers: a translation that explains no more
// than noise (or than a fraction of a pixel) is not observed.
std::string TranslationUnreliableReason(const EssentialModel& model, bool rotation_explains_more, double parallax_rad,
                                        double epipolar_rad, double pixel_rad, const CameraFrontendSettings& s) {
  if (!model.ok) return "the essential matrix could not be estimated";
  if (rotation_explains_more) return "the rotation-only model explains more matches than the essential matrix";
  if (parallax_rad < s.min_parallax_px * pixel_rad)
    return "median parallax " + Fixed(parallax_rad * kDeg) + " deg < min_parallax_px (" +
           Fixed(s.min_parallax_px * pixel_rad * kDeg) + " deg)";
  if (parallax_rad < s.parallax_noise_ratio * epipolar_rad)
    return "median parallax " + Fixed(parallax_rad * kDeg) + " deg < " + Fixed(s.parallax_noise_ratio, 1) +
           " x median epipolar error " + Fixed(epipolar_rad * kDeg) + " deg";
  if (model.refinement.covariance_ok) {
    const double std_deg = MaxStdDeg(model.refinement.covariance.block<3, 3>(3, 3));
    if (std_deg > s.max_translation_std_deg)
      return "translation direction std " + Fixed(std_deg, 2) + " deg > max_translation_std_deg";
  }
  return {};
}

// Why matching failed: fewer matches than min_inliers.
std::string TooFewMatchesReason(const RelativePoseResult& r, int min_inliers) {
  return "too few matches: " + std::to_string(r.matches) + " < min_inliers " + std::to_string(min_inliers) +
         " (features " + std::to_string(r.features_i) + ", " + std::to_string(r.features_j) + ")";
}

// Why no model is supported: the larger inlier count (refined essential model, rotation-only RANSAC) is
// below min_inliers.
std::string TooFewInliersReason(const EssentialModel& model, const camera_frontend::RansacResult& rot, int min_inliers,
                                int matches) {
  return "too few inliers: " + std::to_string(std::max(model.inliers.size(), rot.inliers.size())) + " < min_inliers " +
         std::to_string(min_inliers) + " (" + std::to_string(matches) + " matches)";
}

// The bearings of the matched keypoints, f_i[k] and f_j[k] for matches[k].
void MatchedBearings(const std::vector<cv::DMatch>& matches, const ImageFeatures& fi, const ImageFeatures& fj,
                     Bearings* f_i, Bearings* f_j) {
  for (const auto& m : matches) {
    f_i->push_back(fi.bearings[m.queryIdx]);
    f_j->push_back(fj.bearings[m.trainIdx]);
  }
}

// The essential and the rotation-only RANSAC models.
struct RansacModels {
  camera_frontend::RansacResult essential, rotation_only;
};

// 5-point RANSAC and rotation-only RANSAC on the bearings; their time, inliers and iterations go into r.
RansacModels RunRansac(const Bearings& f_i, const Bearings& f_j, const CameraFrontendSettings& s, double threshold,
                       RelativePoseResult* r) {
  const auto t0 = Clock::now();
  RansacModels m;
  m.essential = camera_frontend::FivePointRansac(f_i, f_j, s.ransac, threshold);
  m.rotation_only = camera_frontend::RotationOnlyRansac(f_i, f_j, s.ransac, threshold);
  r->seconds_ransac = SecondsSince(t0);
  r->ransac_inliers = static_cast<int>(m.essential.inliers.size());
  r->ransac_iterations = m.essential.iterations;
  r->rotation_only_inliers = static_cast<int>(m.rotation_only.inliers.size());
  return m;
}

// Median |angle to the epipolar plane| (radians) over the inliers of a refined essential model.
double MedianEpipolarError(const EssentialModel& model, const Bearings& f_i, const Bearings& f_j) {
  std::vector<double> errors;
  for (int k : model.inliers)
    errors.push_back(std::abs(camera_frontend::EpipolarAngle(model.R, model.t, f_i[k], f_j[k])));
  return camera_frontend::Median(errors);
}

// Reliable translation: the motion, covariance and refinement figures of the refined essential model.
void UseEssentialModel(const EssentialModel& model, RelativePoseResult* r) {
  r->R = model.R;
  r->t_unit = model.t;
  r->covariance = model.refinement.covariance;
  r->covariance_valid = model.refinement.covariance_ok;
  r->refinement_iterations = model.refinement.iterations;
  r->refinement_converged = model.refinement.converged;
}

// Near-pure rotation: the essential rotation where it agrees with the rotation-only fit, else the fit's;
// the translation flagged unreliable, its covariance block uninformative.
void UseRotationOnly(const EssentialModel& model, const camera_frontend::RotationOnlyFit& rotation_fit,
                     const std::string& unreliable, RelativePoseResult* r) {
  r->translation_unreliable = true;
  r->failure_reason = {Code::kTranslationUnreliable, "translation unreliable (near-pure rotation): " + unreliable};
  // The refined essential rotation stays unbiased when a little translation is left, where the
  // rotation-only fit absorbs the parallax; it is kept unless it is not the rotation-only one (under pure
  // rotation the chirality test of RANSAC is blind and may pick the twisted pair, 180 degrees away).
  const bool essential_rotation_ok =
      model.ok && RotationErrorDeg(model.R, rotation_fit.R) < kMaxRotationDisagreementDeg;
  r->R = essential_rotation_ok ? model.R : rotation_fit.R;
  r->t_unit = model.ok ? model.t : Eigen::Vector3d::Zero();
  r->covariance = Matrix6::Identity();  // uninformative translation block, no cross terms
  if (essential_rotation_ok && model.refinement.covariance_ok) {
    r->covariance.block<3, 3>(0, 0) = model.refinement.covariance.block<3, 3>(0, 0);
    r->covariance_valid = true;
  } else {
    r->covariance.block<3, 3>(0, 0) = rotation_fit.covariance;
    r->covariance_valid = rotation_fit.covariance_ok;
  }
  r->refinement_converged = rotation_fit.ok;
}

// The inlier count and the keypoint pixels of the inlier matches `used` (indices into matches).
void SetInliers(const std::vector<int>& used, const std::vector<cv::DMatch>& matches, const ImageFeatures& fi,
                const ImageFeatures& fj, RelativePoseResult* r) {
  r->inliers = static_cast<int>(used.size());
  for (int k : used) {
    r->inlier_pixels_i.push_back(fi.keypoints[matches[k].queryIdx].pt);
    r->inlier_pixels_j.push_back(fj.keypoints[matches[k].trainIdx].pt);
  }
}

RelativePoseResult Estimate(const ImageFeatures& fi, const ImageFeatures& fj, const CameraModel& camera,
                            const CameraFrontendSettings& s) {
  RelativePoseResult r;
  r.features_i = static_cast<int>(fi.keypoints.size());
  r.features_j = static_cast<int>(fj.keypoints.size());
  auto fail = [&](Code code, std::string text) {
    r.valid = false;
    r.too_few_inliers = code == Code::kTooFewMatches || code == Code::kTooFewInliers;
    r.failure_reason = {code, std::move(text)};
    return r;
  };
  if (std::string e = s.Validate(); !e.empty()) return fail(Code::kInvalidSettings, "invalid settings: " + e);
  if (Failure<Code> e = CheckFeatures(fi, fj, camera); e.code != Code::kNone) return fail(e.code, e.text);

  // Matching (paper III-A-1).
  auto t0 = Clock::now();
  const std::vector<cv::DMatch> matches = camera_frontend::MatchDescriptors(fi.descriptors, fj.descriptors, s.matching);
  r.seconds_matching = SecondsSince(t0);
  r.matches = static_cast<int>(matches.size());
  if (r.matches < s.min_inliers) return fail(Code::kTooFewMatches, TooFewMatchesReason(r, s.min_inliers));
  Bearings f_i, f_j;
  MatchedBearings(matches, fi, fj, &f_i, &f_j);

  // 5-point RANSAC, and the rotation-only model, on bearing vectors (paper III-A-1).
  const double pixel = camera_frontend::PixelAngleRad(camera);
  const double threshold = s.ransac.threshold_px * pixel;
  const double loss = s.refinement.loss_scale_px * pixel;
  const auto [ess, rot] = RunRansac(f_i, f_j, s, threshold, &r);

  // Refinement of the angular error with respect to the epipolar plane (paper III-A-1).
  t0 = Clock::now();
  EssentialModel model;
  if (ess.ok && r.ransac_inliers >= s.min_inliers) model = RefineEssential(f_i, f_j, ess, s, threshold, loss);

  // Rotation-only fit on the inliers of the better model: the parallax, and the rotation under pure rotation.
  const bool rotation_explains_more = rot.ok && rot.inliers.size() > model.inliers.size();
  const std::vector<int>& support = (model.ok && !rotation_explains_more) ? model.inliers : rot.inliers;
  if (static_cast<int>(support.size()) < s.min_inliers) {
    r.seconds_refinement = SecondsSince(t0);
    return fail(Code::kTooFewInliers, TooFewInliersReason(model, rot, s.min_inliers, r.matches));
  }
  const auto rotation_fit = camera_frontend::FitRotationOnly(f_i, f_j, support, loss, s.refinement.max_iterations,
                                                             s.refinement.compute_covariance);
  r.seconds_refinement = SecondsSince(t0);
  r.median_parallax_deg = rotation_fit.median_residual_rad * kDeg;
  const double epipolar = model.ok ? MedianEpipolarError(model, f_i, f_j) : 0.0;
  if (model.ok) r.median_epipolar_error_deg = epipolar * kDeg;
  const std::string unreliable =
      TranslationUnreliableReason(model, rotation_explains_more, rotation_fit.median_residual_rad, epipolar, pixel, s);

  r.valid = true;
  r.failure_reason = {};
  if (unreliable.empty()) {
    UseEssentialModel(model, &r);
    SetInliers(model.inliers, matches, fi, fj, &r);
  } else {
    UseRotationOnly(model, rotation_fit, unreliable, &r);
    SetInliers(support, matches, fi, fj, &r);
  }
  return r;
}

}  // namespace

RelativePoseResult EstimateRelativePose(const ImageFeatures& features_i, const ImageFeatures& features_j,
                                        const CameraModel& camera, const CameraFrontendSettings& settings) {
  const auto start = Clock::now();
  RelativePoseResult r;
  try {
    r = Estimate(features_i, features_j, camera, settings);
  } catch (const std::exception& e) {
    r = RelativePoseResult();
    r.failure_reason = {Code::kInternalError, std::string("internal error: ") + e.what()};
  } catch (...) {
    r = RelativePoseResult();
    r.failure_reason = {Code::kInternalError, "internal error: unknown exception"};
  }
  r.seconds = SecondsSince(start);
  return r;
}

RelativePoseResult EstimateRelativePose(const cv::Mat& image_i, const cv::Mat& image_j, const CameraModel& camera,
                                        const CameraFrontendSettings& settings) {
  const auto start = Clock::now();
  RelativePoseResult r;
  if (std::string e = settings.Validate(); !e.empty()) {
    r.failure_reason = {Code::kInvalidSettings, "invalid settings: " + e};
    r.seconds = SecondsSince(start);
    return r;
  }
  const ImageFeatures fi = ExtractImageFeatures(image_i, camera, settings.features);
  const ImageFeatures fj = ExtractImageFeatures(image_j, camera, settings.features);
  r = EstimateRelativePose(fi, fj, camera, settings);
  r.seconds_features = fi.seconds + fj.seconds;
  r.seconds = SecondsSince(start);
  return r;
}

}  // namespace fusecal
