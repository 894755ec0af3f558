// SPDX-License-Identifier: BSD-3-Clause
// Dynamics of the whole mechanism (docs/theory/dynamics.md §14): inverse and forward dynamics, the
// mass matrix, the energies, and the drives' equation the closed-loop simulation integrates, from
// the bodies' passes over the legs (mechanism_bodies.cpp) and the drives' losses
// (mechanism_losses.cpp).
#include "hexatwist/dynamics/mechanism.hpp"

#include <Eigen/LU>
#include <cmath>

#include "dynamics/mechanism_bodies.hpp"
#include "dynamics/mechanism_internal.hpp"
#include "hexatwist/kinematics/twist.hpp"

namespace hexatwist {
namespace {

using detail::all_forces;
using detail::Forces;
using detail::LegMotion;
using detail::mass_matrix_of;
using detail::Mechanism;
using detail::mechanism_motion;
using detail::motor_jacobian_of;
using detail::PlatformFrame;
using detail::set_velocity;

// LU of J_phi (or its transpose) with a relative determinant check (as leg_dynamics).
Status factor(const Matrix6d& J, Eigen::PartialPivLU<Matrix6d>& lu) noexcept {
  lu.compute(J);
  double scale = 1.0;
  for (int i = 0; i < 6; ++i) scale *= J.row(i).norm();
  if (!(std::abs(lu.determinant()) > 1e-12 * scale)) return Status::SingularJacobian;
  return Status::Ok;
}

}  // namespace

PlatformMotion platform_motion(const Pose& pose, const Vector6d& pose_rate,
                               const Vector6d& pose_acceleration) noexcept {
  PlatformMotion out;
  out.placement = placement_from_pose(pose);
  const double roll = pose.rpy.x(), pitch = pose.rpy.y(), yaw = pose.rpy.z();
  const Vector3d ez = Vector3d::UnitZ();
  const Matrix3d Rz = Eigen::AngleAxisd(yaw, ez).toRotationMatrix();
  const Matrix3d Ry = Eigen::AngleAxisd(pitch, Vector3d::UnitY()).toRotationMatrix();
  const Vector3d e_pitch = Rz * Vector3d::UnitY();      // pitch axis after yaw
  const Vector3d e_roll = Rz * Ry * Vector3d::UnitX();  // roll axis after yaw and pitch
  const double rd = pose_rate[3], pd = pose_rate[4], yd = pose_rate[5];
  const Vector3d w_zy = yd * ez + pd * e_pitch;
  out.velocity.head<3>() = pose_rate.head<3>();
  out.velocity.tail<3>() = w_zy + rd * e_roll;
  out.acceleration.head<3>() = pose_acceleration.head<3>();
  out.acceleration.tail<3>() = pose_acceleration[5] * ez + pose_acceleration[4] * e_pitch +
                               pose_acceleration[3] * e_roll + pd * (yd * ez).cross(e_pitch) + rd * w_zy.cross(e_roll);
  (void)roll;
  return out;
}

Status motor_jacobian(const Rig& rig, const LegState& legs, Matrix6d& J_phi) noexcept {
  Mechanism mech;
  if (const Status s = mechanism_motion(rig, legs, Vector6d::Zero(), mech); s != Status::Ok) return s;
  detail::motor_jacobian_of(mech, J_phi);
  return Status::Ok;
}

Status motor_angles(const Rig& rig, const Placement& placement, Vector6d& angle) noexcept {
  LegState legs;
  if (const Status s = inverse_kinematics(rig.model(), placement, legs); s != Status::Ok) return s;
  Vector6d dtheta;
  if (const Status s = twist(rig.model(), legs, dtheta); s != Status::Ok) return s;
  const Model& model = rig.model();
  angle = (legs.length - model.length_home() - model.geometry().twist_gain.cwiseProduct(dtheta))
              .cwiseQuotient(rig.motor_gain());
  return Status::Ok;
}

Status inverse_dynamics(const Rig& rig, const PlatformMotion& motion, InverseDynamics& out) noexcept {
  const Model& model = rig.model();
  if (!motion.velocity.allFinite() || !motion.acceleration.allFinite()) return Status::NonFiniteInput;
  if (const Status s = inverse_kinematics(model, motion.placement, out.legs_state); s != Status::Ok) return s;
  Vector6d dtheta;
  if (const Status s = twist(model, out.legs_state, dtheta); s != Status::Ok) return s;
  Mechanism mech;
  if (const Status s = mechanism_motion(rig, out.legs_state, motion.velocity, mech); s != Status::Ok) return s;
  Matrix6d J;
  motor_jacobian_of(mech, J);
  Eigen::PartialPivLU<Matrix6d> lu;
  if (const Status s = factor(J.transpose(), lu); s != Status::Ok) return s;

  Forces f;
  all_forces(rig, mech, motion.acceleration, true, f);
  Eigen::Matrix<double, 6, 6> rhs;
  rhs << f.gravity, f.platform, f.velocity, f.legs, f.drives, f.drives_velocity;
  const Eigen::Matrix<double, 6, 6> tau = lu.solve(rhs);
  out.gravity = tau.col(0);
  out.platform_inertia = tau.col(1);
  out.legs = tau.col(3);
  // The drives' share is all of their inertial torque (rotor and screw accelerating with phi'',
  // which has a velocity-product part of its own); velocity_product is that of the other bodies.
  out.drives = tau.col(4) + f.cphi_drives + tau.col(5) + f.cphi_drives_velocity;
  out.velocity_product = tau.col(2);

  for (int i = 0; i < kLegs; ++i) out.speed[i] = mech.legs[static_cast<std::size_t>(i)].phi_dot;
  out.acceleration = f.phi_dd;
  out.angle = (out.legs_state.length - model.length_home() - model.geometry().twist_gain.cwiseProduct(dtheta))
                  .cwiseQuotient(rig.motor_gain());
  // What the screw passes to the load: everything but the drives' own inertia and friction.
  const Vector6d screw_torque = out.gravity + out.platform_inertia + out.legs + tau.col(2);
  out.screw_force = -screw_torque.cwiseQuotient(rig.motor_gain());
  // The thread slides at the real length rate: its loss follows the power through it (theory §14),
  // a torque pair on screw and nut whose share at the motors is J_phi^-T of its generalised force.
  out.thread_speed = detail::thread_speeds(mech);
  const Vector6d loss = thread_loss(rig, out.thread_speed, screw_torque);
  out.thread_dissipation = loss.cwiseProduct(out.thread_speed);
  out.friction = drive_friction(rig, out.speed) + lu.solve(detail::thread_force(mech, loss));
  out.torque = out.gravity + out.platform_inertia + out.velocity_product + out.legs + out.drives + out.friction;
  out.power = out.torque.cwiseProduct(out.speed);
  return Status::Ok;
}

Status mechanism_mass_matrix(const Rig& rig, const Placement& placement, Matrix6d& M) noexcept {
  LegState legs;
  if (const Status s = inverse_kinematics(rig.model(), placement, legs); s != Status::Ok) return s;
  Mechanism mech;
  if (const Status s = mechanism_motion(rig, legs, Vector6d::Zero(), mech); s != Status::Ok) return s;
  Matrix6d M_drives;
  mass_matrix_of(rig, mech, M, M_drives);
  M += M_drives;
  return Status::Ok;
}

Status mechanism_bias(const Rig& rig, const Placement& placement, const Vector6d& velocity, Vector6d& bias) noexcept {
  if (!velocity.allFinite()) return Status::NonFiniteInput;
  LegState legs;
  if (const Status s = inverse_kinematics(rig.model(), placement, legs); s != Status::Ok) return s;
  Mechanism mech;
  if (const Status s = mechanism_motion(rig, legs, velocity, mech); s != Status::Ok) return s;
  Matrix6d J;
  motor_jacobian_of(mech, J);
  Forces f;
  all_forces(rig, mech, Vector6d::Zero(), false, f);
  bias = f.gravity + f.velocity + f.drives_velocity + J.transpose() * f.cphi_drives_velocity;
  return Status::Ok;
}

Status forward_dynamics(const Rig& rig, const Placement& placement, const Vector6d& velocity, const Vector6d& torque,
                        Vector6d& acceleration) noexcept {
  if (!torque.allFinite()) return Status::NonFiniteInput;
  Matrix6d M;
  if (const Status s = mechanism_mass_matrix(rig, placement, M); s != Status::Ok) return s;
  Vector6d bias;
  if (const Status s = mechanism_bias(rig, placement, velocity, bias); s != Status::Ok) return s;
  LegState legs;
  Matrix6d J;
  if (const Status s = inverse_kinematics(rig.model(), placement, legs); s != Status::Ok) return s;
  if (const Status s = motor_jacobian(rig, legs, J); s != Status::Ok) return s;
  const Eigen::LLT<Matrix6d> llt(M);
  if (llt.info() != Eigen::Success) return Status::SingularJacobian;
  acceleration = llt.solve(J.transpose() * torque - bias);
  return Status::Ok;
}

Status kinetic_energy(const Rig& rig, const Placement& placement, const Vector6d& velocity, double& energy) noexcept {
  LegState legs;
  if (const Status s = inverse_kinematics(rig.model(), placement, legs); s != Status::Ok) return s;
  Mechanism mech;
  if (const Status s = mechanism_motion(rig, legs, velocity, mech); s != Status::Ok) return s;
  const PlatformFrame& p = mech.platform;
  const Vector3d vc = mech.v + mech.w.cross(p.c);
  double T = 0.5 * rig.load().mass * vc.squaredNorm() + 0.5 * mech.w.dot(p.I * mech.w);
  const MechanismSpec& mc = rig.mechanism();
  const ServoSpec& sv = rig.servo();
  for (const LegMotion& m : mech.legs) {
    const double sd2 = m.s_dot.squaredNorm();  // |s x s'|^2: the transverse angular speed squared
    const double wD = m.rotor_on_rod ? m.wr : m.wh;
    T += 0.5 * mc.housing.mass * mc.housing.center * mc.housing.center * sd2 +
         0.5 * mc.housing.transverse_inertia * sd2 + 0.5 * mc.housing.axial_inertia * m.wh * m.wh;
    T += 0.5 * mc.rod.mass * (m.u - mc.rod.center * m.s_dot).squaredNorm() + 0.5 * mc.rod.transverse_inertia * sd2 +
         0.5 * mc.rod.axial_inertia * m.wr * m.wr;
    const double rotor = wD + m.eps * m.phi_dot;
    const double screw = wD + m.eps * m.phi_dot / sv.gear_ratio;
    T += 0.5 * sv.motor_inertia * rotor * rotor + 0.5 * sv.screw_inertia * screw * screw;
  }
  energy = T;
  return Status::Ok;
}

Status potential_energy(const Rig& rig, const Placement& placement, double& energy) noexcept {
  const Model& model = rig.model();
  LegState legs, home;
  if (const Status s = inverse_kinematics(model, placement, legs); s != Status::Ok) return s;
  if (const Status s = inverse_kinematics(model, Placement{}, home); s != Status::Ok) return s;
  const MechanismSpec& mc = rig.mechanism();
  const double g = rig.load().gravity;
  // Height of every centre of mass relative to home.
  const auto height = [&](const LegState& st) {
    const Vector3d c = model.pivot_home_B() + (st.R_BP * (rig.load().center_of_mass_P - model.spec().pivot_P));
    double h = rig.load().mass * c.z();
    for (int i = 0; i < kLegs; ++i) {
      const Vector3d s = st.s_B.row(i).transpose();
      const Vector3d base = model.leg(i).base_B;
      const Vector3d top = base + st.leg_B.row(i).transpose();
      h += mc.housing.mass * (base + mc.housing.center * s).z() + mc.rod.mass * (top - mc.rod.center * s).z();
    }
    return h;
  };
  energy = g * (height(legs) + rig.load().mass * placement.t.z() - height(home));
  return Status::Ok;
}

namespace detail {

Status drive_load(const Rig& rig, const LegState& legs, const Vector6d& speed, const Vector6d& motor_acceleration,
                  bool twist, DriveLoad& out) noexcept {
  Mechanism mech;
  if (const Status s = mechanism_motion(rig, legs, Vector6d::Zero(), mech, twist); s != Status::Ok) return s;
  motor_jacobian_of(mech, out.jacobian);
  Eigen::PartialPivLU<Matrix6d> lu;
  if (const Status s = factor(out.jacobian, lu); s != Status::Ok) return s;
  const Vector6d velocity = lu.solve(speed);
  set_velocity(velocity, mech);
  Matrix6d M_load, M_drives;
  mass_matrix_of(rig, mech, M_load, M_drives);
  Forces f;
  all_forces(rig, mech, Vector6d::Zero(), false, f);
  const Vector6d bias_load = f.gravity + f.velocity;
  const Vector6d bias = bias_load + f.drives_velocity + out.jacobian.transpose() * f.cphi_drives_velocity;
  const Vector6d& a_b = f.phi_dd_bias;  // the velocity-product part of the motor acceleration, J_phi' x'
  // In motor angles: A phi'' = tau_net + L with A = J^-T M J^-1 and L = J^-T (M J^-1 a_b - bias);
  // A^-1 = J M^-1 J^T, from the Cholesky factor of M.
  const Matrix6d M = M_load + M_drives;
  const Eigen::LLT<Matrix6d> llt(M);
  if (llt.info() != Eigen::Success) return Status::SingularJacobian;
  out.inverse_inertia.noalias() = out.jacobian * llt.solve(out.jacobian.transpose());
  out.load = lu.transpose().solve(Vector6d(M * lu.solve(a_b) - bias));
  // What the screw passes to the load at the motor acceleration given.
  const Vector6d x_dd = lu.solve(motor_acceleration - a_b);
  out.screw_torque = lu.transpose().solve(Vector6d(M_load * x_dd + bias_load));
  // The thread's losses at the motors, from the power through the thread (theory §14).
  const Vector6d loss = thread_loss(rig, thread_speeds(mech), out.screw_torque);
  out.thread_loss = lu.transpose().solve(thread_force(mech, loss));
  out.velocity = velocity;
  return Status::Ok;
}

}  // namespace detail

double peak_torque_at(const ServoSpec& servo, double speed) noexcept {
  const double w = std::abs(speed);
  if (!(w <= servo.max_speed)) return 0.0;
  if (w <= servo.peak_corner_speed) return servo.torque_limit;
  const double span = servo.max_speed - servo.peak_corner_speed;
  if (!(span > 0.0)) return servo.peak_torque_at_max_speed;
  const double f = (w - servo.peak_corner_speed) / span;
  return servo.torque_limit + f * (servo.peak_torque_at_max_speed - servo.torque_limit);
}

}  // namespace hexatwist
