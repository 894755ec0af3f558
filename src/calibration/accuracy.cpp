// SPDX-License-Identifier: BSD-3-Clause
// The accuracy an identification predicts for the corrected platform (theory §13): at a pose, the
// covariance of the target point that compensated commands reach, from the parameters' covariance.
#include <fmt/format.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>

#include "calibration/evaluator.hpp"
#include "calibration/random.hpp"
#include "hexatwist/calibration/identification.hpp"
#include "hexatwist/calibration/observations.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "kinematics/geometry.hpp"

namespace hexatwist {
namespace {

// The length shifts per effect parameter at a pose of the corrected platform (6 x
// set.effects().count(), as EffectRegressors): those the corrected configuration keeps, the
// load's (the static forces at the pose less at home) and the plays' (the approach straight from
// home, a run longer than any play); the run's drift is not kept (zero columns).
Eigen::Matrix<double, 6, Eigen::Dynamic> kept_effects(const Model& nominal, const ParameterSet& set, const FkResult& fk,
                                                      const Vector6d& command) {
  const EffectFit& fit = set.effects();
  Eigen::Matrix<double, 6, Eigen::Dynamic> r = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, fit.count());
  int k = 0;
  if (fit.load) {
    Vector6d force;
    if (static_leg_forces(nominal, nominal.spec().static_load, fk.legs, force) == Status::Ok)
      r.col(k) = force - nominal.reference_force();
    ++k;
  }
  if (fit.play) {
    const Vector6d& home = nominal.geometry().home_direction;
    for (int i = 0; i < kLegs; ++i) {
      const double run = command[i] - nominal.home_command()[i];
      const double sense = std::abs(run) > kSameCommand ? (run > 0.0 ? 1.0 : -1.0) : home[i];
      r(i, k + i) = -0.5 * (sense - home[i]);
    }
  }
  return r;
}

// The predicted point error at pose q: sqrt(trace(G C G^T)), G = d A_B / d theta at the commands of
// q held fixed (the error the parameters' uncertainty leaves, the kept effects' included). NaN
// outside a limit; a failed forward kinematics is returned.
Status error_at(const Model& platform, const Model& nominal, const ParameterSet& set, const Eigen::VectorXd& theta,
                const Eigen::MatrixXd& covariance, const Vector6d& q, double& error,
                Eigen::Matrix<double, 3, Eigen::Dynamic>* G_out = nullptr, Vector3d* A_out = nullptr) {
  error = std::numeric_limits<double>::quiet_NaN();
  const Pose pose = Pose::from_vector(q);
  Vector6d command;
  LimitReport limit;
  if (motor_commands(platform, pose, Strategy::Compensated, command, limit) != Status::Ok) return Status::Ok;
  FkResult fk;
  if (const Status s = forward_kinematics(platform, command, LengthKind::Motor, placement_from_pose(pose), fk);
      s != Status::Ok)
    return s;
  Eigen::Matrix<double, 6, Eigen::Dynamic> dx;
  const Eigen::Matrix<double, 6, Eigen::Dynamic> effects = kept_effects(nominal, set, fk, command);
  if (const Status s = detail::pose_sensitivity(platform, set, fk, command, dx, &effects); s != Status::Ok) return s;
  const Eigen::Matrix<double, 3, Eigen::Dynamic> G = detail::point_sensitivity(set, fk, dx, theta, 0);
  error = std::sqrt(std::max(0.0, (G * covariance * G.transpose()).trace()));
  if (G_out != nullptr) *G_out = G;
  if (A_out != nullptr) *A_out = detail::target_B(platform, fk.placement, set, theta, 0);
  return Status::Ok;
}

// The median and largest predicted error after the best rigid re-alignment over the poses: the
// errors G_k d theta less their least-squares rigid motion a + w x A_k, whose covariance per pose
// is that of the rows (I - P) G, P the projection onto the rigid motions of the points A_k.
void aligned_errors(const std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>>& G, const std::vector<Vector3d>& A,
                    const Eigen::MatrixXd& covariance, double& median, double& max) {
  const auto n = static_cast<Eigen::Index>(G.size());
  const Eigen::Index p = covariance.rows();
  Eigen::MatrixXd stack(3 * n, p), rigid(3 * n, 6);
  for (Eigen::Index k = 0; k < n; ++k) {
    stack.middleRows<3>(3 * k) = G[static_cast<std::size_t>(k)];
    rigid.block<3, 3>(3 * k, 0).setIdentity();
    rigid.block<3, 3>(3 * k, 3) = -detail::skew(A[static_cast<std::size_t>(k)]);
  }
  const Eigen::MatrixXd projected = stack - rigid * rigid.colPivHouseholderQr().solve(stack);
  std::vector<double> e(G.size());
  for (Eigen::Index k = 0; k < n; ++k) {
    const auto rows = projected.middleRows<3>(3 * k);
    e[static_cast<std::size_t>(k)] = std::sqrt(std::max(0.0, (rows * covariance * rows.transpose()).trace()));
  }
  max = *std::max_element(e.begin(), e.end());
  std::nth_element(e.begin(), e.begin() + static_cast<std::ptrdiff_t>(e.size() / 2), e.end());
  median = e[e.size() / 2];
}

}  // namespace

Status predicted_errors(const ParameterSet& set, const Eigen::VectorXd& theta, double sign,
                        const Eigen::MatrixXd& covariance, std::span<const Vector6d> poses,
                        std::vector<double>& errors) {
  if (covariance.rows() != set.platform_size() || covariance.cols() != set.platform_size())
    throw Error(fmt::format("predicted errors: the covariance is {}x{}, expected {}x{}", covariance.rows(),
                            covariance.cols(), set.platform_size(), set.platform_size()));
  const Model platform(set.platform(theta, sign)), nominal(set.nominal());
  errors.assign(poses.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t k = 0; k < poses.size(); ++k)
    if (const Status s = error_at(platform, nominal, set, theta, covariance, poses[k], errors[k]); s != Status::Ok)
      return s;
  return Status::Ok;
}

Status predicted_accuracy(const ParameterSet& set, const Eigen::VectorXd& theta, double sign,
                          const Eigen::MatrixXd& covariance, const Vector6d& low, const Vector6d& high, int poses,
                          std::uint64_t seed, AccuracyPrediction& out, std::vector<Vector6d>* poses_out,
                          std::vector<double>* errors) {
  out = AccuracyPrediction{};
  out.range_low = low;
  out.range_high = high;
  if (!(low.allFinite() && high.allFinite()) || poses < 1) return Status::NotIdentifiable;
  // Poses drawn uniformly in the range until `poses` of them are inside every limit (at most ten
  // draws per pose: a range mostly outside the limits gives fewer).
  const Model platform(set.platform(theta, sign)), nominal(set.nominal());
  detail::Random rng(seed);
  std::vector<double> found;
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>> G;
  std::vector<Vector3d> A;
  for (int draw = 0; draw < 10 * poses && static_cast<int>(found.size()) < poses; ++draw) {
    Vector6d q;
    for (int c = 0; c < 6; ++c) q[c] = low[c] + (high[c] - low[c]) * rng.uniform();
    double e = 0.0;
    Eigen::Matrix<double, 3, Eigen::Dynamic> G_q;
    Vector3d A_q;
    if (const Status s = error_at(platform, nominal, set, theta, covariance, q, e, &G_q, &A_q); s != Status::Ok)
      return s;
    if (std::isnan(e)) continue;
    found.push_back(e);
    G.push_back(G_q);
    A.push_back(A_q);
    if (poses_out != nullptr) poses_out->push_back(q);
  }
  if (found.empty()) return Status::NotIdentifiable;
  if (found.size() >= 3) aligned_errors(G, A, covariance, out.aligned_median, out.aligned_max);
  if (errors != nullptr) *errors = found;
  out.poses = static_cast<int>(found.size());
  out.max = *std::max_element(found.begin(), found.end());
  std::nth_element(found.begin(), found.begin() + static_cast<std::ptrdiff_t>(found.size() / 2), found.end());
  out.median = found[found.size() / 2];
  return Status::Ok;
}

Status accuracy_map(const ParameterSet& set, const Eigen::VectorXd& theta, double sign,
                    const Eigen::MatrixXd& covariance, const AccuracyPrediction& range, int axis_u, int axis_v, int n,
                    AccuracyMap& out) {
  if (axis_u < 0 || axis_u > 2 || axis_v < 0 || axis_v > 2 || axis_u == axis_v || n < 2 || n > 1000)
    throw Error(
        fmt::format("accuracy map: expected two different coordinates of 0..2 and 2 to 1000 positions, got "
                    "{}, {} and {}",
                    axis_u, axis_v, n));
  out = AccuracyMap{};
  out.axis_u = axis_u;
  out.axis_v = axis_v;
  const Vector6d middle = 0.5 * (range.range_low + range.range_high);
  for (int i = 0; i < n; ++i) {
    const double f = static_cast<double>(i) / (n - 1);
    out.u.push_back(range.range_low[axis_u] + f * (range.range_high[axis_u] - range.range_low[axis_u]));
    out.v.push_back(range.range_low[axis_v] + f * (range.range_high[axis_v] - range.range_low[axis_v]));
  }
  std::vector<Vector6d> poses;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      Vector6d q = Vector6d::Zero();
      q.head<3>() = middle.head<3>();
      q[axis_u] = out.u[static_cast<std::size_t>(i)];
      q[axis_v] = out.v[static_cast<std::size_t>(j)];
      poses.push_back(q);
    }
  return predicted_errors(set, theta, sign, covariance, poses, out.error);
}

}  // namespace hexatwist
