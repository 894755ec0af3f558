// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/compensation.hpp"

#include "kinematics/compensation_internal.hpp"
#include "kinematics/lanes.hpp"
#include "kinematics/leg_effects_internal.hpp"
#include "kinematics/twist_internal.hpp"

namespace hexatwist {
namespace {

// Names a failure that is not a limit (non-finite input, singular joint) in the report.
Status fail(LimitReport& report, Status status) noexcept {
  report = LimitReport{};
  report.status = status;
  return status;
}

}  // namespace

void length_error(const Model& model, const Vector6d& dtheta, Vector6d& error) noexcept {
  // Eq. (10): lenP_i = dtheta_i / 2pi * P_h, with the thread-hand sign in twist_gain.
  error = model.geometry().twist_gain.cwiseProduct(dtheta);
}

namespace {

// Inverse kinematics, the limits, the twist and Eq. (10)-(12) as the nuts' travels: Ok when the
// pose is inside every limit (out.conventional and out.compensated then hold travels still to be
// checked against the stroke), else the status to return. The twist is defined wherever no U-joint
// is singular, also outside the other limits.
Status rigid_travels(const Model& model, const Pose& pose, CommandReport& out) noexcept {
  out.limit = LimitReport{};
  if (!pose.is_finite()) return fail(out.limit, Status::NonFiniteInput);
  if (const Status s = inverse_kinematics(model, pose, out.legs); s != Status::Ok) return fail(out.limit, s);
  const Status pose_status = check_limits(model, out.legs, out.limit);
  if (const Status s = twist(model, out.legs, out.twist); s != Status::Ok) {
    if (pose_status != Status::Ok) return pose_status;
    return fail(out.limit, s);
  }
  length_error(model, out.twist, out.length_error);
  // Eq. (11)-(12) as absolute motor-side lengths; both commands take the legs' zero errors out.
  out.conventional = out.legs.length - model.geometry().length_offset;
  out.compensated = out.conventional - out.length_error;
  return pose_status;
}

// The stroke is the nut's travel; the drives' commands follow from it (theory §4).
Status drive_commands(const Model& model, CommandReport& out) noexcept {
  const Status stroke = check_stroke(model, out.compensated, out.limit);
  out.conventional = model.motor_from_travel(out.conventional);
  out.compensated = model.motor_from_travel(out.compensated);
  return stroke;
}

}  // namespace

Status compute_commands(const Model& model, const Pose& pose, CommandReport& out) noexcept {
  if (model.has_leg_effects()) return compute_commands(model, pose, LegInputs{}, nullptr, out);
  if (const Status s = rigid_travels(model, pose, out); s != Status::Ok) return s;
  return drive_commands(model, out);
}

namespace {

// The real-time command in one pass over the legs, in registers (lanes.hpp): the kernels of
// inverse_kinematics, check_limits, twist and check_stroke without the LegState between them,
// and with the leg vectors L_i in place of the unit s_i, which spares a division on the
// critical path (the tests and the twist's atan2 are homogeneous in the leg's scale). True,
// with `command` written, if every test passes; false leaves the naming of the limit or joint
// to the full path. The two decide alike except within rounding of a bound. The condition limit
// is proven after the loop (limits.hpp: once every leg passed) for the motor-side Jacobian from
// the geometric one, formed from the same registers, and a bound on the twist's share of it
// (docs/theory.md §8): the twist's own Jacobian costs as much as the proof. With `load`, the
// legs' static forces under it (leg_effects_internal.hpp) go to `force` and their status to
// `force_status`, when every test passed; `twist_term` (may be null) gets k dtheta.
bool commands_in_lanes(const Model& model, const Pose& pose, bool compensated, Vector6d& command,
                       const StaticLoadSpec* load = nullptr, Vector6d* force = nullptr, Status* force_status = nullptr,
                       Vector6d* twist_term = nullptr) noexcept {
  using namespace detail;
  const LegLanes& g = model.geometry().lanes;
  const Matrix3d R = detail::rotation_from_rpy(pose.rpy);
  const bool twist_model = model.has_twist();
  lane_m ok = all_set();
  Vector6d out, twist_out = Vector6d::Zero();
  LegLoads loads;
  ColumnPackets J;
  lane_v twist_share = {};
  const lane_v inv_condition_length = splat<lane_v>(1.0 / model.condition_length());
#pragma GCC unroll 4
  for (int k = 0; k < kPackets; ++k) {
    const LegsAt legs = legs_at(model, R, pose.position, k);
    const lanes3 ja = load_lanes(g.axis_base_B, k);
    const lanes3& jd = legs.axis_platform;
    const lane_v dot_a = dot(legs.leg, ja), dot_d = dot(legs.leg, jd);
    ok &= within_limits(model, limit_terms(model, R, legs.leg, legs.length, legs.length, dot_a, dot_d, k));
    lane_v command_k = legs.length - load_lanes(g.length_offset, k);
    const lane_v inv_length = 1.0 / legs.length;
    if (twist_model) {
      // x scales with |L|^2 and y with |L|: one more |L| on y puts both on the same scale.
      const TwistTerms t = twist_terms(legs.leg, ja, jd, dot_a, dot_d, legs.length2);
      const lane_v y = legs.length * t.y;
      ok &= twist_regular(model, t.x, y, legs.length2 * legs.length2, k);
      twist_share += twist_share_bound(model, t.x, y, dot_a, dot_d, legs.length, legs.length2, inv_length, k);
      if (compensated) {
        const lane_v rigid = command_k;
        command_k -= load_lanes(g.twist_gain, k) * twist_angle(model, t.x, y, true, k);  // Eq. (12)
        ok &= within_stroke(model, command_k);
        // k dtheta as the difference, which leaves Eq. (12)'s multiply-add (batch.cpp's) alone.
        if (twist_term != nullptr) store6(twist_out.data(), rigid - command_k, k);
      }
    }
    store6(out.data(), command_k, k);
    // The geometric Jacobian's rows from the unit s_i, as limits.cpp has them, its rotation
    // columns divided by the condition length (A of limits.hpp).
    const lanes3 s = inv_length * legs.leg;
    const lanes3 arm_x_s = inv_condition_length * cross(legs.arm, s);
    J.set(k, {s.x, s.y, s.z, arm_x_s.x, arm_x_s.y, arm_x_s.z});
    if (load != nullptr) add_leg_loads(*load, s, legs.arm, inv_length, k, loads);
  }
  if (!all_lanes(ok)) return false;
  // The platform singularity last, once every leg passed (limits.hpp): a cheap proof that the
  // condition is inside the limit, which holds for nearly every pose; else the full path. The
  // bound on ||A_m - A_g||_1 gets a factor 1 + 1e-6 for the rounding of the bound and of the
  // twist's rows, and 1e-13 for the rounding of A_m's entries, each by a few u of a magnitude
  // of about 1, in a column sum of six (theory §8).
  PaddedRows rows;
  J.rows(rows);
  // The forces before the proof, which does not need them: the two chains overlap.
  if (load != nullptr) *force_status = finish_leg_forces(model, *load, R, loads, rows, *force);
  const double perturbation = sum_lanes(twist_share) * (1.0 + 1e-6) + 1e-13;
  if (!condition_below(rows, model.condition_reference(), model.condition_max_accepted(), perturbation)) return false;
  command = out;
  if (twist_term != nullptr) *twist_term = twist_out;
  return true;
}

}  // namespace

Status motor_commands(const Model& model, const Pose& pose, Strategy strategy, Vector6d& command,
                      LimitReport& report) noexcept {
  if (strategy == Strategy::Compensated && model.has_leg_effects())
    return motor_commands(model, pose, strategy, LegInputs{}, nullptr, command, report);
  if (!pose.is_finite()) return fail(report, Status::NonFiniteInput);
  const bool compensated = strategy == Strategy::Compensated && model.has_twist();
  if (commands_in_lanes(model, pose, compensated, command)) {
    report = LimitReport{};
    command = model.motor_from_travel(command);  // the drives' reference and scale (theory §4)
    return Status::Ok;
  }
  // Some test failed: the same computation through a LegState, which names the leg and limit.
  return detail::commands_through_state(model, pose, compensated, command, report);
}

Status compute_commands(const Model& model, const Pose& pose, const LegInputs& inputs, const PlayState* play,
                        CommandReport& out) noexcept {
  if (!model.has_leg_effects()) return compute_commands(model, pose, out);
  out.effects = LegEffects{};
  if (const Status s = rigid_travels(model, pose, out); s != Status::Ok) return s;
  Vector6d force, temperature, no_play, direction;
  if (const Status s = resolve_inputs(model, out.legs, inputs, force, temperature); s != Status::Ok)
    return fail(out.limit, s);
  Vector6d travel;
  detail::command_travel(model, out.compensated, out.length_error, force, temperature, play, travel, no_play,
                         direction);
  effect_lengths(model, travel, out.length_error, force, temperature, direction, out.effects);
  out.compensated = travel;
  return drive_commands(model, out);
}

Status motor_commands(const Model& model, const Pose& pose, Strategy strategy, const LegInputs& inputs, PlayState* play,
                      Vector6d& command, LimitReport& report) noexcept {
  if (strategy != Strategy::Compensated || !model.has_leg_effects())
    return motor_commands(model, pose, strategy, command, report);
  if (!pose.is_finite()) return fail(report, Status::NonFiniteInput);
  // The twist-compensated travel u0 in registers (every limit checked), with the static forces
  // where they are needed; else through a LegState, which names the leg and limit.
  const bool static_forces = detail::needs_static_forces(model, inputs);
  const StaticLoadSpec& load = model.spec().static_load;
  Vector6d u0, twist_term = Vector6d::Zero(), static_force = Vector6d::Zero();
  Status static_status = Status::Ok;
  if (!commands_in_lanes(model, pose, model.has_twist(), u0, static_forces ? &load : nullptr, &static_force,
                         &static_status, &twist_term)) {
    LegState legs;
    if (const Status s = inverse_kinematics(model, placement_from_pose(pose), legs); s != Status::Ok)
      return fail(report, s);
    if (const Status s = check_limits(model, legs, report); s != Status::Ok) return s;
    Vector6d dtheta;
    if (const Status s = twist(model, legs, dtheta); s != Status::Ok) return fail(report, s);
    length_error(model, dtheta, twist_term);
    u0 = legs.length - model.geometry().length_offset - twist_term;
    if (static_forces) static_status = static_leg_forces(model, load, legs, static_force);
  }
  Vector6d force, temperature, travel, no_play, direction;
  if (const Status s = detail::resolve_inputs(model, inputs, static_status, static_force, force, temperature);
      s != Status::Ok)
    return fail(report, s);
  detail::command_travel(model, u0, twist_term, force, temperature, play, travel, no_play, direction);
  // The stroke in registers; check_stroke names the leg where it fails.
  detail::lane_m within = detail::all_set();
  for (int k = 0; k < detail::kPackets; ++k) within &= detail::within_stroke(model, detail::load6(travel.data(), k));
  if (!detail::all_lanes(within))
    if (const Status s = check_stroke(model, travel, report); s != Status::Ok) return s;
  report = LimitReport{};
  command = model.motor_from_travel(travel);
  if (play != nullptr) advance_play(*play, no_play, direction);
  return Status::Ok;
}

Status detail::commands_through_state(const Model& model, const Pose& pose, bool compensated, Vector6d& command,
                                      LimitReport& report) noexcept {
  LegState legs;
  // The Placement overload: the Pose one would test finiteness a second time.
  if (const Status s = inverse_kinematics(model, placement_from_pose(pose), legs); s != Status::Ok)
    return fail(report, s);
  if (const Status s = check_limits(model, legs, report); s != Status::Ok) return s;
  const Vector6d& offset = model.geometry().length_offset;
  if (!compensated) {
    command = model.motor_from_travel(legs.length - offset);
    return Status::Ok;
  }
  Vector6d dtheta;
  if (const Status s = twist(model, legs, dtheta); s != Status::Ok) return fail(report, s);
  Vector6d compensated_command = legs.length - offset - model.geometry().twist_gain.cwiseProduct(dtheta);  // Eq. (12)
  if (const Status s = check_stroke(model, compensated_command, report); s != Status::Ok) return s;
  command = model.motor_from_travel(compensated_command);
  return Status::Ok;
}

std::string_view to_string(Strategy strategy) noexcept {
  return strategy == Strategy::Conventional ? "conventional" : "compensated";
}

bool parse_strategy(std::string_view name, Strategy& out) noexcept {
  for (const Strategy s : {Strategy::Conventional, Strategy::Compensated})
    if (name == to_string(s)) {
      out = s;
      return true;
    }
  return false;
}

}  // namespace hexatwist
