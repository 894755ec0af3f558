// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/model.hpp"

#include <fmt/format.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "hexatwist/kinematics/limits.hpp"
#include "kinematics/geometry.hpp"
#include "kinematics/twist_internal.hpp"

namespace hexatwist {
namespace {

// Smallest usable axis length before normalisation (an axis is a direction; any scale is fine).
constexpr double kMinAxisNorm = 1e-9;
// Largest condition number of the home Jacobian we accept as "the legs hold the platform".
constexpr double kMaxHomeCondition = 1e8;

// Every message is "field: what", field one of home_height, limits.<x>, observation_point, pivot,
// legs, "leg N" or "leg N: <base|platform|lead|length_offset|base_axis|platform_axis>": src/io/config.cpp maps the
// field back to the line of the YAML file it came from.
[[noreturn]] void fail(const std::string& msg) { throw Error(msg); }

void require_finite(const Vector3d& v, const std::string& what) {
  if (!v.allFinite()) fail(fmt::format("{}: expected three finite numbers, got NaN or inf", what));
}

void require_finite(double v, const std::string& what) {
  if (!std::isfinite(v)) fail(fmt::format("{}: expected a finite number, got {}", what, v));
}

Vector3d unit_axis(const Vector3d& axis, const std::string& what) {
  require_finite(axis, what);
  const double n = axis.norm();
  if (n < kMinAxisNorm) fail(fmt::format("{}: axis is zero; expected a direction", what));
  if (!std::isfinite(n)) fail(fmt::format("{}: expected a direction of finite length, got one beyond 1e308", what));
  return axis / n;
}

// The plausible size of a platform (configs/seed.yaml and README's "Platform configuration" list the
// ranges): every length and coordinate within kMaxLength. Finite nonsense (1e300 m) would overflow
// the kinematics into inf and NaN downstream; it is refused here, at its field.
constexpr double kMaxLength = 100.0;  // [m]

void require_point(const Vector3d& v, const std::string& what) {
  require_finite(v, what);
  if (v.cwiseAbs().maxCoeff() > kMaxLength)
    fail(fmt::format("{}: expected coordinates within +-{:g} m, got [{}, {}, {}]", what, kMaxLength, v.x(), v.y(),
                     v.z()));
}

void require_length(double v, const std::string& what) {
  require_finite(v, what);
  if (!(v > 0.0 && v <= kMaxLength))
    fail(fmt::format("{}: expected > 0 and at most {:g} m, got {}", what, kMaxLength, v));
}

}  // namespace

// A drive scale further from 1 than this is not a lead error but a wrong drive_lead (a typing error).
constexpr double kMaxDriveScaleError = 0.5;

Model::Model(const ModelSpec& spec) : spec_(spec) {
  check_limits_spec();
  for (int i = 0; i < kLegs; ++i) build_leg(i);
  for (int i = 0; i < kLegs; ++i) build_leg_effects(i);
  lay_out_geometry();
  check_home_and_reference();
  set_reference_force();
}

void Model::set_reference_force() {
  const StaticLoadSpec& load = spec_.static_load;
  if (!load.present) {
    for (int i = 0; i < kLegs; ++i)
      if (legs_[static_cast<std::size_t>(i)].compliance != 0.0)
        fail(
            fmt::format("leg {}: stiffness: the legs' forces need the load they carry (a configuration's load and "
                        "mechanism sections)",
                        i + 1));
    return;
  }
  require_finite(load.gravity, "static_load.gravity");
  require_finite(load.mass, "static_load.mass");
  require_finite(load.rod_mass, "static_load.rod_mass");
  require_finite(load.leg_moment, "static_load.leg_moment");
  require_point(load.center_of_mass_P, "static_load.center_of_mass");
  if (!(load.gravity >= 0.0 && load.mass >= 0.0 && load.rod_mass >= 0.0))
    fail(fmt::format("static_load: expected gravity, mass and rod mass >= 0, got {}, {}, {}", load.gravity, load.mass,
                     load.rod_mass));
  LegState home;
  if (inverse_kinematics(*this, Placement{}, home) != Status::Ok ||
      static_leg_forces(*this, load, home, reference_force_) != Status::Ok)
    fail("legs: the legs' static forces at home cannot be computed");
}

void Model::check_limits_spec() {
  const ModelSpec& spec = spec_;
  const LimitSpec& lim = spec.limits;
  require_length(spec.home_height, "home_height");
  require_length(lim.length_min, "limits.length_min");
  require_length(lim.length_max, "limits.length_max");
  if (lim.length_min >= lim.length_max)
    fail(fmt::format("limits.length_min: expected less than limits.length_max ({} m), got {} m", lim.length_max,
                     lim.length_min));
  require_finite(lim.bend_max, "limits.bend_max");
  if (lim.bend_max <= 0.0 || lim.bend_max > kPi / 2)
    fail(fmt::format("limits.bend_max: expected an angle in (0, 90] deg, got {:.10g} deg", rad2deg(lim.bend_max)));
  require_finite(lim.singularity_margin, "limits.singularity_margin");
  if (lim.singularity_margin <= 0.0 || lim.singularity_margin >= kPi / 2)
    fail(fmt::format("limits.singularity_margin: expected an angle in (0, 90) deg, got {:.10g} deg",
                     rad2deg(lim.singularity_margin)));
  require_finite(lim.jacobian_condition_max, "limits.jacobian_condition_max");
  // A huge limit is no limit (a meaningful choice); at most 1 no pose passes.
  if (!(lim.jacobian_condition_max > 1.0))
    fail(fmt::format("limits.jacobian_condition_max: expected a condition number > 1, got {}",
                     lim.jacobian_condition_max));
  require_point(spec.observation_P, "observation_point");
  require_point(spec.pivot_P, "pivot");
  require_finite(spec.reference_temperature, "reference_temperature");
  if (!(spec.reference_temperature >= kMinTemperature && spec.reference_temperature <= kMaxTemperature))
    fail(fmt::format("reference_temperature: expected {:g} to {:g} degC, got {} degC", kMinTemperature, kMaxTemperature,
                     spec.reference_temperature));

  // The bounds as every limit check compares them, with the tolerance of limits.hpp.
  cos_bend_max_ = std::cos(lim.bend_max) - kLimitTolerance;
  cos2_singularity_margin_ = std::cos(lim.singularity_margin) * std::cos(lim.singularity_margin) + kLimitTolerance;
  length_min_accepted_ = accepted_min(lim.length_min);
  length_max_accepted_ = accepted_max(lim.length_max);
  condition_max_accepted_ = accepted_max(lim.jacobian_condition_max);
  pivot_home_B_ = Vector3d(0.0, 0.0, spec.home_height) + spec.pivot_P;
}

void Model::build_leg(int i) {
  const LimitSpec& lim = spec_.limits;
  const LegSpec& ls = spec_.legs[static_cast<std::size_t>(i)];
  Leg& leg = legs_[static_cast<std::size_t>(i)];
  const std::string who = fmt::format("leg {}", i + 1);
  const double stroke = lim.length_max - lim.length_min;
  require_point(ls.base_B, who + ": base");
  require_point(ls.platform_P, who + ": platform");
  require_finite(ls.lead, who + ": lead");
  if (ls.lead < 0.0) fail(fmt::format("{}: lead: expected >= 0 m, got {}", who, ls.lead));
  // A screw turns at least once over its stroke: a longer lead (1e30 m) is a typing error.
  if (!(ls.lead <= stroke))
    fail(fmt::format("{}: lead: expected at most the stroke ({} m), got {} m", who, stroke, ls.lead));

  leg.base_B = ls.base_B;
  leg.platform_P = ls.platform_P;
  leg.arm_P = ls.platform_P - spec_.pivot_P;
  const Vector3d L0 = Vector3d(0.0, 0.0, spec_.home_height) + ls.platform_P - ls.base_B;
  leg.length_home = L0.norm();
  if (!(leg.length_home > 0.0)) fail(fmt::format("{}: base and platform joints coincide at home", who));
  leg.s_home_B = L0 / leg.length_home;
  if (leg.length_home < length_min_accepted_ || leg.length_home > length_max_accepted_)
    fail(fmt::format("{}: home length {:.6f} m is outside the stroke [{}, {}] m", who, leg.length_home, lim.length_min,
                     lim.length_max));

  // An offset is a zero error of the motor-side length: one as long as the stroke is not.
  require_finite(ls.length_offset, who + ": length_offset");
  if (!(std::abs(ls.length_offset) < stroke))
    fail(fmt::format("{}: length_offset: expected less than the stroke ({} m) in magnitude, got {} m", who, stroke,
                     ls.length_offset));
  leg.length_offset = ls.length_offset;
  // The motor must reach home: its command there, real length minus offset, inside the stroke.
  if (const double command = leg.length_home - ls.length_offset;
      command < length_min_accepted_ || command > length_max_accepted_)
    fail(fmt::format("{}: length_offset: {} m puts the home command {:.6f} m outside the stroke [{}, {}] m", who,
                     ls.length_offset, command, lim.length_min, lim.length_max));

  leg.lead = ls.lead;
  leg.thread = ls.thread;
  leg.driven = ls.driven;
  // docs/theory.md §4: real = motor-side + lead*dtheta/2pi for a right-hand thread, whichever end
  // is driven (swapping the screw and nut between housing and rod negates both the relative
  // rotation and the axial sense); a left-hand thread negates it.
  leg.twist_sign = ls.thread == ThreadSense::Right ? 1.0 : -1.0;
  leg.twist_gain = leg.twist_sign * ls.lead / (2.0 * kPi);
  length_home_[i] = leg.length_home;

  // The drive's reference and scale (theory §4): commands m and nut travel u = h + s (m - h).
  leg.drive_scale = 1.0;
  if (!std::isnan(ls.drive_lead)) {
    require_finite(ls.drive_lead, who + ": drive_lead");
    if (!(ls.lead > 0.0))
      fail(fmt::format("{}: drive_lead: a drive scale needs the real lead (screw.lead or the leg's lead); lead is {} m",
                       who, ls.lead));
    if (!(ls.drive_lead > 0.0)) fail(fmt::format("{}: drive_lead: expected > 0 m, got {} m", who, ls.drive_lead));
    leg.drive_scale = ls.lead / ls.drive_lead;
    if (!(std::abs(leg.drive_scale - 1.0) <= kMaxDriveScaleError))
      fail(
          fmt::format("{}: drive_lead: {} m is {:.3g} times the lead {} m; expected within {:g} % of it (a lead "
                      "error, not another screw)",
                      who, ls.drive_lead, 1.0 / leg.drive_scale, ls.lead, 100 * kMaxDriveScaleError));
  }
  leg.home_command = leg.length_home - ls.length_offset;
  if (!std::isnan(ls.home_command)) {
    require_finite(ls.home_command, who + ": home_command");
    if (ls.home_command < length_min_accepted_ || ls.home_command > length_max_accepted_)
      fail(fmt::format("{}: home_command: {} m is outside the stroke [{}, {}] m", who, ls.home_command, lim.length_min,
                       lim.length_max));
    leg.home_command = ls.home_command;
  }
  has_drive_scale_ = has_drive_scale_ || leg.drive_scale != 1.0;

  build_leg_axes(i);
}

void Model::build_leg_axes(int i) {
  const LimitSpec& lim = spec_.limits;
  const LegSpec& ls = spec_.legs[static_cast<std::size_t>(i)];
  Leg& leg = legs_[static_cast<std::size_t>(i)];
  const std::string who = fmt::format("leg {}", i + 1);
  // Axes are needed for the twist (lead > 0). With lead 0 they may be omitted (all zero).
  const bool axes_given = !ls.axis_base_B.isZero(0.0) || !ls.axis_platform_P.isZero(0.0);
  if (ls.lead > 0.0 || axes_given) {
    leg.axis_base_B = unit_axis(ls.axis_base_B, who + ": base_axis");
    leg.axis_platform_P = unit_axis(ls.axis_platform_P, who + ": platform_axis");
    const double ab = detail::line_axis_angle(leg.s_home_B, leg.axis_base_B);
    const double ap = detail::line_axis_angle(leg.s_home_B, leg.axis_platform_P);
    constexpr const char* kTooClose =
        "{}: {}: {:.3g} deg from the leg's home direction, inside the singularity margin {:.3g} deg "
        "(the U-joint is singular at home)";
    if (ab < lim.singularity_margin)
      fail(fmt::format(kTooClose, who, "base_axis", rad2deg(ab), rad2deg(lim.singularity_margin)));
    if (ap < lim.singularity_margin)
      fail(fmt::format(kTooClose, who, "platform_axis", rad2deg(ap), rad2deg(lim.singularity_margin)));
    const auto xy = detail::twist_xy(leg.s_home_B, leg.axis_base_B, leg.axis_platform_P);
    leg.theta_home = std::atan2(xy.y, xy.x);
    leg.cos_theta_home = std::cos(leg.theta_home);
    leg.sin_theta_home = std::sin(leg.theta_home);
    has_twist_ = has_twist_ || ls.lead > 0.0;
  } else {
    leg.axis_base_B.setZero();
    leg.axis_platform_P.setZero();
    leg.theta_home = std::nan("");
    leg.cos_theta_home = 1.0;
    leg.sin_theta_home = 0.0;
  }
}

void Model::build_leg_effects(int i) {
  const LegSpec& ls = spec_.legs[static_cast<std::size_t>(i)];
  Leg& leg = legs_[static_cast<std::size_t>(i)];
  const std::string who = fmt::format("leg {}", i + 1);
  // Plausible ranges (docs/theory/kinematics.md §4b): beyond them a value is a typing error.
  if (std::isnan(ls.stiffness) || !(ls.stiffness >= kMinStiffness))
    fail(fmt::format("{}: stiffness: expected {:g} N/m (1 N/um) or more, or infinity (rigid), got {} N/m", who,
                     kMinStiffness, ls.stiffness));
  if (std::isfinite(ls.stiffness) && ls.stiffness > kMaxStiffness)
    fail(fmt::format("{}: stiffness: expected at most {:g} N/m (a stiffer leg is rigid: leave it out), got {} N/m", who,
                     kMaxStiffness, ls.stiffness));
  require_finite(ls.play, who + ": play");
  if (!(ls.play >= 0.0 && ls.play <= kMaxPlay))
    fail(fmt::format("{}: play: expected 0 to {:g} m, got {} m", who, kMaxPlay, ls.play));
  if (!(ls.home_direction == 1.0 || ls.home_direction == -1.0))
    fail(fmt::format("{}: home_direction: expected +1 (lengthening into home) or -1, got {}", who, ls.home_direction));
  for (const auto& [value, name] :
       {std::pair{ls.length_expansion, "length_expansion"}, std::pair{ls.lead_expansion, "lead_expansion"}}) {
    require_finite(value, fmt::format("{}: {}", who, name));
    if (!(value >= kMinExpansion && value <= kMaxExpansion))
      fail(fmt::format("{}: {}: expected {:g} to {:g} per kelvin, got {}", who, name, kMinExpansion, kMaxExpansion,
                       value));
  }
  leg.compliance = std::isfinite(ls.stiffness) ? 1.0 / ls.stiffness : 0.0;
  leg.play = ls.play;
  leg.home_direction = ls.home_direction;
  leg.length_expansion = ls.length_expansion;
  leg.lead_expansion = ls.lead_expansion;
  has_stiffness_ = has_stiffness_ || leg.compliance != 0.0;
  has_play_ = has_play_ || leg.play != 0.0;
  has_thermal_ = has_thermal_ || leg.length_expansion != 0.0 || leg.lead_expansion != 0.0;
}

void Model::lay_out_geometry() {
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = legs_[static_cast<std::size_t>(i)];
    const bool axes = !std::isnan(leg.theta_home);
    geometry_.base_B.row(i) = leg.base_B.transpose();
    geometry_.arm_P.row(i) = leg.arm_P.transpose();
    geometry_.axis_base_B.row(i) = leg.axis_base_B.transpose();
    geometry_.axis_platform_P.row(i) = leg.axis_platform_P.transpose();
    geometry_.s_home_B.row(i) = leg.s_home_B.transpose();
    geometry_.cos_theta_home[i] = leg.cos_theta_home;
    geometry_.sin_theta_home[i] = leg.sin_theta_home;
    geometry_.twist_gain[i] = leg.twist_gain;
    geometry_.length_offset[i] = leg.length_offset;
    geometry_.has_axes[i] = axes ? 1.0 : 0.0;
    geometry_.drive_scale[i] = leg.drive_scale;
    geometry_.home_command[i] = leg.home_command;
    geometry_.compliance[i] = leg.compliance;
    geometry_.half_play[i] = 0.5 * leg.play;
    geometry_.home_direction[i] = leg.home_direction;
    geometry_.thermal_length[i] = leg.length_expansion * leg.length_home;
    geometry_.lead_expansion[i] = leg.lead_expansion;
    condition_length_ = std::max(i == 0 ? 0.0 : condition_length_, leg.arm_P.norm());
  }
  if (!(condition_length_ > 0.0))
    fail("legs: every platform joint sits at the pivot; expected a platform of some size");
  LegLanes& lanes = geometry_.lanes;
  for (int lane = 0; lane < 8; ++lane) {
    const int i = lane < kLegs ? lane : 0;
    for (int k = 0; k < 3; ++k) {
      lanes.base_B[k][lane] = geometry_.base_B(i, k);
      lanes.arm_P[k][lane] = geometry_.arm_P(i, k);
      lanes.axis_base_B[k][lane] = geometry_.axis_base_B(i, k);
      lanes.axis_platform_P[k][lane] = geometry_.axis_platform_P(i, k);
      lanes.s_home_B[k][lane] = geometry_.s_home_B(i, k);
    }
    lanes.cos_theta_home[lane] = geometry_.cos_theta_home[i];
    lanes.sin_theta_home[lane] = geometry_.sin_theta_home[i];
    lanes.twist_gain[lane] = geometry_.twist_gain[i];
    lanes.length_offset[lane] = geometry_.length_offset[i];
    lanes.has_axes[lane] = geometry_.has_axes[i];
    lanes.twist_gain_bound[lane] = lane < kLegs ? std::abs(geometry_.twist_gain[i]) * geometry_.has_axes[i] : 0.0;
    lanes.arm_ratio[lane] = geometry_.arm_P.row(i).norm() / condition_length_;
  }
}

void Model::check_home_and_reference() {
  // The six legs must hold the platform: the length Jacobian at home must be well conditioned.
  Matrix6d J;
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = legs_[static_cast<std::size_t>(i)];
    J.row(i) << leg.s_home_B.transpose(), leg.arm_P.cross(leg.s_home_B).transpose();
  }
  const Eigen::JacobiSVD<Matrix6d> svd(J);
  const double smax = svd.singularValues()(0), smin = svd.singularValues()(5);
  if (!(smin > 0.0) || smax / smin > kMaxHomeCondition)
    fail(fmt::format("legs: the six legs do not hold the platform at home (Jacobian condition number {:.3g})",
                     smin > 0.0 ? smax / smin : INFINITY));
  // Home must pass the platform-singularity limit, as it passes the others.
  LegState home;
  double condition = INFINITY;
  if (inverse_kinematics(*this, Placement{}, home) == Status::Ok &&
      jacobian_condition(*this, home, condition) == Status::PlatformSingularity)
    // At fault: the limit if it is tighter than the default and home is within the default (a
    // platform as well conditioned as the seed's), else the legs, which hold the platform weakly there.
    fail(condition <= kDefaultJacobianConditionMax
             ? fmt::format("limits.jacobian_condition_max: the Jacobian's condition number at home is {:.4g}, above "
                           "the limit {:.4g}",
                           condition, spec_.limits.jacobian_condition_max)
             : fmt::format("legs: the Jacobian's condition number at home is {:.4g}, above the limit {:.4g} "
                           "(limits.jacobian_condition_max): the legs hold the platform weakly at home",
                           condition, spec_.limits.jacobian_condition_max));
  // The cheap condition proof's reference: the scaled Jacobian's inverse at home (left at zero,
  // with an infinite norm, where home has no regular Jacobian: every proof then fails).
  Matrix6d J_home = Matrix6d::Zero();
  const bool regular = inverse_kinematics(*this, Placement{}, home) == Status::Ok &&
                       (has_twist_ ? detail::motor_length_jacobian(*this, home, J_home) == Status::Ok
                                   : (length_jacobian(home, J_home), true));
  const Eigen::PartialPivLU<Matrix6d> lu(J_home);
  if (regular && std::abs(lu.determinant()) > 0.0) {
    Matrix6d Y = lu.inverse();
    Y.bottomRows<3>() *= condition_length_;  // W J0^-1
    if (Y.allFinite()) {
      for (int i = 0; i < kLegs; ++i)
        for (int c = 0; c < kLegs; ++c) condition_reference_.inverse[i][c] = Y(i, c);
      condition_reference_.norm = Y.cwiseAbs().colwise().sum().maxCoeff();
      condition_reference_.det_sign = lu.determinant() > 0.0 ? 1.0 : -1.0;
    }
  }
}

PerLeg<LegSpec> symmetric_legs(const SymmetricSpec& s) {
  // docs/theory.md §1: joints in pairs, fixed axes tangential (Eq. 6). Leg i joins base pair
  // kBasePair[i] to platform pair kPlatformPair[i]; each joint sits d/2 along the tangent from its
  // pair centre, on the side facing the pair it connects to (odd legs: base -, platform +).
  constexpr std::array<int, kLegs> kBasePair{0, 1, 1, 2, 2, 0};
  constexpr std::array<int, kLegs> kPlatformPair{0, 0, 1, 1, 2, 2};
  PerLeg<LegSpec> legs;
  for (int i = 0; i < kLegs; ++i) {
    const double side = (i % 2 == 0) ? 1.0 : -1.0;
    const double beta = s.base_pair_angles[static_cast<std::size_t>(kBasePair[i])];
    const double alpha = s.platform_pair_angles[static_cast<std::size_t>(kPlatformPair[i])];
    const Vector3d tb(-std::sin(beta), std::cos(beta), 0.0);
    const Vector3d ta(-std::sin(alpha), std::cos(alpha), 0.0);
    LegSpec& leg = legs[static_cast<std::size_t>(i)];
    leg.base_B = s.Rb * Vector3d(std::cos(beta), std::sin(beta), 0.0) - side * 0.5 * s.db * tb;
    leg.platform_P = s.Ra * Vector3d(std::cos(alpha), std::sin(alpha), 0.0) + side * 0.5 * s.da * ta;
    leg.axis_base_B = tb;
    leg.axis_platform_P = ta;
  }
  return legs;
}

}  // namespace hexatwist
