// SPDX-License-Identifier: BSD-3-Clause
// Reach of the platform along each pose coordinate alone: how far it can move from home in x, y,
// z, roll, pitch or yaw with every limit respected (what a controller's axis limits should be).
#pragma once

#include "hexatwist/kinematics/compensation.hpp"

namespace hexatwist {

/// Interval of one pose coordinate, the others held at home, over which every pose is inside
/// every limit (motor_commands accepts it), and the limit met at each end.
struct AxisRange {
  double lower = 0.0;       ///< smallest reachable value [m or rad] (<= 0)
  double upper = 0.0;       ///< largest reachable value [m or rad] (>= 0)
  LimitReport lower_limit;  ///< the limit just past `lower` (status Ok if the search bound was reached)
  LimitReport upper_limit;  ///< the limit just past `upper`
};

/// Search settings of axis_range.
struct AxisRangeOptions {
  double linear_step = 1e-3;   ///< march step for x, y, z [m]
  double angular_step = 1e-3;  ///< march step for roll, pitch, yaw [rad]
  double linear_bound = 10.0;  ///< search no further than this [m]
  double angular_bound = kPi;  ///< ... or this [rad]
  double tolerance = 1e-9;     ///< bisection stops when the bracket is this narrow [m or rad]
};

/// The connected interval around home of coordinate `coordinate` (0..5: x, y, z [m], roll, pitch,
/// yaw [rad]) inside every limit, for the commands of `strategy`: marched outward from home in
/// steps, then bisected to `tolerance`, on the inside (every value in [lower, upper] was accepted
/// at the march step). Returns NonFiniteInput for a coordinate outside 0..5 or bad options, or
/// the limit status of home itself when home is outside a limit.
[[nodiscard]] Status axis_range(const Model& model, int coordinate, Strategy strategy, AxisRange& out,
                                const AxisRangeOptions& options = {}) noexcept;

}  // namespace hexatwist
