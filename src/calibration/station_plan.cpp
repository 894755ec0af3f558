// SPDX-License-Identifier: BSD-3-Clause
// Where to measure (theory §13): the stations' sensitivities at the nominal model, the Ds-optimal
// choice among seeded candidates (ds_design.hpp), the run's order, and the plan's quality beside
// random stations'.
#include "hexatwist/calibration/station_plan.hpp"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "calibration/ds_design.hpp"
#include "calibration/evaluator.hpp"
#include "calibration/random.hpp"
#include "hexatwist/error.hpp"
#include "kinematics/geometry.hpp"

namespace hexatwist {
namespace {

constexpr int kMaxPlanTargets = 4;  // the observation point and 3 more
constexpr int kTracker = 6;         // the tracker frame's parameters, the nuisance
// Draws per candidate at most: a range mostly outside the limits gives fewer candidates.
constexpr int kDrawsPerCandidate = 20;
// The greedy start's ridge on the column-scaled information (each column about 1 per station):
// it keeps M invertible while fewer stations than parameters are chosen, and is kept throughout.
constexpr double kRidge = 1e-9;

// The parameters planned for, their nominal values (targets beside A as given) and the platform.
struct Layout {
  ParameterSet set;
  Eigen::VectorXd theta;
  Model platform;
  Layout(const Model& nominal, const StationPlanSpec& spec)
      : set(nominal, spec.model, spec.lead_effect, spec.axes, 1 + static_cast<int>(spec.targets_P.size())),
        theta(set.nominal_vector()),
        platform(set.platform(theta, 1.0)) {
    for (std::size_t t = 0; t < spec.targets_P.size(); ++t)
      theta.segment<3>(set.target_index() + 3 * static_cast<Eigen::Index>(t + 1)) = spec.targets_P[t];
  }
  int rows() const { return 3 * set.targets(); }
};

// The station's rows of the measurement Jacobian (3 per target, set.size() columns) at the nominal
// model, the commands of `strategy` held fixed, the tracker frame at the identity: d e / d theta of
// the residual e = p_B + t_BT - A_B as the identification's (theory §13). `inside` is false (and J
// untouched) for a pose outside a limit; a failed forward kinematics is returned.
Status station_rows(const Model& nominal, const Layout& layout, Strategy strategy, const Vector6d& q,
                    Eigen::Ref<Eigen::MatrixXd> J, bool& inside) {
  const ParameterSet& set = layout.set;
  const Pose pose = Pose::from_vector(q);
  Vector6d command;
  LimitReport limit;
  inside = motor_commands(nominal, pose, strategy, command, limit) == Status::Ok;
  if (!inside) return Status::Ok;
  FkResult fk;
  if (const Status s = forward_kinematics(layout.platform, command, LengthKind::Motor, placement_from_pose(pose), fk);
      s != Status::Ok)
    return s;
  Eigen::Matrix<double, 6, Eigen::Dynamic> dx;
  if (const Status s = detail::pose_sensitivity(layout.platform, set, fk, command, dx); s != Status::Ok) return s;
  for (int t = 0; t < set.targets(); ++t) {
    const Vector3d A_B = detail::target_B(layout.platform, fk.placement, set, layout.theta, t);
    J.middleRows<3>(3 * t).setZero();
    J.block(3 * t, 0, 3, set.platform_size()) = -detail::point_sensitivity(set, fk, dx, layout.theta, t);
    J.block<3, 3>(3 * t, set.rotation_index()) = -detail::skew(A_B);
    J.block<3, 3>(3 * t, set.translation_index()).setIdentity();
  }
  return Status::Ok;
}

// Rows of home and the stations, home first. A station outside a limit is NotIdentifiable.
Status run_rows(const Model& nominal, const Layout& layout, Strategy strategy, std::span<const Vector6d> stations,
                Eigen::MatrixXd& rows, std::string& reason) {
  const int r = layout.rows();
  rows.resize(static_cast<Eigen::Index>(r) * static_cast<Eigen::Index>(stations.size() + 1), layout.set.size());
  for (std::size_t i = 0; i <= stations.size(); ++i) {
    const Vector6d q = i == 0 ? Vector6d::Zero() : stations[i - 1];
    bool inside = false;
    const Status s =
        station_rows(nominal, layout, strategy, q, rows.middleRows(r * static_cast<Eigen::Index>(i), r), inside);
    if (s != Status::Ok || !inside) {
      reason = i == 0 ? fmt::format("home: {}", s != Status::Ok ? describe(s) : "outside a limit")
                      : fmt::format("station {}: {}", i, s != Status::Ok ? describe(s) : "outside a limit");
      return s != Status::Ok ? s : Status::NotIdentifiable;
    }
  }
  return Status::Ok;
}

// Column scales that make every column of `rows` of unit rms per block of r rows (1 for a zero column).
Eigen::VectorXd column_scales(const Eigen::MatrixXd& rows, int r) {
  const double blocks = static_cast<double>(rows.rows() / r);
  Eigen::VectorXd d(rows.cols());
  for (Eigen::Index j = 0; j < rows.cols(); ++j) {
    const double rms = std::sqrt(rows.col(j).squaredNorm() / blocks);
    d[j] = rms > 0.0 ? 1.0 / rms : 1.0;
  }
  return d;
}

// The candidates: poses drawn uniformly within the ranges (the generator random_stations uses,
// seeded alike) that are inside every limit with the straight move from home, and their rows.
struct Candidates {
  std::vector<Vector6d> poses;
  Eigen::MatrixXd rows;
  int draws = 0;
};

Status draw_candidates(const Model& nominal, const Layout& layout, Strategy strategy, const StationPlanSpec& spec,
                       Candidates& c, std::string& reason) {
  const int r = layout.rows();
  detail::Random rng(spec.run.seed);
  c.rows.resize(static_cast<Eigen::Index>(r) * spec.candidates, layout.set.size());
  while (static_cast<int>(c.poses.size()) < spec.candidates && c.draws < kDrawsPerCandidate * spec.candidates) {
    ++c.draws;
    Vector6d q;
    for (int k = 0; k < 6; ++k) q[k] = (k < 3 ? spec.run.translation : spec.run.rotation) * rng.symmetric();
    if (!reachable_from(nominal, strategy, Vector6d::Zero(), q)) continue;
    bool inside = false;
    const auto at = static_cast<Eigen::Index>(r) * static_cast<Eigen::Index>(c.poses.size());
    if (const Status s = station_rows(nominal, layout, strategy, q, c.rows.middleRows(at, r), inside);
        s != Status::Ok) {
      reason = fmt::format("candidate pose ({:.4f}, {:.4f}, {:.4f} m, {:.3f}, {:.3f}, {:.3f} deg): {}", q[0], q[1],
                           q[2], rad2deg(q[3]), rad2deg(q[4]), rad2deg(q[5]), describe(s));
      return s;
    }
    if (inside) c.poses.push_back(q);
  }
  c.rows.conservativeResize(static_cast<Eigen::Index>(r) * static_cast<Eigen::Index>(c.poses.size()), c.rows.cols());
  if (static_cast<int>(c.poses.size()) < spec.run.count) {
    reason = fmt::format(
        "{} of {} poses drawn within ±{:g} m and ±{:g} deg are reachable inside the limits from home, fewer than the "
        "{} "
        "stations; give smaller ranges",
        c.poses.size(), c.draws, spec.run.translation, rad2deg(spec.run.rotation), spec.run.count);
    return Status::NotIdentifiable;
  }
  return Status::Ok;
}

double path_length(std::span<const Vector6d> stations) {
  double length = 0.0;
  Vector6d last = Vector6d::Zero();
  for (const Vector6d& q : stations) length += (q - std::exchange(last, q)).norm();
  return length + last.norm();
}

// The quality of a run of `stations` (theory §13): the information of home's two rests and the
// stations' in column-scaled form (its conditioning is identify's), the criterion and covariance
// in SI, and the predicted accuracy over the spec's ranges.
Status quality(const Model& nominal, const Layout& layout, Strategy strategy, std::span<const Vector6d> stations,
               const StationPlanSpec& spec, StationsQuality& out) {
  out = StationsQuality{};
  out.stations.assign(stations.begin(), stations.end());
  out.path = path_length(stations);
  const auto fail = [&](Status s, std::string reason) {
    out.status = s;
    out.reason = std::move(reason);
    return s;
  };
  Eigen::MatrixXd rows;
  std::string reason;
  if (const Status s = run_rows(nominal, layout, strategy, stations, rows, reason); s != Status::Ok)
    return fail(s, reason);
  const int r = layout.rows(), p = layout.set.platform_size();
  const Eigen::VectorXd d = column_scales(rows, r);
  const Eigen::MatrixXd scaled = rows * d.asDiagonal();
  Eigen::MatrixXd M = scaled.transpose() * scaled;
  M.noalias() += scaled.topRows(r).transpose() * scaled.topRows(r);  // home rests twice
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(M, Eigen::EigenvaluesOnly);
  out.condition = eigen.eigenvalues()[0] > 0.0 ? std::sqrt(eigen.eigenvalues().maxCoeff() / eigen.eigenvalues()[0])
                                               : std::numeric_limits<double>::infinity();
  const double max_condition = IdentificationOptions{}.max_condition;
  if (!(out.condition <= max_condition))
    return fail(Status::NotIdentifiable,
                fmt::format("{} stations do not determine every parameter (column-scaled condition number {:.3g}, "
                            "limit {:.3g})",
                            stations.size(), out.condition, max_condition));
  // Back to SI: M_SI = c D^-1 M D^-1 with c = points / noise^2 (theory §13).
  const double c = spec.points_per_station / (spec.noise * spec.noise);
  out.criterion = detail::ds_criterion(M, kTracker) + p * std::log(c) - 2.0 * d.head(p).array().log().sum();
  out.sd_geometric = std::exp(-out.criterion / (2.0 * p));
  const Eigen::MatrixXd C = M.llt().solve(Eigen::MatrixXd::Identity(M.rows(), M.cols()));
  out.covariance = d.head(p).asDiagonal() * C.topLeftCorner(p, p) * d.head(p).asDiagonal() / c;
  Vector6d high;
  high << Vector3d::Constant(spec.run.translation), Vector3d::Constant(spec.run.rotation);
  if (const Status s = predicted_accuracy(layout.set, layout.theta, 1.0, out.covariance, -high, high,
                                          spec.accuracy_poses, spec.accuracy_seed, out.accuracy);
      s != Status::Ok)
    return fail(s, fmt::format("the predicted accuracy: {}", describe(s)));
  out.status = Status::Ok;
  return Status::Ok;
}

// Orders the design into a run (theory §13): from home, the nearest station (in pose coordinates)
// that the straight move reaches inside every limit, the last one also home. When none of the
// remaining stations can be reached, the (station, candidate) exchange of the largest gain whose
// candidate can be reached replaces one. `order` receives candidate indices.
Status order_run(const Model& nominal, Strategy strategy, const Candidates& c, detail::DsDesign& design,
                 std::vector<int>& order, int& replaced, std::string& reason) {
  std::vector<int> remaining(design.design().size());
  std::iota(remaining.begin(), remaining.end(), 0);
  Vector6d current = Vector6d::Zero();
  const auto pose = [&](int position) -> const Vector6d& {
    return c.poses[static_cast<std::size_t>(design.design()[static_cast<std::size_t>(position)])];
  };
  const auto can_go = [&](const Vector6d& q, bool last) {
    return reachable_from(nominal, strategy, current, q) &&
           (!last || reachable_from(nominal, strategy, q, Vector6d::Zero()));
  };
  while (!remaining.empty()) {
    const bool last = remaining.size() == 1;
    std::stable_sort(remaining.begin(), remaining.end(),
                     [&](int a, int b) { return (pose(a) - current).norm() < (pose(b) - current).norm(); });
    auto next = std::find_if(remaining.begin(), remaining.end(), [&](int p) { return can_go(pose(p), last); });
    if (next == remaining.end()) {
      int best_position = -1, best = -1;
      double best_gain = -std::numeric_limits<double>::infinity();
      for (const int position : remaining) {
        const std::vector<double> gains = design.swap_gains(position);
        std::vector<int> by_gain(gains.size());
        std::iota(by_gain.begin(), by_gain.end(), 0);
        std::stable_sort(by_gain.begin(), by_gain.end(), [&](int a, int b) {
          return gains[static_cast<std::size_t>(a)] > gains[static_cast<std::size_t>(b)];
        });
        for (const int k : by_gain) {
          const double g = gains[static_cast<std::size_t>(k)];
          if (!(g > best_gain)) break;
          if (!can_go(c.poses[static_cast<std::size_t>(k)], last)) continue;
          best_position = position, best = k, best_gain = g;
          break;
        }
      }
      if (best < 0) {
        reason = order.empty()
                     ? std::string("no candidate can be reached inside the limits from home")
                     : fmt::format("no candidate can be reached inside the limits from station {}", order.size());
        return Status::NotIdentifiable;
      }
      design.swap(best_position, best);
      ++replaced;
      next = std::find(remaining.begin(), remaining.end(), best_position);
    }
    order.push_back(design.design()[static_cast<std::size_t>(*next)]);
    current = pose(*next);
    remaining.erase(next);
  }
  return Status::Ok;
}

}  // namespace

int min_planned_stations(const Model& nominal, const StationPlanSpec& spec) {
  const ParameterSet set(nominal, spec.model, spec.lead_effect, spec.axes, 1 + static_cast<int>(spec.targets_P.size()));
  // Home's rests give 3 independent rows per target, each station as many: r (N + 1) >= p.
  const int r = 3 * set.targets();
  return std::max(1, (set.size() + r - 1) / r - 1);
}

void check_station_plan_spec(const Model& nominal, const StationPlanSpec& spec) {
  // Each refusal names the field at fault (ParameterError: the CLI's option, Python's keyword).
  const StationsSpec& run = spec.run;
  StationsSpec ranges = run;  // the count is checked below, against the parameters
  ranges.count = 1;
  check_stations_spec(ranges);
  if (spec.targets_P.size() + 1 > static_cast<std::size_t>(kMaxPlanTargets))
    throw ParameterError(fmt::format("station plan: {} targets with the observation point, at most {}",
                                     spec.targets_P.size() + 1, kMaxPlanTargets),
                         "targets");
  for (const Vector3d& t : spec.targets_P)
    if (!t.allFinite()) throw ParameterError("station plan: a target holds NaN or inf", "targets");
  const int fewest = min_planned_stations(nominal, spec);
  if (run.count < fewest || run.count > kMaxStations)
    throw ParameterError(
        fmt::format(
            "station plan: expected {} to {} stations (with home's rests they must give as many "
            "equations as the {} parameters), got {}",
            fewest, kMaxStations,
            ParameterSet(nominal, spec.model, spec.lead_effect, spec.axes, 1 + static_cast<int>(spec.targets_P.size()))
                .size(),
            run.count),
        "count");
  if (spec.candidates < run.count || spec.candidates > kMaxCandidates)
    throw ParameterError(fmt::format("station plan: expected {} (the stations) to {} candidates, got {}", run.count,
                                     kMaxCandidates, spec.candidates),
                         "candidates");
  if (!(spec.noise > 0.0 && spec.noise < kMaxTrackerNoise))
    throw ParameterError(fmt::format("station plan: expected a tracker noise > 0 and below {:g} m, got {:g}",
                                     kMaxTrackerNoise, spec.noise),
                         "noise");
  if (spec.points_per_station < 1 || spec.points_per_station > kMaxPointsPerStation)
    throw ParameterError(fmt::format("station plan: expected 1 to {} points per station, got {}", kMaxPointsPerStation,
                                     spec.points_per_station),
                         "points_per_station");
  if (spec.accuracy_poses < 1)
    throw ParameterError(fmt::format("station plan: expected accuracy poses >= 1, got {}", spec.accuracy_poses),
                         "accuracy_poses");
  if (spec.max_sweeps < 0)
    throw ParameterError(fmt::format("station plan: expected exchange sweeps >= 0, got {}", spec.max_sweeps),
                         "max_sweeps");
  if (!(std::isfinite(spec.tolerance) && spec.tolerance >= 0.0))
    throw ParameterError(fmt::format("station plan: expected an exchange tolerance >= 0, got {}", spec.tolerance),
                         "tolerance");
}

}  // namespace hexatwist

namespace hexatwist {

Status assess_stations(const Model& nominal, Strategy strategy, std::span<const Vector6d> stations,
                       const StationPlanSpec& spec, StationsQuality& out) {
  check_station_plan_spec(nominal, spec);
  const Layout layout(nominal, spec);
  return quality(nominal, layout, strategy, stations, spec, out);
}

Status plan_stations(const Model& nominal, Strategy strategy, const StationPlanSpec& spec, StationPlan& out) {
  check_station_plan_spec(nominal, spec);
  out = StationPlan{};
  const Layout layout(nominal, spec);
  out.parameters = layout.set;
  const auto fail = [&](Status s, std::string reason) {
    out.status = s;
    out.reason = std::move(reason);
    return s;
  };
  Candidates c;
  std::string reason;
  if (const Status s = draw_candidates(nominal, layout, strategy, spec, c, reason); s != Status::Ok)
    return fail(s, reason);
  out.candidates = static_cast<int>(c.poses.size());
  out.draws = c.draws;
  // The design in column-scaled form (the choice does not depend on units, noise or points); home's
  // two rests and a small ridge are the information every design has.
  const int r = layout.rows();
  const Eigen::VectorXd d = column_scales(c.rows, r);
  Eigen::MatrixXd home(r, layout.set.size());
  if (run_rows(nominal, layout, strategy, {}, home, reason) != Status::Ok) return fail(Status::NotIdentifiable, reason);
  const Eigen::MatrixXd home_scaled = home * d.asDiagonal();
  Eigen::MatrixXd fixed = 2.0 * home_scaled.transpose() * home_scaled;
  fixed.diagonal().array() += kRidge;
  detail::DsDesign design(c.rows * d.asDiagonal(), r, kTracker, fixed);
  design.greedy(spec.run.count);
  const detail::DsDesign::Exchanges exchanges = design.exchange(spec.max_sweeps, spec.tolerance);
  out.sweeps = exchanges.sweeps;
  out.exchanges = exchanges.exchanges;
  out.converged = exchanges.converged;
  std::vector<int> order;
  if (const Status s = order_run(nominal, strategy, c, design, order, out.replaced, reason); s != Status::Ok)
    return fail(s, reason);
  std::vector<Vector6d> stations;
  for (const int k : order) stations.push_back(c.poses[static_cast<std::size_t>(k)]);
  if (const Status s = quality(nominal, layout, strategy, stations, spec, out.planned); s != Status::Ok)
    return fail(s, "the planned stations: " + out.planned.reason);
  // The comparison: random stations of the same run spec (their failure is theirs, not the plan's).
  try {
    const std::vector<Vector6d> random = random_stations(nominal, strategy, spec.run);
    (void)quality(nominal, layout, strategy, random, spec, out.random);
  } catch (const Error& e) {
    out.random.status = Status::NotIdentifiable;
    out.random.reason = e.what();
  }
  out.status = Status::Ok;
  return Status::Ok;
}

}  // namespace hexatwist
