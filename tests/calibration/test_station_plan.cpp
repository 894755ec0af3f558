// SPDX-License-Identifier: BSD-3-Clause
// Where to measure (include/hexatwist/calibration/station_plan.hpp, theory §13): planned stations
// against random ones on the predicted worst error; every station inside every limit and every
// move of the run reachable; the same plan for a seed; the Ds criterion's rank-r and rank-2r
// updates (src/calibration/ds_design.hpp) against direct log determinants and the Schur complement;
// the plan's covariance against identify's Jacobian and against identify on synthetic data at the
// planned stations; specs refused.
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <vector>

#include "calibration/calibration_support.hpp"
#include "calibration/ds_design.hpp"

namespace hexatwist::test {
namespace {

StationPlanSpec spec_of(int count, std::uint64_t seed, int candidates = 2000) {
  StationPlanSpec spec;
  spec.run.count = count;
  spec.run.seed = seed;
  spec.candidates = candidates;
  spec.accuracy_poses = 300;
  return spec;
}

StationPlan plan_of(const StationPlanSpec& spec) {
  StationPlan plan;
  EXPECT_EQ(plan_stations(seed_model(), Strategy::Compensated, spec, plan), Status::Ok) << plan.reason;
  return plan;
}

TEST(StationPlan, PlannedStationsBeatRandomOnesOnThePredictedWorstError) {
  // Measured (2000 candidates, 300 poses): the planned worst error 0.15-0.47 of the random
  // stations' in the gauge frames, 0.14-0.33 after a rigid re-alignment.
  for (const auto& [count, seed] : {std::pair{14, 3}, std::pair{20, 1}, std::pair{20, 2}, std::pair{40, 1}}) {
    SCOPED_TRACE(::testing::Message() << count << " stations, seed " << seed);
    const StationPlan plan = plan_of(spec_of(count, static_cast<std::uint64_t>(seed)));
    ASSERT_EQ(plan.random.status, Status::Ok) << plan.random.reason;
    const AccuracyPrediction &p = plan.planned.accuracy, &r = plan.random.accuracy;
    std::printf(
        "  %d stations, seed %d: worst %.1f um planned, %.1f um random (aligned %.2f, %.2f um); criterion "
        "%.2f, %.2f; %d exchanges in %d sweeps\n",
        count, seed, 1e6 * p.max, 1e6 * r.max, 1e6 * p.aligned_max, 1e6 * r.aligned_max, plan.planned.criterion,
        plan.random.criterion, plan.exchanges, plan.sweeps);
    EXPECT_GT(plan.planned.criterion, plan.random.criterion);
    EXPECT_LT(p.max, 0.75 * r.max);
    EXPECT_LT(p.aligned_max, 0.75 * r.aligned_max);
    EXPECT_LT(p.median, r.median);
    EXPECT_LT(plan.planned.condition, plan.random.condition);
    EXPECT_TRUE(plan.converged);
    EXPECT_EQ(plan.planned.stations.size(), static_cast<std::size_t>(count));
  }
}

// Every station inside every limit, every straight move of home, stations, home reachable, and
// station_run accepting the run.
void expect_a_valid_run(const StationPlanSpec& spec, const StationPlan& plan) {
  Vector6d last = Vector6d::Zero();
  for (std::size_t i = 0; i < plan.planned.stations.size(); ++i) {
    const Vector6d& q = plan.planned.stations[i];
    SCOPED_TRACE(::testing::Message() << "station " << i + 1 << ": " << q.transpose());
    Vector6d command;
    LimitReport limit;
    EXPECT_EQ(motor_commands(seed_model(), Pose::from_vector(q), Strategy::Compensated, command, limit), Status::Ok);
    EXPECT_TRUE(reachable_from(seed_model(), Strategy::Compensated, last, q));
    EXPECT_LE(q.head<3>().cwiseAbs().maxCoeff(), spec.run.translation);
    EXPECT_LE(q.tail<3>().cwiseAbs().maxCoeff(), spec.run.rotation);
    for (std::size_t j = 0; j < i; ++j) EXPECT_NE(q, plan.planned.stations[j]) << "a station twice";
    last = q;
  }
  EXPECT_TRUE(reachable_from(seed_model(), Strategy::Compensated, last, Vector6d::Zero()));
  EXPECT_NO_THROW((void)station_run(seed_model(), Strategy::Compensated, plan.planned.stations, spec.run, 0.01));
}

TEST(StationPlan, EveryStationIsInsideEveryLimitAndEveryMoveIsReachable) {
  const StationPlanSpec spec = spec_of(40, 1);
  expect_a_valid_run(spec, plan_of(spec));
  // Wider ranges (±0.4 m, ±25 deg), where the workspace is no longer convex: a station the
  // nearest-neighbour order cannot reach is exchanged for one it can (measured: 1 of 40).
  StationPlanSpec wide = spec_of(40, 1, 1000);
  wide.run.translation = 0.4;
  wide.run.rotation = deg2rad(25.0);
  const StationPlan plan = plan_of(wide);
  std::printf("  wide ranges: %d of 40 stations replaced while ordering\n", plan.replaced);
  EXPECT_GE(plan.replaced, 1);
  expect_a_valid_run(wide, plan);
}

TEST(StationPlan, TheSameSeedGivesTheSamePlanAndAnotherSeedAnother) {
  const StationPlan a = plan_of(spec_of(20, 5, 800)), b = plan_of(spec_of(20, 5, 800));
  const StationPlan c = plan_of(spec_of(20, 6, 800));
  ASSERT_EQ(a.planned.stations.size(), b.planned.stations.size());
  for (std::size_t i = 0; i < a.planned.stations.size(); ++i) EXPECT_EQ(a.planned.stations[i], b.planned.stations[i]);
  EXPECT_EQ(a.planned.criterion, b.planned.criterion);
  EXPECT_EQ(a.planned.accuracy.max, b.planned.accuracy.max);
  EXPECT_EQ(a.random.stations, b.random.stations);
  EXPECT_NE(a.planned.stations.front(), c.planned.stations.front());
}

// ---- the Ds criterion and its updates -------------------------------------------------------------

// log det of the Schur complement M_pp - M_pn M_nn^-1 M_np, by LU: an independent formula.
double schur_log_det(const Eigen::MatrixXd& M, int nuisance) {
  const Eigen::Index p = M.rows() - nuisance;
  const Eigen::MatrixXd S =
      M.topLeftCorner(p, p) - M.topRightCorner(p, nuisance) *
                                  M.bottomRightCorner(nuisance, nuisance).lu().solve(M.bottomLeftCorner(nuisance, p));
  return std::log(S.lu().determinant());
}

Eigen::MatrixXd random_matrix(std::mt19937_64& rng, Eigen::Index rows, Eigen::Index cols) {
  Eigen::MatrixXd A(rows, cols);
  for (Eigen::Index i = 0; i < A.size(); ++i) A.data()[i] = gaussian(rng);
  return A;
}

TEST(DsDesign, RankUpdatesEqualADirectLogDeterminant) {
  // Random candidates (blocks of 3 and of 6 rows: one and two targets), a design built by adds and
  // changed by swaps: every gain the determinant lemma gives equals the change of a direct log
  // det, before and after many Woodbury updates of the forms. Measured: 2.7e-11 at most.
  double worst = 0.0;
  for (const int r : {3, 6}) {
    std::mt19937_64 rng(kSeed + static_cast<std::uint32_t>(r));
    const int p = 20, nuisance = 6, candidates = 60;
    const Eigen::MatrixXd rows = random_matrix(rng, r * candidates, p);
    const Eigen::MatrixXd F0 = random_matrix(rng, p, p);
    detail::DsDesign design(rows, r, nuisance, 0.1 * F0.transpose() * F0 + 0.01 * Eigen::MatrixXd::Identity(p, p));
    const auto block = [&](int k) { return rows.middleRows(r * k, r); };
    const auto check = [&](double gain, const Eigen::MatrixXd& after) {
      const double direct = detail::ds_criterion(after, nuisance) - design.criterion();
      worst = std::max(worst, std::abs(gain - direct));
      EXPECT_NEAR(gain, direct, 3e-10 * std::max(1.0, std::abs(direct)));
    };
    for (int step = 0; step < 40; ++step) {
      const int k = static_cast<int>(rng() % candidates);
      if (design.in_design(k)) continue;
      const Eigen::MatrixXd M = design.information();
      if (design.design().size() < 8) {
        check(design.add_gain(k), M + block(k).transpose() * block(k));
        design.add(k);
        continue;
      }
      const int position = static_cast<int>(rng() % design.design().size());
      const int i = design.design()[static_cast<std::size_t>(position)];
      const Eigen::MatrixXd after = M - block(i).transpose() * block(i) + block(k).transpose() * block(k);
      check(design.swap_gain(position, k), after);
      EXPECT_NEAR(design.swap_gains(position)[static_cast<std::size_t>(k)], design.swap_gain(position, k), 1e-12);
      design.swap(position, k);
      EXPECT_NEAR(design.criterion(), detail::ds_criterion(after, nuisance), 1e-9);
    }
    // The criterion is the log det of the Schur complement, and the information is the design's.
    Eigen::MatrixXd M = 0.1 * F0.transpose() * F0 + 0.01 * Eigen::MatrixXd::Identity(p, p);
    for (const int k : design.design()) M += block(k).transpose() * block(k);
    EXPECT_LT((M - design.information()).norm(), 1e-10 * M.norm());
    EXPECT_NEAR(design.criterion(), schur_log_det(M, nuisance), 1e-9 * std::abs(design.criterion()));
  }
  std::printf("  largest difference of a gain from the direct log det %.2g\n", worst);
}

TEST(DsDesign, TheExchangeEndsWhereNoSwapGainsAndAboveTheGreedyStart) {
  std::mt19937_64 rng(kSeed + 7);
  const int r = 3, p = 15, nuisance = 6, candidates = 200, count = 8;
  const Eigen::MatrixXd rows = random_matrix(rng, r * candidates, p);
  detail::DsDesign design(rows, r, nuisance, 1e-3 * Eigen::MatrixXd::Identity(p, p));
  design.greedy(count);
  const double greedy = design.criterion();
  const detail::DsDesign::Exchanges e = design.exchange(100, 1e-9);
  EXPECT_TRUE(e.converged);
  EXPECT_GT(e.exchanges, 0);
  EXPECT_GT(design.criterion(), greedy);
  // No (station, candidate) swap raises the direct criterion.
  const Eigen::MatrixXd& M = design.information();
  for (int position = 0; position < count; ++position)
    for (int k = 0; k < candidates; ++k) {
      if (design.in_design(k)) continue;
      const auto J_i = rows.middleRows(r * design.design()[static_cast<std::size_t>(position)], r);
      const auto J_k = rows.middleRows(r * k, r);
      const Eigen::MatrixXd after = M - J_i.transpose() * J_i + J_k.transpose() * J_k;
      EXPECT_LE(detail::ds_criterion(after, nuisance), design.criterion() + 1e-8);
    }
}

// ---- the plan's covariance against identify ------------------------------------------------------

TEST(StationPlan, TheCovarianceIsThatOfIdentifysJacobianAtTheNominalModel) {
  // The identification's own Jacobian (identification_residuals: forward kinematics of each
  // station's commands) at the nominal model, one observation per station and home twice, gives
  // the same information: C = noise^2 / points (J^T J)^-1, its platform block.
  for (const int targets : {1, 2}) {
    SCOPED_TRACE(targets);
    StationPlanSpec spec = spec_of(16, 2, 500);
    if (targets == 2) spec.targets_P.push_back(Vector3d(-0.4, 0.5, 0.1));
    const StationPlan plan = plan_of(spec);
    const ParameterSet& set = plan.parameters;
    Eigen::VectorXd theta = set.nominal_vector();
    if (targets == 2) theta.segment<3>(set.target_index() + 3) = spec.targets_P[0];
    const Model model(set.platform(theta, 1.0));
    std::vector<Vector6d> poses{Vector6d::Zero(), Vector6d::Zero()};
    poses.insert(poses.end(), plan.planned.stations.begin(), plan.planned.stations.end());
    std::vector<Observation> obs;
    for (const Vector6d& q : poses) {
      Vector6d command;
      LimitReport limit;
      ASSERT_EQ(motor_commands(seed_model(), Pose::from_vector(q), Strategy::Compensated, command, limit), Status::Ok);
      for (int t = 0; t < targets; ++t)
        obs.push_back({command,
                       platform_point_B(model, placement_from_pose(Pose::from_vector(q)),
                                        theta.segment<3>(set.target_index() + 3 * t)),
                       t});
    }
    Eigen::VectorXd e;
    Eigen::MatrixXd J;
    ASSERT_EQ(identification_residuals(set, obs, theta, 1.0, RigidTransform{}, FkOptions{}, e, &J), Status::Ok);
    EXPECT_LT(e.norm(), 1e-9);  // the points are the model's
    const Eigen::MatrixXd N = J.transpose() * J;
    const Eigen::MatrixXd C = spec.noise * spec.noise / spec.points_per_station *
                              N.ldlt().solve(Eigen::MatrixXd::Identity(N.rows(), N.cols()));
    const int p = set.platform_size();
    const Eigen::MatrixXd diff = C.topLeftCorner(p, p) - plan.planned.covariance;
    const double rel = (diff.diagonal().array() / plan.planned.covariance.diagonal().array()).abs().maxCoeff();
    std::printf("  %d target(s): the covariances' diagonals differ by %.2g relative at most\n", targets, rel);
    EXPECT_LT(rel, 4e-9);  // measured 3.8e-10
  }
}

TEST(StationPlan, IdentifyAtPlannedStationsHasThePredictedStandardDeviations) {
  // A real platform with every error (joints 1 mm, lead 2.5 %, offsets, A), 75 points of 10 um
  // noise at home twice and at each planned station: identify's standard deviations are the
  // plan's (its sigma is the noise to a few %, its Jacobian at the estimate the nominal one's), and
  // its errors lie within 4 of them.
  const StationPlanSpec spec = spec_of(30, 4, 1000);
  const StationPlan plan = plan_of(spec);
  std::mt19937_64 rng(kSeed + 30);
  const Truth truth = random_truth(seed_model(), TruthErrors{}, rng);
  std::vector<Pose> poses{Pose{}};
  for (const Vector6d& q : plan.planned.stations) poses.push_back(Pose::from_vector(q));
  poses.push_back(Pose{});
  const std::vector<Observation> obs = observe(seed_model(), truth, poses, spec.points_per_station, spec.noise, rng);
  IdentificationOptions o;
  o.axes = AxisFit::None;
  o.folds = 0;
  o.accuracy_poses = 50;
  Identification id;
  ASSERT_EQ(identify(seed_model(), obs, id, o), Status::Ok) << id.reason;
  const int p = plan.parameters.platform_size();
  ASSERT_EQ(id.parameters.platform_size(), p);
  const Eigen::VectorXd predicted = plan.planned.covariance.diagonal().cwiseSqrt();
  const Eigen::ArrayXd ratio = id.sd.head(p).array() / predicted.array();
  std::printf("  identify's sd over the plan's: %.3f-%.3f\n", ratio.minCoeff(), ratio.maxCoeff());
  EXPECT_GT(ratio.minCoeff(), 0.9);
  EXPECT_LT(ratio.maxCoeff(), 1.1);
  const double lead_error = id.estimate[0] - truth.spec.legs[0].lead;
  EXPECT_LT(std::abs(lead_error), 4.0 * predicted[0]);
  for (int i = 0; i < kLegs; ++i)
    EXPECT_LT(std::abs(id.estimate[plan.parameters.offset_index() + i] -
                       truth.spec.legs[static_cast<std::size_t>(i)].length_offset),
              4.0 * predicted[plan.parameters.offset_index() + i]);
}

// ---- what is refused -------------------------------------------------------------------------------

TEST(StationPlan, TheChoiceDoesNotDependOnTheNoiseOrThePoints) {
  StationPlanSpec a = spec_of(16, 3, 500), b = a;
  b.noise = 25e-6;
  b.points_per_station = 300;
  const StationPlan pa = plan_of(a), pb = plan_of(b);
  EXPECT_EQ(pa.planned.stations, pb.planned.stations);
  // The covariance scales with noise^2 / points, the criterion by p log of that.
  const double scale = (b.noise * b.noise / b.points_per_station) / (a.noise * a.noise / a.points_per_station);
  EXPECT_LT((pb.planned.covariance - scale * pa.planned.covariance).norm(), 1e-9 * pb.planned.covariance.norm());
  EXPECT_NEAR(pa.planned.criterion - pb.planned.criterion, pa.parameters.platform_size() * std::log(scale), 1e-8);
}

TEST(StationPlan, BadSpecsAreRefusedNamingTheField) {
  const int fewest = min_planned_stations(seed_model(), StationPlanSpec{});
  EXPECT_EQ(fewest, 13);  // 40 parameters (34 and the tracker frame), 3 rows per station, home's too
  // One line naming the field (ParameterError's parameter: the CLI's option, Python's keyword).
  const auto refused = [](StationPlanSpec spec, std::string_view field, std::initializer_list<std::string_view> parts) {
    StationPlan plan;
    // "station plan: ", or "stations: " for the run's own fields (check_stations_spec).
    expect_error_line([&] { (void)plan_stations(seed_model(), Strategy::Compensated, spec, plan); }, "station", parts);
    try {
      (void)plan_stations(seed_model(), Strategy::Compensated, spec, plan);
      ADD_FAILURE() << field << ": not refused";
    } catch (const ParameterError& e) {
      EXPECT_EQ(e.parameter(), field) << e.what();
    }
  };
  StationPlanSpec s;
  s.run.count = fewest - 1;
  refused(s, "count", {"13 to 10000 stations", "40 parameters", "got 12"});
  s.run.count = kMaxStations + 1;
  refused(s, "count", {"got 10001"});
  s = {};
  s.run.translation = std::nan("");
  refused(s, "translation", {"translation range of 0 to 10 m"});
  s.run.translation = 10.5;
  refused(s, "translation", {"translation range of 0 to 10 m", "got 10.5"});
  s = {};
  s.run.rotation = -0.1;
  refused(s, "rotation", {"rotation range of 0 to 90 deg"});
  s.run.rotation = kMaxStationRotation + 1e-9;
  refused(s, "rotation", {"rotation range of 0 to 90 deg"});
  s = {};
  s.run.translation = s.run.rotation = 0.0;
  refused(s, "translation", {"a range > 0 in translation or rotation"});
  s = {};
  s.candidates = 39;
  refused(s, "candidates", {"40 (the stations) to 100000 candidates", "got 39"});
  s = {};
  s.noise = 0.0;
  refused(s, "noise", {"noise > 0 and below 0.01 m"});
  s.noise = kMaxTrackerNoise;
  refused(s, "noise", {"noise > 0 and below 0.01 m"});
  s = {};
  s.points_per_station = 0;
  refused(s, "points_per_station", {"1 to 100000 points per station"});
  s.points_per_station = kMaxPointsPerStation + 1;
  refused(s, "points_per_station", {"got 100001"});
  s = {};
  s.accuracy_poses = 0;
  refused(s, "accuracy_poses", {"accuracy poses >= 1"});
  s = {};
  s.max_sweeps = -1;
  refused(s, "max_sweeps", {"sweeps >= 0"});
  s = {};
  s.targets_P.assign(4, Vector3d::Zero());
  refused(s, "targets", {"5 targets", "at most 4"});
  s = {};
  s.tolerance = -1.0;
  refused(s, "tolerance", {"tolerance"});
}

TEST(StationPlan, RangesBeyondTheLimitsAreNotIdentifiableAndSaySo) {
  StationPlanSpec spec = spec_of(20, 1, 200);
  spec.run.translation = 3.0;  // a leg's whole stroke is 1.05 m
  StationPlan plan;
  EXPECT_EQ(plan_stations(seed_model(), Strategy::Compensated, spec, plan), Status::NotIdentifiable);
  EXPECT_EQ(plan.status, Status::NotIdentifiable);
  EXPECT_NE(plan.reason.find("reachable inside the limits"), std::string::npos) << plan.reason;
  EXPECT_NE(plan.reason.find("give smaller ranges"), std::string::npos) << plan.reason;
  // Stations that do not determine the model: 13 at home-like poses.
  StationsQuality q;
  const std::vector<Vector6d> near_home(13, Vector6d::Constant(1e-4));
  EXPECT_EQ(assess_stations(seed_model(), Strategy::Compensated, near_home, spec_of(20, 1), q),
            Status::NotIdentifiable);
  EXPECT_NE(q.reason.find("do not determine every parameter"), std::string::npos) << q.reason;
}

}  // namespace
}  // namespace hexatwist::test
