// SPDX-License-Identifier: BSD-3-Clause
// The immutable, validated description of a six-leg U-P-U lead-screw Stewart platform.
#pragma once

#include <cmath>
#include <limits>
#include <string>

#include "hexatwist/types.hpp"

namespace hexatwist {

/// Hand of the lead screw's thread.
enum class ThreadSense { Right, Left };

/// Which end of the leg carries the motor that turns the screw. It does not change the sign of the
/// twist term (docs/theory.md §4); it is recorded for the servo model and for the report.
enum class DrivenSide { Base, Platform };

/// One leg as given by the user (unvalidated).
struct LegSpec {
  Vector3d base_B = Vector3d::Zero();           ///< base U-joint centre, A2 [m, B]
  Vector3d platform_P = Vector3d::Zero();       ///< platform U-joint centre, A1 [m, P]
  Vector3d axis_base_B = Vector3d::Zero();      ///< base U-joint fixed axis ja, Eq. (6) [-, B]
  Vector3d axis_platform_P = Vector3d::Zero();  ///< platform U-joint fixed axis jd, Eq. (6) [-, P]
  double lead = 0.0;                            ///< screw lead, travel per revolution [m]
  ThreadSense thread = ThreadSense::Right;      ///< thread hand
  DrivenSide driven = DrivenSide::Base;         ///< side whose motor turns the screw
  double length_offset = 0.0;                   ///< real minus motor-side length at zero twist (theory §4) [m]
  /// Lead the drive converts lengths to motor angles with: the controller's counts per metre come
  /// from it [m]. A real `lead` that differs from it scales the nut's travel by lead / drive_lead
  /// (theory §4, "The drives' reference and scale"). NaN = `lead` (no scale); needs lead > 0.
  double drive_lead = std::numeric_limits<double>::quiet_NaN();
  /// Motor-side length the drive reads at its reference, the homing position: the controller's
  /// HOME value, about which a drive scale acts [m]. NaN = the command at home, length at home
  /// minus length_offset.
  double home_command = std::numeric_limits<double>::quiet_NaN();

  // What a real leg adds to its geometry (docs/theory/kinematics.md §4b, "Heat, load and play"). Each
  // acts relative to the reference state: the platform at home after homing, at the reference
  // temperature, under the configuration's static load; there the commands are those without it.
  /// Axial stiffness between the joint centres (screw, nut, bearings, tubes and the joints' axial
  /// compliance in series): the leg's length changes by F / stiffness under its axial force F
  /// [N/m]. Infinity = rigid (the default); plausible 1e6..1e11 (1 to 100,000 N/um).
  double stiffness = std::numeric_limits<double>::infinity();
  /// Lost motion of the nut and the joints along the leg: the nut lags the motor by play / 2 in
  /// the direction of the last motion [m]. 0 = none; plausible 0..1e-3.
  double play = 0.0;
  /// Direction of the last motion when the drive reached its reference (homing): +1 the leg
  /// lengthening, -1 shortening [-].
  double home_direction = 1.0;
  /// Thermal expansion of the length between the joints at home [1/K], and of the screw's lead
  /// (the nut's travel from the reference and the twist term) [1/K]. 0 = none; plausible -2e-5..1e-4
  /// (steel 11.5e-6, aluminium 23e-6).
  double length_expansion = 0.0;
  double lead_expansion = 0.0;
};

/// Default of LimitSpec::jacobian_condition_max (docs/theory.md §6: chosen on the seed platform).
inline constexpr double kDefaultJacobianConditionMax = 50.0;

/// Plausible ranges of the legs' effects and of the reference temperature (theory §4b): a Model
/// refuses values outside them, naming the field; the CLI checks its options against the same.
inline constexpr double kMinStiffness = 1e6, kMaxStiffness = 1e11;         ///< [N/m] (inf: rigid)
inline constexpr double kMaxPlay = 1e-3;                                   ///< [m]
inline constexpr double kMinExpansion = -2e-5, kMaxExpansion = 1e-4;       ///< [1/K]
inline constexpr double kMinTemperature = -60.0, kMaxTemperature = 200.0;  ///< [degC]

/// Tolerance of every limit check (limits.hpp, docs/theory.md §6): a value on a bound, or within
/// 4 ulp of it (relative, 4 * 2^-52 = 8.9e-16 of the bound), is inside the limit. Rounding on the
/// way (1.4 m typed, 1.3999999999999997 m recomputed by forward kinematics) cannot move a value
/// across a bound; anything further away is decided exactly.
inline constexpr double kLimitTolerance = 4.0 * std::numeric_limits<double>::epsilon();
/// The largest value accepted under the upper bound `bound` [unit of bound].
constexpr double accepted_max(double bound) noexcept { return bound + kLimitTolerance * (bound < 0 ? -bound : bound); }
/// The smallest value accepted above the lower bound `bound` [unit of bound].
constexpr double accepted_min(double bound) noexcept { return bound - kLimitTolerance * (bound < 0 ? -bound : bound); }

/// Motion limits (unvalidated).
struct LimitSpec {
  double length_min = 0.0;          ///< shortest leg [m]
  double length_max = 0.0;          ///< longest leg [m]
  double bend_max = 0.0;            ///< largest U-joint bend away from its home direction [rad]
  double singularity_margin = 0.0;  ///< smallest angle between a leg and a fixed U-joint axis [rad]
  /// largest 1-norm condition number of the (motor-side) Jacobian, rotation columns divided by
  /// Model::condition_length() (limits.hpp, jacobian_condition) [-]
  double jacobian_condition_max = kDefaultJacobianConditionMax;
};

/// What gravity pulls on, for the legs' static axial forces (leg_effects.hpp): the load on the
/// platform and every leg's two bodies (housing on the base joint, rod on the platform joint). A
/// configuration fills it from its load and mechanism sections, as the Rig does (dynamics/rig.hpp);
/// without it the legs' forces are unknown and a finite stiffness cannot be compensated.
struct StaticLoadSpec {
  bool present = false;                          ///< false: no load known
  double gravity = 9.81;                         ///< gravitational acceleration, along -z of B [m/s^2]
  double mass = 0.0;                             ///< platform and payload [kg]
  Vector3d center_of_mass_P = Vector3d::Zero();  ///< their centre of mass [m, P]
  double rod_mass = 0.0;                         ///< each leg's rod, on the platform joint [kg]
  /// Each leg's housing mass times its centre's distance from the base joint, less the rod's mass
  /// times its centre's distance from the platform joint [kg m] (theory §4b).
  double leg_moment = 0.0;
};

/// Everything a Model is built from. Frames: B is the base frame; P is the platform frame, equal
/// to B translated by `home_height` along z at home.
struct ModelSpec {
  std::string name;                           ///< free text shown by the CLI
  PerLeg<LegSpec> legs;                       ///< the six legs
  double home_height = 0.0;                   ///< height of P's origin above B's origin at home [m]
  LimitSpec limits;                           ///< motion limits
  Vector3d observation_P = Vector3d::Zero();  ///< observation point "A" [m, P]
  Vector3d pivot_P = Vector3d::Zero();        ///< point about which pose rotations act [m, P]
  /// Temperature at which the geometry holds, the reference of the legs' thermal expansion [degC];
  /// plausible -60..200.
  double reference_temperature = 20.0;
  /// The static load the legs carry at the reference state (their forces at home are the
  /// deflection's zero).
  StaticLoadSpec static_load;
};

/// A leg with everything that depends only on the geometry precomputed.
struct Leg {
  Vector3d base_B;           ///< base U-joint centre [m, B]
  Vector3d platform_P;       ///< platform U-joint centre [m, P]
  Vector3d arm_P;            ///< platform joint relative to the pivot, platform_P - pivot_P [m, P]
  Vector3d axis_base_B;      ///< unit fixed base axis ja [-, B]
  Vector3d axis_platform_P;  ///< unit fixed platform axis jd [-, P]
  Vector3d s_home_B;         ///< unit leg axis at home, base to platform [-, B]
  double length_home;        ///< leg length at home [m]
  double theta_home;         ///< absolute twist angle jb -> je at home [rad]; NaN if lead is 0
  double cos_theta_home;     ///< cos(theta_home)
  double sin_theta_home;     ///< sin(theta_home)
  double lead;               ///< screw lead [m]
  double twist_sign;         ///< +1 for a right-hand thread, -1 for a left-hand one (docs/theory.md §4)
  double twist_gain;         ///< twist_sign * lead / 2pi: real minus motor-side length per rad [m/rad]
  ThreadSense thread;        ///< thread hand
  DrivenSide driven;         ///< driven side
  double length_offset;      ///< real minus motor-side length at zero twist [m]
  double drive_scale;        ///< real nut travel per commanded motor-side length, lead / drive_lead [-]
  double home_command;       ///< motor-side length the drive reads at its reference (homing) [m]
  double compliance;         ///< 1 / stiffness; 0 for a rigid leg [m/N]
  double play;               ///< lost motion along the leg [m]
  double home_direction;     ///< direction of the homing approach, +1 or -1 [-]
  double length_expansion;   ///< of the length between the joints at home [1/K]
  double lead_expansion;     ///< of the lead [1/K]
};

/// The same numbers in the layout of the library's vectorised kernels: eight lanes per quantity
/// (x, y, z for vectors), leg i in lane i, lanes 6 and 7 repeating leg 0; one aligned 512-bit
/// load each.
struct alignas(64) LegLanes {
  double base_B[3][8];
  double arm_P[3][8];
  double axis_base_B[3][8];
  double axis_platform_P[3][8];
  double s_home_B[3][8];
  double cos_theta_home[8];
  double sin_theta_home[8];
  double twist_gain[8];
  double length_offset[8];
  double has_axes[8];
  /// For the bound on the twist's share of the motor-side Jacobian (docs/theory.md §8): |twist_gain|
  /// of legs with axes, 0 for the others and in lanes 6 and 7 (so that a sum over lanes counts each
  /// leg once) [m/rad], and |arm_P| / Model::condition_length() [-].
  double twist_gain_bound[8];
  double arm_ratio[8];
};

/// The legs' precomputed geometry with one leg per row, for code vectorised over legs.
struct LegGeometry {
  LegVectors base_B;           ///< base U-joint centres [m, B]
  LegVectors arm_P;            ///< platform joints relative to the pivot [m, P]
  LegVectors axis_base_B;      ///< unit fixed base axes ja; zero rows for legs without axes [-, B]
  LegVectors axis_platform_P;  ///< unit fixed platform axes jd; zero rows for legs without axes [-, P]
  LegVectors s_home_B;         ///< unit leg axes at home [-, B]
  Vector6d cos_theta_home;     ///< cos of the absolute twist at home (1 without axes)
  Vector6d sin_theta_home;     ///< sin of the absolute twist at home (0 without axes)
  Vector6d twist_gain;         ///< real minus motor-side length per rad of twist [m/rad]
  Vector6d length_offset;      ///< real minus motor-side length at zero twist [m]
  Vector6d has_axes;           ///< 1 for legs whose U-joint axes are given, else 0
  Vector6d drive_scale;        ///< real nut travel per commanded motor-side length [-]
  Vector6d home_command;       ///< motor-side length the drives read at their reference [m]
  Vector6d compliance;         ///< 1 / stiffness, 0 for rigid legs [m/N]
  Vector6d half_play;          ///< play / 2 [m]
  Vector6d home_direction;     ///< direction of the homing approach, +1 or -1 [-]
  Vector6d thermal_length;     ///< length_expansion * length at home: growth of the length per kelvin [m/K]
  Vector6d lead_expansion;     ///< growth of the lead per kelvin, relative [1/K]
  LegLanes lanes;              ///< the geometry above the legs' effects, padded to eight lanes
};

/// The reference of the cheap proof that the Jacobian's condition is within the limit
/// (docs/theory.md §8): Y0 = W J0^-1, the inverse of the scaled Jacobian at home (W = diag(1, 1, 1,
/// l_c, l_c, l_c), l_c = Model::condition_length()), rows padded with zeros to eight lanes, and
/// its 1-norm. Any Y0 keeps the proof sound; a good one makes it succeed.
struct alignas(64) ConditionReference {
  double inverse[6][8] = {};  ///< Y0 [-]
  double norm = INFINITY;     ///< ||Y0||_1; inf where home's Jacobian is singular (no proof then) [-]
  double det_sign = 0.0;      ///< sign of det J0; 0 where Y0 is not set [-]
};

/// Immutable, validated platform model. Construction throws hexatwist::Error naming the leg and
/// field at fault; every other function of the library takes a `const Model&` and never throws.
class Model {
 public:
  /// Validates `spec` and precomputes the home configuration.
  explicit Model(const ModelSpec& spec);

  /// The specification this model was built from (axes as given, not normalised).
  const ModelSpec& spec() const noexcept { return spec_; }
  /// Leg `i` (0-based).
  const Leg& leg(int i) const noexcept { return legs_[static_cast<std::size_t>(i)]; }
  /// All legs.
  const PerLeg<Leg>& legs() const noexcept { return legs_; }
  /// Position of the pivot at home, (0,0,home_height) + pivot_P [m, B].
  const Vector3d& pivot_home_B() const noexcept { return pivot_home_B_; }
  /// True if any leg has a non-zero lead (the twist term matters).
  bool has_twist() const noexcept { return has_twist_; }
  /// Leg lengths at home [m].
  const Vector6d& length_home() const noexcept { return length_home_; }
  /// Motor-side lengths the drives read at their reference, the homing position (LinuxCNC's
  /// HOME), LegSpec::home_command [m].
  const Vector6d& home_command() const noexcept { return geometry_.home_command; }
  /// True if a leg's drive scale differs from 1 (a real lead other than the drive's, theory §4).
  bool has_drive_scale() const noexcept { return has_drive_scale_; }
  /// The real nut travel as a motor-side length, u = h + s (m - h), for the drives' commanded
  /// motor-side lengths m [m] (h = home_command, s = drive_scale; u = m without a drive scale).
  /// The kinematics relate u to the pose: real length = u + length_offset + twist term (theory §4).
  Vector6d travel_from_motor(const Vector6d& motor) const noexcept {
    if (!has_drive_scale_) return motor;
    return geometry_.home_command + geometry_.drive_scale.cwiseProduct(motor - geometry_.home_command);
  }
  /// The drives' motor-side lengths m = h + (u - h) / s for the travel u [m] (the inverse).
  Vector6d motor_from_travel(const Vector6d& travel) const noexcept {
    if (!has_drive_scale_) return travel;
    return geometry_.home_command + (travel - geometry_.home_command).cwiseQuotient(geometry_.drive_scale);
  }
  /// True if a leg has a finite stiffness, play or thermal expansion (leg_effects.hpp): the commands
  /// and forward kinematics then take the legs' forces, temperatures and directions into account.
  bool has_leg_effects() const noexcept { return has_stiffness_ || has_play_ || has_thermal_; }
  bool has_stiffness() const noexcept { return has_stiffness_; }  ///< a leg has a finite stiffness
  bool has_play() const noexcept { return has_play_; }            ///< a leg has play
  bool has_thermal() const noexcept { return has_thermal_; }      ///< a leg has thermal expansion
  /// ModelSpec::reference_temperature [degC].
  double reference_temperature() const noexcept { return spec_.reference_temperature; }
  /// The legs' static axial forces at home under spec().static_load, tension positive: the
  /// deflection's zero [N]. Zero without a static load.
  const Vector6d& reference_force() const noexcept { return reference_force_; }
  /// The legs one per row (the same numbers as leg(i), laid out for vectorised code).
  const LegGeometry& geometry() const noexcept { return geometry_; }
  /// cos(bend_max), precomputed for the limit check, less kLimitTolerance (a cosine of unit
  /// vectors: the tolerance is relative to 1) [-].
  double cos_bend_max() const noexcept { return cos_bend_max_; }
  /// cos(singularity_margin)^2, precomputed for the limit check, plus kLimitTolerance [-].
  double cos2_singularity_margin() const noexcept { return cos2_singularity_margin_; }
  /// The stroke and condition bounds as the checks compare them, widened by kLimitTolerance
  /// (accepted_min, accepted_max) [m, m, -].
  double length_min_accepted() const noexcept { return length_min_accepted_; }
  double length_max_accepted() const noexcept { return length_max_accepted_; }
  double condition_max_accepted() const noexcept { return condition_max_accepted_; }
  /// Characteristic length of the platform, the largest distance of a platform joint from the
  /// pivot: the Jacobian's rotation columns are divided by it for its condition number [m].
  double condition_length() const noexcept { return condition_length_; }
  /// The scaled inverse Jacobian at home, for the cheap condition proof.
  const ConditionReference& condition_reference() const noexcept { return condition_reference_; }

 private:
  void check_limits_spec();
  void build_leg(int i);
  void build_leg_axes(int i);     // the U-joints' fixed axes and the twist at home (lead > 0)
  void build_leg_effects(int i);  // stiffness, play, thermal expansion (leg_effects.hpp)
  void set_reference_force();     // the static forces at home (spec_.static_load)
  void lay_out_geometry();
  void check_home_and_reference();

  ModelSpec spec_;
  PerLeg<Leg> legs_;
  LegGeometry geometry_;
  Vector3d pivot_home_B_;
  Vector6d length_home_;
  double cos_bend_max_ = 1.0;
  double cos2_singularity_margin_ = 1.0;
  double length_min_accepted_ = 0.0;
  double length_max_accepted_ = 0.0;
  double condition_max_accepted_ = 0.0;
  double condition_length_ = 1.0;
  ConditionReference condition_reference_;
  bool has_twist_ = false;
  bool has_drive_scale_ = false;
  bool has_stiffness_ = false;
  bool has_play_ = false;
  bool has_thermal_ = false;
  Vector6d reference_force_ = Vector6d::Zero();
};

/// Joint positions and axes of a "symmetric" platform: the seed's parameters, Eq. (6), joints in
/// pairs with tangential fixed axes (layout in docs/theory.md).
struct SymmetricSpec {
  double Ra = 0.0;  ///< platform joint-pair radius [m]
  double Rb = 0.0;  ///< base joint-pair radius [m]
  double da = 0.0;  ///< distance between the two platform joints of a pair [m]
  double db = 0.0;  ///< distance between the two base joints of a pair [m]
  double H = 0.0;   ///< height of the platform joint plane above the base joint plane at home [m]
  std::array<double, 3> base_pair_angles{deg2rad(60), deg2rad(-60), deg2rad(180)};  ///< pairs (1,6),(2,3),(4,5) [rad]
  std::array<double, 3> platform_pair_angles{0.0, deg2rad(240), deg2rad(120)};      ///< pairs (1,2),(3,4),(5,6) [rad]
};

/// Leg geometry (positions and fixed axes) of a symmetric platform; lead, thread and driven side
/// are left at their defaults for the caller to set.
PerLeg<LegSpec> symmetric_legs(const SymmetricSpec& s);

}  // namespace hexatwist
