// SPDX-License-Identifier: BSD-3-Clause
// What the legs' effects (heat, load and play: kinematics/leg_effects.hpp, theory §4b) cost at the
// observation point along a trajectory, as the paper's Table 1 gives the twist's: with commands
// that ignore them, with commands that compensate the twist alone (Eq. 12), and with commands that
// compensate both.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "hexatwist/simulation/study.hpp"

namespace hexatwist {

/// The largest temperature rise over a run [K] the study and synth accept (either sign).
inline constexpr double kMaxTemperatureRise = 50.0;

/// One effect's cost along a trajectory: the observation point's error [m] with the motors exactly
/// at their targets (quasi-static, as StrategyRun::twist_only; the servos' own error is the same
/// with and without the effect).
struct EffectCost {
  std::string effect;            ///< "load", "play", "heat" (each alone on otherwise rigid legs) or "all"
  ErrorStats conventional;       ///< commands that ignore the twist and the legs' effects
  ErrorStats twist_compensated;  ///< Eq. (12): the twist compensated, the effect not (a rigid-leg model's commands)
  ErrorStats compensated;        ///< the twist and the effect compensated (compensation.hpp), the legs' forces
                                 ///< known along the run (the trajectory's accelerations included)
  /// The twist and the effect compensated with the static load alone: the commands of ik, stream,
  /// the C API and LinuxCNC, which know the pose but not the trajectory's accelerations. The same
  /// as compensated without a stiffness.
  ErrorStats static_load_compensated;
};

/// The share of a warm-up reached at `time` of a run of `duration` [s]:
/// (1 - exp(-t / T)) / (1 - exp(-1)) with T = duration, 0 at the start and 1 at the end (a motor's
/// and a screw's warm-up, whose time constant is of the run's length); 0 for a run of no duration.
/// The temperature history of synth's and of effect_costs' warming legs.
[[nodiscard]] double warm_up_share(double time, double duration) noexcept;

/// Why `temperature_rise` [K per leg] cannot be used on `model` (empty when it can): a value that is
/// not finite or beyond +-kMaxTemperatureRise, or a rise on legs that do not expand (it would change
/// nothing). The front ends put their argument's name before it.
[[nodiscard]] std::string_view check_temperature_rise(const Model& model, const Vector6d& temperature_rise) noexcept;

/// One row per effect the model's legs have: "load" (a finite stiffness, under the configuration's
/// static load and the trajectory's accelerations: dynamics/leg_forces.hpp), "play", "heat" (an expansion and a
/// `temperature_rise` [K] per leg other than zero, reached at the trajectory's end along warm_up_share from the
/// reference temperature), then "all" (the model's legs) when there are two or more; none for rigid legs. The
/// compensated commands know the legs' temperatures (sensors on the legs) and follow each leg's direction from home;
/// the plant's nuts follow the motors through their play's dead band (NutGap). Returns InvalidArgument for a
/// temperature_rise check_temperature_rise refuses, else the first failure's status with `issue` saying where (a limit
/// of the commands, the plant's forward kinematics); `out` is complete only on Ok.
[[nodiscard]] Status effect_costs(const Rig& rig, const Trajectory& trajectory, const Vector6d& temperature_rise,
                                  std::vector<EffectCost>& out, SimulationIssue& issue);

}  // namespace hexatwist
