// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/simulation/servo.hpp"

#include <cmath>

namespace hexatwist {

void read_encoder(const Rig& rig, const Vector6d& angle, Vector6d& measured) noexcept {
  const double step = rig.encoder_step();
  for (int i = 0; i < kLegs; ++i) measured[i] = std::floor(angle[i] / step) * step;
}

void start_controller(const Rig& rig, const Vector6d& measured, const Vector6d& holding_torque,
                      ControllerState& state) noexcept {
  state = ControllerState{};
  state.last_measured = measured;
  for (int i = 0; i < kLegs; ++i) state.integral[i] = rig.ki()[i] > 0.0 ? holding_torque[i] / rig.ki()[i] : 0.0;
}

void update_controller(const Rig& rig, const ServoReference& reference, const Vector6d& measured,
                       ControllerState& state, Vector6d& torque) noexcept {
  const ServoSpec& s = rig.servo();
  const double T = rig.control_period();
  const double limit = s.torque_limit;
  bool saturated = false;
  for (int i = 0; i < kLegs; ++i) {
    const double e = reference.angle[i] - measured[i];
    const double speed = (measured[i] - state.last_measured[i]) / T;
    const double rest = rig.kp()[i] * e + rig.kd()[i] * (reference.speed[i] - speed) +
                        s.velocity_feedforward * s.viscous_friction * reference.speed[i] +
                        s.acceleration_feedforward * rig.nominal_inertia()[i] * reference.acceleration[i];
    double integral = state.integral[i] + e * T;
    const double ki = rig.ki()[i];
    if (ki > 0.0) integral = std::clamp(integral, -limit / ki, limit / ki);
    const double u = rest + ki * integral;
    // Anti-windup by conditional integration: keep the old integral when the new one would drive
    // the output further into saturation.
    if (std::abs(u) > limit && (u > 0.0) == (e > 0.0)) integral = state.integral[i];
    const double raw = rest + ki * integral;
    torque[i] = std::clamp(raw, -limit, limit);
    saturated = saturated || std::abs(raw) > limit;
    state.integral[i] = integral;
  }
  state.last_measured = measured;
  if (saturated) ++state.saturated_ticks;
}

void integrate_drives(const Rig& rig, const Matrix6d& inverse_inertia, const Vector6d& load_torque,
                      const Vector6d& torque, DriveState& drives) noexcept {
  const ServoSpec& sv = rig.servo();
  const double b = sv.viscous_friction;
  const double tc = sv.coulomb_friction;
  const double inv_wf = 1.0 / sv.friction_speed;
  const double T = sv.torque_time_constant;
  const double h = rig.plant_step();
  // State (theta, w, tau_m): theta' = w, w' = A^-1 (tau_m - b w - tc tanh(w / wf) + load),
  // tau_m' = (torque - tau_m) / T (tau_m = torque when T = 0).
  struct Rates {
    Vector6d w, dw, dtau;
  };
  const auto rates = [&](const Vector6d& w, const Vector6d& tau) {
    Rates r;
    r.w = w;
    const Vector6d friction = b * w + tc * (w * inv_wf).array().tanh().matrix();
    r.dw.noalias() = inverse_inertia * (tau - friction + load_torque);
    r.dtau = T > 0.0 ? Vector6d((torque - tau) / T) : Vector6d::Zero();
    return r;
  };
  Vector6d& th = drives.angle;
  Vector6d& w = drives.speed;
  Vector6d& tau = drives.torque;
  if (T <= 0.0) tau = torque;
  for (int n = 0; n < rig.substeps(); ++n) {
    const Rates k1 = rates(w, tau);
    const Rates k2 = rates(w + 0.5 * h * k1.dw, tau + 0.5 * h * k1.dtau);
    const Rates k3 = rates(w + 0.5 * h * k2.dw, tau + 0.5 * h * k2.dtau);
    const Rates k4 = rates(w + h * k3.dw, tau + h * k3.dtau);
    th += (h / 6.0) * (k1.w + 2.0 * k2.w + 2.0 * k3.w + k4.w);
    w += (h / 6.0) * (k1.dw + 2.0 * k2.dw + 2.0 * k3.dw + k4.dw);
    tau += (h / 6.0) * (k1.dtau + 2.0 * k2.dtau + 2.0 * k3.dtau + k4.dtau);
  }
}

}  // namespace hexatwist
