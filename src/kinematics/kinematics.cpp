// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/kinematics.hpp"

#include "kinematics/geometry.hpp"
#include "kinematics/lanes.hpp"

namespace hexatwist {

using detail::Array6d;

Status inverse_kinematics(const Model& model, const Placement& x, LegState& out) noexcept {
  if (!detail::all_finite(x.t) || !detail::all_finite(x.R_BP)) return Status::NonFiniteInput;
  out.R_BP = x.R_BP;
// Eq. (1)-(4), all legs at once (lanes.hpp).
#pragma GCC unroll 4
  for (int k = 0; k < detail::kPackets; ++k) {
    const detail::LegsAt legs = detail::legs_at(model, x.R_BP, x.t, k);
    detail::store6(out.arm_B, legs.arm, k);
    detail::store6(out.axis_platform_B, legs.axis_platform, k);
    detail::store6(out.leg_B, legs.leg, k);
    detail::store6(out.length.data(), legs.length, k);
    detail::store6(out.s_B, (1.0 / legs.length) * legs.leg, k);
  }
  // Finite numbers whose lengths overflow (a pose 1e300 m away) are as unusable as NaN.
  if (!out.length.allFinite()) return Status::NonFiniteInput;
  if (out.length.minCoeff() > 0.0) return Status::Ok;
  for (int i = 0; i < kLegs; ++i)
    if (!(out.length[i] > 0.0)) out.s_B.row(i).setZero();
  return Status::StrokeBelowMin;
}

Status inverse_kinematics(const Model& model, const Pose& pose, LegState& out) noexcept {
  if (!pose.is_finite()) return Status::NonFiniteInput;
  return inverse_kinematics(model, placement_from_pose(pose), out);
}

void length_jacobian(const LegState& state, Matrix6d& J) noexcept {
  J.leftCols<3>() = state.s_B;
  J.rightCols<3>() = detail::cross(state.arm_B, state.s_B);
}

Vector3d platform_point_B(const Model& model, const Placement& x, const Vector3d& p_P) noexcept {
  return model.pivot_home_B() + x.t + x.R_BP * (p_P - model.spec().pivot_P);
}

}  // namespace hexatwist
