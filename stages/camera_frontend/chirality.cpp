#include "stages/camera_frontend/chirality.hpp"

#include <Eigen/Geometry>
#include <cmath>

namespace fusecal::camera_frontend {

bool TriangulateDepths(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& f_i,
                       const Eigen::Vector3d& f_j, double* depth_i, double* depth_j) {
  // Normal equations of [f_i, -R f_j] [l_i; l_j] = t.
  const Eigen::Vector3d g = R * f_j;
  const double a = f_i.dot(f_i), b = -f_i.dot(g), c = g.dot(g);
  const double det = a * c - b * b;  // = |f_i x g|^2 for unit vectors
  if (det < 1e-12) return false;     // parallax below about 1e-6 rad: no decision
  const double r_i = f_i.dot(t), r_j = -g.dot(t);
  *depth_i = (c * r_i - b * r_j) / det;
  *depth_j = (a * r_j - b * r_i) / det;
  return true;
}

ChiralityVotes CountInFront(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Bearings& f_i,
                            const Bearings& f_j, const std::vector<int>& indices) {
  ChiralityVotes votes;
  for (int k : indices) {
    double l_i = 0, l_j = 0;
    if (!TriangulateDepths(R, t, f_i[k], f_j[k], &l_i, &l_j)) continue;
    ++votes.decided;
    if (l_i > 0 && l_j > 0) ++votes.in_front;
  }
  return votes;
}

ChiralityVotes ResolveChirality(const Bearings& f_i, const Bearings& f_j, const std::vector<int>& indices,
                                Eigen::Matrix3d* R, Eigen::Vector3d* t) {
  const Eigen::Vector3d axis = t->norm() > 0 ? Eigen::Vector3d(t->normalized()) : Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d twisted = Eigen::AngleAxisd(M_PI, axis).toRotationMatrix() * *R;
  const Eigen::Matrix3d rotations[2] = {*R, twisted};
  const Eigen::Vector3d translations[2] = {*t, -*t};
  ChiralityVotes best;
  int best_r = 0, best_t = 0;
  bool first = true;
  for (int r = 0; r < 2; ++r) {
    for (int s = 0; s < 2; ++s) {
      const ChiralityVotes votes = CountInFront(rotations[r], translations[s], f_i, f_j, indices);
      if (first || votes.in_front > best.in_front) {
        best = votes;
        best_r = r;
        best_t = s;
        first = false;
      }
    }
  }
  *R = rotations[best_r];
  *t = translations[best_t];
  return best;
}

}  // namespace fusecal::camera_frontend
