#include "stages/lidar_icp/registration.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <sstream>
#include <tuple>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "stages/lidar_icp/consistency.hpp"
#include "stages/lidar_icp/covariance.hpp"
#include "stages/lidar_icp/distance_field.hpp"
#include "stages/lidar_icp/global_alignment.hpp"
#include "stages/lidar_icp/icp.hpp"
#include "stages/lidar_icp/preprocess.hpp"

namespace fusecal::lidar_icp {
namespace {

using Outcome = Failure<RegistrationFailure>;
using Code = RegistrationFailure;

constexpr double kDeg = M_PI / 180.0;
constexpr size_t kCoarseSourcePoints = 2500;    // source points of the candidates' coarse ICP
constexpr size_t kMaxAutoTargetPoints = 50000;  // the automatic voxel grows until the target is this small
constexpr size_t kCoarseLevels = 2;             // thresholds run on the coarse clouds for every candidate

int ThreadCount(int requested) {
#ifdef _OPENMP
  return requested > 0 ? requested : omp_get_max_threads();
#else
  (void)requested;
  return 1;
#endif
}

std::string Format(double v, int precision = 3) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

// Scale-dependent sizes: a room of a few metres and a street of tens of metres need different voxels and
// thresholds; the median range of the target sets the scale unless the settings fix them.
struct Scales {
  double fine_voxel, coarse_voxel, first_threshold, last_threshold;
};

Scales ChooseScales(const RegistrationSettings& s, double fine_voxel) {
  Scales k;
  k.fine_voxel = fine_voxel;
  k.coarse_voxel = 3.0 * fine_voxel;
  k.last_threshold = s.min_correspondence_m > 0 ? s.min_correspondence_m : std::max(1.2 * fine_voxel, 0.1);
  k.first_threshold = s.max_correspondence_m > 0 ? s.max_correspondence_m : 4.0 * k.coarse_voxel;
  k.first_threshold = std::max(k.first_threshold, k.last_threshold);
  return k;
}

// Both scans, preprocessed once for every stage.
struct Clouds {
  Scales scales;
  PreparedCloud target_fine, target_coarse;                 // scan i
  std::vector<Eigen::Vector3f> source_fine, source_coarse;  // scan j
  std::unique_ptr<FreeSpaceImage> free_space;               // of scan i
  double free_space_margin_m = 0.3;
};

// 1. Preprocessing: NaN removal and range crop, voxel grids, target normals. Returns the failure, if any.
Outcome Prepare(const PointCloud& scan_i, const PointCloud& scan_j, const RegistrationSettings& settings, int threads,
                Clouds* c) {
  const std::vector<Eigen::Vector3f> valid_i = ValidPoints(scan_i, settings.min_range_m, settings.max_range_m);
  const std::vector<Eigen::Vector3f> valid_j = ValidPoints(scan_j, settings.min_range_m, settings.max_range_m);
  for (auto [name, valid, total] : {std::tuple("i", &valid_i, scan_i.size()), std::tuple("j", &valid_j, scan_j.size())})
    if (static_cast<int>(valid->size()) < settings.min_points)
      return {Code::kTooFewPoints, "scan " + std::string(name) + " has " + std::to_string(valid->size()) +
                                       " valid points of " + std::to_string(total) + " (finite, range in [" +
                                       Format(settings.min_range_m) + ", " + Format(settings.max_range_m) +
                                       "] m), fewer than min_points " + std::to_string(settings.min_points)};

  const bool automatic = settings.voxel_size_m <= 0;
  c->scales =
      ChooseScales(settings, automatic ? std::clamp(0.012 * MedianRange(valid_i), 0.05, 0.25) : settings.voxel_size_m);
  c->target_fine.points = NeighbourhoodVoxelCentroids(valid_i, c->scales.fine_voxel);
  if (automatic && c->target_fine.points.size() > kMaxAutoTargetPoints) {
    // Dense scans of small scenes: a coarser voxel keeps the target (normals, tree) bounded.
    const double grow = std::sqrt(double(c->target_fine.points.size()) / double(kMaxAutoTargetPoints));
    c->scales = ChooseScales(settings, c->scales.fine_voxel * grow);
    c->target_fine.points = NeighbourhoodVoxelCentroids(valid_i, c->scales.fine_voxel);
  }
  // The coarse grids are built from the fine ones (fewer points to sort).
  c->target_coarse.points = VoxelDownsample(c->target_fine.points, c->scales.coarse_voxel);
  const std::vector<Eigen::Vector3f> source_voxels = NeighbourhoodVoxelCentroids(valid_j, c->scales.fine_voxel);
  c->source_fine = Subsample(source_voxels, settings.max_source_points);
  c->source_coarse = Subsample(VoxelDownsample(source_voxels, c->scales.coarse_voxel), kCoarseSourcePoints);
  if (static_cast<int>(std::min(c->source_fine.size(), c->target_fine.points.size())) < settings.min_points)
    return {Code::kTooFewPoints, "after voxel downsampling (" + Format(c->scales.fine_voxel) + " m) scan i has " +
                                     std::to_string(c->target_fine.points.size()) + " and scan j " +
                                     std::to_string(c->source_fine.size()) + " points, fewer than min_points " +
                                     std::to_string(settings.min_points)};
  c->target_fine.BuildTarget(settings.normal_neighbors, threads);
  c->target_coarse.BuildTarget(std::min(settings.normal_neighbors, 10), threads);
  c->free_space = std::make_unique<FreeSpaceImage>(valid_i);
  c->free_space_margin_m = std::max(2.0 * c->scales.last_threshold, 0.3);
  return {};
}

// 2. Global alignment: candidate poses with no guess (a guess, when given, is one more seed).
std::vector<PoseCandidate> Candidates(const Clouds& c, const Isometry3* guess, const RegistrationSettings& settings,
                                      int threads) {
  if (!settings.global_alignment) return {{guess ? *guess : Isometry3::Identity(), 0.0}};
  const auto voxel = static_cast<float>(c.scales.coarse_voxel);
  const DistanceField field(c.target_coarse.points, voxel, 4.0f * voxel);
  const DistanceField sharp(c.target_coarse.points, voxel, 2.0f * voxel);
  GlobalSearchOptions options;
  options.max_tilt_rad = settings.max_tilt_deg * kDeg;
  options.rotation_step_rad = settings.rotation_step_deg * kDeg;
  options.candidates = settings.global_candidates;
  options.threads = threads;
  std::vector<Isometry3> seeds;
  if (guess) seeds.push_back(*guess);
  return GlobalCandidates(field, sharp, Subsample(c.source_coarse, settings.global_sample_points), options, seeds);
}

// 3a. Coarse ICP from every candidate over the first (largest) thresholds; the best one wins: inlier ratio
// minus 4 x free-space violation. Violations weigh more because at a coarse threshold a wrong pose in a
// small room can have more inliers than the right one (surfaces are near everywhere), but it puts points
// where scan i saw through.
Isometry3 SelectCandidate(const Clouds& c, const std::vector<PoseCandidate>& candidates,
                          const std::vector<double>& schedule, const IcpOptions& icp,
                          const RegistrationSettings& settings, RegistrationResult* result) {
  IcpOptions coarse = icp;  // candidates only need to reach the basin of the fine levels
  coarse.convergence_rotation_rad *= 10.0;
  coarse.convergence_translation_m *= 10.0;
  coarse.max_iterations = std::min(coarse.max_iterations, 10);
  const size_t levels = std::min(kCoarseLevels, schedule.size());
  double best_score = -1e9;
  Isometry3 best = candidates.front().T_target_source;
  for (const PoseCandidate& candidate : candidates) {
    Isometry3 T = candidate.T_target_source;
    for (size_t level = 0; level < levels; ++level)
      result->iterations += IcpLevel(c.target_coarse, c.source_coarse, schedule[level], coarse, &T).iterations;
    const double score =
        Fitness(c.target_coarse, c.source_coarse, T, schedule[levels - 1], icp.threads) -
        4.0 * c.free_space->ViolationRatio(c.source_coarse, T, settings.min_range_m, c.free_space_margin_m);
    if (score > best_score) {
      best_score = score;
      best = T;
      result->global_score = candidate.score;
    }
  }
  return best;
}

// 3b. The fine levels go on from the last coarse threshold (repeated when it is the last one); only the
// last level must settle to the full tolerance. Returns the last level's outcome.
LevelResult RefineFine(const Clouds& c, const std::vector<double>& schedule, const IcpOptions& fine, Isometry3* T,
                       RegistrationResult* result) {
  LevelResult last;
  for (size_t level = std::min(kCoarseLevels, schedule.size() - 1); level < schedule.size(); ++level) {
    IcpOptions options = fine;
    if (level + 1 == schedule.size()) {
      options.max_iterations *= 3;
    } else {
      options.convergence_rotation_rad *= 10.0;
      options.convergence_translation_m *= 10.0;
    }
    last = IcpLevel(c.target_fine, c.source_fine, schedule[level], options, T);
    result->iterations += last.iterations;
  }
  return last;
}

// 4. Statistics at the last threshold, covariance, acceptance. Returns the failure, if any.
Outcome Evaluate(const Clouds& c, const IcpOptions& fine, double last, const LevelResult& last_level,
                 const RegistrationSettings& settings, RegistrationResult* r) {
  const Linearization lin = Linearize(c.target_fine, c.source_fine, r->T_li_lj, last, fine);
  r->inliers = lin.inliers;
  r->fitness = Fitness(c.target_fine, c.source_fine, r->T_li_lj, last, fine.threads);
  r->inlier_rms_m = lin.inliers ? std::sqrt(lin.sq_sum / double(lin.inliers)) : 0.0;
  r->free_space_violation =
      c.free_space->ViolationRatio(c.source_fine, r->T_li_lj, settings.min_range_m, c.free_space_margin_m);
  if (static_cast<int>(lin.inliers) < settings.min_points)
    return {Code::kTooFewInliers, "only " + std::to_string(lin.inliers) +
                                      " source points have a planar target point within " + Format(last) +
                                      " m, fewer than min_points " + std::to_string(settings.min_points)};
  if (r->fitness < settings.min_fitness)
    return {Code::kLowFitness, "inlier ratio " + Format(r->fitness) + " at " + Format(last) +
                                   " m is below min_fitness " + Format(settings.min_fitness) +
                                   ": the scans do not overlap enough or are unrelated"};
  if (r->free_space_violation > settings.max_free_space_violation)
    return {Code::kFreeSpaceViolation,
            Format(100.0 * r->free_space_violation) + " % of scan j's points lie in space scan i observed as empty " +
                "(limit " + Format(100.0 * settings.max_free_space_violation) +
                " %): the alignment is inconsistent, the scans are unrelated or the global alignment failed"};
  double sum_sq_range = 0.0;
  for (const Eigen::Vector3f& p : c.source_fine) sum_sq_range += p.squaredNorm();
  r->conditioning = Conditioning(lin, std::sqrt(sum_sq_range / double(c.source_fine.size())));
  if (r->conditioning < settings.min_conditioning)
    return {Code::kDegenerate, "degenerate geometry: Hessian conditioning " + Format(r->conditioning) + " below " +
                                   Format(settings.min_conditioning) +
                                   ", a direction of the motion is unconstrained (a single plane, a corridor)"};
  if (!CovarianceFromHessian(lin, &r->covariance))
    return {Code::kDegenerate,
            "degenerate geometry: the point-to-plane Hessian is singular, not all 6 DoF are constrained"};
  double rotation_std, translation_std;
  CovarianceExtent(r->covariance, &rotation_std, &translation_std);
  if (rotation_std > 0.5 * kDeg || translation_std > 0.1)
    return {Code::kDegenerate, "degenerate geometry: standard deviation up to " + Format(rotation_std / kDeg) +
                                   " deg and " + Format(translation_std) + " m (e.g. a corridor or a single plane)"};
  if (!last_level.converged)
    return {Code::kNotConverged, "ICP did not converge at the last threshold (" + Format(last) + " m) within " +
                                     std::to_string(last_level.iterations) + " iterations"};
  return {};
}

// Records the outcome of a registration: usable when `outcome` is kNone.
void Conclude(Outcome outcome, RegistrationResult* result) { result->failure_reason = std::move(outcome); }

RegistrationResult RegisterImpl(const PointCloud& scan_i, const PointCloud& scan_j, const Isometry3* guess,
                                const RegistrationSettings& settings) {
  RegistrationResult result;
  auto fail = [&result](Outcome outcome) {
    Conclude(std::move(outcome), &result);
    return result;
  };
  if (const std::string problem = settings.Validate(); !problem.empty())
    return fail({Code::kInvalidSettings, "invalid settings: " + problem});
  if (guess && !IsValidTransform(*guess, 1e-3))
    return fail({Code::kInvalidGuess, "the initial guess is not a valid transform"});
  const int threads = ThreadCount(settings.num_threads);

  Clouds clouds;
  if (Outcome problem = Prepare(scan_i, scan_j, settings, threads, &clouds); problem.code != Code::kNone)
    return fail(std::move(problem));
  result.voxel_size_m = clouds.scales.fine_voxel;
  result.source_points = clouds.source_fine.size();
  result.target_points = clouds.target_fine.points.size();

  const std::vector<PoseCandidate> candidates = Candidates(clouds, guess, settings, threads);
  if (candidates.empty()) return fail({Code::kNoCandidate, "global alignment found no candidate pose"});

  // Paper III-A-1: the correspondence threshold starts large and shrinks level by level, rejecting the
  // correspondences beyond it as outliers.
  IcpOptions icp;
  icp.convergence_rotation_rad = settings.convergence_rotation_rad;
  icp.convergence_translation_m = settings.convergence_translation_m;
  icp.max_iterations = settings.max_iterations_per_level;
  icp.threads = threads;
  const std::vector<double> schedule =
      ThresholdSchedule(clouds.scales.first_threshold, clouds.scales.last_threshold, settings.threshold_shrink);
  Isometry3 T = SelectCandidate(clouds, candidates, schedule, icp, settings, &result);
  IcpOptions fine = icp;
  fine.tangential_limit_m = 2.0 * clouds.scales.fine_voxel;
  const LevelResult last_level = RefineFine(clouds, schedule, fine, &T, &result);
  result.T_li_lj = T;
  Conclude(Evaluate(clouds, fine, schedule.back(), last_level, settings, &result), &result);
  return result;
}

template <typename F>
RegistrationResult Timed(F&& run) {
  const auto start = std::chrono::steady_clock::now();
  RegistrationResult result;
  try {
    result = run();
  } catch (const std::exception& e) {
    result = RegistrationResult();
    Conclude({Code::kInternalError, std::string("internal error: ") + e.what()}, &result);
  } catch (...) {
    result = RegistrationResult();
    Conclude({Code::kInternalError, "internal error: unknown exception"}, &result);
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace

RegistrationResult Register(const PointCloud& scan_i, const PointCloud& scan_j, const RegistrationSettings& settings) {
  return Timed([&] { return RegisterImpl(scan_i, scan_j, nullptr, settings); });
}

RegistrationResult RegisterWithGuess(const PointCloud& scan_i, const PointCloud& scan_j, const Isometry3& guess_T_li_lj,
                                     const RegistrationSettings& settings) {
  return Timed([&] { return RegisterImpl(scan_i, scan_j, &guess_T_li_lj, settings); });
}

}  // namespace fusecal::lidar_icp
