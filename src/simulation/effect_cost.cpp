// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/simulation/effect_cost.hpp"

#include <cmath>
#include <limits>
#include <string_view>
#include <tuple>

#include "hexatwist/dynamics/leg_forces.hpp"
#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/kinematics/forward.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "simulation_internal.hpp"

namespace hexatwist {

double warm_up_share(double time, double duration) noexcept {
  if (!(duration > 0.0)) return 0.0;
  return (1.0 - std::exp(-time / duration)) / (1.0 - std::exp(-1.0));
}

namespace {

// The model's legs with the effects `effect` names ("load", "play", "heat", "all") and no other:
// "" gives rigid legs.
Model with_effect(const Model& model, std::string_view effect) {
  ModelSpec spec = model.spec();
  const bool all = effect == "all";
  for (std::size_t i = 0; i < spec.legs.size(); ++i) {
    LegSpec& leg = spec.legs[i];
    if (!all && effect != "load") leg.stiffness = std::numeric_limits<double>::infinity();
    if (!all && effect != "play") leg.play = 0.0;
    if (!all && effect != "heat") leg.length_expansion = leg.lead_expansion = 0.0;
  }
  return Model(spec);
}

// The observation point's error along `trajectory` for the commands of `controller` with
// `strategy` sent to `plant`'s legs, the motors exactly at their commands. The plant's legs carry
// `force` (one per sample: the static load and the motion's inertia; empty: the static load
// alone); the commands know it when `commands_know_force`, else they compensate the static load.
Status quasi_static(const Model& plant, const Model& controller, Strategy strategy, const Trajectory& trajectory,
                    const Vector6d& temperature_rise, const std::vector<Vector6d>& force, bool commands_know_force,
                    ErrorStats& out, SimulationIssue& issue) {
  const std::size_t n = trajectory.poses.size();
  const double duration = trajectory.duration();
  const Vector3d& obs = plant.spec().observation_P;
  PlayState play;
  start_play(controller, controller.home_command(), play);
  NutGap nuts;
  FkResult fk;
  Placement guess = placement_from_pose(trajectory.poses[0]);
  std::vector<double> error(n);
  for (std::size_t k = 0; k < n; ++k) {
    LegInputs inputs;
    const double share = warm_up_share(trajectory.time(k) - trajectory.time(0), duration);
    for (int i = 0; i < kLegs; ++i) inputs.temperature[i] = plant.reference_temperature() + temperature_rise[i] * share;
    LegInputs real = inputs;
    if (!force.empty()) real.force = force[k];
    Vector6d command;
    LimitReport limit;
    if (const Status s = motor_commands(controller, trajectory.poses[k], strategy, commands_know_force ? real : inputs,
                                        &play, command, limit);
        s != Status::Ok)
      return detail::fail_at(issue, s, k, trajectory, limit);
    const Vector6d direction = follow_nuts(plant, command, inputs.temperature, nuts);
    if (const Status s = forward_kinematics(plant, command, real, &direction, guess, fk); s != Status::Ok)
      return detail::fail_at(issue, s, k, trajectory);
    guess = fk.placement;
    const Placement desired = placement_from_pose(trajectory.poses[k]);
    error[k] = (platform_point_B(plant, fk.placement, obs) - platform_point_B(plant, desired, obs)).norm();
  }
  out = error_stats(error);
  return Status::Ok;
}

}  // namespace

std::string_view check_temperature_rise(const Model& model, const Vector6d& temperature_rise) noexcept {
  if (!(temperature_rise.allFinite() && temperature_rise.cwiseAbs().maxCoeff() <= kMaxTemperatureRise))
    return "expected a finite temperature rise within -50 to 50 K over the run";
  if (!model.has_thermal() && temperature_rise.any())
    return "the configuration's legs do not expand (leg_effects: length_expansion, lead_expansion), so a warm-up "
           "changes nothing";
  return {};
}

Status effect_costs(const Rig& rig, const Trajectory& trajectory, const Vector6d& temperature_rise,
                    std::vector<EffectCost>& out, SimulationIssue& issue) {
  const Model& model = rig.model();
  out.clear();
  issue = SimulationIssue{};
  if (!check_temperature_rise(model, temperature_rise).empty()) {
    issue.status = issue.limit.status = Status::InvalidArgument;
    return Status::InvalidArgument;
  }
  if (trajectory.poses.empty()) return Status::Ok;
  const bool heat = model.has_thermal() && temperature_rise.cwiseAbs().maxCoeff() > 0.0;
  std::vector<std::string> effects;
  if (model.has_stiffness()) effects.emplace_back("load");
  if (model.has_play()) effects.emplace_back("play");
  if (heat) effects.emplace_back("heat");
  if (effects.size() > 1) effects.emplace_back("all");
  if (effects.empty()) return Status::Ok;
  // The legs' forces along the run, the trajectory's accelerations included (dynamics/leg_forces.hpp).
  std::vector<Vector6d> force;
  if (model.has_stiffness() && trajectory.poses.size() > 1) {
    std::size_t at = 0;
    if (const Status s = trajectory_leg_forces(rig, trajectory, force, at); s != Status::Ok)
      return detail::fail_at(issue, s, at, trajectory);
  }
  const Model rigid = with_effect(model, "");
  for (const std::string& effect : effects) {
    const Model plant = effect == "all" ? model : with_effect(model, effect);
    EffectCost& row = out.emplace_back();
    row.effect = effect;
    const bool loaded = plant.has_stiffness();
    for (auto [controller, strategy, know, stats] :
         {std::tuple{&rigid, Strategy::Conventional, true, &row.conventional},
          std::tuple{&rigid, Strategy::Compensated, true, &row.twist_compensated},
          std::tuple{&plant, Strategy::Compensated, true, &row.compensated},
          std::tuple{&plant, Strategy::Compensated, false, &row.static_load_compensated}}) {
      if (!know && !loaded) {  // without a stiffness the forces change nothing
        *stats = row.compensated;
        continue;
      }
      if (const Status s =
              quasi_static(plant, *controller, strategy, trajectory, temperature_rise, force, know, *stats, issue);
          s != Status::Ok) {
        out.clear();
        return s;
      }
    }
  }
  return Status::Ok;
}

}  // namespace hexatwist
