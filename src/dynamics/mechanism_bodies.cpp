// SPDX-License-Identifier: BSD-3-Clause
// The bodies of the mechanism (docs/theory/dynamics.md §14; the symbols below are the section's):
// velocities and accelerations of every body from the platform's motion, Newton-Euler on each
// body projected onto the platform's coordinates by virtual power, and the mass matrix from the
// kinetic energy.
#include "dynamics/mechanism_bodies.hpp"

#include <cmath>

#include "kinematics/geometry.hpp"

namespace hexatwist::detail {
namespace {

// Below this |j x s|^2 a U-joint is at its singularity: the spin of its body is undefined.
constexpr double kSingularSpin = 1e-12;

// f for axis j at leg axis s.
Vector3d spin_f(const Vector3d& j, const Vector3d& s) noexcept {
  const Vector3d u = j.cross(s);
  return (j.dot(s) / u.squaredNorm()) * u;
}

// f' for the axis moving at j' and the leg axis at s'.
Vector3d spin_f_dot(const Vector3d& j, const Vector3d& j_dot, const Vector3d& s, const Vector3d& s_dot) noexcept {
  const double g = j.dot(s);
  const Vector3d u = j.cross(s);
  const double q = u.squaredNorm();
  const double g_dot = j_dot.dot(s) + j.dot(s_dot);
  const Vector3d u_dot = j_dot.cross(s) + j.cross(s_dot);
  const double q_dot = 2.0 * u.dot(u_dot);
  return ((g_dot * u + g * u_dot) - (g * q_dot / q) * u) / q;
}

// The parts that depend on the pose only.
Status leg_position(const Rig& rig, const LegState& legs, int i, bool twist, LegMotion& m) noexcept {
  const Model& model = rig.model();
  const Leg& leg = model.leg(i);
  m.s = legs.s_B.row(i).transpose();
  m.a = legs.arm_B.row(i).transpose();
  m.l = legs.length[i];
  m.k = twist ? leg.twist_gain : 0.0;
  m.c = rig.motor_gain()[i];
  m.rotor_on_rod = leg.driven == DrivenSide::Platform;
  m.eps = m.rotor_on_rod ? leg.twist_sign : -leg.twist_sign;
  m.has_axes = model.geometry().has_axes[i] != 0.0;
  if (!m.has_axes) {
    // No U-joint axes given: the bodies do not spin about the leg (and there is no twist).
    m.fa.f.setZero();
    m.fd.f.setZero();
    m.ja.setZero();
    m.jd.setZero();
    return Status::Ok;
  }
  m.ja = leg.axis_base_B;
  m.jd = legs.axis_platform_B.row(i).transpose();
  if (m.ja.cross(m.s).squaredNorm() < kSingularSpin) return Status::SingularBase;
  if (m.jd.cross(m.s).squaredNorm() < kSingularSpin) return Status::SingularPlatform;
  m.fa.f = spin_f(m.ja, m.s);
  m.fd.f = spin_f(m.jd, m.s);
  return Status::Ok;
}

// The parts that depend on the platform's velocity too.
void leg_velocity(const Vector3d& v, const Vector3d& w, LegMotion& m) noexcept {
  m.omega = w;
  m.u = v + w.cross(m.a);
  m.l_dot = m.s.dot(m.u);
  m.s_dot = (m.u - m.l_dot * m.s) / m.l;
  m.s_dot_rel = m.s_dot - w.cross(m.s);
  if (m.has_axes) {
    m.fa.f_dot = spin_f_dot(m.ja, Vector3d::Zero(), m.s, m.s_dot);
    m.fd.f_dot = spin_f_dot(m.jd, w.cross(m.jd), m.s, m.s_dot);
  } else {
    m.fa.f_dot.setZero();
    m.fd.f_dot.setZero();
  }
  m.wh = m.fa.f.dot(m.s_dot);
  m.wr = w.dot(m.s) + m.fd.f.dot(m.s_dot_rel);
  m.phi_dot = (m.l_dot - m.k * (m.wr - m.wh)) / m.c;
}

LegAcceleration leg_acceleration(const LegMotion& m, const Vector3d& u_dd, const Vector3d& w_dot, bool bias) noexcept {
  LegAcceleration a;
  a.u_dd = u_dd;
  a.l_dd = m.s.dot(u_dd) + (bias ? m.l * m.s_dot.squaredNorm() : 0.0);
  a.s_dd = u_dd - a.l_dd * m.s;
  if (bias) a.s_dd -= 2.0 * m.l_dot * m.s_dot;
  a.s_dd /= m.l;
  a.wh_dot = m.fa.f.dot(a.s_dd);
  a.wr_dot = w_dot.dot(m.s) + m.fd.f.dot(a.s_dd - w_dot.cross(m.s));
  if (bias) {
    a.wh_dot += m.fa.f_dot.dot(m.s_dot);
    a.wr_dot += m.omega.dot(m.s_dot) + m.fd.f_dot.dot(m.s_dot_rel) - m.fd.f.dot(m.omega.cross(m.s_dot));
  }
  a.phi_dd = (a.l_dd - m.k * (a.wr_dot - a.wh_dot)) / m.c;
  return a;
}

// A leg's generalised force, as coefficients of the virtual velocities it is written in: the
// virtual power is Au.du + As.ds' + cwh dwh + cwr dwr + cphi dphi' (theory §14).
struct LegForce {
  Vector3d Au = Vector3d::Zero(), As = Vector3d::Zero();
  double cwh = 0, cwr = 0, cphi = 0;
};

// What to include when turning accelerations into forces.
enum class Part { Legs, Drives };

// Inertial forces of the leg bodies or of the drives for accelerations `acc`; with `gyro`, the
// velocity-only (gyroscopic) terms too.
void add_inertia(const Rig& rig, const LegMotion& m, const LegAcceleration& acc, bool gyro, Part part,
                 LegForce& F) noexcept {
  const MechanismSpec& mech = rig.mechanism();
  const Vector3d sdot_x_s = m.s_dot.cross(m.s);
  if (part == Part::Legs) {
    const LegBodySpec& h = mech.housing;
    const LegBodySpec& r = mech.rod;
    const Vector3d a_h = h.center * acc.s_dd;
    const Vector3d a_r = acc.u_dd - r.center * acc.s_dd;
    F.As += h.mass * h.center * a_h + h.transverse_inertia * acc.s_dd;
    F.cwh += h.axial_inertia * acc.wh_dot;
    F.Au += r.mass * a_r;
    F.As += -r.center * r.mass * a_r + r.transverse_inertia * acc.s_dd;
    F.cwr += r.axial_inertia * acc.wr_dot;
    if (gyro) F.As += (h.axial_inertia * m.wh + r.axial_inertia * m.wr) * sdot_x_s;
    return;
  }
  const ServoSpec& servo = rig.servo();
  const double wD = m.rotor_on_rod ? m.wr : m.wh;
  const double wD_dot = m.rotor_on_rod ? acc.wr_dot : acc.wh_dot;
  const double N = servo.gear_ratio;
  // Rotor (with gear) at motor speed, screw at screw speed, both about s on the driven body.
  const double rotor_acc = wD_dot + m.eps * acc.phi_dd;
  const double screw_acc = wD_dot + m.eps * acc.phi_dd / N;
  const double cD = servo.motor_inertia * rotor_acc + servo.screw_inertia * screw_acc;
  (m.rotor_on_rod ? F.cwr : F.cwh) += cD;
  F.cphi += m.eps * (servo.motor_inertia * rotor_acc + servo.screw_inertia * screw_acc / N);
  if (gyro) {
    const double rotor_spin = wD + m.eps * m.phi_dot;
    const double screw_spin = wD + m.eps * m.phi_dot / N;
    F.As += (servo.motor_inertia * rotor_spin + servo.screw_inertia * screw_spin) * sdot_x_s;
  }
}

// Gravity on the leg bodies, as the force that holds them (-m g), in the same coefficients.
void add_leg_gravity(const Rig& rig, const LegMotion& m, const Vector3d& g, LegForce& F) noexcept {
  (void)m;
  const MechanismSpec& mech = rig.mechanism();
  F.As += -mech.housing.mass * mech.housing.center * g + mech.rod.center * mech.rod.mass * g;
  F.Au += -mech.rod.mass * g;
}

// A leg's force as a generalised force on the platform's coordinates (excluding cphi, which acts
// through the motor angle), added to Q.
void add_generalised(const LegMotion& m, const LegForce& F, Vector6d& Q) noexcept {
  const Vector3d tangential = (F.As + F.cwh * m.fa.f + F.cwr * m.fd.f);
  const Vector3d Fu = F.Au + (tangential - m.s.dot(tangential) * m.s) / m.l;
  const Vector3d Tw = F.cwr * (m.s + m.fd.f.cross(m.s));
  Q.head<3>() += Fu;
  Q.tail<3>() += m.a.cross(Fu) + Tw;
}

// Row of J_phi for one leg: phi' = row . [v; w].
void motor_row(const LegMotion& m, int i, Matrix6d& J) noexcept {
  const Vector3d e = m.s + (m.k / m.l) * (m.fa.f - m.fd.f);
  const Vector3d ew = m.a.cross(e) - m.k * (m.s + m.fd.f.cross(m.s));
  J.block<1, 3>(i, 0) = e.transpose() / m.c;
  J.block<1, 3>(i, 3) = ew.transpose() / m.c;
}

PlatformFrame platform_frame(const Rig& rig, const Matrix3d& R) noexcept {
  const LoadSpec& load = rig.load();
  return {R * (load.center_of_mass_P - rig.model().spec().pivot_P), R * load.inertia_tensor() * R.transpose()};
}

void add_platform_force(const PlatformFrame& p, double mass, const Vector3d& a_c, const Vector3d& torque,
                        Vector6d& Q) noexcept {
  const Vector3d F = mass * a_c;
  Q.head<3>() += F;
  Q.tail<3>() += p.c.cross(F) + torque;
}

Vector3d gravity_vector(const Rig& rig) noexcept { return Vector3d(0.0, 0.0, -rig.load().gravity); }

// Adds w (the generalised direction of a velocity written in (u, w_platform) = (P_i', w)) as
// weight * q q^T to M: q = [q_u; q_w + a x q_u] (theory §14, "Mass matrix").
void add_rank_one(const Vector3d& a, const Vector3d& q_u, const Vector3d& q_w, double weight, Matrix6d& M) noexcept {
  if (weight == 0.0) return;
  Vector6d q;
  q.head<3>() = q_u;
  q.tail<3>() = q_w + a.cross(q_u);
  M.noalias() += weight * q * q.transpose();
}

}  // namespace

void set_velocity(const Vector6d& velocity, Mechanism& mech) noexcept {
  mech.v = velocity.head<3>();
  mech.w = velocity.tail<3>();
  for (LegMotion& m : mech.legs) leg_velocity(mech.v, mech.w, m);
}

Status mechanism_motion(const Rig& rig, const LegState& legs, const Vector6d& velocity, Mechanism& mech,
                        bool twist) noexcept {
  mech.platform = platform_frame(rig, legs.R_BP);
  for (int i = 0; i < kLegs; ++i)
    if (const Status s = leg_position(rig, legs, i, twist, mech.legs[static_cast<std::size_t>(i)]); s != Status::Ok)
      return s;
  set_velocity(velocity, mech);
  return Status::Ok;
}

// `linear` false: zero platform acceleration (only gravity and velocity products are computed).
void all_forces(const Rig& rig, const Mechanism& mech, const Vector6d& acceleration, bool linear, Forces& f) noexcept {
  const double M = rig.load().mass;
  const PlatformFrame& p = mech.platform;
  const Vector3d& w = mech.w;
  const Vector3d vd = acceleration.head<3>(), wd = acceleration.tail<3>();
  const Vector3d g = gravity_vector(rig);
  // Platform: a_c = v' + w' x c + w x (w x c); torque about the centre of mass I w' + w x I w.
  if (linear) add_platform_force(p, M, vd + wd.cross(p.c), p.I * wd, f.platform);
  add_platform_force(p, M, w.cross(w.cross(p.c)), w.cross(p.I * w), f.velocity);
  add_platform_force(p, M, -g, Vector3d::Zero(), f.gravity);
  for (int i = 0; i < kLegs; ++i) {
    const LegMotion& m = mech.legs[static_cast<std::size_t>(i)];
    LegForce gravity;
    add_leg_gravity(rig, m, g, gravity);
    add_generalised(m, gravity, f.gravity);
    const LegAcceleration bias = leg_acceleration(m, w.cross(w.cross(m.a)), Vector3d::Zero(), true);
    LegForce legs_velocity, drives_velocity;
    add_inertia(rig, m, bias, true, Part::Legs, legs_velocity);
    add_inertia(rig, m, bias, true, Part::Drives, drives_velocity);
    add_generalised(m, legs_velocity, f.velocity);
    add_generalised(m, drives_velocity, f.drives_velocity);
    f.cphi_drives_velocity[i] = drives_velocity.cphi;
    f.phi_dd_bias[i] = bias.phi_dd;
    f.phi_dd[i] = bias.phi_dd;
    if (!linear) continue;
    const LegAcceleration lin = leg_acceleration(m, vd + wd.cross(m.a), wd, false);
    LegForce legs, drives;
    add_inertia(rig, m, lin, false, Part::Legs, legs);
    add_inertia(rig, m, lin, false, Part::Drives, drives);
    add_generalised(m, legs, f.legs);
    add_generalised(m, drives, f.drives);
    f.cphi_drives[i] = drives.cphi;
    f.phi_dd[i] += lin.phi_dd;
  }
}

// The mass matrix from the kinetic energy, split into the load (platform and leg bodies) and the
// drives (rotors and screws).
void mass_matrix_of(const Rig& rig, const Mechanism& mech, Matrix6d& M_load, Matrix6d& M_drives) noexcept {
  const PlatformFrame& p = mech.platform;
  const double mass = rig.load().mass;
  const Matrix3d C = detail::skew(p.c);
  M_load.topLeftCorner<3, 3>() = mass * Matrix3d::Identity();
  M_load.topRightCorner<3, 3>() = -mass * C;
  M_load.bottomLeftCorner<3, 3>() = mass * C;
  M_load.bottomRightCorner<3, 3>() = p.I - mass * C * C;
  M_drives.setZero();
  const MechanismSpec& mc = rig.mechanism();
  const ServoSpec& sv = rig.servo();
  const LegBodySpec& h = mc.housing;
  const LegBodySpec& r = mc.rod;
  for (const LegMotion& m : mech.legs) {
    const double il = 1.0 / m.l;
    // Translation and tumbling of the leg bodies: K_uu = gamma I - beta s s^T with s' = P u / l.
    const double tumble =
        (h.mass * h.center * h.center + h.transverse_inertia + r.transverse_inertia + r.mass * r.center * r.center) *
        il * il;
    const double across = r.mass - 2.0 * r.mass * r.center * il + tumble;  // along P = I - s s^T
    const double gamma = across, beta = across - r.mass;                   // K_uu = gamma I - beta s s^T
    const Matrix3d A = detail::skew(m.a);
    M_load.topLeftCorner<3, 3>() += gamma * Matrix3d::Identity();
    M_load.topRightCorner<3, 3>() -= gamma * A;
    M_load.bottomLeftCorner<3, 3>() += gamma * A;
    M_load.bottomRightCorner<3, 3>() -= gamma * A * A;
    add_rank_one(m.a, m.s, Vector3d::Zero(), -beta, M_load);
    // Spins about the leg: housing (fa / l on u), rod (fd / l on u, s + fd x s on w).
    const Vector3d hu = m.fa.f * il;
    const Vector3d ru = m.fd.f * il, rw = m.s + m.fd.f.cross(m.s);
    add_rank_one(m.a, hu, Vector3d::Zero(), h.axial_inertia, M_load);
    add_rank_one(m.a, ru, rw, r.axial_inertia, M_load);
    // Rotor and screw: the driven body's spin plus eps phi' (or eps phi' / N).
    const Vector3d pu = (m.s + m.k * il * (m.fa.f - m.fd.f)) / m.c;
    const Vector3d pw = -m.k / m.c * rw;
    const Vector3d Du = m.rotor_on_rod ? ru : hu;
    const Vector3d Dw = m.rotor_on_rod ? rw : Vector3d::Zero();
    const double inv_n = 1.0 / sv.gear_ratio;
    add_rank_one(m.a, Du + m.eps * pu, Dw + m.eps * pw, sv.motor_inertia, M_drives);
    add_rank_one(m.a, Du + m.eps * inv_n * pu, Dw + m.eps * inv_n * pw, sv.screw_inertia, M_drives);
  }
}

void motor_jacobian_of(const Mechanism& mech, Matrix6d& J) noexcept {
  for (int i = 0; i < kLegs; ++i) motor_row(mech.legs[static_cast<std::size_t>(i)], i, J);
}

}  // namespace hexatwist::detail
