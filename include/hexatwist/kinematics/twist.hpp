// SPDX-License-Identifier: BSD-3-Clause
// Passive rotation ("twist") of each leg: the signed angle of the rod relative to the housing
// about the leg axis, minus its home value (paper Eq. 7-8; Eq. 9 corrected, docs/theory.md).
#pragma once

#include "hexatwist/kinematics/kinematics.hpp"

namespace hexatwist {

/// Absolute twist angle theta_i = angle from jb_i = s x ja to je_i = s x jd about s [rad],
/// in [-pi, pi]. Computed as atan2(s.(ja x jd), ja.jd - (ja.s)(jd.s)), which equals the angle
/// between the normalised Eq. (8) vectors. Returns SingularBase/SingularPlatform (and leaves
/// `theta` unspecified) if a leg is parallel to a fixed axis.
[[nodiscard]] Status twist_absolute(const Model& model, const LegState& state, Vector6d& theta) noexcept;

/// Twist relative to home, dtheta_i = theta_i - theta_home_i, wrapped to [-pi, pi] [rad].
/// Legs without U-joint axes (allowed only with lead 0) get 0.
[[nodiscard]] Status twist(const Model& model, const LegState& state, Vector6d& dtheta) noexcept;

/// Twist relative to home on the branch closest to `reference` [rad]: continuous along a motion
/// when `reference` is the previous sample's twist, also past +-pi.
[[nodiscard]] Status twist_continued(const Model& model, const LegState& state, const Vector6d& reference,
                                     Vector6d& dtheta) noexcept;

/// Jacobian of the twist with respect to the platform twist (dt [m, B], dw [rad, B]), same
/// perturbation as length_jacobian. Rows of legs without axes are zero.
[[nodiscard]] Status twist_jacobian(const Model& model, const LegState& state, Matrix6d& J_twist_x) noexcept;

}  // namespace hexatwist
