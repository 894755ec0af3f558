// SPDX-License-Identifier: BSD-3-Clause
// The drives' losses (docs/theory/dynamics.md §14, "Friction and efficiency"): viscous and dry
// friction at the motor shaft, and the screw's efficiency loss in the thread, decided by the power
// that passes through the thread, which slides at the real length rate.
#include <cmath>

#include "dynamics/mechanism_bodies.hpp"

namespace hexatwist {

Vector6d drive_friction(const Rig& rig, const Vector6d& speed) noexcept {
  const ServoSpec& sv = rig.servo();
  return sv.viscous_friction * speed + sv.coulomb_friction * (speed / sv.friction_speed).array().tanh().matrix();
}

Vector6d thread_loss(const Rig& rig, const Vector6d& thread_speed, const Vector6d& screw_torque) noexcept {
  const MechanismSpec& mech = rig.mechanism();
  // Per unit of the power through the thread: driving (the screw pushes the nut), 1/eta - 1 more
  // at the motor; driven back, 1 - eta' less (theory §14).
  const double driving = 1.0 / mech.efficiency - 1.0, driven = 1.0 - mech.back_efficiency;
  const double inv_speed = 1.0 / rig.servo().friction_speed;
  Vector6d loss;
  for (int i = 0; i < kLegs; ++i) {
    const double share = screw_torque[i] * thread_speed[i] > 0.0 ? driving : driven;
    // Opposes the sliding, smoothed over the dry friction's speed: the dissipation
    // loss * thread_speed = share |tau_s| tanh(w_t / w_f) w_t is never negative.
    loss[i] = share * std::abs(screw_torque[i]) * std::tanh(thread_speed[i] * inv_speed);
  }
  return loss;
}

namespace detail {

Vector6d thread_speeds(const Mechanism& mech) noexcept {
  Vector6d w;
  for (int i = 0; i < kLegs; ++i) {
    const LegMotion& m = mech.legs[static_cast<std::size_t>(i)];
    w[i] = m.l_dot / m.c;
  }
  return w;
}

Vector6d thread_force(const Mechanism& mech, const Vector6d& loss) noexcept {
  // The pair acts on the screw and, reversed, on the nut: its virtual power is loss_i times the
  // thread's sliding, delta(l_i') / c_i, so it enters as the force loss_i / c_i along the leg at the
  // platform joint (length_jacobian's row).
  Vector6d Q = Vector6d::Zero();
  for (int i = 0; i < kLegs; ++i) {
    const LegMotion& m = mech.legs[static_cast<std::size_t>(i)];
    const Vector3d F = (loss[i] / m.c) * m.s;
    Q.head<3>() += F;
    Q.tail<3>() += m.a.cross(F);
  }
  return Q;
}

}  // namespace detail
}  // namespace hexatwist
