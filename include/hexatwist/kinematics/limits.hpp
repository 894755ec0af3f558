// SPDX-License-Identifier: BSD-3-Clause
// Limit check of a pose: leg stroke, U-joint bend, U-joint singularity and platform (Jacobian)
// singularity.
#pragma once

#include <string>

#include "hexatwist/kinematics/kinematics.hpp"

namespace hexatwist {

// Boundaries (docs/theory.md §6): a value on a limit is inside it. Every check below, and the
// vectorised real-time path, compares against the bounds widened by kLimitTolerance (model.hpp:
// 4 ulp, 8.9e-16 relative to the bound; to 1 for the cosines of the bend and singularity tests),
// so that rounding on the way (fk's 1.4 m coming back as 1.3999999999999997 m) cannot refuse a
// pose that lies on a limit. A LimitReport's `bound` is the configured limit, not the widened one.

/// Which leg broke which limit, by how much.
struct LimitReport {
  Status status = Status::Ok;  ///< Ok, or the limit status (see is_limit)
  int leg = -1;                ///< offending leg, 0-based; -1 if none
  double value = 0.0;          ///< the offending quantity [m, rad, or - for a condition number]
  double bound = 0.0;          ///< the limit it crossed [m, rad, or -]
};

/// One line for a limit report, as the CLI and Python word it: "leg 3: length 2.450013 m is above
/// the maximum 2.450000 m (limits.length_max)", with the configuration key of the limit and as
/// many decimals as it takes to tell the value from its bound; "ok" for Ok.
[[nodiscard]] std::string describe(const LimitReport& report);

/// U-joint bend angles: base, angle between s_i and its home direction; platform, the same seen
/// from the platform frame [rad].
void bend_angles(const Model& model, const LegState& state, Vector6d& bend_base, Vector6d& bend_platform) noexcept;

/// Condition number of the platform Jacobian at `state` (inverse kinematics done): the motor-side
/// Jacobian when the model has twist, else the geometric one, rotation columns divided by
/// model.condition_length(), in the 1-norm, ||A||_1 ||A^-1||_1 (docs/theory.md §6) [-].
/// Returns Ok, PlatformSingularity when `condition` exceeds limits.jacobian_condition_max (also
/// for an exactly singular Jacobian: condition = inf), or SingularBase/SingularPlatform where the
/// twist's Jacobian is undefined (condition = NaN).
[[nodiscard]] Status jacobian_condition(const Model& model, const LegState& state, double& condition) noexcept;

/// Checks each leg in order for stroke, then bend, then singularity, and reports the first
/// violation; then, if every leg passed, the Jacobian's condition number (jacobian_condition,
/// reported with leg -1). The leg tests use no trigonometry (cosine / sine comparisons).
[[nodiscard]] Status check_limits(const Model& model, const LegState& state, LimitReport& report) noexcept;

/// Checks that motor-side commands lie inside the stroke [m]; report names the first bad leg.
[[nodiscard]] Status check_stroke(const Model& model, const Vector6d& command, LimitReport& report) noexcept;

/// The limit a pose is nearest to: over every leg's stroke (either end), U-joint bends and
/// U-joint singularity margins, and the platform's Jacobian condition, the one with the smallest
/// share of its range left. `margin` is that share: 1 far from every limit (mid-stroke, no bend,
/// leg perpendicular to both fixed axes, condition 1), 0 on the limit, negative past it. For
/// the stroke the range is half the stroke; for a bend, 0 to bend_max; for a singularity margin,
/// 90 deg down to the margin; for the condition number, its logarithm from 0 to log(max).
/// `nearest` names the leg (-1 for the condition), the value and the bound as check_limits does.
/// `condition` is the Jacobian condition number at `state` (jacobian_condition). Not real-time
/// critical: it takes a few inverse cosines per leg.
void nearest_limit(const Model& model, const LegState& state, double condition, LimitReport& nearest,
                   double& margin) noexcept;

}  // namespace hexatwist
