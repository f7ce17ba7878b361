#include "stages/handeye/shared_error.hpp"

#include <Eigen/QR>
#include <array>

namespace fusecal::handeye {

namespace {

using Matrix63 = Eigen::Matrix<double, 6, 3>;

// sum_i u_ik J_x,i^T W_i J_m,i for k = 0..2, for one sensor and one map (J_m: the 6x3 block of the
// residual's Jacobian that the map's output enters).
struct Accumulated {
  std::array<Matrix63, 3> sum{Matrix63::Zero(), Matrix63::Zero(), Matrix63::Zero()};
  void Add(const Eigen::Vector3d& u, const Matrix63& JtWJm) {
    for (int k = 0; k < 3; ++k) sum[k] += u[k] * JtWJm;
  }
  Matrix6 Covariance(const Matrix6& H_pinv, double sigma) const {
    Matrix6 C = Matrix6::Zero();
    if (!(sigma > 0)) return C;
    for (const auto& S : sum) {
      const Matrix63 B = H_pinv * S;
      C += sigma * sigma * B * B.transpose();
    }
    return C;
  }
};

struct SensorMaps {
  Accumulated G, H, K;
  Vector6 scale = Vector6::Zero();  // sum_i J_x,i^T W_i J_t,i t_i: the common length scale's column
  void Add(const Eigen::Vector3d& w, const Eigen::Vector3d& tr, const Matrix6& JtW, const Matrix6& Jm) {
    const Matrix63 rot = JtW * Jm.leftCols<3>(), trans = JtW * Jm.rightCols<3>();
    G.Add(w, rot);
    H.Add(tr, trans);
    K.Add(w, trans);
    scale += trans * tr;
  }
  Matrix6 Covariance(const Matrix6& H_pinv, const SharedErrors& e) const {
    const Vector6 b = H_pinv * scale;
    return G.Covariance(H_pinv, e.rotation_per_rotation) + H.Covariance(H_pinv, e.translation_per_translation) +
           K.Covariance(H_pinv, e.translation_per_rotation_m) +
           e.translation_scale * e.translation_scale * b * b.transpose();
  }
};

}  // namespace

Matrix6 SharedErrorCovariance(const std::vector<MotionPair>& pairs, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                              const NoiseModel& noise, const SharedErrors& camera, const SharedErrors& lidar) {
  if (pairs.empty() || (!camera.Any() && !lidar.Any())) return Matrix6::Zero();
  Matrix6 information = Matrix6::Zero();
  SensorMaps maps_a, maps_b;
  for (const auto& p : pairs) {
    const Matrix6 Jx = JacobianWrtExtrinsic(p, R);
    const Matrix6 L = WhiteningMatrix(ResidualCovariance(p, R, t, noise));
    const Matrix6 W = L.transpose() * L;
    const Matrix6 JtW = Jx.transpose() * W;
    information += JtW * Jx;
    maps_a.Add(LogSO3(p.A.linear()), p.A.translation(), JtW, JacobianWrtA(p, R, t));
    maps_b.Add(LogSO3(p.B.linear()), p.B.translation(), JtW, JacobianWrtB(p, R));
  }
  const Matrix6 H_pinv = information.completeOrthogonalDecomposition().pseudoInverse();
  const Matrix6 C = maps_a.Covariance(H_pinv, camera) + maps_b.Covariance(H_pinv, lidar);
  return 0.5 * (C + C.transpose());
}

}  // namespace fusecal::handeye
