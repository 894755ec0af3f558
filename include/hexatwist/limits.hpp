// Limit check of a pose: leg stroke, U-joint bend and U-joint singularity.
#pragma once

#include "hexatwist/kinematics.hpp"

namespace hexatwist {

/// Which leg broke which limit, by how much.
struct LimitReport {
  Status status = Status::Ok;  ///< Ok, or the limit status (see is_limit)
  int leg = -1;                ///< offending leg, 0-based; -1 if none
  double value = 0.0;          ///< the offending quantity [m or rad]
  double bound = 0.0;          ///< the limit it crossed [m or rad]
};

/// U-joint bend angles: base, angle between s_i and its home direction; platform, the same seen
/// from the platform frame [rad].
void bend_angles(const Model& model, const LegState& state, Vector6d& bend_base,
                 Vector6d& bend_platform) noexcept;

/// Checks each leg in order for stroke, then bend, then singularity, and reports the first
/// violation. Uses no trigonometry (cosine / sine comparisons).
[[nodiscard]] Status check_limits(const Model& model, const LegState& state, LimitReport& report) noexcept;

/// Checks that motor-side commands lie inside the stroke [m]; report names the first bad leg.
[[nodiscard]] Status check_stroke(const Model& model, const Vector6d& command, LimitReport& report) noexcept;

}  // namespace hexatwist
