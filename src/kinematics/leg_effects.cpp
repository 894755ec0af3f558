#include "hexatwist/kinematics/leg_effects.hpp"

#include <Eigen/LU>
#include <cmath>

namespace hexatwist {

Status static_leg_forces(const Model& model, const StaticLoadSpec& load, const LegState& legs,
                         Vector6d& force) noexcept {
  if (!load.present) return Status::InvalidArgument;
  // The generalised force of gravity for the platform twist [dt; dw] about the pivot (theory
  // §4b): the load's weight at its centre of mass, and each leg's housing and rod, whose centres
  // move with the leg's axis: f_i = m_r g + (m_h c_h - m_r c_r) / l_i (g - (s_i . g) s_i) at the
  // platform joint.
  const Vector3d g(0.0, 0.0, -load.gravity);
  const Vector3d weight = load.mass * g;
  const Vector3d com_B = legs.R_BP * (load.center_of_mass_P - model.spec().pivot_P);
  Vector3d G_force = weight, G_moment = com_B.cross(weight);
  Matrix6d Jt;  // columns: the length Jacobian's rows [s_i; a_i x s_i]
  for (int i = 0; i < kLegs; ++i) {
    const Vector3d s = legs.s_B.row(i).transpose();
    const Vector3d a = legs.arm_B.row(i).transpose();
    const Vector3d f = load.rod_mass * g + (load.leg_moment / legs.length[i]) * (g - s.dot(g) * s);
    G_force += f;
    G_moment += a.cross(f);
    Jt.col(i) << s, a.cross(s);
  }
  Vector6d G;
  G << G_force, G_moment;
  // J^T F = G: the legs' tensions pull the platform towards the base and balance gravity.
  const Eigen::PartialPivLU<Matrix6d> lu(Jt);
  if (!(std::abs(lu.determinant()) > 0.0)) return Status::SingularJacobian;
  force = lu.solve(G);
  return force.allFinite() ? Status::Ok : Status::NonFiniteInput;
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
  const Vector6d& half = model.geometry().half_play;
  const Vector6d& home = model.geometry().home_direction;
  if (!nuts.started) {
    nuts.started = true;
    nuts.gap = -half.cwiseProduct(home);
    nuts.last = motor;
  }
  nuts.gap = (nuts.gap - (motor - nuts.last)).cwiseMax(-half).cwiseMin(half);
  nuts.last = motor;
  Vector6d direction = home;
  for (int i = 0; i < kLegs; ++i)
    if (half[i] > 0.0) direction[i] = -nuts.gap[i] / half[i];
  return direction;
}

Status resolve_inputs(const Model& model, const LegState& legs, const LegInputs& inputs, Vector6d& force,
                      Vector6d& temperature) noexcept {
  for (int i = 0; i < kLegs; ++i)
    if (std::isinf(inputs.force[i]) || std::isinf(inputs.temperature[i])) return Status::NonFiniteInput;
  temperature = inputs.temperature;
  for (int i = 0; i < kLegs; ++i)
    if (std::isnan(temperature[i])) temperature[i] = model.reference_temperature();
  force = inputs.force;
  if (!model.has_stiffness()) {
    force = force.unaryExpr([](double f) { return std::isnan(f) ? 0.0 : f; });
    return Status::Ok;
  }
  if (force.array().isNaN().any()) {
    Vector6d load;
    if (const Status s = static_leg_forces(model, model.spec().static_load, legs, load); s != Status::Ok) return s;
    for (int i = 0; i < kLegs; ++i)
      if (std::isnan(force[i])) force[i] = load[i];
  }
  return Status::Ok;
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

}  // namespace

void travel_under_effects(const Model& model, const Vector6d& u0, const Vector6d& twist_term, const Vector6d& force,
                          const Vector6d& temperature, const Vector6d& direction, Vector6d& travel,
                          LegEffects* effects) noexcept {
  const LegGeometry& g = model.geometry();
  LegEffects e;
  fixed_parts(model, force, temperature, direction, e);
  const Vector6d dT = temperature.array() - model.reference_temperature();
  // u + E(u) = u0 with E linear in w = u - h + k dtheta: w = (u0 - h + k dtheta - E_fixed) / (1 + a_P dT).
  const Vector6d fixed = e.load + dT.cwiseProduct(g.thermal_length) + e.play;
  const Vector6d aP_dT = g.lead_expansion.cwiseProduct(dT);
  const Vector6d w = (u0 - g.home_command + twist_term - fixed).cwiseQuotient(Vector6d::Ones() + aP_dT);
  e.thermal = dT.cwiseProduct(g.thermal_length) + aP_dT.cwiseProduct(w);
  e.total = e.load + e.thermal + e.play;
  travel = u0 - e.total;
  if (effects != nullptr) *effects = e;
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
