#include "stages/handeye/refinement.hpp"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <cmath>
#include <memory>

namespace fusecal::handeye {
namespace {

template <typename T>
using Mat3 = Eigen::Matrix<T, 3, 3>;
template <typename T>
using Vec3 = Eigen::Matrix<T, 3, 1>;

// R = R0 Exp(d).
template <typename T>
Mat3<T> PerturbedRotation(const Eigen::Matrix3d& R0, const T* d) {
  Mat3<T> dR;
  ceres::AngleAxisToRotationMatrix(d, dR.data());  // column-major, as Eigen
  return R0.cast<T>() * dR;
}

// Log(R_b^T R^T R_a R): zero when R_a R = R R_b.
template <typename T>
Vec3<T> RotationError(const MotionPair& p, const Mat3<T>& R) {
  const Mat3<T> M = p.B.linear().transpose().cast<T>() * R.transpose() * p.A.linear().cast<T>() * R;
  Vec3<T> r;
  ceres::RotationMatrixToAngleAxis(M.data(), r.data());
  return r;
}

struct RotationCost {
  RotationCost(const MotionPair& p, const Eigen::Matrix3d& R0, const Eigen::Matrix3d& W) : p(p), R0(R0), W(W) {}
  template <typename T>
  bool operator()(const T* d, T* residual) const {
    Eigen::Map<Vec3<T>> out(residual);
    out = W.cast<T>() * RotationError(p, PerturbedRotation(R0, d));
    return true;
  }
  MotionPair p;
  Eigen::Matrix3d R0, W;
};

struct PoseCost {
  PoseCost(const MotionPair& p, const Eigen::Matrix3d& R0, const Matrix6& W) : p(p), R0(R0), W(W) {}
  template <typename T>
  bool operator()(const T* d, const T* t, T* residual) const {
    const Mat3<T> R = PerturbedRotation(R0, d);
    const Vec3<T> tv(t[0], t[1], t[2]);
    Eigen::Matrix<T, 6, 1> r;
    r.template head<3>() = RotationError(p, R);
    r.template tail<3>() = (p.A.linear().cast<T>() - Mat3<T>::Identity()) * tv + p.A.translation().cast<T>() -
                           R * p.B.translation().cast<T>();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> out(residual);
    out = W.cast<T>() * r;
    return true;
  }
  MotionPair p;
  Eigen::Matrix3d R0;
  Matrix6 W;
};

ceres::LossFunction* MakeLoss(const HandEyeSettings& s, bool robust) {
  if (!robust) return nullptr;
  switch (s.robust_loss) {
    case RobustLoss::kHuber:
      return new ceres::HuberLoss(s.robust_loss_scale);
    case RobustLoss::kCauchy:
      return new ceres::CauchyLoss(s.robust_loss_scale);
    case RobustLoss::kNone:
      break;
  }
  return nullptr;
}

ceres::Solver::Options SolverOptions(const HandEyeSettings& s) {
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::DENSE_QR;
  o.max_num_iterations = s.max_iterations;
  o.function_tolerance = s.function_tolerance;
  o.parameter_tolerance = s.parameter_tolerance;
  o.gradient_tolerance = s.gradient_tolerance;
  o.logging_type = ceres::SILENT;
  o.minimizer_progress_to_stdout = false;
  o.num_threads = 1;
  return o;
}

void FillOutput(const ceres::Solver::Summary& summary, RefineOutput* out) {
  out->usable = summary.IsSolutionUsable();
  out->converged = out->usable && summary.termination_type == ceres::CONVERGENCE;
  // Ceres declares a step invalid when the model predicts no decrease, and gives up after a few: that
  // happens at a stationary point (round-off level gradient, or a null direction in a degenerate set). The
  // parameters are the best found, so this counts as converged.
  if (summary.termination_type == ceres::FAILURE && std::isfinite(summary.final_cost) &&
      summary.final_cost <= summary.initial_cost && summary.message.find("invalid steps") != std::string::npos) {
    out->usable = out->converged = true;
  }
  out->iterations = static_cast<int>(summary.iterations.size());
  out->final_cost = summary.final_cost;
  out->message = summary.message;
}

void AddRotationBlocks(ceres::Problem* problem, const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R0,
                       const NoiseModel& noise, ceres::LossFunction* loss, double* d) {
  for (const auto& p : pairs) {
    const Eigen::Matrix3d C = ResidualCovariance(p, R0, Eigen::Vector3d::Zero(), noise).topLeftCorner<3, 3>();
    const Eigen::Matrix3d W = WhiteningMatrix(C);
    problem->AddResidualBlock(new ceres::AutoDiffCostFunction<RotationCost, 3, 3>(new RotationCost(p, R0, W)), loss, d);
  }
}

void AddPoseBlocks(ceres::Problem* problem, const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R0,
                   const Eigen::Vector3d& t0, const NoiseModel& noise, ceres::LossFunction* loss, double* d,
                   double* t) {
  for (const auto& p : pairs) {
    const Matrix6 W = WhiteningMatrix(ResidualCovariance(p, R0, t0, noise));
    problem->AddResidualBlock(new ceres::AutoDiffCostFunction<PoseCost, 6, 3, 3>(new PoseCost(p, R0, W)), loss, d, t);
  }
}

ceres::Problem::Options ProblemOptions() {
  ceres::Problem::Options o;
  // One loss object is shared by all residual blocks; the problem must not delete it once per block.
  o.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return o;
}

ceres::Covariance::Options CovarianceOptions() {
  ceres::Covariance::Options o;
  o.algorithm_type = ceres::DENSE_SVD;
  o.null_space_rank = -1;  // pseudo-inverse: unobservable directions are reported separately
  o.min_reciprocal_condition_number = 1e-14;
  o.apply_loss_function = false;
  o.num_threads = 1;
  return o;
}

}  // namespace

RefineOutput RefineRotation(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R0, const NoiseModel& noise,
                            bool robust, const HandEyeSettings& settings) {
  std::unique_ptr<ceres::LossFunction> loss(MakeLoss(settings, robust));
  double d[3] = {0.0, 0.0, 0.0};
  ceres::Problem problem(ProblemOptions());
  AddRotationBlocks(&problem, pairs, R0, noise, loss.get(), d);
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(settings), &problem, &summary);
  RefineOutput out;
  FillOutput(summary, &out);
  out.R = R0 * ExpSO3(Eigen::Vector3d(d[0], d[1], d[2]));
  return out;
}

RefineOutput RefinePose(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R0, const Eigen::Vector3d& t0,
                        const NoiseModel& noise, bool robust, const HandEyeSettings& settings) {
  std::unique_ptr<ceres::LossFunction> loss(MakeLoss(settings, robust));
  double d[3] = {0.0, 0.0, 0.0};
  double t[3] = {t0.x(), t0.y(), t0.z()};
  ceres::Problem problem(ProblemOptions());
  AddPoseBlocks(&problem, pairs, R0, t0, noise, loss.get(), d, t);
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(settings), &problem, &summary);
  RefineOutput out;
  FillOutput(summary, &out);
  out.R = R0 * ExpSO3(Eigen::Vector3d(d[0], d[1], d[2]));
  out.t = Eigen::Vector3d(t[0], t[1], t[2]);
  return out;
}

bool RotationCovariance(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const NoiseModel& noise,
                        Eigen::Matrix3d* covariance, double* cost) {
  double d[3] = {0.0, 0.0, 0.0};
  ceres::Problem problem(ProblemOptions());
  AddRotationBlocks(&problem, pairs, R, noise, nullptr, d);
  problem.Evaluate(ceres::Problem::EvaluateOptions(), cost, nullptr, nullptr, nullptr);
  ceres::Covariance cov(CovarianceOptions());
  const std::vector<std::pair<const double*, const double*>> blocks = {{d, d}};
  if (!cov.Compute(blocks, &problem)) return false;
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> C;
  if (!cov.GetCovarianceBlock(d, d, C.data())) return false;
  *covariance = C;
  return true;
}

bool PoseCovariance(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                    const NoiseModel& noise, Matrix6* covariance, double* cost) {
  double d[3] = {0.0, 0.0, 0.0};
  double tt[3] = {t.x(), t.y(), t.z()};
  ceres::Problem problem(ProblemOptions());
  AddPoseBlocks(&problem, pairs, R, t, noise, nullptr, d, tt);
  problem.Evaluate(ceres::Problem::EvaluateOptions(), cost, nullptr, nullptr, nullptr);
  ceres::Covariance cov(CovarianceOptions());
  const std::vector<std::pair<const double*, const double*>> blocks = {{d, d}, {d, tt}, {tt, tt}};
  if (!cov.Compute(blocks, &problem)) return false;
  Eigen::Matrix<double, 6, 6, Eigen::RowMajor> C;
  if (!cov.GetCovarianceMatrix({d, tt}, C.data())) return false;
  *covariance = C;
  return true;
}

}  // namespace fusecal::handeye
