#include "hexatwist/kinematics.hpp"

#include "geometry.hpp"

namespace hexatwist {

using detail::Array6d;

Status inverse_kinematics(const Model& model, const Placement& x, LegState& out) noexcept {
  if (!x.t.allFinite() || !x.R_BP.allFinite()) return Status::NonFiniteInput;
  const LegGeometry& g = model.geometry();
  out.R_BP = x.R_BP;
  // Eq. (1)-(2), all legs at once: L_i = (pivot_home + t) + R_BP * arm_P,i - base_B,i.
  out.arm_B = detail::rotate_rows(x.R_BP, g.arm_P);
  out.axis_platform_B = detail::rotate_rows(x.R_BP, g.axis_platform_P);
  const Vector3d origin_B = model.pivot_home_B() + x.t;
  for (int k = 0; k < 3; ++k) out.leg_B.col(k) = (out.arm_B.col(k) - g.base_B.col(k)).array() + origin_B[k];
  const Array6d length = detail::dot(out.leg_B, out.leg_B).sqrt();  // Eq. (4)
  out.length = length.matrix();
  out.s_B = detail::scale_rows(length.inverse(), out.leg_B);
  if (length.minCoeff() > 0.0) return Status::Ok;
  for (int i = 0; i < kLegs; ++i)
    if (!(length[i] > 0.0)) out.s_B.row(i).setZero();
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
