#include "stages/camera_frontend/five_point_ransac.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <opengv/relative_pose/CentralRelativeAdapter.hpp>
#include <opengv/relative_pose/methods.hpp>
#include <opengv/sac/Ransac.hpp>
#include <opengv/sac_problems/relative_pose/RotationOnlySacProblem.hpp>
#include <random>

#include "stages/camera_frontend/chirality.hpp"

namespace fusecal::camera_frontend {

namespace {

opengv::bearingVectors_t ToOpengv(const Bearings& f) {
  opengv::bearingVectors_t out;
  out.reserve(f.size());
  for (const auto& b : f) out.push_back(b);
  return out;
}

// Essential matrices E = [t]x R with f_i^T E f_j = 0 (OpenGV's convention with viewpoint 1 = image i).
std::vector<Eigen::Matrix3d> SolveEssentials(const opengv::relative_pose::CentralRelativeAdapter& adapter,
                                             const std::vector<int>& sample, const std::string& algorithm) {
  std::vector<Eigen::Matrix3d> out;
  if (algorithm == "nister") {
    for (const auto& E : opengv::relative_pose::fivept_nister(adapter, sample)) out.push_back(E);
  } else {
    // Stewenius returns all ten (complex) solutions; only the real ones are motions.
    for (const auto& E : opengv::relative_pose::fivept_stewenius(adapter, sample))
      if (E.imag().norm() <= 1e-9 * E.real().norm()) out.push_back(E.real());
  }
  return out;
}

// The motion of each essential matrix: E = U diag(1, 1, 0) V^T = [t]x R gives t = +-u3 and
// R = U W V^T or U W^T V^T (Hartley and Zisserman, section 9.6.2); of the four, the one that puts most of
// the sample in front of both cameras (chirality.hpp). Points behind a camera are penalised by the scoring.
std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> MotionsFromEssentials(
    const std::vector<Eigen::Matrix3d>& essentials, const Bearings& f_i, const Bearings& f_j,
    const std::vector<int>& sample) {
  Eigen::Matrix3d W;
  W << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> motions;
  for (const Eigen::Matrix3d& E : essentials) {
    if (!E.allFinite() || E.norm() < 1e-12) continue;
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d U = svd.matrixU(), V = svd.matrixV();
    if (U.determinant() < 0) U = -U;
    if (V.determinant() < 0) V = -V;
    Eigen::Matrix3d R = U * W * V.transpose();
    Eigen::Vector3d t = U.col(2);
    ResolveChirality(f_i, f_j, sample, &R, &t);
    motions.emplace_back(R, t);
  }
  return motions;
}

// Chirality part of IsEpipolarInlier: not behind a camera, unless the parallax is at noise level.
inline bool InFrontOrDistant(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& f_i,
                             const Eigen::Vector3d& f_j, double threshold_rad) {
  double l_i = 0, l_j = 0;
  if (!TriangulateDepths(R, t, f_i, f_j, &l_i, &l_j) || (l_i > 0 && l_j > 0)) return true;
  return RotationOnlyAngle(R, f_i, f_j) <= 2.0 * threshold_rad;  // behind: acceptable for distant points only
}

// MSAC cost of one correspondence: sin^2 e for an inlier (IsEpipolarInlier: |e| <= threshold is
// |sin e| <= sin threshold), sin^2 threshold otherwise; e is the angle to the epipolar plane. Written
// without asin and sqrt: this is the inner loop of the RANSAC.
inline double MsacCost(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& f_i,
                       const Eigen::Vector3d& f_j, double threshold_rad, double sin2_threshold, bool* inlier) {
  const Eigen::Vector3d n = t.cross(R * f_j);
  const double n2 = n.squaredNorm();
  const double d = f_i.dot(n);
  const double sin2 = n2 < 1e-24 ? 0.0 : d * d / n2;  // undefined plane: no error (as EpipolarAngle)
  *inlier = sin2 <= sin2_threshold && InFrontOrDistant(R, t, f_i, f_j, threshold_rad);
  return *inlier ? sin2 : sin2_threshold;
}

// Iterations needed to draw an all-inlier sample of `sample_size` with `probability`.
int RequiredIterations(double inlier_ratio, int sample_size, double probability, int max_iterations) {
  const double all_inliers = std::pow(std::clamp(inlier_ratio, 1e-9, 1.0), sample_size);
  if (all_inliers >= 1.0 - 1e-12) return 1;
  const double n = std::log(1.0 - probability) / std::log(1.0 - all_inliers);
  return static_cast<int>(std::min<double>(max_iterations, std::ceil(n)));
}

}  // namespace

bool IsEpipolarInlier(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& f_i,
                      const Eigen::Vector3d& f_j, double threshold_rad) {
  return std::abs(EpipolarAngle(R, t, f_i, f_j)) <= threshold_rad && InFrontOrDistant(R, t, f_i, f_j, threshold_rad);
}

std::vector<int> EpipolarInliers(const Bearings& f_i, const Bearings& f_j, const Eigen::Matrix3d& R,
                                 const Eigen::Vector3d& t, double threshold_rad) {
  std::vector<int> inliers;
  for (int k = 0; k < static_cast<int>(f_i.size()); ++k)
    if (IsEpipolarInlier(R, t, f_i[k], f_j[k], threshold_rad)) inliers.push_back(k);
  return inliers;
}

std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> FivePointMotions(const Bearings& f_i, const Bearings& f_j,
                                                                          const std::vector<int>& sample,
                                                                          const std::string& algorithm) {
  const opengv::bearingVectors_t b_i = ToOpengv(f_i), b_j = ToOpengv(f_j);
  const opengv::relative_pose::CentralRelativeAdapter adapter(b_i, b_j);
  return MotionsFromEssentials(SolveEssentials(adapter, sample, algorithm), f_i, f_j, sample);
}

RansacResult FivePointRansac(const Bearings& f_i, const Bearings& f_j, const RansacSettings& settings,
                             double threshold_rad) {
  RansacResult out;
  const int n = static_cast<int>(f_i.size());
  if (static_cast<int>(f_j.size()) != n || n < 8) return out;
  const opengv::bearingVectors_t b_i = ToOpengv(f_i), b_j = ToOpengv(f_j);
  const opengv::relative_pose::CentralRelativeAdapter adapter(b_i, b_j);
  const double sin2_threshold = std::pow(std::sin(threshold_rad), 2);
  std::mt19937 rng(20180312u);
  std::uniform_int_distribution<int> pick(0, n - 1);
  double best_cost = std::numeric_limits<double>::infinity();
  int best_inliers = 0;
  int needed = settings.max_iterations;
  std::vector<int> sample(5);
  for (int iteration = 0; iteration < needed; ++iteration) {
    out.iterations = iteration + 1;
    for (int s = 0; s < 5; ++s) {  // five distinct correspondences
      int k = pick(rng);
      while (std::find(sample.begin(), sample.begin() + s, k) != sample.begin() + s) k = pick(rng);
      sample[s] = k;
    }
    for (const auto& [R, t] :
         MotionsFromEssentials(SolveEssentials(adapter, sample, settings.algorithm), f_i, f_j, sample)) {
      // Score, giving up as soon as the hypothesis cannot beat the best one.
      double cost = 0;
      int inliers = 0;
      for (int k = 0; k < n && cost < best_cost; ++k) {
        bool inlier = false;
        cost += MsacCost(R, t, f_i[k], f_j[k], threshold_rad, sin2_threshold, &inlier);
        inliers += inlier ? 1 : 0;
      }
      if (cost < best_cost) {
        best_cost = cost;
        best_inliers = inliers;
        out.R = R;
        out.t = t;
        needed = std::min(needed, RequiredIterations(static_cast<double>(best_inliers) / n, 5, settings.probability,
                                                     settings.max_iterations));
      }
    }
  }
  if (!std::isfinite(best_cost)) return out;
  out.t.normalize();
  out.inliers = EpipolarInliers(f_i, f_j, out.R, out.t, threshold_rad);
  out.ok = true;
  return out;
}

RansacResult RotationOnlyRansac(const Bearings& f_i, const Bearings& f_j, const RansacSettings& settings,
                                double threshold_rad) {
  using Problem = opengv::sac_problems::relative_pose::RotationOnlySacProblem;
  RansacResult out;
  if (f_i.size() != f_j.size() || f_i.size() < 3) return out;
  const opengv::bearingVectors_t b_i = ToOpengv(f_i), b_j = ToOpengv(f_j);
  opengv::relative_pose::CentralRelativeAdapter adapter(b_i, b_j);
  opengv::sac::Ransac<Problem> ransac;
  ransac.sac_model_ = std::make_shared<Problem>(adapter, /*randomSeed=*/false);
  ransac.threshold_ = 1.0 - std::cos(std::sqrt(2.0) * threshold_rad);  // score 1 - f_i . (R f_j)
  ransac.max_iterations_ = settings.max_iterations;
  ransac.probability_ = settings.probability;
  if (!ransac.computeModel(0)) return out;
  out.R = ransac.model_coefficients_;
  if (!out.R.allFinite()) return out;
  out.inliers = ransac.inliers_;
  out.iterations = ransac.iterations_;
  out.ok = true;
  return out;
}

}  // namespace fusecal::camera_frontend
