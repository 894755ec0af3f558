// SPDX-License-Identifier: BSD-3-Clause
// MJCF export of the rig (docs/theory.md §15).
#include "hexatwist/io/mjcf.hpp"

#include <fmt/format.h>

#include <cmath>

#include "hexatwist/error.hpp"

namespace hexatwist {
namespace {

// Mass and inertia are shared out so that no constrained body is nearly massless (MuJoCo scales
// each constraint's softness by its bodies' inverse weights, docs/theory.md §15): the rod end,
// welded to the platform, carries 1/7 of the load; rotor and screw, whose centre of mass is put at
// the centre of mass of the leg body that carries them, carry 1/3 of that body's mass each.
// kTinyMass stands in for a mass of 0 (MuJoCo needs > mjMINVAL); kTinyInertia keeps a disc's
// inertia on the right side of MuJoCo's check A + B >= C after rounding.
constexpr double kTinyMass = 1e-6;        // [kg]
constexpr double kTinyInertia = 1e-9;     // [kg m^2]
constexpr double kLoadShare = 1.0 / 7.0;  // of the load, in the platform body and in each rod end
// Solver settings (docs/theory.md §15: the step and the constraints' stiffness were chosen by
// the study of bench/bench_dynamics.cpp and the residuals of tests/io/test_mjcf.cpp).
constexpr double kTimestep = 4e-4;      // [s]
constexpr double kTimeConstant = 8e-4;  // equality constraints' time constant, 2 timesteps [s]

// Numbers that read back to the same double.
std::string num(double v) { return fmt::format("{}", v == 0.0 ? 0.0 : v); }  // shortest exact form
// Text that may stand inside an XML comment: no "--", no control characters.
std::string comment_text(std::string text) {
  for (char& c : text)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  for (std::size_t k = text.find("--"); k != std::string::npos; k = text.find("--")) text.replace(k, 2, "- -");
  return text;
}
std::string vec(const Vector3d& v) { return fmt::format("{} {} {}", num(v.x()), num(v.y()), num(v.z())); }

// MuJoCo's fullinertia: Ixx Iyy Izz Ixy Ixz Iyz.
std::string full_inertia(const Matrix3d& I) {
  return fmt::format("{} {} {} {} {} {}", num(I(0, 0)), num(I(1, 1)), num(I(2, 2)), num(I(0, 1)), num(I(0, 2)),
                     num(I(1, 2)));
}

// Inertia of a body symmetric about the unit axis s [kg m^2, B].
Matrix3d axisymmetric(const Vector3d& s, double axial, double transverse) {
  return transverse * Matrix3d::Identity() + (axial - transverse) * s * s.transpose();
}

std::string inertial(const Vector3d& pos, double mass, const Matrix3d& I) {
  return fmt::format("<inertial pos=\"{}\" mass=\"{}\" fullinertia=\"{}\"/>", vec(pos), num(mass), full_inertia(I));
}

// A leg body's inertia with the rotor's and screw's transverse inertia (J/2 each, a thin disc's)
// taken out: hexatwist lumps it into the body that carries the motor.
Matrix3d leg_body_inertia(const LegBodySpec& b, double lumped, const char* field) {
  const double transverse = b.transverse_inertia - lumped;
  const double axial = std::max(b.axial_inertia, kTinyInertia);
  if (!(transverse >= kTinyInertia) || axial > 2.0 * transverse * (1.0 + 1e-12))
    throw Error(
        fmt::format("{}: MuJoCo needs a rigid body's inertia: the transverse inertia {:.6g} kg m^2 minus the "
                    "rotor's and screw's {:.6g} kg m^2 must be positive and at least half the axial {:.6g} "
                    "kg m^2",
                    field, b.transverse_inertia, lumped, b.axial_inertia));
  return Matrix3d(Vector3d(transverse, transverse, axial).asDiagonal());
}

// One leg's frame at home: the axes of its joints, its length and where its bodies' mass sits.
struct LegFrame {
  int n;                       // 1-based
  Vector3d s, ja, jd, jb, je;  // leg axis and the U-joints' axes [-, B]
  double L;                    // home length [m]
  bool base_driven;
  Matrix3d I_h, I_r;  // housing and rod inertia about their centres of mass [kg m^2, B]
  Vector3d c_h, c_r;  // their centres of mass from the base joint, at home [m, B]
};

// What every leg's bodies share: the rig's numbers and the inertias lumped into the leg bodies.
struct LegBodies {
  const Rig& rig;
  double Jm, Js, lumped;
  Matrix3d I_housing_base, I_housing_plain, I_rod_platform, I_rod_plain;
  double housing_share, rod_share, housing_whole, rod_whole, load_share;
  Matrix3d load_inertia_share;

  // A disc's transverse inertia is half its axial; a little more, as MuJoCo checks A + B >= C after
  // rounding.
  static double disc(double axial) { return 0.5 * axial + kTinyInertia; }

  explicit LegBodies(const Rig& r) : rig(r) {
    const ServoSpec& servo = rig.servo();
    const MechanismSpec& mech = rig.mechanism();
    Jm = servo.motor_inertia;
    Js = servo.screw_inertia;
    lumped = disc(Jm) + disc(Js);
    // Which leg body carries motor and screw decides the inertia lumped into it.
    bool any_base = false, any_platform = false;
    for (const Leg& leg : rig.model().legs()) (leg.driven == DrivenSide::Base ? any_base : any_platform) = true;
    I_housing_base =
        any_base ? leg_body_inertia(mech.housing, lumped, "mechanism.housing.transverse_inertia") : Matrix3d::Zero();
    I_housing_plain = leg_body_inertia(mech.housing, 0.0, "mechanism.housing.transverse_inertia");
    I_rod_platform =
        any_platform ? leg_body_inertia(mech.rod, lumped, "mechanism.rod.transverse_inertia") : Matrix3d::Zero();
    I_rod_plain = leg_body_inertia(mech.rod, 0.0, "mechanism.rod.transverse_inertia");
    // The mass of the body carrying motor and screw is split in three (itself, rotor, screw).
    housing_share = std::max(mech.housing.mass / 3.0, kTinyMass);
    rod_share = std::max(mech.rod.mass / 3.0, kTinyMass);
    housing_whole = std::max(mech.housing.mass, kTinyMass);
    rod_whole = std::max(mech.rod.mass, kTinyMass);
    load_share = std::max(rig.load().mass * kLoadShare, kTinyMass);
    load_inertia_share = kLoadShare * rig.load().inertia_tensor();
  }

  std::string leg(int i) const;

 private:
  LegFrame frame(int i) const;
  std::string rotor(const LegFrame& f, int level, const Vector3d& com) const;
  std::string end(const LegFrame& f, int level) const;
};

std::string indent(int level) { return std::string(static_cast<std::size_t>(2 * level), ' '); }

LegFrame LegBodies::frame(int i) const {
  const Leg& leg = rig.model().leg(i);
  const MechanismSpec& mech = rig.mechanism();
  LegFrame f;
  f.n = i + 1;
  f.s = leg.s_home_B;
  f.L = leg.length_home;
  f.ja = leg.axis_base_B.normalized();
  f.jd = leg.axis_platform_P.normalized();  // P is aligned with B at home
  f.jb = f.s.cross(f.ja).normalized();
  f.je = f.s.cross(f.jd).normalized();
  f.base_driven = leg.driven == DrivenSide::Base;
  // Leg-body inertia in the body frame (aligned with B at home), rotated onto s.
  Eigen::Matrix3d R;  // columns: two unit vectors across s, then s
  R.col(2) = f.s;
  R.col(0) = f.jb;
  R.col(1) = f.s.cross(f.jb);
  f.I_h = R * (f.base_driven ? I_housing_base : I_housing_plain) * R.transpose();
  f.I_r = R * (f.base_driven ? I_rod_plain : I_rod_platform) * R.transpose();
  f.c_h = mech.housing.center * f.s;
  f.c_r = (f.L - mech.rod.center) * f.s;
  return f;
}

std::string LegBodies::rotor(const LegFrame& f, int level, const Vector3d& com) const {
  return fmt::format(
      "{0}<body name=\"rotor{1}\">\n"
      "{0}  <joint name=\"leg{1}_rotor\" type=\"hinge\" axis=\"{2}\" damping=\"{4}\" frictionloss=\"{5}\"/>\n"
      "{0}  {3}\n"
      "{0}</body>\n",
      indent(level), f.n, vec(f.s),
      inertial(com, f.base_driven ? housing_share : rod_share, axisymmetric(f.s, Jm, disc(Jm))),
      num(rig.servo().viscous_friction), num(rig.servo().coulomb_friction));
}

std::string LegBodies::end(const LegFrame& f, int level) const {
  return fmt::format(
      "{0}<body name=\"end{1}\">\n"
      "{0}  <joint name=\"leg{1}_je\" type=\"hinge\" axis=\"{2}\"/>\n"
      "{0}  <joint name=\"leg{1}_jd\" type=\"hinge\" axis=\"{3}\"/>\n"
      "{0}  {4}\n"
      "{0}</body>\n",
      indent(level), f.n, vec(f.je), vec(f.jd),
      inertial(rig.load().center_of_mass_P - rig.model().leg(f.n - 1).platform_P, load_share, load_inertia_share));
}

// Leg i's bodies: housing (on the base U-joint), rotor, screw, rod and rod end, nested as the joints
// connect them; which holds the rotor and screw depends on the driven side.
std::string LegBodies::leg(int i) const {
  const Leg& leg = rig.model().leg(i);
  const MechanismSpec& mech = rig.mechanism();
  const LegFrame f = frame(i);
  const int n = f.n;
  const Vector3d& s = f.s;
  const std::string rod_geom = fmt::format(
      "<geom type=\"capsule\" fromto=\"0 0 0 {}\" size=\"0.02\" rgba=\"0.7 0.7 0.75 1\"/>", vec(-0.5 * f.L * s));
  const std::string housing_geom = fmt::format(
      "<geom type=\"capsule\" fromto=\"0 0 0 {}\" size=\"0.04\" rgba=\"0.3 0.3 0.35 1\"/>", vec(0.6 * f.L * s));
  std::string t = fmt::format("    <!-- leg {}: {}-driven, {}-hand thread, lead {} m, home length {} m -->\n", n,
                              f.base_driven ? "base" : "platform", leg.thread == ThreadSense::Right ? "right" : "left",
                              num(leg.lead), num(f.L));
  t += fmt::format(
      "    <body name=\"housing{0}\" pos=\"{1}\">\n"
      "      <joint name=\"leg{0}_ja\" type=\"hinge\" axis=\"{2}\"/>\n"
      "      <joint name=\"leg{0}_jb\" type=\"hinge\" axis=\"{3}\"/>\n"
      "      {4}\n"
      "      {5}\n",
      n, vec(leg.base_B), vec(f.ja), vec(f.jb), inertial(f.c_h, f.base_driven ? housing_share : housing_whole, f.I_h),
      housing_geom);
  if (f.base_driven) {
    // Motor and screw in the housing, nut in the rod.
    t += rotor(f, 3, f.c_h);
    t += fmt::format(
        "      <body name=\"screw{0}\">\n"
        "        <joint name=\"leg{0}_screw\" type=\"hinge\" axis=\"{1}\"/>\n"
        "        {2}\n"
        "        <body name=\"rod{0}\" pos=\"{3}\">\n"
        "          <joint name=\"leg{0}_nut\" type=\"hinge\" axis=\"{1}\"/>\n"
        "          <joint name=\"leg{0}_slide\" type=\"slide\" axis=\"{1}\"/>\n"
        "          {4}\n"
        "          {5}\n",
        n, vec(s), inertial(f.c_h, housing_share, axisymmetric(s, Js, disc(Js))), vec(f.L * s),
        inertial(-mech.rod.center * s, rod_whole, f.I_r), rod_geom);
  } else {
    // Motor and screw in the rod, nut in the housing: the screw turns in the nut and slides
    // with the rod.
    t += fmt::format(
        "      <body name=\"screw{0}\">\n"
        "        <joint name=\"leg{0}_nut\" type=\"hinge\" axis=\"{1}\"/>\n"
        "        <joint name=\"leg{0}_slide\" type=\"slide\" axis=\"{1}\"/>\n"
        "        {2}\n"
        "        <body name=\"rod{0}\" pos=\"{3}\">\n"
        "          <joint name=\"leg{0}_screw\" type=\"hinge\" axis=\"{1}\"/>\n"
        "          {4}\n"
        "          {5}\n",
        n, vec(s), inertial(f.c_r, rod_share, axisymmetric(s, Js, disc(Js))), vec(f.L * s),
        inertial(-mech.rod.center * s, rod_share, f.I_r), rod_geom);
    t += rotor(f, 5, -mech.rod.center * s);
  }
  t += end(f, 5);
  t += "        </body>\n      </body>\n";
  return t + "    </body>\n";
}

// The header comment and the global settings, up to the world body's light.
std::string preamble(const Rig& rig) {
  std::string t = fmt::format(
      "<!-- MuJoCo model (MJCF) of the lead-screw Stewart platform \"{}\", written by hexatwist (hexatwist mjcf).\n"
      "     Frames: the world is the base frame B; body \"platform\" is the platform frame P, at home B raised by\n"
      "     home_height. Units SI (m, kg, s, rad). Each leg: housingN on the base U-joint (hinges legN_ja, fixed\n"
      "     in the base, then legN_jb = unit(s x ja), fixed in the housing); screwN and rodN turn and slide\n"
      "     about the leg axis s (legN_screw + legN_nut = the rod's rotation relative to the housing, hexatwist's\n"
      "     twist; legN_slide = leg length minus its home length); endN on the rod (hinges legN_je = unit(s x jd),\n"
      "     fixed in the rod, then legN_jd, fixed in the platform), welded to the platform (legN_weld).\n"
      "     legN_helix: the screw-nut pair, nut = slide / (sigma lead / 2 pi); legN_gear: screw = +-rotor / N.\n"
      "     motorN drives legN_rotor; its force is the motor torque [N m], positive lengthens the leg.\n"
      "     Shares: the platform body and each rod end carry 1/7 of the load's mass and inertia (the rod ends are\n"
      "     welded to the platform); rotor, screw and the leg body carrying them 1/3 of its mass each, all at its\n"
      "     centre of mass; the rotor's and screw's transverse inertia (J/2, a disc's) is taken out of that body.\n"
      "     docs/theory.md section 14 describes the model. -->\n",
      comment_text(rig.model().spec().name));
  t += fmt::format(
      "<mujoco model=\"hexatwist\">\n"
      "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>\n"
      "  <option timestep=\"{}\" gravity=\"0 0 {}\" integrator=\"Euler\" solver=\"Newton\" "
      "iterations=\"100\" tolerance=\"1e-12\" jacobian=\"dense\">\n"
      "    <flag contact=\"disable\"/>\n"
      "  </option>\n"
      "  <default>\n"
      "    <equality solref=\"{} 1\" solimp=\"0.9999 0.9999 0.001 0.5 2\"/>\n"
      "    <geom contype=\"0\" conaffinity=\"0\" group=\"1\"/>\n"
      "  </default>\n"
      "  <worldbody>\n"
      "    <light pos=\"0 0 6\" dir=\"0 0 -1\" directional=\"true\"/>\n",
      num(kTimestep), num(-rig.load().gravity), num(kTimeConstant));
  return t;
}

// The constraints (rod ends welded to the platform, screw-nut pairs, gears) and the motors.
std::string equalities_and_actuators(const Rig& rig) {
  const Model& model = rig.model();
  std::string t = "  <equality>\n";
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = model.leg(i);
    const int n = i + 1;
    // The screw-nut pair as nut = slide / k, in radians: MuJoCo softens a joint equality by the sum of
    // its two joints' inverse weights whatever the coefficient, and the nut's (1/J_s) would make
    // a row in metres 1/k^2 softer (docs/theory.md §15).
    // The rotor's angle relative to the body carrying the motor is -sigma phi (base-driven) or
    // +sigma phi (platform-driven), phi the motor angle that lengthens the leg (theory §4).
    const double gear_sign = leg.driven == DrivenSide::Base ? 1.0 : -1.0;
    t += fmt::format(
        "    <weld name=\"leg{0}_weld\" body1=\"platform\" body2=\"end{0}\"/>\n"
        "    <joint name=\"leg{0}_helix\" joint1=\"leg{0}_nut\" joint2=\"leg{0}_slide\" polycoef=\"0 {1} 0 0 0\"/>\n"
        "    <joint name=\"leg{0}_gear\" joint1=\"leg{0}_screw\" joint2=\"leg{0}_rotor\" polycoef=\"0 {2} 0 0 0\"/>\n",
        n, num(1.0 / leg.twist_gain), num(gear_sign / rig.servo().gear_ratio));
  }
  t += "  </equality>\n  <actuator>\n";
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = model.leg(i);
    const double gear = (leg.driven == DrivenSide::Base ? -1.0 : 1.0) * leg.twist_sign;
    t += fmt::format(
        "    <motor name=\"motor{0}\" joint=\"leg{0}_rotor\" gear=\"{1}\" ctrllimited=\"true\" "
        "ctrlrange=\"{2} {3}\" forcelimited=\"true\" forcerange=\"{2} {3}\"/>\n",
        i + 1, num(gear), num(-rig.servo().torque_limit), num(rig.servo().torque_limit));
  }
  return t + "  </actuator>\n</mujoco>\n";
}

}  // namespace

std::string mjcf_model(const Rig& rig) {
  const Model& model = rig.model();
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = model.leg(i);
    if (!(leg.lead > 0.0))
      throw Error(
          fmt::format("leg {}: the MuJoCo model needs a lead screw on every leg (lead 0 has no screw to "
                      "couple the motor to the leg)",
                      i + 1));
    if (!(leg.axis_base_B.squaredNorm() > 0.0) || !(leg.axis_platform_P.squaredNorm() > 0.0))
      throw Error(fmt::format("leg {}: the MuJoCo model needs both U-joint axes", i + 1));
  }
  const LegBodies bodies(rig);
  std::string t = preamble(rig);
  for (int i = 0; i < kLegs; ++i) t += bodies.leg(i);
  // The platform with its payload: P's origin, aligned with B at home.
  t += fmt::format(
      "    <body name=\"platform\" pos=\"{}\">\n"
      "      <freejoint name=\"platform\"/>\n"
      "      {}\n"
      "      <geom type=\"cylinder\" pos=\"{}\" size=\"{} 0.03\" rgba=\"0.2 0.45 0.7 0.6\"/>\n"
      "    </body>\n"
      "  </worldbody>\n",
      vec(Vector3d(0.0, 0.0, model.spec().home_height)),
      inertial(rig.load().center_of_mass_P, bodies.load_share, bodies.load_inertia_share), vec(model.spec().pivot_P),
      num(model.condition_length()));
  return t + equalities_and_actuators(rig);
}

}  // namespace hexatwist
