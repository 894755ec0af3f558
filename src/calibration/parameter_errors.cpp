// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/parameter_errors.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>

#include "calibration/random.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/pose.hpp"

namespace hexatwist {

Model real_model(const Model& nominal, const ParameterErrors& errors) {
  ModelSpec spec = nominal.spec();
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
    const Leg& n = nominal.leg(i);
    // The drive keeps converting with the nominal lead about the nominal reference (theory §4).
    if (n.lead > 0.0) leg.drive_lead = n.lead / n.drive_scale;
    leg.home_command = nominal.home_command()[i];
    leg.lead = n.lead * (1.0 + errors.lead_error[i]);
    if (errors.flip_twist_sign) leg.thread = leg.thread == ThreadSense::Right ? ThreadSense::Left : ThreadSense::Right;
    leg.length_offset += errors.zero_offset[i];
    leg.base_B += errors.base_offset_B.row(i).transpose();
    leg.platform_P += errors.platform_offset_P.row(i).transpose();
    const Vector3d wb = errors.base_axis_rotation.row(i).transpose();
    const Vector3d wp = errors.platform_axis_rotation.row(i).transpose();
    leg.axis_base_B = exp_so3(wb) * leg.axis_base_B;
    leg.axis_platform_P = exp_so3(wp) * leg.axis_platform_P;
    if (!std::isnan(errors.stiffness[i])) leg.stiffness = errors.stiffness[i];
    if (!std::isnan(errors.play[i])) leg.play = errors.play[i];
    if (!std::isnan(errors.length_expansion)) leg.length_expansion = errors.length_expansion;
    if (!std::isnan(errors.lead_expansion)) leg.lead_expansion = errors.lead_expansion;
  }
  spec.observation_P += errors.observation_offset_P;
  return Model(spec);
}

LegVectors without_rigid_part(const LegVectors& points, const LegVectors& d) {
  // Least squares: d_i ~ a + w x (x_i - c), six unknowns; the fit's normal equations are small
  // and well conditioned for six points spread over a platform.
  const Vector3d c = points.colwise().mean().transpose();
  Eigen::Matrix<double, 3 * kLegs, 6> A;
  Eigen::Matrix<double, 3 * kLegs, 1> b;
  for (int i = 0; i < kLegs; ++i) {
    const Vector3d r = points.row(i).transpose() - c;
    Matrix3d skew_r;
    skew_r << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
    A.block<3, 3>(3 * i, 0).setIdentity();
    A.block<3, 3>(3 * i, 3) = -skew_r;  // w x r = -r x w
    b.segment<3>(3 * i) = d.row(i).transpose();
  }
  const Eigen::Matrix<double, 6, 1> rigid = A.colPivHouseholderQr().solve(b);
  LegVectors out = d;
  for (int i = 0; i < kLegs; ++i) out.row(i) -= (A.block<3, 6>(3 * i, 0) * rigid).transpose();
  return out;
}

void random_geometry_errors(const Model& nominal, double bound, double axis_bound, std::uint64_t seed,
                            ParameterErrors& errors) {
  if (!(bound >= 0.0 && bound <= kMaxJointError))
    throw ParameterError(
        fmt::format("joint errors: expected a bound from 0 to {:g} m, got {:g}", kMaxJointError, bound),
        "joint_errors");
  if (!(axis_bound >= 0.0 && axis_bound <= kMaxAxisError))
    throw ParameterError(
        fmt::format("axis errors: expected a bound from 0 to {:g} rad (10 deg), got {:g}", kMaxAxisError, axis_bound),
        "axis_errors");
  detail::Random rng(seed ^ 0x6A09E667F3BCC909ull);  // another stream than the tracker's and the offsets'
  LegVectors base = LegVectors::Zero(), platform = LegVectors::Zero();
  for (int i = 0; i < kLegs; ++i)
    for (int a = 0; a < 3; ++a) base(i, a) = bound * rng.symmetric();
  for (int i = 0; i < kLegs; ++i)
    for (int a = 0; a < 3; ++a) platform(i, a) = bound * rng.symmetric();
  errors.base_offset_B = without_rigid_part(nominal.geometry().base_B, base);
  errors.platform_offset_P = without_rigid_part(nominal.geometry().arm_P, platform);
  const auto across = [&](const Vector3d& axis) {
    // A rotation about two directions across the axis (one about the axis itself does nothing).
    const Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1).normalized();
    return Vector3d(axis_bound * rng.symmetric() * e1 + axis_bound * rng.symmetric() * e2);
  };
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = nominal.leg(i);
    if (std::isnan(leg.theta_home)) continue;  // a leg without axes
    errors.base_axis_rotation.row(i) = across(leg.axis_base_B).transpose();
    errors.platform_axis_rotation.row(i) = across(leg.axis_platform_P).transpose();
  }
}

}  // namespace hexatwist
