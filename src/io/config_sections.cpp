// SPDX-License-Identifier: BSD-3-Clause
// The configuration's optional sections: servo, load, mechanism, simulation and study. Every key
// has a default (rig.hpp, study.hpp); sign errors are caught here, where the units the file uses
// (rpm, Hz, deg) are known, and the plausible ranges by the Rig and check_study.
#include <fmt/format.h>

#include "io/config_reader.hpp"

namespace hexatwist::config_detail {
namespace {

// Reads the values of the optional sections, noting where each came from.
class Sections {
 public:
  enum Range { Positive, NonNegative };

  Sections(const Reader& r, const Field& top, Locations& locs) : r_(r), top_(top), locs_(locs) {}

  // The section `key` (absent or not), with its keys checked against `keys`.
  Field section(const char* key, std::initializer_list<const char*> keys) const {
    const Field f = Reader::child(top_, key);
    if (f.present()) {
      r_.require_map(f, "a mapping of settings");
      r_.only_keys(f, keys);
    }
    return f;
  }

  // Reads `key` of `sec` into `value` times `scale` if present; `field` is the name the library's
  // validation uses in its messages.
  void num(const Field& sec, const char* key, std::string_view what, Range range, double& value, double scale = 1.0,
           const char* field = nullptr) const {
    if (!sec.present()) return;
    const Field f = Reader::child(sec, key);
    if (!f.present()) return;
    const double v = r_.number(f, what);
    if (range == Positive && !(v > 0.0)) r_.fail(f.at(), f.path, fmt::format("expected > 0 ({}), got {}", what, v));
    if (range == NonNegative && v < 0.0) r_.fail(f.at(), f.path, fmt::format("expected >= 0 ({}), got {}", what, v));
    value = v * scale;
    locs_[field != nullptr ? std::string(field) : f.path] = loc(f);
  }

  void vec(const Field& sec, const char* key, const char* what, Vector3d& value) const {
    if (!sec.present()) return;
    const Field f = Reader::child(sec, key);
    if (!f.present()) return;
    value = r_.vec3(f, what);
    locs_[f.path] = loc(f);
  }

  // A mapping `key` of `sec` with the keys `keys`, noted where it is; absent: not present.
  Field block(const Field& sec, const char* key, const char* what, std::initializer_list<const char*> keys) const {
    if (!sec.present()) return sec;  // not present either
    const Field f = Reader::child(sec, key);
    if (!f.present()) return f;
    r_.require_map(f, what);
    r_.only_keys(f, keys);
    locs_[f.path] = loc(f);
    return f;
  }

  void servo(ServoSpec& sv) const;
  void load(LoadSpec& ld) const;
  void mechanism(MechanismSpec& mc) const;
  void simulation(SimulationSpec& sm) const;
  void study(StudySpec& st) const;

 private:
  void leg_body(const Field& mech, const char* key, LegBodySpec& b) const;

  const Reader& r_;
  const Field& top_;
  Locations& locs_;
};

constexpr double kRpm = 2.0 * kPi / 60.0;

void Sections::servo(ServoSpec& sv) const {
  const Field s =
      section("servo", {"motor_inertia", "screw_inertia", "viscous_friction", "coulomb_friction", "friction_speed",
                        "torque_time_constant", "torque_limit", "max_speed_rpm", "encoder_counts", "gear_ratio",
                        "pole_frequency_hz", "kp", "ki", "kd", "velocity_feedforward", "acceleration_feedforward",
                        "peak_corner_rpm", "peak_torque_at_max_speed", "continuous_torque"});
  num(s, "motor_inertia", "rotor inertia [kg m^2]", Positive, sv.motor_inertia);
  num(s, "screw_inertia", "screw and coupling inertia [kg m^2]", NonNegative, sv.screw_inertia);
  num(s, "viscous_friction", "at the motor shaft [N m s/rad]", NonNegative, sv.viscous_friction);
  num(s, "coulomb_friction", "dry friction at the motor shaft [N m]", NonNegative, sv.coulomb_friction);
  num(s, "friction_speed", "speed over which dry friction changes sign [rad/s]", Positive, sv.friction_speed);
  num(s, "torque_time_constant", "current-loop lag [s]; 0 = instant", NonNegative, sv.torque_time_constant);
  num(s, "torque_limit", "peak motor torque [N m]", Positive, sv.torque_limit);
  num(s, "max_speed_rpm", "motor speed limit [rpm]", Positive, sv.max_speed, kRpm, "servo.max_speed");
  num(s, "encoder_counts", "counts per motor revolution", Positive, sv.encoder_counts);
  num(s, "gear_ratio", "motor revolutions per screw revolution", Positive, sv.gear_ratio);
  num(s, "pole_frequency_hz", "closed-loop pole frequency of the position loop [Hz]", Positive, sv.pole_frequency, 1.0,
      "servo.pole_frequency");
  num(s, "kp", "[N m/rad]; 0 = from pole_frequency_hz", NonNegative, sv.kp);
  num(s, "ki", "[N m/(rad s)]; 0 = from pole_frequency_hz", NonNegative, sv.ki);
  num(s, "kd", "[N m s/rad]; 0 = from pole_frequency_hz", NonNegative, sv.kd);
  num(s, "velocity_feedforward", "fraction of the viscous torque", NonNegative, sv.velocity_feedforward);
  num(s, "acceleration_feedforward", "fraction of the inertia torque", NonNegative, sv.acceleration_feedforward);
  num(s, "peak_corner_rpm", "speed up to which the peak torque holds [rpm]", Positive, sv.peak_corner_speed, kRpm,
      "servo.peak_corner_speed");
  num(s, "peak_torque_at_max_speed", "peak torque left at the maximum speed [N m]", NonNegative,
      sv.peak_torque_at_max_speed);
  num(s, "continuous_torque", "largest RMS torque [N m]", Positive, sv.continuous_torque);
}

void Sections::load(LoadSpec& ld) const {
  const Field s = section("load", {"mass", "center_of_mass", "inertia", "products_of_inertia", "gravity"});
  num(s, "mass", "platform + payload [kg]", Positive, ld.mass);
  vec(s, "center_of_mass", "x, y, z [m, platform frame]", ld.center_of_mass_P);
  vec(s, "inertia", "principal moments Ixx, Iyy, Izz about the centre of mass [kg m^2]", ld.inertia);
  vec(s, "products_of_inertia", "Ixy, Ixz, Iyz of the inertia tensor about the centre of mass [kg m^2]", ld.products);
  num(s, "gravity", "[m/s^2]", NonNegative, ld.gravity);
}

void Sections::leg_body(const Field& mech, const char* key, LegBodySpec& b) const {
  const Field f = block(mech, key, "mass, center, axial_inertia, transverse_inertia",
                        {"mass", "center", "axial_inertia", "transverse_inertia"});
  if (!f.present()) return;
  num(f, "mass", "[kg]", NonNegative, b.mass);
  if (const Field c = Reader::child(f, "center"); c.present()) {
    b.center = r_.number(c, "distance of the centre of mass from the body's U-joint along the leg [m]");
    locs_[c.path] = loc(c);
  }
  num(f, "axial_inertia", "about the leg axis [kg m^2]", NonNegative, b.axial_inertia);
  num(f, "transverse_inertia", "across the leg through the centre of mass [kg m^2]", NonNegative, b.transverse_inertia);
}

void Sections::mechanism(MechanismSpec& mc) const {
  const Field s = section("mechanism", {"housing", "rod", "efficiency", "back_efficiency"});
  leg_body(s, "housing", mc.housing);
  leg_body(s, "rod", mc.rod);
  num(s, "efficiency", "screw efficiency, motor driving the load, in (0, 1]", Positive, mc.efficiency);
  num(s, "back_efficiency", "screw efficiency, load driving the motor, in (0, 1]", Positive, mc.back_efficiency);
}

void Sections::simulation(SimulationSpec& sm) const {
  const Field s = section("simulation", {"control_rate_hz", "plant_step"});
  num(s, "control_rate_hz", "servo rate [Hz]", Positive, sm.control_rate, 1.0, "simulation.control_rate");
  num(s, "plant_step", "largest plant integration step [s]", Positive, sm.plant_step);
}

void Sections::study(StudySpec& st) const {
  const Field s = section("study", {"linear_amplitude", "angular_amplitude_deg", "linear", "angular_deg", "dwell"});
  num(s, "linear_amplitude", "translation sweep amplitude [m]", Positive, st.linear_amplitude);
  num(s, "angular_amplitude_deg", "rotation sweep amplitude [deg]", Positive, st.angular_amplitude, deg2rad(1.0));
  num(s, "dwell", "rest before, between and after the moves [s]", NonNegative, st.dwell);
  for (const bool linear : {true, false}) {
    const Field f = block(s, linear ? "linear" : "angular_deg", "velocity, acceleration, jerk",
                          {"velocity", "acceleration", "jerk"});
    if (!f.present()) continue;
    const char* unit = linear ? "m" : "deg";
    const double scale = linear ? 1.0 : deg2rad(1.0);
    MotionLimits& m = linear ? st.linear : st.angular;
    num(f, "velocity", fmt::format("largest speed [{}/s]", unit), Positive, m.velocity, scale);
    num(f, "acceleration", fmt::format("largest acceleration [{}/s^2]", unit), Positive, m.acceleration, scale);
    num(f, "jerk", fmt::format("largest jerk [{}/s^3]", unit), Positive, m.jerk, scale);
  }
}

}  // namespace

void read_sections(const Reader& r, const Field& top, Locations& locs, ConfigSpec& out) {
  const Sections sections(r, top, locs);
  sections.servo(out.rig.servo);
  sections.load(out.rig.load);
  sections.mechanism(out.rig.mechanism);
  sections.simulation(out.rig.simulation);
  sections.study(out.study);
  for (const char* name : {"servo", "load", "mechanism"})
    if (!Reader::child(top, name).present()) out.defaulted.emplace_back(name);
}

}  // namespace hexatwist::config_detail
