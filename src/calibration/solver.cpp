// SPDX-License-Identifier: BSD-3-Clause
#include "calibration/solver.hpp"

#include <ceres/ceres.h>
#include <fmt/format.h>

#include <Eigen/SVD>
#include <cmath>
#include <vector>

#include "hexatwist/kinematics/pose.hpp"
#include "kinematics/geometry.hpp"

namespace hexatwist::detail {
namespace {

using RowMajor3d = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
constexpr double kMaxAxisTurn = 0.2;  // [rad], of each axis parameter
using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

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
      const RowMajor3d dR = skew(Vector3d::Unit(j)) * R;
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

// The groups' residuals as one block over [platform parameters (n), R_BT (9), t_BT (3)].
class MeasurementCost final : public ceres::CostFunction {
 public:
  MeasurementCost(const ParameterSet& set, Evaluator& evaluator, int rows, double sign, std::span<const char> skip)
      : set_(set), evaluator_(evaluator), sign_(sign), skip_(skip) {
    set_num_residuals(rows);
    *mutable_parameter_block_sizes() = {set.platform_size(), 9, 3};
  }

  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    RigidTransform X_BT;
    Eigen::VectorXd theta;
    unpack(x, theta, X_BT);
    const bool want =
        jacobians != nullptr && (jacobians[0] != nullptr || jacobians[1] != nullptr || jacobians[2] != nullptr);
    last_status_ = evaluator_.evaluate(theta, sign_, X_BT, e_, want ? &J_ : nullptr, skip_);
    if (last_status_ != Status::Ok) return false;
    Eigen::Map<Eigen::VectorXd>(residuals, num_residuals()) = e_;
    if (!want) return true;
    const Eigen::Index n = num_residuals();
    if (jacobians[0] != nullptr)
      Eigen::Map<Rows>(jacobians[0], n, set_.platform_size()) = J_.leftCols(set_.platform_size());
    if (jacobians[1] != nullptr) {
      // e = w (R p + t - A): de_a/dR_ab = w p_b, with w the row's weight (its translation entry,
      // 0 on a skipped station).
      Eigen::Map<Rows> J(jacobians[1], n, 9);
      J.setZero();
      for (Eigen::Index g = 0; g < n / 3; ++g) {
        const Vector3d wp = J_(3 * g, set_.translation_index()) * evaluator_.mean_T(static_cast<std::size_t>(g));
        for (int a = 0; a < 3; ++a) J.block<1, 3>(3 * g + a, 3 * a) = wp.transpose();
      }
    }
    if (jacobians[2] != nullptr) Eigen::Map<Rows>(jacobians[2], n, 3) = J_.middleCols<3>(set_.translation_index());
    return true;
  }

  void unpack(double const* const* x, Eigen::VectorXd& theta, RigidTransform& X_BT) const {
    theta = Eigen::VectorXd::Zero(set_.size());
    theta.head(set_.platform_size()) = Eigen::Map<const Eigen::VectorXd>(x[0], set_.platform_size());
    X_BT.R = Eigen::Map<const RowMajor3d>(x[1]);
    X_BT.t = Eigen::Map<const Vector3d>(x[2]);
    // The rotation's entries stay 0: theta holds dw about X_BT.R, which is kept apart.
    theta.segment<3>(set_.translation_index()) = X_BT.t;
  }

  Status last_status() const noexcept { return last_status_; }

 private:
  const ParameterSet& set_;
  Evaluator& evaluator_;
  double sign_;
  std::span<const char> skip_;
  mutable Eigen::VectorXd e_;
  mutable Eigen::MatrixXd J_;
  mutable Status last_status_ = Status::Ok;
};

// Ends a solve once a lead has reached its bound 0 (the sense held cannot explain the twist): from
// there the projected steps only crawl, and the rest is solved with the leads held at 0.
class StopAtLeadBound final : public ceres::IterationCallback {
 public:
  StopAtLeadBound(const double* leads, int count) : leads_(leads), count_(count) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    for (int j = 0; j < count_; ++j)
      if (!(leads_[j] > 0.0)) return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const double* leads_;
  int count_;
};

}  // namespace

SignFit solve(const ParameterSet& set, Evaluator& evaluator, double sign, const Eigen::VectorXd& theta,
              const RigidTransform& X_BT, const IdentificationOptions& options, double scatter_cost,
              std::span<const char> skip) {
  Eigen::VectorXd x = theta.head(set.platform_size());
  RowMajor3d R = X_BT.R;
  Vector3d t = X_BT.t;
  const int rows = 3 * static_cast<int>(evaluator.group_count());

  ceres::Problem problem;
  auto* cost = new MeasurementCost(set, evaluator, rows, sign, skip);  // owned by the problem
  problem.AddResidualBlock(cost, nullptr, x.data(), R.data(), t.data());
  problem.SetManifold(R.data(), new RotationManifold);
  for (int j = 0; j < set.lead_count(); ++j) problem.SetParameterLowerBound(x.data(), j, 0.0);
  // An axis turns by atan(|u|): within 0.2 rad (11 deg) of its drawing, beyond any machining error.
  for (int k = set.axis_index(); k < set.axis_index() + set.axis_count(); ++k) {
    problem.SetParameterLowerBound(x.data(), k, -kMaxAxisTurn);
    problem.SetParameterUpperBound(x.data(), k, kMaxAxisTurn);
  }

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
  StopAtLeadBound stop(x.data(), set.lead_count());
  so.callbacks.push_back(&stop);
  so.update_state_every_iteration = true;  // the callback reads the leads
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);

  SignFit fit;
  fit.twist_sign = sign;
  fit.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  for (int j = 0; j < set.lead_count(); ++j) fit.lead_at_bound = fit.lead_at_bound || !(x[j] > 0.0);
  if (fit.lead_at_bound && summary.IsSolutionUsable()) {
    // Hold the leads where they are and solve the rest.
    std::vector<int> held;
    for (int j = 0; j < set.lead_count(); ++j) held.push_back(j);
    problem.SetManifold(x.data(), new ceres::SubsetManifold(set.platform_size(), held));
    so.callbacks.clear();
    ceres::Solve(so, &problem, &summary);
    fit.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
  }
  fit.message = summary.message;
  double const* blocks[] = {x.data(), R.data(), t.data()};
  cost->unpack(blocks, fit.theta, fit.X_BT);
  if (summary.termination_type == ceres::CONVERGENCE) {
    fit.status = Status::Ok;
  } else if (summary.termination_type == ceres::NO_CONVERGENCE) {
    fit.status = Status::SolverNoConvergence;
  } else {
    fit.status = cost->last_status() != Status::Ok ? cost->last_status() : Status::SolverNoConvergence;
  }
  if (summary.IsSolutionUsable()) fit.cost = summary.final_cost + scatter_cost;
  return fit;
}

Conditioning conditioning(const ParameterSet& set, const Eigen::MatrixXd& J, double max_condition) {
  Conditioning c;
  const Eigen::Index n = J.cols();
  Eigen::VectorXd scale(n);
  Eigen::MatrixXd Js = J;
  for (Eigen::Index j = 0; j < n; ++j) {
    scale[j] = J.col(j).norm();
    if (scale[j] > 0.0) Js.col(j) /= scale[j];
  }
  // Fewer equations than parameters: as many zero rows as make J square, so that the combinations
  // the rows cannot fix are the zero singular values (undetermined), not missing ones.
  if (Js.rows() < n) Js.conservativeResizeLike(Eigen::MatrixXd::Zero(n, n));
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Js, Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  const Eigen::MatrixXd& V = svd.matrixV();
  const Eigen::Index last = n - 1;
  c.condition = s[last] > 0.0 ? s[0] / s[last] : std::numeric_limits<double>::infinity();
  c.weakest = V.col(last);
  // Which parameters take part in the undetermined combinations: joints by joint (their gauge
  // coordinates mean nothing to a reader), the rest by name.
  std::vector<std::string> names;
  const auto add = [&](const std::string& name) {
    if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
  };
  for (Eigen::Index i = 0; i <= last; ++i) {
    if (!(s[i] * max_condition < s[0]) && s[i] > 0.0) continue;
    ++c.undetermined;
    Eigen::VectorXd v = V.col(i);  // in scaled parameters
    for (Eigen::Index j = 0; j < n; ++j) {
      const int k = static_cast<int>(j);
      const bool joint = (set.base_index() >= 0 && k >= set.base_index() && k < set.platform_index() + 3 * kLegs - 6);
      if (!joint && std::abs(v[j]) >= 0.1) add(set.name(k));
    }
    if (set.base_index() >= 0) {
      const int m = 3 * kLegs - 6;
      const Eigen::VectorXd db = set.base_basis() * v.segment(set.base_index(), m);
      const Eigen::VectorXd dp = set.platform_basis() * v.segment(set.platform_index(), m);
      for (int leg = 0; leg < kLegs; ++leg) {
        if (db.segment<3>(3 * leg).norm() >= 0.1) add(fmt::format("base joint {}", leg + 1));
        if (dp.segment<3>(3 * leg).norm() >= 0.1) add(fmt::format("platform joint {}", leg + 1));
      }
    }
  }
  for (const std::string& name : names) c.involved += (c.involved.empty() ? "" : ", ") + name;
  if (std::isfinite(c.condition)) {
    const Eigen::VectorXd inv_s2 = s.cwiseAbs2().cwiseInverse();
    const Eigen::MatrixXd scaled = V * inv_s2.asDiagonal() * V.transpose();
    const Eigen::VectorXd inv_scale = scale.cwiseInverse();
    c.inverse_normal = inv_scale.asDiagonal() * scaled * inv_scale.asDiagonal();
  }
  return c;
}

double f_normal_deviate(double f, double d1, double d2) noexcept {
  const double a = 2.0 / (9.0 * d1);
  const double b = d2 > 0.0 ? 2.0 / (9.0 * d2) : 0.0;
  const double c = std::cbrt(f);
  return ((1.0 - b) * c - (1.0 - a)) / std::sqrt(a + c * c * b);
}

}  // namespace hexatwist::detail
