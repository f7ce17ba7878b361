// SE(3) and SO(3) helpers shared by every stage.
// Convention (docs/design.md section 2): T_a_b maps a point from frame b into frame a, p_a = T_a_b * p_b.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace fusecal {

using Isometry3 = Eigen::Isometry3d;
using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// Rotation angle of R in radians, in [0, pi], robust near 0 and pi.
double RotationAngle(const Eigen::Matrix3d& R);

// Geodesic distance between two rotations, radians: angle of R_a^T R_b.
double RotationErrorRad(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);
double RotationErrorDeg(const Eigen::Matrix3d& R_a, const Eigen::Matrix3d& R_b);

// Axis-angle vector (rotation vector) of R and back.
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R);
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& omega);

// Skew-symmetric matrix [v]x such that [v]x w = v x w.
Eigen::Matrix3d Skew(const Eigen::Vector3d& v);

// Build a transform from rotation and translation.
Isometry3 MakeIsometry(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);

// Roll-pitch-yaw (x, y, z fixed axes; R = Rz(yaw) Ry(pitch) Rx(roll)), radians.
Eigen::Matrix3d RotationFromRpy(double roll, double pitch, double yaw);
Eigen::Vector3d RpyFromRotation(const Eigen::Matrix3d& R);

// Row-major 16 numbers <-> transform. FromRowMajor re-orthonormalises the rotation block.
void ToRowMajor(const Isometry3& T, double out[16]);
Isometry3 FromRowMajor(const double in[16]);

// Rotation matrix nearest to M in the Frobenius norm (SVD projection).
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& M);

// True when all 16 entries are finite and the rotation block is orthonormal within tol.
bool IsValidTransform(const Isometry3& T, double tol = 1e-6);

}  // namespace fusecal
