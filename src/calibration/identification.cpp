#include "hexatwist/calibration/identification.hpp"
#include "kinematics/geometry.hpp"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>
#include <optional>

#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/twist.hpp"

namespace hexatwist {
namespace {

// Columns of the parameters that enter through the platform (lead, offsets, A), which the
// evaluator differentiates; the tracker transform's columns follow from the points alone.
constexpr int kModelParameters = kRotationIndex;

using RowMajor3d = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

// The platform's residuals e_k = X_BT p_T,k - A_B,k and their Jacobian with respect to lead,
// offsets and A, through twist-aware forward kinematics of every observation (theory §13). Each
// observation's last solution is the next start, so a solver's small steps cost one or two Newton
// iterations each.
class Evaluator {
 public:
  Evaluator(const Model& nominal, std::span<const Observation> observations, const IdentificationOptions& options)
      : nominal_(nominal),
        observations_(observations),
        options_(options),
        guess_(observations.size()),
        home_command_(nominal.length_home() - nominal.geometry().length_offset) {
    for (int i = 0; i < kLegs; ++i) {
      const double lead = nominal.leg(i).lead;
      inverse_lead_[i] = lead > 0.0 ? 1.0 / lead : 0.0;
    }
  }

  // Residuals into e (3K) and, if J is given, their derivatives (3K x 10) for the candidate p.
  // Returns Ok or the status of the forward kinematics that failed (failed_index() says where).
  Status evaluate(const PlatformParameters& p, double* e, Eigen::MatrixXd* J) {
    // The candidate platform: the nominal geometry with this lead and sign. The offsets are
    // applied to the lengths below, so the candidate's own are zero.
    ModelSpec spec = nominal_.spec();
    for (LegSpec& leg : spec.legs) {
      leg.lead = p.lead;
      leg.thread = p.twist_sign > 0.0 ? ThreadSense::Right : ThreadSense::Left;
      leg.length_offset = 0.0;
    }
    std::optional<Model> model;
    try {
      model.emplace(spec);
    } catch (const Error&) {
      failed_index_ = -1;
      return Status::NonFiniteInput;  // only a lead that is NaN or negative gets here
    }
    const bool travel = options_.lead_effect == LeadEffect::TwistAndTravel;
    const Vector3d& pivot_P = spec.pivot_P;
    const Vector3d& pivot_home_B = model->pivot_home_B();
    const double gain_per_lead = p.twist_sign / (2.0 * kPi);
    if (J != nullptr) J->resize(3 * static_cast<Eigen::Index>(observations_.size()), kModelParameters);

    FkResult fk;
    Matrix6d J_f_x;
    Eigen::Matrix<double, 6, 7> J_f_theta, J_x_theta;
    Eigen::Matrix<double, 3, 6> J_q_x;
    Vector6d dtheta;
    for (std::size_t k = 0; k < observations_.size(); ++k) {
      const Observation& o = observations_[k];
      // Real motor-side lengths r = m + delta (+ the travel at the real lead, theory §13).
      Vector6d r = o.motor + p.length_offset;
      Vector6d r_lead = Vector6d::Zero();
      if (travel) {
        const Vector6d turned = (o.motor - home_command_).cwiseProduct(inverse_lead_);  // screw revolutions
        r += turned * p.lead - (o.motor - home_command_);
        r_lead = turned;
      }
      if (const Status s = forward_kinematics(*model, r, LengthKind::Motor, guess_[k], fk, options_.fk);
          s != Status::Ok) {
        failed_index_ = static_cast<int>(k);
        return s;
      }
      guess_[k] = fk.placement;
      const Vector3d arm_B = fk.placement.R_BP * (p.observation_P - pivot_P);
      const Eigen::Index row = 3 * static_cast<Eigen::Index>(k);
      Eigen::Map<Vector3d>(e + row) = p.X_BT.R * o.p_T + p.X_BT.t - (pivot_home_B + fk.placement.t + arm_B);
      if (J == nullptr) continue;

      // Implicit function theorem on f(x, theta) = g(x; lead) - r(theta) = 0 at the solution:
      // dx/dtheta = -J_f_x^-1 df/dtheta, with g = |L| - sign lead / 2pi dtheta (theory §5, §13).
      Status s = length_jacobian(*model, fk.legs, LengthKind::Motor, J_f_x);
      if (s == Status::Ok) s = twist(*model, fk.legs, dtheta);
      if (s != Status::Ok) {
        failed_index_ = static_cast<int>(k);
        return s;
      }
      J_f_theta.col(0) = -gain_per_lead * dtheta - r_lead;
      J_f_theta.rightCols<6>() = -Matrix6d::Identity();
      J_x_theta = -Eigen::PartialPivLU<Matrix6d>(J_f_x).solve(J_f_theta);
      // A_B = pivot_home + t + R_BP (A_P - pivot_P): left perturbation of R_BP turns arm_B.
      J_q_x.leftCols<3>().setIdentity();
      J_q_x.rightCols<3>() = -detail::skew(arm_B);
      J->block<3, 7>(row, 0) = -J_q_x * J_x_theta;
      J->block<3, 3>(row, kObservationIndex) = -fk.placement.R_BP;
    }
    return Status::Ok;
  }

  // Observation whose forward kinematics failed last (-1: the candidate model itself).
  int failed_index() const noexcept { return failed_index_; }

 private:
  const Model& nominal_;
  std::span<const Observation> observations_;
  const IdentificationOptions& options_;
  std::vector<Placement> guess_;
  Vector6d home_command_;  // motor-side length at which the encoders read zero (home) [m]
  Vector6d inverse_lead_;  // 1 / nominal lead: the drives' screw revolutions per metre commanded
  int failed_index_ = -1;
};

// The whole Jacobian in the parameter order, from the platform's part and the points.
void full_jacobian(const Eigen::MatrixXd& J_model, std::span<const Observation> observations,
                   const RigidTransform& X_BT, Eigen::MatrixXd& J) {
  J.resize(J_model.rows(), kIdentifiedParameters);
  J.leftCols<kModelParameters>() = J_model;
  for (std::size_t k = 0; k < observations.size(); ++k) {
    const Eigen::Index row = 3 * static_cast<Eigen::Index>(k);
    J.block<3, 3>(row, kRotationIndex) = -detail::skew(X_BT.R * observations[k].p_T);  // exp(dw) R p = R p + dw x R p
    J.block<3, 3>(row, kTranslationIndex).setIdentity();
  }
}

// R_BT stored row-major in 9 numbers, moved by a left rotation: Plus(R, dw) = exp(dw) R.
class RotationManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 9; }
  int TangentSize() const override { return 3; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override {
    Eigen::Map<RowMajor3d> out(x_plus_delta);
    out = exp_so3(Eigen::Map<const Vector3d>(delta)) * Eigen::Map<const RowMajor3d>(x);
    return true;
  }
  bool PlusJacobian(const double* x, double* jacobian) const override {
    // Column j: d(exp(dw) R)/d dw_j at 0 = [e_j]x R.
    const Eigen::Map<const RowMajor3d> R(x);
    Eigen::Map<Eigen::Matrix<double, 9, 3, Eigen::RowMajor>> J(jacobian);
    for (int j = 0; j < 3; ++j) {
      const RowMajor3d dR = detail::skew(Vector3d::Unit(j)) * R;
      J.col(j) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(dR.data());
    }
    return true;
  }
  bool Minus(const double* y, const double* x, double* y_minus_x) const override {
    const Eigen::AngleAxisd d(Matrix3d(Eigen::Map<const RowMajor3d>(y) * Eigen::Map<const RowMajor3d>(x).transpose()));
    Eigen::Map<Vector3d> out(y_minus_x);
    out = d.angle() * d.axis();
    return true;
  }
  bool MinusJacobian(const double* x, double* jacobian) const override {
    // dw = vee of the skew part of dY X^T at Y = X.
    const Eigen::Map<const RowMajor3d> X(x);
    Eigen::Map<Eigen::Matrix<double, 3, 9, Eigen::RowMajor>> J(jacobian);
    J.setZero();
    for (int c = 0; c < 3; ++c) {
      J(0, 3 * 2 + c) = 0.5 * X(1, c);
      J(0, 3 * 1 + c) = -0.5 * X(2, c);
      J(1, 3 * 0 + c) = 0.5 * X(2, c);
      J(1, 3 * 2 + c) = -0.5 * X(0, c);
      J(2, 3 * 1 + c) = 0.5 * X(0, c);
      J(2, 3 * 0 + c) = -0.5 * X(1, c);
    }
    return true;
  }
};

// All observations as one residual block over lead [1], offsets [6], A [3], R_BT [9], t_BT [3].
class MeasurementCost final : public ceres::CostFunction {
 public:
  MeasurementCost(Evaluator& evaluator, std::span<const Observation> observations, double twist_sign)
      : evaluator_(evaluator), observations_(observations), twist_sign_(twist_sign) {
    set_num_residuals(3 * static_cast<int>(observations.size()));
    *mutable_parameter_block_sizes() = {1, 6, 3, 9, 3};
  }

  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    const PlatformParameters p = parameters(x, twist_sign_);
    bool want = false;
    for (int b = 0; jacobians != nullptr && b < 5; ++b) want = want || jacobians[b] != nullptr;
    last_status_ = evaluator_.evaluate(p, residuals, want ? &J_model_ : nullptr);
    if (last_status_ != Status::Ok) return false;
    if (!want) return true;
    const Eigen::Index n = J_model_.rows();
    using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
    if (jacobians[0] != nullptr) Eigen::Map<Eigen::VectorXd>(jacobians[0], n) = J_model_.col(kLeadIndex);
    if (jacobians[1] != nullptr) Eigen::Map<Rows>(jacobians[1], n, 6) = J_model_.middleCols<6>(kOffsetIndex);
    if (jacobians[2] != nullptr) Eigen::Map<Rows>(jacobians[2], n, 3) = J_model_.middleCols<3>(kObservationIndex);
    if (jacobians[3] != nullptr) {
      // e = R p_T + t - A_B: de_a/dR_ab = p_T,b (R row-major).
      Eigen::Map<Rows> J(jacobians[3], n, 9);
      J.setZero();
      for (std::size_t k = 0; k < observations_.size(); ++k)
        for (int a = 0; a < 3; ++a)
          J.block<1, 3>(3 * static_cast<Eigen::Index>(k) + a, 3 * a) = observations_[k].p_T.transpose();
    }
    if (jacobians[4] != nullptr) {
      Eigen::Map<Rows> J(jacobians[4], n, 3);
      for (Eigen::Index k = 0; k < n / 3; ++k) J.block<3, 3>(3 * k, 0).setIdentity();
    }
    return true;
  }

  static PlatformParameters parameters(double const* const* x, double twist_sign) {
    PlatformParameters p;
    p.lead = x[0][0];
    p.twist_sign = twist_sign;
    p.length_offset = Eigen::Map<const Vector6d>(x[1]);
    p.observation_P = Eigen::Map<const Vector3d>(x[2]);
    p.X_BT.R = Eigen::Map<const RowMajor3d>(x[3]);
    p.X_BT.t = Eigen::Map<const Vector3d>(x[4]);
    return p;
  }

  Status last_status() const noexcept { return last_status_; }

 private:
  Evaluator& evaluator_;
  std::span<const Observation> observations_;
  double twist_sign_;
  mutable Eigen::MatrixXd J_model_;
  mutable Status last_status_ = Status::Ok;
};

// Ends a solve once the lead has reached its bound 0 (the sign held cannot explain the twist):
// from there the projected steps only crawl, and the rest is solved with the lead held at 0.
class StopAtLeadBound final : public ceres::IterationCallback {
 public:
  explicit StopAtLeadBound(const double& lead) : lead_(lead) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return lead_ > 0.0 ? ceres::SOLVER_CONTINUE : ceres::SOLVER_TERMINATE_SUCCESSFULLY;
  }

 private:
  const double& lead_;
};

// Levenberg-Marquardt with the twist sign held at `sign`, from `start`.
SignFit solve_sign(Evaluator evaluator, std::span<const Observation> observations, double sign,
                   const PlatformParameters& start, const IdentificationOptions& options) {
  double lead = start.lead;
  Vector6d offsets = start.length_offset;
  Vector3d A = start.observation_P;
  RowMajor3d R = start.X_BT.R;
  Vector3d t = start.X_BT.t;
  double* blocks[] = {&lead, offsets.data(), A.data(), R.data(), t.data()};

  ceres::Problem problem;
  auto* cost = new MeasurementCost(evaluator, observations, sign);  // owned by the problem
  problem.AddResidualBlock(cost, nullptr, blocks[0], blocks[1], blocks[2], blocks[3], blocks[4]);
  problem.SetManifold(R.data(), new RotationManifold);
  problem.SetParameterLowerBound(&lead, 0, 0.0);

  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_iterations;
  // Stop on the relative decrease of the cost, or on a step below 1e-12 of the parameters (about
  // a picometre): tight enough that noise-free data are recovered to rounding.
  so.function_tolerance = 1e-12;
  so.parameter_tolerance = 1e-12;
  so.gradient_tolerance = 1e-16;
  so.logging_type = ceres::SILENT;
  so.num_threads = 1;
  StopAtLeadBound stop(lead);
  so.callbacks.push_back(&stop);
  so.update_state_every_iteration = true;  // the callback reads the lead
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  SignFit fit;
  fit.twist_sign = sign;
  fit.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  fit.lead_at_bound = !(lead > 0.0);
  if (fit.lead_at_bound && summary.IsSolutionUsable()) {
    problem.SetParameterBlockConstant(&lead);
    so.callbacks.clear();
    ceres::Solve(so, &problem, &summary);
    fit.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
  }
  fit.message = summary.message;
  fit.estimate = MeasurementCost::parameters(blocks, sign);
  if (summary.termination_type == ceres::CONVERGENCE) {
    fit.status = Status::Ok;
  } else if (summary.termination_type == ceres::NO_CONVERGENCE) {
    fit.status = Status::SolverNoConvergence;
  } else {
    fit.status = cost->last_status() != Status::Ok ? cost->last_status() : Status::SolverNoConvergence;
  }
  if (summary.IsSolutionUsable()) fit.cost = summary.final_cost;
  return fit;
}

// Conditioning of J after scaling every column to unit norm (units and scales drop out): the
// condition number, the least-determined combination, (J^T J)^-1, and the parameters that take
// part in the combinations weaker than `max_condition` allows.
struct Conditioning {
  double condition = std::numeric_limits<double>::infinity();
  ParameterVector weakest = ParameterVector::Zero();
  ParameterMatrix inverse_normal = ParameterMatrix::Zero();  // (J^T J)^-1, valid if condition is finite
  int undetermined = 0;                                      // combinations above max_condition
  std::string involved;                                      // their parameters' names
};

Conditioning conditioning(const Eigen::MatrixXd& J, double max_condition) {
  Conditioning c;
  ParameterVector scale;
  Eigen::MatrixXd Js = J;
  for (int j = 0; j < kIdentifiedParameters; ++j) {
    scale[j] = J.col(j).norm();
    if (scale[j] > 0.0) Js.col(j) /= scale[j];
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Js, Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  const Eigen::MatrixXd& V = svd.matrixV();
  const int last = kIdentifiedParameters - 1;
  c.condition = s[last] > 0.0 ? s[0] / s[last] : std::numeric_limits<double>::infinity();
  c.weakest = V.col(last);
  std::array<bool, kIdentifiedParameters> named{};
  for (int i = 0; i <= last; ++i) {
    if (!(s[i] * max_condition < s[0]) && s[i] > 0.0) continue;
    ++c.undetermined;
    for (int j = 0; j < kIdentifiedParameters; ++j) named[static_cast<std::size_t>(j)] |= std::abs(V(j, i)) >= 0.1;
  }
  for (int j = 0; j < kIdentifiedParameters; ++j)
    if (named[static_cast<std::size_t>(j)])
      c.involved += (c.involved.empty() ? "" : ", ") + std::string(parameter_name(j));
  if (std::isfinite(c.condition)) {
    const Eigen::VectorXd inv_s2 = s.cwiseAbs2().cwiseInverse();
    const ParameterMatrix scaled = V * inv_s2.asDiagonal() * V.transpose();
    const ParameterVector inv_scale = scale.cwiseInverse();
    c.inverse_normal = inv_scale.asDiagonal() * scaled * inv_scale.asDiagonal();
  }
  return c;
}

std::string undetermined_reason(const Conditioning& c, double max_condition) {
  return fmt::format(
      "the data do not determine {} combination{} of {} (column-scaled condition number {:.3g}, "
      "limit {:.3g})",
      c.undetermined, c.undetermined == 1 ? "" : "s", c.involved, c.condition, max_condition);
}

std::string fk_reason(Status s, int index, const char* where) {
  if (index < 0) return fmt::format("{}: the candidate model is invalid ({})", where, describe(s));
  return fmt::format("{}: observation {}: {}", where, index + 1, describe(s));
}

}  // namespace

std::string_view parameter_name(int i) noexcept {
  static constexpr std::array<std::string_view, kIdentifiedParameters> kNames{
      "lead", "offset 1", "offset 2",   "offset 3",   "offset 4",   "offset 5",      "offset 6",      "A x",
      "A y",  "A z",      "rotation x", "rotation y", "rotation z", "translation x", "translation y", "translation z"};
  return i >= 0 && i < kIdentifiedParameters ? kNames[static_cast<std::size_t>(i)] : "?";
}

Status identification_residuals(const Model& nominal, std::span<const Observation> observations,
                                const PlatformParameters& p, const IdentificationOptions& options,
                                Eigen::VectorXd& residuals, Eigen::MatrixXd* J) {
  Evaluator evaluator(nominal, observations, options);
  residuals.resize(3 * static_cast<Eigen::Index>(observations.size()));
  Eigen::MatrixXd J_model;
  if (const Status s = evaluator.evaluate(p, residuals.data(), J != nullptr ? &J_model : nullptr); s != Status::Ok)
    return s;
  if (J != nullptr) full_jacobian(J_model, observations, p.X_BT, *J);
  return Status::Ok;
}

Status identify(const Model& nominal, std::span<const Observation> observations, Identification& out,
                const IdentificationOptions& options) {
  out = Identification{};
  const int K = static_cast<int>(observations.size());
  out.count = K;
  const auto fail = [&](Status s, std::string reason) {
    out.reason = std::move(reason);
    return s;
  };

  // What the data and the nominal model must provide.
  for (int k = 0; k < K; ++k) {
    const Observation& o = observations[static_cast<std::size_t>(k)];
    if (!o.motor.allFinite() || !o.p_T.allFinite())
      return fail(Status::NonFiniteInput, fmt::format("observation {} holds NaN or inf", k + 1));
  }
  for (int i = 0; i < kLegs; ++i) {
    if (nominal.geometry().has_axes[i] == 0.0)
      return fail(
          Status::NotIdentifiable,
          fmt::format("leg {} has no U-joint axes: its twist and so the lead and its sign are undefined", i + 1));
    if (options.lead_effect == LeadEffect::TwistAndTravel && !(nominal.leg(i).lead > 0.0))
      return fail(Status::NotIdentifiable,
                  fmt::format("leg {} has lead 0 in the nominal model: the drives' travel is unknown", i + 1));
  }
  if (K < kMinObservations)
    return fail(Status::NotIdentifiable,
                fmt::format("{} observations give {} equations for {} parameters; at least {} are needed", K, 3 * K,
                            kIdentifiedParameters, kMinObservations));

  // Start: the nominal model, the tracker frame by Kabsch onto its predictions of A.
  PlatformParameters start;
  start.lead = 0.0;
  for (int i = 0; i < kLegs; ++i) start.lead += nominal.leg(i).lead / kLegs;
  start.twist_sign = nominal.leg(0).twist_sign;
  start.length_offset = nominal.geometry().length_offset;
  start.observation_P = nominal.spec().observation_P;
  Evaluator evaluator(nominal, observations, options);
  Eigen::VectorXd e(3 * K);
  if (const Status s = evaluator.evaluate(start, e.data(), nullptr); s != Status::Ok)  // X_BT = I: e = p_T - A_B
    return fail(s, fk_reason(s, evaluator.failed_index(), "nominal model"));
  std::vector<PointPair> pairs(static_cast<std::size_t>(K));
  for (int k = 0; k < K; ++k) {
    const Vector3d& p_T = observations[static_cast<std::size_t>(k)].p_T;
    pairs[static_cast<std::size_t>(k)] = {p_T, p_T - e.segment<3>(3 * k)};
  }
  if (const Status s = register_points(pairs, out.registration); s != Status::Ok)
    return fail(Status::NotIdentifiable,
                fmt::format("the start registration of the points onto the nominal model failed: {}", describe(s)));
  start.X_BT = out.registration.X_BT;
  out.rms_before = out.registration.rms_residual;

  // Identifiability at the start: a rank-deficient problem is reported, not solved.
  Eigen::MatrixXd J_model, J;
  if (const Status s = evaluator.evaluate(start, e.data(), &J_model); s != Status::Ok)
    return fail(s, fk_reason(s, evaluator.failed_index(), "nominal model"));
  full_jacobian(J_model, observations, start.X_BT, J);
  if (const Conditioning c = conditioning(J, options.max_condition); c.undetermined > 0) {
    out.condition = c.condition;
    out.weakest = c.weakest;
    return fail(Status::NotIdentifiable, undetermined_reason(c, options.max_condition));
  }

  // Both signs from the same start; the data choose.
  for (int i = 0; i < 2; ++i) {
    const double sign = i == 0 ? 1.0 : -1.0;
    PlatformParameters from = start;
    from.twist_sign = sign;
    out.fits[static_cast<std::size_t>(i)] = solve_sign(evaluator, observations, sign, from, options);
  }
  const std::size_t best = out.fits[1].cost < out.fits[0].cost ? 1 : 0;
  const SignFit& fit = out.fits[best];
  const SignFit& other = out.fits[1 - best];
  if (!std::isfinite(fit.cost))
    return fail(fit.status, fmt::format("no solve ended with a usable solution: {}", fit.message));
  out.estimate = fit.estimate;
  out.cost_ratio = other.cost / fit.cost;

  // Residuals, noise, covariance and conditioning at the estimate.
  if (const Status s = evaluator.evaluate(out.estimate, e.data(), &J_model); s != Status::Ok)
    return fail(s, fk_reason(s, evaluator.failed_index(), "estimate"));
  full_jacobian(J_model, observations, out.estimate.X_BT, J);
  out.residual_B.resize(static_cast<std::size_t>(K));
  double sum2 = 0.0;
  out.max_after = 0.0;
  for (int k = 0; k < K; ++k) {
    const Vector3d r = e.segment<3>(3 * k);
    out.residual_B[static_cast<std::size_t>(k)] = r;
    sum2 += r.squaredNorm();
    if (r.norm() >= out.max_after) {
      out.max_after = r.norm();
      out.max_after_index = k;
    }
  }
  out.rms_after = std::sqrt(sum2 / K);
  out.sigma = std::sqrt(sum2 / (3 * K - kIdentifiedParameters));
  const Conditioning c = conditioning(J, options.max_condition);
  out.condition = c.condition;
  out.weakest = c.weakest;
  if (c.undetermined > 0) return fail(Status::NotIdentifiable, undetermined_reason(c, options.max_condition));
  out.covariance = out.sigma * out.sigma * c.inverse_normal;
  out.sd = out.covariance.diagonal().cwiseSqrt();
  if (fit.status != Status::Ok) return fail(fit.status, fmt::format("sign {:+.0f}: {}", fit.twist_sign, fit.message));
  return Status::Ok;
}

ModelSpec corrected_spec(const ModelSpec& nominal, const PlatformParameters& estimate) {
  ModelSpec spec = nominal;
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
    leg.lead = estimate.lead;
    // theory §4: the sign of the twist term is the thread hand's, whichever side is driven.
    leg.thread = estimate.twist_sign > 0.0 ? ThreadSense::Right : ThreadSense::Left;
    leg.length_offset = estimate.length_offset[i];
  }
  spec.observation_P = estimate.observation_P;
  return spec;
}

}  // namespace hexatwist
