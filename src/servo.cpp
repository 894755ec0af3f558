#include "hexatwist/servo.hpp"

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
  // theta' = w, w' = c - B w with c = A^-1 (torque + load) and B = b A^-1, constant over the period.
  const Vector6d c = inverse_inertia * (torque + load_torque);
  const Matrix6d B = rig.servo().viscous_friction * inverse_inertia;
  const double h = rig.plant_step();
  Vector6d& th = drives.angle;
  Vector6d& w = drives.speed;
  for (int n = 0; n < rig.substeps(); ++n) {
    const Vector6d k1w = c - B * w;
    const Vector6d w2 = w + 0.5 * h * k1w;
    const Vector6d k2w = c - B * w2;
    const Vector6d w3 = w + 0.5 * h * k2w;
    const Vector6d k3w = c - B * w3;
    const Vector6d w4 = w + h * k3w;
    const Vector6d k4w = c - B * w4;
    th += (h / 6.0) * (w + 2.0 * w2 + 2.0 * w3 + w4);
    w += (h / 6.0) * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
  }
}

}  // namespace hexatwist
