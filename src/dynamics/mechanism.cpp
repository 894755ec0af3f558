// Dynamics of the whole mechanism: velocities and accelerations of every body from the platform's
// motion, Newton-Euler on each body, projected onto the platform's coordinates by virtual power
// (docs/theory.md §14; the symbols below are the section's).
#include "hexatwist/dynamics/mechanism.hpp"
#include "kinematics/geometry.hpp"

#include <Eigen/LU>
#include <cmath>

#include "dynamics/mechanism_internal.hpp"
#include "hexatwist/kinematics/twist.hpp"

namespace hexatwist {
namespace {

// Below this |j x s|^2 a U-joint is at its singularity: the spin of its body is undefined.
constexpr double kSingularSpin = 1e-12;

// The spin coefficient of a U-joint body (theory §14): for fixed axis j, the body's angular
// velocity about s is f . s' with f = (j.s)(j x s)/|j x s|^2, and its rate of change along s'
// (with j' the axis's own velocity) is f'.
struct SpinCoefficient {
  Vector3d f;
  Vector3d f_dot;
};

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

// One leg's velocity-level state (theory §14, "Velocities").
struct LegMotion {
  Vector3d s, a;           // unit leg axis; pivot to platform joint [m, B]
  Vector3d u;              // velocity of the platform joint P_i [m/s]
  Vector3d s_dot;          // s'
  Vector3d s_dot_rel;      // s' - w x s: s' seen from the platform
  Vector3d omega;          // the platform's angular velocity [rad/s]
  SpinCoefficient fa, fd;  // spin coefficients of the housing (ja) and the rod (jd)
  Vector3d ja, jd;         // base and platform axes [B]
  bool has_axes = true;
  double l = 0, l_dot = 0;  // length and its rate
  double wh = 0, wr = 0;    // spin rates of housing and rod about s [rad/s]
  double phi_dot = 0;       // motor speed [rad/s]
  double k = 0, c = 0;      // twist gain; motor gain [m/rad]
  double eps = 0;           // rotor sense: rotor spin relative to its body = eps * phi
  bool rotor_on_rod = false;
};

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

// One leg's accelerations: either the part linear in the platform's acceleration (bias = false;
// `u_dd` and `w_dot` are then that acceleration's), or the velocity-product part (bias = true,
// with u_dd = w x (w x a) and w_dot = 0).
struct LegAcceleration {
  Vector3d u_dd, s_dd;
  double l_dd = 0, wh_dot = 0, wr_dot = 0, phi_dd = 0;
};

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

// The platform's inertial forces: linear part for (v', w'), velocity part, and gravity.
struct PlatformFrame {
  Vector3d c;  // centre of mass from the pivot [m, B]
  Matrix3d I;  // inertia tensor about the centre of mass [kg m^2, B]
};

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

// Everything a pass over the legs needs.
struct Mechanism {
  PerLeg<LegMotion> legs;
  PlatformFrame platform;
  Vector3d v, w;
};

void set_velocity(const Vector6d& velocity, Mechanism& mech) noexcept {
  mech.v = velocity.head<3>();
  mech.w = velocity.tail<3>();
  for (LegMotion& m : mech.legs) leg_velocity(mech.v, mech.w, m);
}

Status mechanism_motion(const Rig& rig, const LegState& legs, const Vector6d& velocity, Mechanism& mech,
                        bool twist = true) noexcept {
  mech.platform = platform_frame(rig, legs.R_BP);
  for (int i = 0; i < kLegs; ++i)
    if (const Status s = leg_position(rig, legs, i, twist, mech.legs[static_cast<std::size_t>(i)]); s != Status::Ok)
      return s;
  set_velocity(velocity, mech);
  return Status::Ok;
}

Vector3d gravity_vector(const Rig& rig) noexcept { return Vector3d(0.0, 0.0, -rig.load().gravity); }

// All parts of the generalised force at (legs, velocity, acceleration): each leg's accelerations
// are computed once, split into the part linear in the platform's acceleration and the
// velocity-product part (theory §14).
struct Forces {
  Vector6d gravity = Vector6d::Zero();               // -m g of every body
  Vector6d platform = Vector6d::Zero();              // the platform's inertia, linear part
  Vector6d velocity = Vector6d::Zero();              // velocity products of the platform and the leg bodies
  Vector6d legs = Vector6d::Zero();                  // the leg bodies' inertia, linear part
  Vector6d drives = Vector6d::Zero();                // rotors and screws, linear part (generalised) ...
  Vector6d cphi_drives = Vector6d::Zero();           // ... and through the motor angles
  Vector6d drives_velocity = Vector6d::Zero();       // rotors and screws, velocity products (generalised) ...
  Vector6d cphi_drives_velocity = Vector6d::Zero();  // ... and through the motor angles
  Vector6d phi_dd = Vector6d::Zero();                // motor acceleration [rad/s^2]
  Vector6d phi_dd_bias = Vector6d::Zero();           // its velocity-product part, J_phi' x'
};

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

// Adds w (the generalised direction of a velocity written in (u, w_platform) = (P_i', w)) as
// weight * q q^T to M: q = [q_u; q_w + a x q_u] (theory §14, "Mass matrix").
void add_rank_one(const Vector3d& a, const Vector3d& q_u, const Vector3d& q_w, double weight, Matrix6d& M) noexcept {
  if (weight == 0.0) return;
  Vector6d q;
  q.head<3>() = q_u;
  q.tail<3>() = q_w + a.cross(q_u);
  M.noalias() += weight * q * q.transpose();
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

Status motor_jacobian_of(const Mechanism& mech, Matrix6d& J) noexcept {
  for (int i = 0; i < kLegs; ++i) motor_row(mech.legs[static_cast<std::size_t>(i)], i, J);
  return Status::Ok;
}

// LU of J_phi (or its transpose) with a relative determinant check (as leg_dynamics).
Status factor(const Matrix6d& J, Eigen::PartialPivLU<Matrix6d>& lu) noexcept {
  lu.compute(J);
  double scale = 1.0;
  for (int i = 0; i < 6; ++i) scale *= J.row(i).norm();
  if (!(std::abs(lu.determinant()) > 1e-12 * scale)) return Status::SingularJacobian;
  return Status::Ok;
}

// tanh-smoothed share of driving: 1 when the motor drives the load, 0 when the load drives it.
// The efficiency loss for p = tanh(speed / friction_speed): the share of driving d = (1 + p sign
// tau_s) / 2 is 1 when the motor drives the load and 0 when the load drives it.
Vector6d efficiency_loss_of(const Rig& rig, const Vector6d& p, const Vector6d& screw_torque) noexcept {
  const MechanismSpec& mech = rig.mechanism();
  Vector6d f;
  for (int i = 0; i < kLegs; ++i) {
    const double sign = screw_torque[i] > 0.0 ? 1.0 : (screw_torque[i] < 0.0 ? -1.0 : 0.0);
    const double d = 0.5 * (1.0 + p[i] * sign);
    // Driving: tau = tau_s / eta; driven back: tau = tau_s * eta' (theory §14), blended by d.
    const double factor = d / mech.efficiency + (1.0 - d) * mech.back_efficiency;
    f[i] = (factor - 1.0) * screw_torque[i];
  }
  return f;
}

Vector6d smoothed_sign(const Rig& rig, const Vector6d& speed) noexcept {
  return (speed / rig.servo().friction_speed).array().tanh().matrix();
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
  return motor_jacobian_of(mech, J_phi);
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

Vector6d detail::efficiency_loss(const Rig& rig, const Vector6d& speed, const Vector6d& screw_torque) noexcept {
  return efficiency_loss_of(rig, smoothed_sign(rig, speed), screw_torque);
}

Vector6d drive_friction(const Rig& rig, const Vector6d& speed, const Vector6d& screw_torque) noexcept {
  const ServoSpec& sv = rig.servo();
  const Vector6d p = smoothed_sign(rig, speed);
  return sv.viscous_friction * speed + sv.coulomb_friction * p + efficiency_loss_of(rig, p, screw_torque);
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
  out.friction = drive_friction(rig, out.speed, screw_torque);
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
