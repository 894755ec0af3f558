#include "hexatwist/forward.hpp"

#include <Eigen/LU>
#include <cmath>

#include "hexatwist/twist.hpp"

namespace hexatwist {
namespace {

// Largest number of step halvings in the line search.
constexpr int kMaxHalvings = 12;

}  // namespace

Status fk_residual(const Model& model, const Placement& x, const Vector6d& lengths, LengthKind kind,
                   LegState& legs, Vector6d& f, Matrix6d* J) noexcept {
  if (const Status s = inverse_kinematics(model, x, legs); s != Status::Ok) return s;
  f = legs.length - lengths;
  if (J != nullptr) length_jacobian(legs, *J);
  if (kind == LengthKind::Geometric || !model.has_twist()) return Status::Ok;
  // Motor-side length m = |L| - twist_gain * dtheta (docs/theory.md §5).
  Vector6d dtheta;
  if (const Status s = twist(model, legs, dtheta); s != Status::Ok) return s;
  Matrix6d J_twist;
  if (J != nullptr) {
    if (const Status s = twist_jacobian(model, legs, J_twist); s != Status::Ok) return s;
  }
  for (int i = 0; i < kLegs; ++i) {
    const double gain = model.leg(i).twist_gain;
    f[i] -= gain * dtheta[i];
    if (J != nullptr) J->row(i) -= gain * J_twist.row(i);
  }
  return Status::Ok;
}

Status forward_kinematics(const Model& model, const Vector6d& lengths, LengthKind kind, const Placement& guess,
                          FkResult& out, const FkOptions& options) noexcept {
  out.iterations = 0;
  out.residual = INFINITY;
  out.placement = guess;
  if (!lengths.allFinite() || !guess.t.allFinite() || !guess.R_BP.allFinite()) return Status::NonFiniteInput;

  Placement x = guess;
  Vector6d f;
  Matrix6d J;
  if (const Status s = fk_residual(model, x, lengths, kind, out.legs, f, &J); s != Status::Ok) return s;

  Placement x_try;
  Vector6d f_try;
  Matrix6d J_try;
  LegState legs_try;
  for (;;) {
    out.placement = x;
    out.residual = f.cwiseAbs().maxCoeff();
    if (out.residual <= options.tolerance) {
      out.pose = pose_from_placement(x);
      return Status::Ok;
    }
    if (out.iterations >= options.max_iterations) return Status::NoConvergence;

    // Newton step on R^3 x SO(3): J [dt; dw] = -f, then t += dt, R = exp(dw) R.
    const Eigen::PartialPivLU<Matrix6d> lu(J);
    const Vector6d pivots = lu.matrixLU().diagonal().cwiseAbs();
    if (!(pivots.minCoeff() > options.singular_ratio * pivots.maxCoeff())) return Status::SingularJacobian;
    const Vector6d step = -lu.solve(f);

    // Backtracking: accept the first fraction of the step that lowers |f| (and stays away from
    // singular joints), so a far guess cannot throw the iterate to another assembly mode.
    const double norm_f = f.norm();
    double alpha = 1.0;
    bool accepted = false;
    for (int h = 0; h <= kMaxHalvings && !accepted; ++h, alpha *= 0.5) {
      x_try.t = x.t + alpha * step.head<3>();
      x_try.R_BP = exp_so3(alpha * step.tail<3>()) * x.R_BP;
      if (fk_residual(model, x_try, lengths, kind, legs_try, f_try, &J_try) != Status::Ok) continue;
      accepted = f_try.norm() < norm_f;
    }
    ++out.iterations;
    if (!accepted) return Status::NoConvergence;
    x = x_try;
    f = f_try;
    J = J_try;
    out.legs = legs_try;
  }
}

}  // namespace hexatwist
