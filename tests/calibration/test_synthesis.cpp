// SPDX-License-Identifier: BSD-3-Clause
// Synthetic tracker logs (synthesis.hpp): the points are where the real platform puts the
// observation point, in the drawn tracker frame, at the tracker's rate, with the noise asked for;
// the same seed gives the same log.
#include <gtest/gtest.h>

#include <functional>

#include <Eigen/Geometry>

#include <limits>
#include "hexatwist/hexatwist.hpp"

#include "support.hpp"

namespace hexatwist {
namespace {

using test::report;

// A short run: home, a 10 cm heave with 5 deg of yaw, home.
Trajectory short_trajectory(const Rig& rig) {
  const std::array<Vector6d, 3> w{Vector6d::Zero(), (Vector6d() << 0, 0, 0.1, 0, 0, deg2rad(5)).finished(),
                                  Vector6d::Zero()};
  return waypoint_trajectory(w, MotionLimits{0.2, 0.5, 2.5}, 0.3, rig.control_period());
}

TEST(Synthesis, NoiseFreePointsAreTheSimulatedPointInTheTrackerFrame) {
  const Config config = default_config();
  const Trajectory traj = short_trajectory(config.rig);
  SynthesisOptions o;
  o.noise = 0.0;
  o.rate = 250.0;
  SyntheticLog log;
  SimulationIssue issue;
  ASSERT_EQ(synthesize(config.rig, traj, o, log, issue), Status::Ok);
  // Every fourth tick, from the first.
  ASSERT_EQ(log.simulation.size(), traj.poses.size());
  ASSERT_EQ(log.ticks.size(), (traj.poses.size() + 3) / 4);
  const Model& model = config.rig.model();
  double worst = 0.0;
  for (std::size_t k = 0; k < log.ticks.size(); ++k) {
    ASSERT_EQ(log.ticks[k], 4 * k);
    const SimulationSample& s = log.simulation[log.ticks[k]];
    EXPECT_EQ(log.log.stamps[k], s.time);
    EXPECT_EQ(log.log.lines[k], static_cast<int>(k) + 2);
    // Without parameter errors the real platform is the simulated one.
    const Vector3d p_B =
        platform_point_B(model, placement_from_pose(Pose::from_vector(s.actual)), model.spec().observation_P);
    worst = std::max(worst, (apply(log.X_BT, log.log.points_T[k]) - p_B).norm());
    worst = std::max(worst, (log.true_B[k] - p_B).norm());
  }
  report("synthetic point minus simulated point [m]", worst);
  EXPECT_LT(worst, 1e-10);
}

TEST(Synthesis, ParameterErrorsMoveThePointsAsTheRealPlatformDoes) {
  const Config config = default_config();
  const Trajectory traj = short_trajectory(config.rig);
  SynthesisOptions o;
  o.noise = 0.0;
  o.errors.lead_error.setConstant(0.01);
  o.errors.flip_twist_sign = true;
  o.errors.zero_offset << 1e-3, -1e-3, 0.5e-3, 0, 2e-4, -7e-4;
  o.errors.observation_offset_P = Vector3d(0.002, 0, -0.001);
  SyntheticLog log;
  SimulationIssue issue;
  ASSERT_EQ(synthesize(config.rig, traj, o, log, issue), Status::Ok);
  // Independently: the nut's real travel, h + (1 + lead error)(m - h) with the drives' nominal
  // reference h, through a real model whose drives have no scale, FK from home each time.
  const Model real = real_model(config.rig.model(), o.errors);
  ModelSpec unscaled = real.spec();
  for (LegSpec& leg : unscaled.legs) leg.drive_lead = std::numeric_limits<double>::quiet_NaN();
  const Model travel(unscaled);
  const Vector6d h = config.rig.model().home_command();
  double worst = 0.0, moved = 0.0;
  for (std::size_t k = 0; k < log.ticks.size(); k += 10) {
    const SimulationSample& s = log.simulation[log.ticks[k]];
    const Vector6d motor = h + 1.01 * (s.motor - h);
    FkResult fk;
    ASSERT_EQ(forward_kinematics(travel, motor, LengthKind::Motor, Placement{}, fk), Status::Ok);
    worst = std::max(worst, (platform_point_B(real, fk.placement, real.spec().observation_P) - log.true_B[k]).norm());
    const Model& model = config.rig.model();
    moved = std::max(
        moved, (platform_point_B(model, placement_from_pose(Pose::from_vector(s.actual)), model.spec().observation_P) -
                log.true_B[k])
                   .norm());
  }
  report("synthetic real point minus FK from home [m]", worst);
  EXPECT_LT(worst, 1e-10);
  EXPECT_GT(moved, 1e-3);  // the errors move the point by millimetres
}

TEST(Synthesis, NoiseHasTheStandardDeviationAskedFor) {
  const Config config = default_config();
  const Trajectory traj = short_trajectory(config.rig);
  SynthesisOptions o;
  o.noise = 10e-6;
  o.rate = 1000.0;
  SyntheticLog log;
  SimulationIssue issue;
  ASSERT_EQ(synthesize(config.rig, traj, o, log, issue), Status::Ok);
  const RigidTransform X_TB = inverse(log.X_BT);
  Vector3d sum = Vector3d::Zero(), sum2 = Vector3d::Zero();
  const double n = static_cast<double>(log.ticks.size());
  for (std::size_t k = 0; k < log.ticks.size(); ++k) {
    const Vector3d e = log.log.points_T[k] - apply(X_TB, log.true_B[k]);
    sum += e;
    sum2 += e.cwiseAbs2();
  }
  // Per axis: mean within 4 standard errors, standard deviation within 4 of its standard errors.
  for (int a = 0; a < 3; ++a) {
    const double sd = std::sqrt(sum2[a] / n);
    report("noise standard deviation / asked", sd / o.noise);
    EXPECT_LT(std::abs(sum[a] / n), 4.0 * o.noise / std::sqrt(n));
    EXPECT_NEAR(sd / o.noise, 1.0, 4.0 / std::sqrt(2.0 * n));
  }
}

TEST(Synthesis, TheSeedFixesTheLog) {
  const Config config = default_config();
  const Trajectory traj = short_trajectory(config.rig);
  SynthesisOptions o;
  SyntheticLog a, b, c;
  SimulationIssue issue;
  ASSERT_EQ(synthesize(config.rig, traj, o, a, issue), Status::Ok);
  ASSERT_EQ(synthesize(config.rig, traj, o, b, issue), Status::Ok);
  o.seed = 2;
  ASSERT_EQ(synthesize(config.rig, traj, o, c, issue), Status::Ok);
  EXPECT_EQ(a.log.points_T, b.log.points_T);
  EXPECT_NE(a.log.points_T[0], c.log.points_T[0]);
  // Pinned: the generator is mt19937_64's raw output, fixed by the standard.
  EXPECT_EQ(random_tracker_frame(1).t, a.X_BT.t);
}

TEST(Synthesis, TrackerFramesAreRotationsInRange) {
  Eigen::Vector3d mean_axis = Eigen::Vector3d::Zero();
  for (std::uint64_t seed = 1; seed <= 2000; ++seed) {
    const RigidTransform X = random_tracker_frame(seed);
    ASSERT_LT((X.R * X.R.transpose() - Matrix3d::Identity()).cwiseAbs().maxCoeff(), 1e-14);
    ASSERT_NEAR(X.R.determinant(), 1.0, 1e-14);
    const double horizontal = std::hypot(X.t.x(), X.t.y());
    ASSERT_GE(horizontal, 3.0);
    ASSERT_LE(horizontal, 6.0);
    ASSERT_GE(X.t.z(), 0.0);
    ASSERT_LE(X.t.z(), 2.0);
    mean_axis += X.R.col(2);
  }
  // Uniform orientations: the mean of a rotated axis tends to zero (here 1/sqrt(3 * 2000) per component).
  EXPECT_LT((mean_axis / 2000.0).cwiseAbs().maxCoeff(), 4.0 / std::sqrt(3.0 * 2000.0));
}

TEST(Synthesis, RandomOffsetsStayWithinTheirBound) {
  const Vector6d d = random_zero_offsets(1e-3, 5);
  EXPECT_LE(d.cwiseAbs().maxCoeff(), 1e-3);
  EXPECT_GT(d.maxCoeff() - d.minCoeff(), 1e-4);
  EXPECT_EQ(random_zero_offsets(1e-3, 5), d);
  EXPECT_EQ(random_zero_offsets(0.0, 5), Vector6d::Zero());
  EXPECT_THROW((void)random_zero_offsets(-1.0, 5), Error);
}

TEST(Synthesis, BadOptionsThrow) {
  const Config config = default_config();
  const Trajectory traj = short_trajectory(config.rig);
  SyntheticLog log;
  SimulationIssue issue;
  SynthesisOptions o;
  o.rate = 300.0;  // 1000 / 300 is not whole
  EXPECT_THROW((void)synthesize(config.rig, traj, o, log, issue), Error);
  o.rate = 2000.0;  // faster than the control loop
  EXPECT_THROW((void)synthesize(config.rig, traj, o, log, issue), Error);
  // A whole ratio too large for the sample divisor (1e303 periods; it would overflow the
  // conversion, a UBSan error), and the largest one accepted.
  o.rate = 1e-300;
  try {
    (void)synthesize(config.rig, traj, o, log, issue);
    ADD_FAILURE() << "a rate of 1e-300 Hz was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is below the control rate 1000 Hz / 1e9"), std::string::npos) << e.what();
  }
  o.rate = 1e-6;  // one sample in 1e9 control periods: accepted (none falls in the short run)
  EXPECT_EQ(synthesize(config.rig, traj, o, log, issue), Status::Ok);
  o.rate = 100.0;
  o.noise = -1.0;
  EXPECT_THROW((void)synthesize(config.rig, traj, o, log, issue), Error);
}

TEST(Synthesis, EachOptionOutOfItsRangeIsRefusedNamingItsField) {
  // check_synthesis_options (synthesize runs it): the field named, as the CLI maps it to its option.
  const Config config = default_config();  // kept: the model lives in it
  const Model& model = config.rig.model();
  const auto refused = [&](const std::function<void(SynthesisOptions&)>& set) -> std::string {
    SynthesisOptions o;
    set(o);
    try {
      check_synthesis_options(model, o);
    } catch (const ParameterError& e) {
      return e.parameter();
    }
    return "accepted";
  };
  EXPECT_EQ(refused([](SynthesisOptions&) {}), "accepted");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.noise = 2.0; }), "noise");  // above the 1.05 m stroke
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.noise = NAN; }), "noise");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.rate = 0.0; }), "rate");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.lead_error[3] = -1.0; }), "lead_error");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.lead_error[3] = 0.5; }), "accepted");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.zero_offset[5] = 1.1; }), "zero_offset");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.observation_offset_P.z() = INFINITY; }), "observation_offset");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.base_offset_B(2, 1) = 0.06; }), "joint_errors");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.platform_axis_rotation(0, 2) = 0.2; }), "axis_errors");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.stiffness[1] = 1.0; }), "stiffness");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.stiffness[1] = INFINITY; }), "accepted");  // rigid
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.play[0] = 2e-3; }), "play");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.errors.lead_expansion = 1e-3; }), "expansion");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.temperature_rise[4] = 300.0; }), "temperature_rise");
  EXPECT_EQ(refused([](SynthesisOptions& o) { o.extra_targets_P.assign(kMaxTargets, Vector3d::Zero()); }), "targets");
  // The random geometry errors' bounds.
  ParameterErrors e;
  EXPECT_THROW(random_geometry_errors(model, 0.051, 0.0, 1, e), ParameterError);
  EXPECT_THROW(random_geometry_errors(model, 0.0, deg2rad(10.5), 1, e), ParameterError);
  EXPECT_NO_THROW(random_geometry_errors(model, 0.05, deg2rad(10.0), 1, e));
}

}  // namespace
}  // namespace hexatwist
