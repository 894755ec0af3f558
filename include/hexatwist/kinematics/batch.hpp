// SPDX-License-Identifier: BSD-3-Clause
// Batches of poses for atlases, design searches and Monte Carlo: the poses side by side in the
// SIMD lanes (eight to a register with AVX-512), where the real-time call puts the six legs of one
// pose. Motor-side commands with every limit checked, as motor_commands decides them, and the
// leg lengths alone, as inverse_kinematics gives them (docs/theory/kinematics.md §8, "Batches").
#pragma once

#include <span>

#include "hexatwist/kinematics/compensation.hpp"

namespace hexatwist {

/// Motor-side commands (Eq. 11-12) for a batch of poses, every limit checked: for each pose the
/// status, commands and report that motor_commands(model, pose, strategy, ...) gives, bit for bit.
/// `poses` holds rows [x, y, z, roll, pitch, yaw] [m, rad] relative to home, pose i at
/// poses[6 i .. 6 i + 5] (an (N, 6) array in C order); `commands` the same layout [m], a row of NaN
/// where the status is not Ok (never send those); `reports` one per pose: Ok, or the status
/// motor_commands returns (NonFiniteInput, a limit, a singular joint) with its leg, value and bound.
/// Returns MalformedInput, writing nothing, unless poses.size() = commands.size() = 6 reports.size();
/// else Ok. Allocation-free.
[[nodiscard]] Status motor_commands_batch(const Model& model, std::span<const double> poses, Strategy strategy,
                                          std::span<double> commands, std::span<LimitReport> reports) noexcept;

/// Leg lengths |L_i| [m] of a batch of poses (Eq. 1-4 only: no limit, no twist): for each pose the
/// LegState::length and the status inverse_kinematics gives, bit for bit. `poses` as in
/// motor_commands_batch; `lengths` the same layout [m], a row of NaN for a pose that is not finite;
/// `status` one per pose: Ok, NonFiniteInput, or StrokeBelowMin where a leg has zero length.
/// Returns MalformedInput, writing nothing, unless poses.size() = lengths.size() = 6 status.size();
/// else Ok. Allocation-free.
[[nodiscard]] Status leg_lengths_batch(const Model& model, std::span<const double> poses, std::span<double> lengths,
                                       std::span<Status> status) noexcept;

}  // namespace hexatwist
