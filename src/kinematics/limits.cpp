// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/limits.hpp"

#include <fmt/format.h>

#include <cmath>
#include <utility>

#include "kinematics/geometry.hpp"
#include "kinematics/lanes.hpp"
#include "kinematics/linear_solve.hpp"
#include "kinematics/twist_internal.hpp"

namespace hexatwist {
namespace {

using detail::angle_between;
using detail::Array6d;
using detail::line_axis_angle;

Status report_violation(LimitReport& r, Status s, int leg, double value, double bound) noexcept {
  r.status = s;
  r.leg = leg;
  r.value = value;
  r.bound = bound;
  return s;
}

}  // namespace

Status jacobian_condition(const Model& model, const LegState& state, double& condition) noexcept {
  Matrix6d J;
  condition = std::nan("");
  if (model.has_twist()) {
    if (const Status s = detail::motor_length_jacobian(model, state, J); s != Status::Ok) return s;
  } else {
    length_jacobian(state, J);
  }
  double det_sign;
  condition = detail::scaled_condition(J, model.condition_length(), det_sign);
  return condition <= model.condition_max_accepted() ? Status::Ok : Status::PlatformSingularity;
}

namespace detail {

bool condition_proven_within(const Model& model, const LegState& state) noexcept {
  Matrix6d J;
  if (model.has_twist()) {
    if (motor_length_jacobian(model, state, J) != Status::Ok) return false;
  } else {
    length_jacobian(state, J);
  }
  return scaled_condition_below(J, model.condition_length(), model.condition_reference(),
                                model.condition_max_accepted());
}

}  // namespace detail

void bend_angles(const Model& model, const LegState& state, Vector6d& bend_base, Vector6d& bend_platform) noexcept {
  for (int i = 0; i < kLegs; ++i) {
    const Vector3d s = state.s_B.row(i).transpose();
    const Vector3d& s0 = model.leg(i).s_home_B;
    bend_base[i] = angle_between(s, s0);
    bend_platform[i] = angle_between(state.R_BP.transpose() * s, s0);
  }
}

Status check_limits(const Model& model, const LegState& state, LimitReport& r) noexcept {
  r = LimitReport{};
  const LimitSpec& lim = model.spec().limits;
  const LegGeometry& g = model.geometry();
  const double cos_bend = model.cos_bend_max();
  const double cos2_margin = model.cos2_singularity_margin();
  const LegVectors& s = state.s_B;
  // All legs at once (lanes.hpp).
  detail::LimitTerms terms[detail::kPackets];
  detail::lane_m ok = detail::all_set();
#pragma GCC unroll 4
  for (int k = 0; k < detail::kPackets; ++k) {
    const detail::lanes3 u = detail::load6(s, k);
    terms[k] = detail::limit_terms(model, state.R_BP, u, detail::splat<detail::lane_v>(1.0),
                                   detail::load6(state.length.data(), k),
                                   detail::dot(u, detail::load_lanes(g.lanes.axis_base_B, k)),
                                   detail::dot(u, detail::load6(state.axis_platform_B, k)), k);
    ok &= detail::within_limits(model, terms[k]);
  }
  if (detail::all_lanes(ok)) {
    // Most poses are far inside the condition limit: prove that cheaply, else compute it exactly.
    if (detail::condition_proven_within(model, state)) return Status::Ok;
    double condition;
    if (const Status st = jacobian_condition(model, state, condition); st != Status::Ok)
      return report_violation(r, st, -1, condition, lim.jacobian_condition_max);
    return Status::Ok;
  }
  // Leg i's terms, as the test saw them.
  const auto lane = [&](detail::lane_v detail::LimitTerms::*field, int i) {
    return (terms[i / detail::kWidth].*field)[i % detail::kWidth];
  };
  Vector6d len, cos_base, cos_platform, dot_a, dot_d;
  for (int i = 0; i < kLegs; ++i) {
    len[i] = lane(&detail::LimitTerms::length, i);
    cos_base[i] = lane(&detail::LimitTerms::cos_base, i);
    cos_platform[i] = lane(&detail::LimitTerms::cos_platform, i);
    dot_a[i] = lane(&detail::LimitTerms::dot_a, i);
    dot_d[i] = lane(&detail::LimitTerms::dot_d, i);
  }

  // Some leg is out: name the first, with the first limit it breaks (stroke, bend, singularity).
  for (int i = 0; i < kLegs; ++i) {
    const Vector3d si = s.row(i).transpose();
    if (!std::isfinite(len[i])) return report_violation(r, Status::NonFiniteInput, i, len[i], 0.0);
    if (len[i] < model.length_min_accepted())
      return report_violation(r, Status::StrokeBelowMin, i, len[i], lim.length_min);
    if (len[i] > model.length_max_accepted())
      return report_violation(r, Status::StrokeAboveMax, i, len[i], lim.length_max);
    if (!(cos_base[i] >= cos_bend))
      return report_violation(r, Status::BendBase, i, angle_between(si, model.leg(i).s_home_B), lim.bend_max);
    if (!(cos_platform[i] >= cos_bend))
      return report_violation(r, Status::BendPlatform, i,
                              angle_between(state.R_BP.transpose() * si, model.leg(i).s_home_B), lim.bend_max);
    if (g.has_axes[i] == 0.0) continue;
    if (dot_a[i] * dot_a[i] > cos2_margin)
      return report_violation(r, Status::SingularBase, i, line_axis_angle(si, model.leg(i).axis_base_B),
                              lim.singularity_margin);
    if (dot_d[i] * dot_d[i] > cos2_margin)
      return report_violation(r, Status::SingularPlatform, i,
                              line_axis_angle(si, state.axis_platform_B.row(i).transpose()), lim.singularity_margin);
  }
  return report_violation(r, Status::NonFiniteInput, -1, 0.0, 0.0);  // NaN in the leg axes
}

void nearest_limit(const Model& model, const LegState& state, double condition, LimitReport& nearest,
                   double& margin) noexcept {
  const LimitSpec& lim = model.spec().limits;
  margin = INFINITY;
  nearest = LimitReport{};
  const auto consider = [&](double m, Status s, int leg, double value, double bound) {
    if (m < margin || std::isnan(m)) {
      margin = m;
      nearest = LimitReport{s, leg, value, bound};
    }
  };
  const double half_stroke = 0.5 * (lim.length_max - lim.length_min);
  for (int i = 0; i < kLegs; ++i) {
    const double len = state.length[i];
    consider((len - lim.length_min) / half_stroke, Status::StrokeBelowMin, i, len, lim.length_min);
    consider((lim.length_max - len) / half_stroke, Status::StrokeAboveMax, i, len, lim.length_max);
    const Vector3d s = state.s_B.row(i).transpose();
    const double bend_base = angle_between(s, model.leg(i).s_home_B);
    const double bend_platform = angle_between(state.R_BP.transpose() * s, model.leg(i).s_home_B);
    consider(1.0 - bend_base / lim.bend_max, Status::BendBase, i, bend_base, lim.bend_max);
    consider(1.0 - bend_platform / lim.bend_max, Status::BendPlatform, i, bend_platform, lim.bend_max);
    if (model.geometry().has_axes[i] == 0.0) continue;
    const double free_range = kPi / 2 - lim.singularity_margin;
    const double a = line_axis_angle(s, model.leg(i).axis_base_B);
    const double d = line_axis_angle(s, state.axis_platform_B.row(i).transpose());
    consider((a - lim.singularity_margin) / free_range, Status::SingularBase, i, a, lim.singularity_margin);
    consider((d - lim.singularity_margin) / free_range, Status::SingularPlatform, i, d, lim.singularity_margin);
  }
  const double log_max = std::log(lim.jacobian_condition_max);
  const double c = std::isnan(condition) ? INFINITY : std::max(condition, 1.0);  // NaN: no Jacobian there
  consider(1.0 - std::log(c) / log_max, Status::PlatformSingularity, -1, condition, lim.jacobian_condition_max);
}

Status check_stroke(const Model& model, const Vector6d& command, LimitReport& r) noexcept {
  r = LimitReport{};
  const LimitSpec& lim = model.spec().limits;
  detail::lane_m ok = detail::all_set();
#pragma GCC unroll 4
  for (int k = 0; k < detail::kPackets; ++k) ok &= detail::within_stroke(model, detail::load6(command.data(), k));
  if (detail::all_lanes(ok)) return Status::Ok;
  for (int i = 0; i < kLegs; ++i) {
    if (!std::isfinite(command[i])) return report_violation(r, Status::NonFiniteInput, i, command[i], 0.0);
    if (command[i] < model.length_min_accepted())
      return report_violation(r, Status::StrokeBelowMin, i, command[i], lim.length_min);
    if (command[i] > model.length_max_accepted())
      return report_violation(r, Status::StrokeAboveMax, i, command[i], lim.length_max);
  }
  return Status::Ok;
}

namespace {

// A value and its bound with as many decimals as it takes to tell them apart (at least `least`):
// "1.4000003 m is below the minimum 1.4000000 m", never "1.400000 below 1.400000".
std::pair<std::string, std::string> apart(double value, double bound, int least) {
  for (int d = least; d <= 16; ++d) {
    std::string a = fmt::format("{:.{}f}", value, d), b = fmt::format("{:.{}f}", bound, d);
    if (a != b) return {a, b};
  }
  return {fmt::format("{}", value), fmt::format("{}", bound)};
}

}  // namespace

std::string describe(const LimitReport& r) {
  if (r.status == Status::Ok) return "ok";
  const std::string leg = r.leg >= 0 ? fmt::format("leg {}: ", r.leg + 1) : std::string();
  switch (r.status) {
    case Status::StrokeBelowMin:
    case Status::StrokeAboveMax: {
      const bool below = r.status == Status::StrokeBelowMin;
      const char* which = below ? "minimum" : "maximum";
      const char* field = below ? "limits.length_min" : "limits.length_max";
      // Within 10 nm (a boundary found by bisection): at the limit, in digits every CPU prints alike.
      if (std::abs(r.value - r.bound) < 1e-8)
        return fmt::format("{}length at the {} {:.6f} m ({})", leg, which, r.bound, field);
      const auto [v, b] = apart(r.value, r.bound, 6);
      return fmt::format("{}length {} m is {} the {} {} m ({})", leg, v, below ? "below" : "above", which, b, field);
    }
    case Status::BendBase:
    case Status::BendPlatform: {
      const auto [v, b] = apart(rad2deg(r.value), rad2deg(r.bound), 3);
      return fmt::format("{}{} U-joint bends {} deg, above the limit {} deg (limits.bend_max_deg)", leg,
                         r.status == Status::BendBase ? "base" : "platform", v, b);
    }
    case Status::SingularBase:
    case Status::SingularPlatform:
      return fmt::format(
          "{}leg is {:.3f} deg from the {} U-joint's fixed axis, inside the singularity margin {:.3f} deg "
          "(limits.singularity_margin_deg)",
          leg, rad2deg(r.value), r.status == Status::SingularBase ? "base" : "platform", rad2deg(r.bound));
    case Status::MotorSpeedAboveMax:
      return fmt::format("{}motor speed {:.0f} rpm is above the limit {:.0f} rpm (servo.max_speed_rpm)", leg,
                         r.value * 60.0 / (2.0 * kPi), r.bound * 60.0 / (2.0 * kPi));
    case Status::TorqueAboveMax:
      return fmt::format("{}holding the load takes {:.2f} N m, above the motor's limit {:.2f} N m (servo.torque_limit)",
                         leg, r.value, r.bound);
    case Status::PlatformSingularity:
      return fmt::format(
          "the platform is near a singularity: the Jacobian's condition number {:.4g} is above the limit "
          "{:.4g} (limits.jacobian_condition_max)",
          r.value, r.bound);
    default:
      return leg + std::string(describe(r.status));
  }
}

}  // namespace hexatwist
