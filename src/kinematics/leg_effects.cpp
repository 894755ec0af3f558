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

bool detail::needs_static_forces(const Model& model, const LegInputs& inputs) noexcept {
  return model.has_stiffness() && inputs.force.array().isNaN().any();
}

namespace {

/// The status for inputs check_leg_inputs refuses; Ok for the others.
Status input_status(const LegInputs& inputs) noexcept {
  Status s = Status::Ok;
  for (int i = 0; i < kLegs; ++i) {
    const double t = inputs.temperature[i];
    if (std::isinf(inputs.force[i]) || std::isinf(t)) return Status::NonFiniteInput;
    if (!(std::isnan(t) || (t >= kMinTemperature && t <= kMaxTemperature))) s = Status::InvalidArgument;
  }
  return s;
}

}  // namespace

std::string_view check_leg_inputs(const LegInputs& inputs) noexcept {
  for (int i = 0; i < kLegs; ++i) {
    const double t = inputs.temperature[i];
    if (!(std::isnan(t) || (t >= kMinTemperature && t <= kMaxTemperature)))
      return "inputs.temperature must be from -60 to 200 degC, or NaN for the reference temperature";
    if (std::isinf(inputs.force[i])) return "inputs.force must be finite [N], or NaN for the static force";
  }
  return {};
}

Status detail::resolve_inputs(const Model& model, const LegInputs& inputs, Status static_status,
                              const Vector6d& static_force, Vector6d& force, Vector6d& temperature) noexcept {
  if (const Status s = input_status(inputs); s != Status::Ok) return s;
  temperature = inputs.temperature;
  for (int i = 0; i < kLegs; ++i)
    if (std::isnan(temperature[i])) temperature[i] = model.reference_temperature();
  force = inputs.force;
  if (!model.has_stiffness()) {
    force = force.unaryExpr([](double f) { return std::isnan(f) ? 0.0 : f; });
    return Status::Ok;
  }
  if (needs_static_forces(model, inputs)) {
    if (static_status != Status::Ok) return static_status;
    for (int i = 0; i < kLegs; ++i)
      if (std::isnan(force[i])) force[i] = static_force[i];
  }
  return Status::Ok;
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
  for (int i = 0; i < kLegs; ++i) d[i] = travel[i] > last[i] ? 1.0 : travel[i] < last[i] ? -1.0 : kept[i];
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
    nuts.started = true;
    nuts.gap = -half.cwiseProduct(home);
    nuts.last = motor;
  }
  // The thread moves by the motor-side change times the warm lead's scale 1 + a_P dT.
  const Vector6d scale = Vector6d::Ones() + model.geometry().lead_expansion.cwiseProduct(
                                                temperature - Vector6d::Constant(model.reference_temperature()));
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
  e.play = -g.half_play.cwiseProduct(direction - g.home_direction);
}

// u + E(u) = u0 with E linear in w = u - h + k dtheta (leg_effects.hpp): with the home direction
// (no play term), w = (u0 - h + k dtheta - E_fixed) / (1 + a_P dT) and u = u0 - E; the play's
// term p then moves u by -p / (1 + a_P dT). `scale` gets 1 + a_P dT.
void travel_without_play(const Model& model, const Vector6d& u0, const Vector6d& twist_term, const Vector6d& force,
                         const Vector6d& temperature, Vector6d& travel, Vector6d& scale) noexcept {
  const LegGeometry& g = model.geometry();
  const Vector6d dT = temperature.array() - model.reference_temperature();
  const Vector6d fixed = g.compliance.cwiseProduct(force - model.reference_force()) + dT.cwiseProduct(g.thermal_length);
  const Vector6d aP_dT = g.lead_expansion.cwiseProduct(dT);
  scale = Vector6d::Ones() + aP_dT;
  const Vector6d w = (u0 - g.home_command + twist_term - fixed).cwiseQuotient(scale);
  travel = u0 - fixed - aP_dT.cwiseProduct(w);
}

Vector6d play_term(const Model& model, const Vector6d& direction) noexcept {
  const LegGeometry& g = model.geometry();
  return -g.half_play.cwiseProduct(direction - g.home_direction);
}

}  // namespace

void travel_under_effects(const Model& model, const Vector6d& u0, const Vector6d& twist_term, const Vector6d& force,
                          const Vector6d& temperature, const Vector6d& direction, Vector6d& travel,
                          LegEffects* effects) noexcept {
  Vector6d no_play, scale;
  travel_without_play(model, u0, twist_term, force, temperature, no_play, scale);
  travel = no_play - play_term(model, direction).cwiseQuotient(scale);
  if (effects != nullptr) effect_lengths(model, travel, twist_term, force, temperature, direction, *effects);
}

void detail::command_travel(const Model& model, const Vector6d& u0, const Vector6d& twist_term, const Vector6d& force,
                            const Vector6d& temperature, const PlayState* play, Vector6d& travel, Vector6d& no_play,
                            Vector6d& direction) noexcept {
  Vector6d scale;
  travel_without_play(model, u0, twist_term, force, temperature, no_play, scale);
  direction = play_direction(model, play != nullptr ? *play : PlayState{}, no_play);
  travel = no_play - play_term(model, direction).cwiseQuotient(scale);
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
