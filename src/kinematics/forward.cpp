// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/forward.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/kinematics/twist.hpp"
#include "kinematics/gauss_jordan.hpp"
#include "kinematics/geometry.hpp"
#include "kinematics/linear_solve.hpp"
#include "kinematics/twist_internal.hpp"

namespace hexatwist {
namespace {

// Largest number of step halvings in the line search.
constexpr int kMaxHalvings = 12;

// f = g(x) - lengths at the placement x, with g the geometric or motor-side lengths.
Status residual(const Model& model, const Placement& x, const Vector6d& lengths, LengthKind kind, LegState& legs,
                Vector6d& f) noexcept {
  if (const Status s = inverse_kinematics(model, x, legs); s != Status::Ok) return s;
  f = legs.length - lengths;
  if (kind == LengthKind::Geometric) return Status::Ok;
  // Motor-side length m = |L| - length_offset - twist_gain * dtheta (docs/theory.md §4-5).
  f -= model.geometry().length_offset;
  if (!model.has_twist()) return Status::Ok;
  Vector6d dtheta;
  if (const Status s = twist(model, legs, dtheta); s != Status::Ok) return s;
  f -= model.geometry().twist_gain.cwiseProduct(dtheta);
  return Status::Ok;
}

// The Cayley retraction, the rotation (I - W/2)^-1 (I + W/2) = I + c W + (c/2) W^2 with
// c = 4 / (4 + |w|^2), W = [w]x: a rotation by 2 atan(|w|/2) about w, equal to exp(W) to second
// order, so Newton's steps converge as with exp_so3, without its sine and cosine on the chain
// from step to step (docs/theory.md §5).
Matrix3d cayley(const Vector3d& w) noexcept {
  const double x = w.x(), y = w.y(), z = w.z();
  const double A = 4.0 / (4.0 + (x * x + y * y + z * z)), B = 0.5 * A;
  Matrix3d R;
  R(0, 0) = 1.0 - B * (y * y + z * z);
  R(1, 1) = 1.0 - B * (x * x + z * z);
  R(2, 2) = 1.0 - B * (x * x + y * y);
  R(0, 1) = -A * z + B * (x * y);
  R(1, 0) = A * z + B * (x * y);
  R(0, 2) = A * y + B * (x * z);
  R(2, 0) = -A * y + B * (x * z);
  R(1, 2) = -A * x + B * (y * z);
  R(2, 1) = A * x + B * (y * z);
  return R;
}

// The residual f and the Jacobian of g at x in one pass over the legs (lanes.hpp): the kernels of
// inverse_kinematics (into `legs`), twist and length_jacobian from the same registers, with the
// same operations, so that f is residual()'s. A zero-length leg or a singular joint goes to
// residual(), which names it (`regular` collects both).
Status evaluate(const Model& model, const Placement& x, const Vector6d& lengths, LengthKind kind, LegState& legs,
                Vector6d& f, detail::Columns& J) noexcept {
  using namespace detail;
  if (!all_finite(x.t) || !all_finite(x.R_BP)) return Status::NonFiniteInput;
  const LegLanes& g = model.geometry().lanes;
  const bool motor = kind == LengthKind::Motor;
  const bool twisted = motor && model.has_twist();
  legs.R_BP = x.R_BP;
  lane_m regular = all_set();
#pragma GCC unroll 4
  for (int k = 0; k < kPackets; ++k) {
    const LegsAt at = legs_at(model, x.R_BP, x.t, k);
    store6(legs.arm_B, at.arm, k);
    store6(legs.axis_platform_B, at.axis_platform, k);
    store6(legs.leg_B, at.leg, k);
    store6(legs.length.data(), at.length, k);
    regular &= at.length > 0.0;  // NaN fails
    const lane_v inv_length = 1.0 / at.length;
    const lanes3 s = inv_length * at.leg;
    store6(legs.s_B, s, k);
    lane_v f_k = at.length - load6(lengths.data(), k);
    if (motor) f_k -= load_lanes(g.length_offset, k);
    lane_v col[6];
    if (twisted) {
      // Motor-side length m = |L| - length_offset - twist_gain * dtheta (docs/theory.md §4-5).
      const lanes3 ja = load_lanes(g.axis_base_B, k);
      const lanes3& jd = at.axis_platform;
      const lane_v ja_s = dot(s, ja), jd_s = dot(s, jd);
      const TwistTerms t = twist_terms(s, ja, jd, ja_s, jd_s, splat<lane_v>(1.0));
      regular &= twist_regular(model, t.x, t.y, splat<lane_v>(1.0), k);
      f_k -= load_lanes(g.twist_gain, k) * twist_angle(model, t.x, t.y, true, k);
      jacobian_columns(model, s, inv_length, at.arm, ja, jd, ja_s, jd_s, t, true, k, col);
    } else {
      const lanes3 arm_x_s = cross(at.arm, s);
      col[0] = s.x, col[1] = s.y, col[2] = s.z, col[3] = arm_x_s.x, col[4] = arm_x_s.y, col[5] = arm_x_s.z;
    }
    store6(f.data(), f_k, k);
    for (int c = 0; c < 6; ++c) J.c[c][k] = col[c];
  }
  if (!all_lanes(regular)) return residual(model, x, lengths, kind, legs, f);
  return Status::Ok;
}

}  // namespace

Status length_jacobian(const Model& model, const LegState& legs, LengthKind kind, Matrix6d& J) noexcept {
  if (kind == LengthKind::Geometric || !model.has_twist()) {
    length_jacobian(legs, J);
    return Status::Ok;
  }
  return detail::motor_length_jacobian(model, legs, J);
}

Status fk_residual(const Model& model, const Placement& x, const Vector6d& lengths, LengthKind kind, LegState& legs,
                   Vector6d& f, Matrix6d* J) noexcept {
  const Vector6d target = kind == LengthKind::Motor ? model.travel_from_motor(lengths) : lengths;
  if (const Status s = residual(model, x, target, kind, legs, f); s != Status::Ok) return s;
  return J != nullptr ? length_jacobian(model, legs, kind, *J) : Status::Ok;
}

std::string_view check_fk_options(const FkOptions& o) noexcept {
  if (!(o.max_iterations >= 1 && o.max_iterations <= kMaxFkIterations))
    return "max_iterations: expected 1 to 1000 Newton iterations";
  if (!(o.tolerance > 0.0 && o.tolerance <= kMaxFkTolerance))
    return "tolerance: expected a largest length residual > 0 and at most 1e-6 m";
  if (!(o.singular_ratio > 0.0 && o.singular_ratio <= 1e-3))
    return "singular_ratio: expected a pivot ratio in (0, 1e-3]";
  if (!(o.max_step_translation > 0.0 && o.max_step_translation <= 10.0))
    return "max_step_translation: expected a step cap > 0 and at most 10 m";
  if (!(o.max_step_rotation > 0.0 && o.max_step_rotation <= kPi))
    return "max_step_rotation: expected a step cap > 0 and at most pi rad";
  return {};
}

namespace {

// Forward kinematics of rigid legs (the legs' effects left out): the Newton iteration.
Status forward_rigid(const Model& model, const Vector6d& motor_or_geometric, LengthKind kind, const Placement& guess,
                     FkResult& out, const FkOptions& options) noexcept {
  // Motor-side lengths as the nut's travel (the drives' reference and scale, theory §4): the
  // equations below are in it.
  const Vector6d lengths = kind == LengthKind::Motor ? model.travel_from_motor(motor_or_geometric) : motor_or_geometric;
  out.iterations = 0;
  out.residual = INFINITY;
  out.placement = guess;
  out.condition = std::nan("");
  out.det_sign = 0.0;
  if (!detail::all_finite(lengths) || !detail::all_finite(guess.t) || !detail::all_finite(guess.R_BP))
    return Status::NonFiniteInput;
  // A leg is never shorter than nothing, and the options have documented ranges (check_fk_options).
  if (!(motor_or_geometric.array() > 0.0).all() || !check_fk_options(options).empty()) return Status::InvalidArgument;

  // The state at the iterate and at the trial point live in two buffers that trade places when
  // a step is accepted (copying a LegState is ~90 moves); *legs ends up in out.legs on return.
  LegState legs_try;
  LegState* legs = &out.legs;
  LegState* trial = &legs_try;
  detail::Columns J_a, J_b;  // the Jacobian at the iterate and at the trial point, likewise
  detail::Columns* J = &J_a;
  detail::Columns* J_trial = &J_b;
  const auto finish = [&](Status status) noexcept {
    if (legs != &out.legs) out.legs = *legs;
    return status;
  };

  Placement x = guess;
  Vector6d f;
  if (const Status s = evaluate(model, x, lengths, kind, *legs, f, *J); s != Status::Ok) return s;

  Placement x_try;
  Vector6d f_try, step;
  detail::Columns A;  // the scaled Jacobian of the last Newton step, and its inverse
  detail::Inverse6 inverse;
  double det_sign_guess = 0.0;  // 0: not computed yet
  bool have_inverse = false;    // `inverse` is that of the last step's A
  const ConditionReference& ref = model.condition_reference();
  const bool home_inverse = ref.det_sign != 0.0 && (kind == LengthKind::Motor || !model.has_twist()) &&
                            guess.t == Vector3d::Zero() && guess.R_BP == Matrix3d::Identity();
  for (;;) {
    out.placement = x;
    out.residual = f.cwiseAbs().maxCoeff();
    if (out.residual <= options.tolerance) {
      out.pose = pose_from_placement(x);
      // The assembly mode and condition at the solution (theory §5), taken from the last Newton
      // step's Jacobian and its inverse: that iterate lies one step (|J^-1 f|, f the residual before
      // the step) from the solution, so the condition differs from the solution's by a relative
      // O(condition * step / condition_length) -- about 1e-8 from a warm start -- and the sign of
      // det J cannot differ unless J is singular within that step, which a condition below half the
      // limit rules out. Nearer the limit, or with no step taken, the Jacobian is formed at the
      // solution, so that which poses pass the limit is decided exactly as before.
      const double bound = model.spec().limits.jacobian_condition_max;
      if (have_inverse) {
        out.det_sign = inverse.det_sign;
        out.condition = detail::gj_condition(A, inverse);
      }
      if (!have_inverse || !(out.condition <= 0.5 * bound)) {
        Matrix6d J_exact;
        if (const Status s = length_jacobian(model, *legs, kind, J_exact); s != Status::Ok) return finish(s);
        out.condition = detail::scaled_condition(J_exact, model.condition_length(), out.det_sign);
      }
      if (det_sign_guess == 0.0) det_sign_guess = out.det_sign;  // no step taken: the guess is the solution
      return finish(out.det_sign == det_sign_guess ? Status::Ok : Status::AssemblyModeChanged);
    }
    if (out.iterations >= options.max_iterations) return finish(Status::NoConvergence);

    // Newton step on R^3 x SO(3): J [dt; dw] = -f, then t += dt, R = cay(dw) R. It is solved with
    // the inverse of the scaled Jacobian A = J diag(1, 1, 1, s, s, s), s = 1/condition_length (the
    // matrix whose condition the limit bounds), by Gauss-Jordan elimination (gauss_jordan.hpp):
    // A y = -f, [dt; dw] = diag(1, 1, 1, s, s, s) y. (Reusing J for chord steps was measured: more
    // iterations, no gain, since two Newton steps usually suffice.)
    // From home, the usual cold start, the model holds A's inverse already (the condition proof's
    // reference, Model::condition_reference), which spares the first elimination.
    const double s = 1.0 / model.condition_length();
    if (out.iterations == 0 && home_inverse) {
      for (int i = 0; i < 6; ++i) {
        double y = 0.0;
        for (int c = 0; c < 6; ++c) y -= ref.inverse[i][c] * f[c];
        step[i] = y;
      }
      det_sign_guess = ref.det_sign;
      have_inverse = false;  // no elimination to read the condition from
    } else {
      for (int c = 0; c < 6; ++c)
        for (int k = 0; k < detail::kPackets; ++k) A.c[c][k] = c < 3 ? J->c[c][k] : s * J->c[c][k];
      if (!(detail::gauss_jordan(A, inverse) > options.singular_ratio)) return finish(Status::SingularJacobian);
      if (det_sign_guess == 0.0) det_sign_guess = inverse.det_sign;
      have_inverse = true;
      detail::gj_solve(inverse, -f, step);
    }
    step.tail<3>() *= s;
    // Step cap: near a singularity, or far from the solution, the Newton step can be far longer
    // than the platform; shorten it (direction kept) to a length the linear model can be trusted over.
    // (Squared lengths first: no square root on the way to the trial point when nothing is capped.)
    const double dt2 = step.head<3>().squaredNorm(), dw2 = step.tail<3>().squaredNorm();
    if (dt2 > options.max_step_translation * options.max_step_translation ||
        dw2 > options.max_step_rotation * options.max_step_rotation)
      step *= std::min(options.max_step_translation / std::sqrt(dt2), options.max_step_rotation / std::sqrt(dw2));

    // Backtracking: accept the first fraction of the step that lowers |f| (and stays away from
    // singular joints), so a far guess cannot throw the iterate to another assembly mode.
    const double norm_f = f.squaredNorm();
    double alpha = 1.0;
    bool accepted = false;
    for (int h = 0; h <= kMaxHalvings && !accepted; ++h, alpha *= 0.5) {
      x_try.t = x.t + alpha * step.head<3>();
      x_try.R_BP = cayley(alpha * step.tail<3>()) * x.R_BP;
      if (evaluate(model, x_try, lengths, kind, *trial, f_try, *J_trial) != Status::Ok) continue;
      accepted = f_try.squaredNorm() < norm_f;
    }
    ++out.iterations;
    if (!accepted) return finish(Status::NoConvergence);
    x = x_try;
    f = f_try;
    std::swap(legs, trial);
    std::swap(J, J_trial);
  }
}

// Most passes of the effects' fixed point: each moves E by the change of the forces and of the
// twist over the last pass's step, a few parts in 1e4 of it, so that three passes usually end it.
constexpr int kMaxEffectPasses = 8;
// Where E has settled [m]: far below the solve's own tolerance (1e-12).
constexpr double kEffectTolerance = 1e-14;

}  // namespace

Status forward_kinematics(const Model& model, const Vector6d& lengths, LengthKind kind, const Placement& guess,
                          FkResult& out, const FkOptions& options) noexcept {
  if (kind == LengthKind::Motor && model.has_leg_effects())
    return forward_kinematics(model, lengths, LegInputs{}, nullptr, guess, out, options, nullptr);
  return forward_rigid(model, lengths, kind, guess, out, options);
}

Status forward_kinematics(const Model& model, const Vector6d& motor, const LegInputs& inputs, const Vector6d* direction,
                          const Placement& guess, FkResult& out, const FkOptions& options,
                          LegEffects* effects) noexcept {
  if (!model.has_leg_effects()) return forward_rigid(model, motor, LengthKind::Motor, guess, out, options);
  // The legs' effects add E to the nut's travel u (leg_effects.hpp); E depends on the pose through
  // the forces and the twist only, so that a fixed point of rigid solves finds the pose: each pass
  // solves with the last E and evaluates E at its solution.
  const Vector6d travel = model.travel_from_motor(motor);
  const Vector6d d = direction != nullptr ? *direction : play_direction(model, PlayState{}, travel);
  const Vector6d& scale = model.geometry().drive_scale;
  LegEffects e;
  Vector6d E = Vector6d::Zero();
  Placement start = guess;
  Status first = Status::Ok;
  for (int pass = 0; pass < kMaxEffectPasses; ++pass) {
    const Status s = forward_rigid(model, motor + E.cwiseQuotient(scale), LengthKind::Motor, start, out, options);
    if (s != Status::Ok && s != Status::AssemblyModeChanged) return s;
    if (pass == 0) first = s;  // the mode is the guess's or not: later passes start at the solution
    Vector6d dtheta, twist_term, force, temperature;
    if (const Status t = twist(model, out.legs, dtheta); t != Status::Ok) return t;
    length_error(model, dtheta, twist_term);
    if (const Status r = resolve_inputs(model, out.legs, inputs, force, temperature); r != Status::Ok) return r;
    effect_lengths(model, travel, twist_term, force, temperature, d, e);
    const double change = (e.total - E).cwiseAbs().maxCoeff();
    E = e.total;
    start = out.placement;
    if (change <= kEffectTolerance) {
      if (effects != nullptr) *effects = e;
      return first;
    }
  }
  return Status::NoConvergence;
}

Status fk_tracker_set(const Model& model, const Placement& x, LengthKind kind, FkTracker& tracker) noexcept {
  LegState legs;
  if (const Status s = inverse_kinematics(model, x, legs); s != Status::Ok) return s;
  Matrix6d J;
  if (const Status s = length_jacobian(model, legs, kind, J); s != Status::Ok) return s;
  double det_sign = 0.0;
  detail::scaled_condition(J, model.condition_length(), det_sign);
  if (det_sign == 0.0) return Status::SingularJacobian;
  tracker = FkTracker{x, det_sign, true};
  return Status::Ok;
}

namespace {

/// The tracker's acceptance of a solve's result `s` (forward_kinematics_tracked).
Status accept_tracked(const Model& model, Status s, FkTracker& tracker, const FkResult& out) noexcept {
  if (s != Status::Ok) return s;
  // The guess's mode is the tracker's unless the caller's tracker came from another kind of lengths.
  if (tracker.valid && out.det_sign != tracker.det_sign) return Status::AssemblyModeChanged;
  // Past the condition limit the lengths of a pose beyond a singularity can have a solution on
  // this side of it (a fold): refuse it rather than follow (docs/theory.md §5).
  if (!(out.condition <= model.condition_max_accepted())) return Status::PlatformSingularity;
  tracker = FkTracker{out.placement, out.det_sign, true};
  return Status::Ok;
}

}  // namespace

Status forward_kinematics_tracked(const Model& model, const Vector6d& lengths, LengthKind kind, FkTracker& tracker,
                                  FkResult& out, const FkOptions& options) noexcept {
  const Placement guess = tracker.valid ? tracker.last : Placement{};
  return accept_tracked(model, forward_kinematics(model, lengths, kind, guess, out, options), tracker, out);
}

Status forward_kinematics_tracked(const Model& model, const Vector6d& motor, const LegInputs& inputs,
                                  const Vector6d* direction, FkTracker& tracker, FkResult& out,
                                  const FkOptions& options, LegEffects* effects) noexcept {
  const Placement guess = tracker.valid ? tracker.last : Placement{};
  return accept_tracked(model, forward_kinematics(model, motor, inputs, direction, guess, out, options, effects),
                        tracker, out);
}

}  // namespace hexatwist
