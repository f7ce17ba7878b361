// Chirality: which of the motions sharing one essential matrix is the physical one.
//
// The epipolar constraint f_i . (t x R f_j) = 0, and so the angular error the refinement minimises, does not
// change when t is negated, nor when R is replaced by its "twisted pair" R_pi R (R_pi: rotation by pi about
// t). Only one of the four puts the scene in front of both cameras, i.e. gives positive depths l_i, l_j in
// l_i f_i = l_j R f_j + t. With that one, t is the position of camera j in the frame of camera i (up to
// scale), consistently with A = T_ci_cj.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "stages/camera_frontend/bearings.hpp"

namespace fusecal::camera_frontend {

// Depths (l_i, l_j) of the midpoint triangulation of one correspondence: least squares of
// l_i f_i - l_j R f_j = t. False when the rays are (nearly) parallel, so the sign is not determined.
bool TriangulateDepths(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& f_i,
                       const Eigen::Vector3d& f_j, double* depth_i, double* depth_j);

struct ChiralityVotes {
  int in_front = 0;  // both depths positive
  int decided = 0;   // correspondences whose rays are not parallel
};

ChiralityVotes CountInFront(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Bearings& f_i,
                            const Bearings& f_j, const std::vector<int>& indices);

// Replaces (*R, *t) by the one of (R, t), (R, -t), (R_pi R, t), (R_pi R, -t) that puts the most of the
// indexed correspondences in front of both cameras; returns its votes. The rotation changes only when the
// twisted pair wins, which a correct RANSAC model never needs; the usual effect is fixing the sign of t.
ChiralityVotes ResolveChirality(const Bearings& f_i, const Bearings& f_j, const std::vector<int>& indices,
                                Eigen::Matrix3d* R, Eigen::Vector3d* t);

}  // namespace fusecal::camera_frontend
