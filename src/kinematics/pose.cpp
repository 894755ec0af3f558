// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/pose.hpp"

#include <cmath>

#include "kinematics/fast_math.hpp"

namespace hexatwist {

Pose Pose::from_vector(const Vector6d& q) noexcept {
  Pose p;
  p.position = q.head<3>();
  p.rpy = q.tail<3>();
  return p;
}

Vector6d Pose::to_vector() const noexcept {
  Vector6d q;
  q << position, rpy;
  return q;
}

bool Pose::is_finite() const noexcept { return detail::all_finite(position) && detail::all_finite(rpy); }

Matrix3d rotation_from_rpy(const Vector3d& rpy) noexcept { return detail::rotation_from_rpy(rpy); }

Vector3d rpy_from_rotation(const Matrix3d& R) noexcept {
  // roll = atan2(R21, R22), pitch = atan2(-R20, |(R00, R10)|), yaw = atan2(R10, R00), as one
  // vectorised call (fast_math.hpp; 2 ulp).
  const double c5 = std::sqrt(R(0, 0) * R(0, 0) + R(1, 0) * R(1, 0));
#if HEXATWIST_LANE_WIDTH >= 4
  // One 4-lane call where the target has them: the forward kinematics ends with it.
  const detail::v4d a =
      detail::atan2(detail::v4d{R(2, 1), -R(2, 0), R(1, 0), 0.0}, detail::v4d{R(2, 2), c5, R(0, 0), 1.0});
  return {a[0], a[1], a[2]};
#else
  const detail::v2d a = detail::atan2(detail::v2d{R(2, 1), -R(2, 0)}, detail::v2d{R(2, 2), c5});
  const detail::v2d b = detail::atan2(detail::v2d{R(1, 0), 0.0}, detail::v2d{R(0, 0), 1.0});
  return {a[0], a[1], b[0]};
#endif
}

Matrix3d exp_so3(const Vector3d& w) noexcept {
  const double a2 = w.squaredNorm();
  double A, B;  // R = I + A W + B W^2
  if (a2 < 1e-12) {
    // Taylor series: error below 1e-25 for |w| < 1e-6.
    A = 1.0 - a2 / 6.0;
    B = 0.5 - a2 / 24.0;
  } else {
    const double a = std::sqrt(a2);
    detail::v2d sn, cs;
    detail::sin_cos(detail::v2d{a, 0.0}, sn, cs);
    if (!(a < 1e5)) sn[0] = std::sin(a), cs[0] = std::cos(a);  // outside the kernel's range
    A = sn[0] / a;
    B = (1.0 - cs[0]) / a2;
  }
  // Written out with W = [w]x and W^2 = w w^T - |w|^2 I, each entry in the order the 3x3 product
  // W * W sums it (the zero terms are exact), without the matrix temporaries and product.
  const double x = w.x(), y = w.y(), z = w.z();
  Matrix3d R;
  R(0, 0) = 1.0 + B * (-(z * z) - y * y);
  R(1, 1) = 1.0 + B * (-(z * z) - x * x);
  R(2, 2) = 1.0 + B * (-(y * y) - x * x);
  R(0, 1) = A * -z + B * (y * x);
  R(1, 0) = A * z + B * (x * y);
  R(0, 2) = A * y + B * (z * x);
  R(2, 0) = A * -y + B * (x * z);
  R(1, 2) = A * -x + B * (z * y);
  R(2, 1) = A * x + B * (y * z);
  return R;
}

Placement placement_from_pose(const Pose& pose) noexcept {
  return Placement{pose.position, rotation_from_rpy(pose.rpy)};
}

Pose pose_from_placement(const Placement& x) noexcept {
  Pose p;
  p.position = x.t;
  p.rpy = rpy_from_rotation(x.R_BP);
  return p;
}

}  // namespace hexatwist
