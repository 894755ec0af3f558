// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/twist.hpp"

#include <cmath>

#include "kinematics/geometry.hpp"
#include "kinematics/lanes.hpp"
#include "kinematics/twist_internal.hpp"

namespace hexatwist {
namespace {

// Called when the fast test of the lanes failed: the singular joint of the leg nearest to a
// singularity (legs without axes never are), by the scalar formula of geometry.hpp. Always
// returns SingularBase or SingularPlatform, so no caller can mistake it for success.
Status singular_joint(const Model& model, const LegState& st) noexcept {
  int worst = -1;
  double worst_n2 = INFINITY;
  for (int i = 0; i < kLegs; ++i) {
    if (model.geometry().has_axes[i] == 0.0) continue;
    const auto xy =
        detail::twist_xy(st.s_B.row(i).transpose(), model.leg(i).axis_base_B, st.axis_platform_B.row(i).transpose());
    const double n2 = xy.x * xy.x + xy.y * xy.y;
    if (!(n2 >= worst_n2)) {  // also picks a NaN leg
      worst = i;
      worst_n2 = n2;
    }
  }
  if (worst < 0) return Status::SingularBase;  // unreachable: the fast test passes without axes
  const Vector3d s = st.s_B.row(worst).transpose();
  return s.cross(model.leg(worst).axis_base_B).squaredNorm() <=
                 s.cross(st.axis_platform_B.row(worst).transpose()).squaredNorm()
             ? Status::SingularBase
             : Status::SingularPlatform;
}

// Wraps an angle to (-pi, pi].
double wrap(double a) noexcept { return a - 2.0 * kPi * std::ceil((a - kPi) / (2.0 * kPi)); }

// Packet k of the legs at the state, with their twist terms (lanes.hpp).
struct LegTwist {
  detail::lanes3 s, ja, jd;
  detail::lane_v ja_s, jd_s;
};

LegTwist leg_twist(const Model& model, const LegState& st, int k) noexcept {
  using namespace detail;
  LegTwist l;
  l.s = load6(st.s_B, k);
  l.ja = load_lanes(model.geometry().lanes.axis_base_B, k);
  l.jd = load6(st.axis_platform_B, k);
  l.ja_s = dot(l.s, l.ja);
  l.jd_s = dot(l.s, l.jd);
  return l;
}

detail::TwistTerms terms_of(const LegTwist& l) noexcept {
  return detail::twist_terms(l.s, l.ja, l.jd, l.ja_s, l.jd_s, detail::splat<detail::lane_v>(1.0));
}

// Absolute (relative = false) or home-relative twist of all legs.
Status twist_angles(const Model& model, const LegState& state, bool relative, Vector6d& out) noexcept {
  using namespace detail;
  TwistTerms t[kPackets];
  lane_m regular = all_set();
#pragma GCC unroll 4
  for (int k = 0; k < kPackets; ++k) {
    t[k] = terms_of(leg_twist(model, state, k));
    regular &= twist_regular(model, t[k].x, t[k].y, splat<lane_v>(1.0), k);
  }
  if (!all_lanes(regular)) return singular_joint(model, state);
#pragma GCC unroll 4
  for (int k = 0; k < kPackets; ++k) store6(out.data(), twist_angle(model, t[k].x, t[k].y, relative, k), k);
  return Status::Ok;
}

}  // namespace

Status twist_absolute(const Model& model, const LegState& state, Vector6d& theta) noexcept {
  return twist_angles(model, state, false, theta);
}

Status twist(const Model& model, const LegState& state, Vector6d& dtheta) noexcept {
  return twist_angles(model, state, true, dtheta);
}

Status twist_continued(const Model& model, const LegState& state, const Vector6d& reference,
                       Vector6d& dtheta) noexcept {
  const Status status = twist(model, state, dtheta);
  if (status != Status::Ok) return status;
  for (int i = 0; i < kLegs; ++i) dtheta[i] = reference[i] + wrap(dtheta[i] - reference[i]);
  return Status::Ok;
}

namespace {

// The twist Jacobian (twist_jacobian), or, with kMotor, the motor-side length Jacobian, all rows
// at once (lanes.hpp jacobian_columns). Where a leg is near a U-joint singularity its row is
// unspecified and the result names the joint.
template <bool kMotor>
Status jacobian(const Model& model, const LegState& state, Matrix6d& J) noexcept {
  using namespace detail;
  lane_m regular = all_set();
#pragma GCC unroll 4
  for (int k = 0; k < kPackets; ++k) {
    const LegTwist l = leg_twist(model, state, k);
    const TwistTerms t = terms_of(l);
    regular &= twist_regular(model, t.x, t.y, splat<lane_v>(1.0), k);
    lane_v col[6];
    jacobian_columns(model, l.s, 1.0 / load6(state.length.data(), k), load6(state.arm_B, k), l.ja, l.jd, l.ja_s, l.jd_s,
                     t, kMotor, k, col);
    for (int c = 0; c < 6; ++c) store6(J.data() + kLegs * c, col[c], k);
  }
  return all_lanes(regular) ? Status::Ok : singular_joint(model, state);
}

}  // namespace

Status twist_jacobian(const Model& model, const LegState& state, Matrix6d& J) noexcept {
  // Computed into a temporary so that J is left untouched at a singular joint, as before.
  Matrix6d J_twist;
  if (const Status s = jacobian<false>(model, state, J_twist); s != Status::Ok) return s;
  J = J_twist;
  return Status::Ok;
}

namespace detail {

Status motor_length_jacobian(const Model& model, const LegState& state, Matrix6d& J) noexcept {
  return jacobian<true>(model, state, J);
}

}  // namespace detail

}  // namespace hexatwist
