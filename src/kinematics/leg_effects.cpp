// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/leg_effects.hpp"

#include <cmath>

#include "kinematics/leg_effects_internal.hpp"

namespace hexatwist {
Status static_leg_forces(const Model& model, const StaticLoadSpec& load, const LegState& legs,
                         Vector6d& force) noexcept {
  // The generalised force of gravity for the platform twist [dt; dw] about the pivot (theory
  // §4b), and J^T F = G (leg_effects_internal.hpp).
  const double w = 1.0 / model.condition_length();
  detail::LegLoads loads;
  detail::ColumnPackets A;
  for (int k = 0; k < detail::kPackets; ++k) {
    const detail::lanes3 s = detail::load6(legs.s_B, k), arm = detail::load6(legs.arm_B, k);
    const detail::lanes3 arm_x_s = detail::splat<detail::lane_v>(w) * detail::cross(arm, s);
    A.set(k, {s.x, s.y, s.z, arm_x_s.x, arm_x_s.y, arm_x_s.z});
    detail::add_leg_loads(load, s, arm, 1.0 / detail::load6(legs.length.data(), k), k, loads);
  }
  detail::PaddedRows rows;
  A.rows(rows);
  return detail::finish_leg_forces(model, load, legs.R_BP, loads, rows, force);
}

std::string_view check_leg_inputs(const LegInputs& inputs) noexcept {
  // The commands' decision (detail::input_status), worded: an infinite temperature is out of range.
  if (detail::input_status(inputs) == Status::Ok) return {};
  for (const double t : inputs.temperature)
    if (!(std::isnan(t) || (t >= kMinTemperature && t <= kMaxTemperature)))
      return "inputs.temperature must be from -60 to 200 degC, or NaN for the reference temperature";
  return "inputs.force must be finite [N], or NaN for the static force";
}

Status resolve_inputs(const Model& model, const LegState& legs, const LegInputs& inputs, Vector6d& force,
                      Vector6d& temperature) noexcept {
  Vector6d static_force = Vector6d::Zero();
  const Status static_status = detail::needs_static_forces(model, inputs)
                                   ? static_leg_forces(model, model.spec().static_load, legs, static_force)
                                   : Status::Ok;
  return detail::resolve_inputs(model, inputs, static_status, static_force, force, temperature);
}

void start_play(const Model& model, const Vector6d& travel, PlayState& play) noexcept {
  play.started = true;
  play.direction = model.geometry().home_direction;
  play.last = travel;
}

Vector6d play_direction(const Model& model, const PlayState& play, const Vector6d& travel) noexcept {
  const Vector6d& last = play.started ? play.last : model.geometry().home_command;
  const Vector6d& kept = play.started ? play.direction : model.geometry().home_direction;
  Vector6d d;
  for (int k = 0; k < detail::kPackets; ++k)
    detail::store6(d.data(),
                   detail::direction_of(detail::load6(travel.data(), k), detail::load6(last.data(), k),
                                        detail::load6(kept.data(), k)),
                   k);
  return d;
}

void advance_play(PlayState& play, const Vector6d& travel, const Vector6d& direction) noexcept {
  play.started = true;
  play.direction = direction;
  play.last = travel;
}

Vector6d follow_nuts(const Model& model, const Vector6d& motor, NutGap& nuts) noexcept {
  return follow_nuts(model, motor, Vector6d::Constant(model.reference_temperature()), nuts);
}

Vector6d follow_nuts(const Model& model, const Vector6d& motor, const Vector6d& temperature, NutGap& nuts) noexcept {
  const Vector6d& half = model.geometry().half_play;
  const Vector6d& home = model.geometry().home_direction;
  if (!nuts.started) {
    // Where homing left them: at the drives' reference, each nut on its home_direction's side; the
    // first call moves them from there, as the commands' PlayState starts there (start_play).
    nuts.started = true;
    nuts.gap = -half.cwiseProduct(home);
    nuts.last = model.home_command();
  }
  // The thread moves by the motor-side change times the drive's scale (the real lead over the lead
  // the drive computes with, theory §4) and the warm lead's 1 + a_P dT.
  const Vector6d scale = model.geometry().drive_scale.cwiseProduct(
      Vector6d::Ones() +
      model.geometry().lead_expansion.cwiseProduct(temperature - Vector6d::Constant(model.reference_temperature())));
  nuts.gap = (nuts.gap - (motor - nuts.last).cwiseProduct(scale)).cwiseMax(-half).cwiseMin(half);
  nuts.last = motor;
  Vector6d direction = home;
  for (int i = 0; i < kLegs; ++i)
    if (half[i] > 0.0) direction[i] = -nuts.gap[i] / half[i];
  return direction;
}

namespace {

// The parts of E that do not depend on the travel: the load, the length's expansion and the play.
void fixed_parts(const Model& model, const Vector6d& force, const Vector6d& temperature, const Vector6d& direction,
                 LegEffects& e) noexcept {
  const LegGeometry& g = model.geometry();
  e.force = force;
  e.temperature = temperature;
  e.direction = direction;
  e.load = g.compliance.cwiseProduct(force - model.reference_force());
  e.play = detail::play_term(model, direction);
}

}  // namespace

void travel_under_effects(const Model& model, const Vector6d& u0, const Vector6d& twist_term, const Vector6d& force,
                          const Vector6d& temperature, const Vector6d& direction, Vector6d& travel,
                          LegEffects* effects) noexcept {
  Vector6d d = direction;
  detail::travel_in_lanes(model, u0, twist_term, force, temperature, nullptr, nullptr, d, travel, nullptr);
  if (effects != nullptr) effect_lengths(model, travel, twist_term, force, temperature, direction, *effects);
}

void effect_lengths(const Model& model, const Vector6d& travel, const Vector6d& twist_term, const Vector6d& force,
                    const Vector6d& temperature, const Vector6d& direction, LegEffects& effects) noexcept {
  const LegGeometry& g = model.geometry();
  fixed_parts(model, force, temperature, direction, effects);
  const Vector6d dT = temperature.array() - model.reference_temperature();
  effects.thermal =
      dT.cwiseProduct(g.thermal_length + g.lead_expansion.cwiseProduct(travel - g.home_command + twist_term));
  effects.total = effects.load + effects.thermal + effects.play;
}

}  // namespace hexatwist
