// SPDX-License-Identifier: BSD-3-Clause
// Platform pose relative to home: position and roll-pitch-yaw (paper Eq. 2-3), and the
// rotation-matrix placement that forward kinematics iterates on.
#pragma once

#include "hexatwist/types.hpp"

namespace hexatwist {

/// Pose of the moving platform relative to home.
struct Pose {
  Vector3d position = Vector3d::Zero();  ///< surge, sway, heave (q1..q3) [m, B]
  Vector3d rpy = Vector3d::Zero();       ///< roll, pitch, yaw (q4..q6) [rad]; R = Rz·Ry·Rx

  /// Pose from `[x, y, z, roll, pitch, yaw]` [m, rad].
  static Pose from_vector(const Vector6d& q) noexcept;
  /// `[x, y, z, roll, pitch, yaw]` [m, rad].
  Vector6d to_vector() const noexcept;
  /// True if every component is finite.
  bool is_finite() const noexcept;
};

/// Rotation matrix R_BP = Rz(yaw)·Ry(pitch)·Rx(roll), paper Eq. (3).
Matrix3d rotation_from_rpy(const Vector3d& rpy) noexcept;

/// Roll, pitch, yaw [rad] of a rotation matrix, inverse of `rotation_from_rpy`
/// (pitch in [-pi/2, pi/2]).
Vector3d rpy_from_rotation(const Matrix3d& R_BP) noexcept;

/// Exponential map of so(3): the rotation by |w| about w/|w| (Rodrigues).
Matrix3d exp_so3(const Vector3d& w) noexcept;

/// Pose as a displacement and a rotation matrix: the representation forward kinematics updates.
struct Placement {
  Vector3d t = Vector3d::Zero();         ///< displacement from home [m, B]
  Matrix3d R_BP = Matrix3d::Identity();  ///< platform orientation relative to home
};

/// Placement of a pose (computes Eq. 3 once).
Placement placement_from_pose(const Pose& pose) noexcept;

/// Pose of a placement.
Pose pose_from_placement(const Placement& x) noexcept;

}  // namespace hexatwist
