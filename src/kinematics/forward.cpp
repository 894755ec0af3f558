#include "hexatwist/kinematics/forward.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "hexatwist/kinematics/twist.hpp"
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

}  // namespace

Status length_jacobian(const Model& model, const LegState& legs, LengthKind kind, Matrix6d& J) noexcept {
  if (kind == LengthKind::Geometric || !model.has_twist()) {
    length_jacobian(legs, J);
    return Status::Ok;
  }
  return detail::motor_length_jacobian(model, legs, J);
}

Status fk_residual(const Model& model, const Placement& x, const Vector6d& lengths, LengthKind kind,
                   LegState& legs, Vector6d& f, Matrix6d* J) noexcept {
  if (const Status s = residual(model, x, lengths, kind, legs, f); s != Status::Ok) return s;
  return J != nullptr ? length_jacobian(model, legs, kind, *J) : Status::Ok;
}

Status forward_kinematics(const Model& model, const Vector6d& lengths, LengthKind kind, const Placement& guess,
                          FkResult& out, const FkOptions& options) noexcept {
  out.iterations = 0;
  out.residual = INFINITY;
  out.placement = guess;
  out.condition = std::nan("");
  out.det_sign = 0.0;
  if (!detail::all_finite(lengths) || !detail::all_finite(guess.t) || !detail::all_finite(guess.R_BP))
    return Status::NonFiniteInput;

  // The state at the iterate and at the trial point live in two buffers that trade places when
  // a step is accepted (copying a LegState is ~90 moves); *legs ends up in out.legs on return.
  LegState legs_try;
  LegState* legs = &out.legs;
  LegState* trial = &legs_try;
  const auto finish = [&](Status status) noexcept {
    if (legs != &out.legs) out.legs = *legs;
    return status;
  };

  Placement x = guess;
  Vector6d f;
  if (const Status s = residual(model, x, lengths, kind, *legs, f); s != Status::Ok) return s;

  Placement x_try;
  Vector6d f_try, step;
  Matrix6d J;
  detail::Lu6 lu;
  double det_sign_guess = 0.0;  // 0: not computed yet
  for (;;) {
    out.placement = x;
    out.residual = f.cwiseAbs().maxCoeff();
    if (out.residual <= options.tolerance) {
      out.pose = pose_from_placement(x);
      // The assembly mode and condition at the solution (theory §5), taken from the factors of the
      // last Newton step's Jacobian: that iterate lies one step (|J^-1 f|, f the residual before
      // the step) from the solution, so the condition differs from the solution's by a relative
      // O(condition * step / condition_length) -- about 1e-8 from a warm start -- and the sign of
      // det J cannot differ unless J is singular within that step, which a condition below half the
      // limit rules out. Nearer the limit, or with no step taken, the Jacobian is formed at the
      // solution, so that which poses pass the limit is decided exactly as before.
      const double bound = model.spec().limits.jacobian_condition_max;
      if (out.iterations > 0) {
        out.det_sign = detail::lu6_det_sign(lu);
        out.condition = detail::lu6_scaled_condition(lu, J.cwiseAbs().colwise().sum().transpose(),
                                                     1.0 / model.condition_length());
      }
      if (out.iterations == 0 || !(out.condition <= 0.5 * bound)) {
        if (const Status s = length_jacobian(model, *legs, kind, J); s != Status::Ok) return finish(s);
        out.condition = detail::scaled_condition(J, model.condition_length(), out.det_sign);
      }
      if (det_sign_guess == 0.0) det_sign_guess = out.det_sign;  // no step taken: the guess is the solution
      return finish(out.det_sign == det_sign_guess ? Status::Ok : Status::AssemblyModeChanged);
    }
    if (out.iterations >= options.max_iterations) return finish(Status::NoConvergence);

    // Newton step on R^3 x SO(3): J [dt; dw] = -f, then t += dt, R = exp(dw) R. The Jacobian is
    // formed only here, so the converged last iterate never pays for one. (Reusing it for chord
    // steps was measured: more iterations, no gain, since two Newton steps usually suffice.)
    if (const Status s = length_jacobian(model, *legs, kind, J); s != Status::Ok) return finish(s);
    if (!(detail::lu6_factor(J, lu) > options.singular_ratio)) return finish(Status::SingularJacobian);
    if (det_sign_guess == 0.0) det_sign_guess = detail::lu6_det_sign(lu);
    detail::lu6_solve(lu, -f, step);
    // Step cap: near a singularity, or far from the solution, the Newton step can be far longer
    // than the platform; shorten it (direction kept) to a length the linear model can be trusted over.
    const double dt = step.head<3>().norm(), dw = step.tail<3>().norm();
    if (dt > options.max_step_translation || dw > options.max_step_rotation)
      step *= std::min(options.max_step_translation / dt, options.max_step_rotation / dw);

    // Backtracking: accept the first fraction of the step that lowers |f| (and stays away from
    // singular joints), so a far guess cannot throw the iterate to another assembly mode.
    const double norm_f = f.squaredNorm();
    double alpha = 1.0;
    bool accepted = false;
    for (int h = 0; h <= kMaxHalvings && !accepted; ++h, alpha *= 0.5) {
      x_try.t = x.t + alpha * step.head<3>();
      x_try.R_BP = exp_so3(alpha * step.tail<3>()) * x.R_BP;
      if (residual(model, x_try, lengths, kind, *trial, f_try) != Status::Ok) continue;
      accepted = f_try.squaredNorm() < norm_f;
    }
    ++out.iterations;
    if (!accepted) return finish(Status::NoConvergence);
    x = x_try;
    f = f_try;
    std::swap(legs, trial);
  }
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

Status forward_kinematics_tracked(const Model& model, const Vector6d& lengths, LengthKind kind, FkTracker& tracker,
                                  FkResult& out, const FkOptions& options) noexcept {
  const Placement guess = tracker.valid ? tracker.last : Placement{};
  if (const Status s = forward_kinematics(model, lengths, kind, guess, out, options); s != Status::Ok) return s;
  // The guess's mode is the tracker's unless the caller's tracker came from another kind of lengths.
  if (tracker.valid && out.det_sign != tracker.det_sign) return Status::AssemblyModeChanged;
  // Past the condition limit the lengths of a pose beyond a singularity can have a solution on
  // this side of it (a fold): refuse it rather than follow (docs/theory.md §5).
  if (!(out.condition <= model.condition_max_accepted())) return Status::PlatformSingularity;
  tracker = FkTracker{out.placement, out.det_sign, true};
  return Status::Ok;
}

}  // namespace hexatwist
