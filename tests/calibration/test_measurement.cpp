// SPDX-License-Identifier: BSD-3-Clause
// Measured points (measurement.hpp): the point-log reader and its one-line errors, the calibration
// moves, and the whole pipeline on synthetic logs whose truth is known: registration recovers the
// tracker frame, a noise-free log of the model reproduces the simulation, a lead error shows up
// with its sign and size.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <initializer_list>
#include <string>
#include <string_view>

#include "hexatwist/hexatwist.hpp"
#include "support.hpp"

namespace hexatwist {
namespace {

using test::report;

// ---- the point log ------------------------------------------------------------------------------

PointLogFormat format_mm() {
  PointLogFormat f;
  f.length_unit = 1e-3;
  return f;
}

TEST(Measurement, SpatialAnalyzerLikeLogWithUnitsGivenIsConvertedToSi) {
  PointLogFormat f = format_mm();
  f.time_column = "time";
  const std::string text =
      "\xEF\xBB\xBF# exported\r\n"
      "Time,X,Y,Z\r\n"
      "0.000, 1000.5, -2.25, 3\r\n"
      "\r\n"
      "0.010, 1000.5, -2.25, +3.5\r\n"
      "0.020,0,0,0";
  const PointLog log = parse_point_log(text, "sa.csv", f);
  ASSERT_EQ(log.stamps.size(), 3u);
  EXPECT_EQ(log.lines, (std::vector<int>{3, 5, 6}));
  EXPECT_EQ(log.stamps, (std::vector<double>{0.0, 0.010, 0.020}));
  EXPECT_LT((log.points_T[0] - Vector3d(1.0005, -0.00225, 0.003)).cwiseAbs().maxCoeff(), 1e-15);  // 1 ulp
  EXPECT_DOUBLE_EQ(log.points_T[1].z(), 0.0035);
  EXPECT_EQ(log.stamp_columns, (std::vector<int>{1, 1, 1}));
  EXPECT_FALSE(log.indexed);
}

TEST(Measurement, IndexedLogWithSuffixesAndOtherColumns) {
  PointLogFormat f;  // no unit given: the suffixes say mm
  f.time_column = "index";
  f.indexed = true;
  const std::string text = "name,index,x_mm,y_mm,z_mm,rms_mm\nA,10,1,2,3,0.01\nA,11,4,5,6,0.01\nA,13,7,8,9,0.01\n";
  const PointLog log = parse_point_log(text, "ix.csv", f);
  EXPECT_EQ(log.stamps, (std::vector<double>{10, 11, 13}));
  EXPECT_LT((log.points_T[2] - Vector3d(0.007, 0.008, 0.009)).cwiseAbs().maxCoeff(), 1e-17);
  EXPECT_EQ(log.stamp_columns[0], 3);
  EXPECT_TRUE(log.indexed);
  // index / rate - offset
  const std::vector<double> t = trajectory_times(log, TimeAlignment{0.05, 100.0});
  EXPECT_DOUBLE_EQ(t[0], 0.05);
  EXPECT_DOUBLE_EQ(t[2], 0.08);
  EXPECT_THROW((void)trajectory_times(log, TimeAlignment{0.0, 0.0}), Error);
  // Metres and milliseconds by suffix; case ignored.
  const PointLog m = parse_point_log("T_MS,x_m,Y_M,z_m\n0,1,2,3\n5,1,2,3\n10,1,2,3\n", "m.csv", PointLogFormat{});
  EXPECT_EQ(m.stamps[2], 0.010);
  EXPECT_EQ(m.points_T[0], Vector3d(1, 2, 3));
}

// parse_point_log must throw one line starting "bad.csv:<line>:<column>: column '<name>':" and
// containing every one of `parts`.
void expect_log_error(const std::string& text, const PointLogFormat& format, int line, int column,
                      std::string_view name, std::initializer_list<std::string_view> parts = {}) {
  SCOPED_TRACE(text);
  test::expect_error_line(
      [&] { (void)parse_point_log(text, "bad.csv", format); },
      "bad.csv:" + std::to_string(line) + ":" + std::to_string(column) + ": column '" + std::string(name) + "':",
      parts);
}

TEST(Measurement, BadLogsNameLineColumnAndColumn) {
  const PointLogFormat mm = format_mm();
  const std::string head = "t,x,y,z\n0,1,2,3\n0.01,1,2,3\n";
  // Wrong number of cells, either way.
  expect_log_error(head + "0.02,1,2\n", mm, 4, 9, "z", {"missing", "3 cells", "header on line 1 has 4"});
  expect_log_error(head + "0.02,1,2,3,4\n", mm, 4, 12, "z", {"extra cell '4'", "5 cells"});
  // Units: none given, or contradictory.
  expect_log_error(head + "0.02,1,2,3\n", PointLogFormat{}, 1, 3, "x", {"units missing", "'x'", "_mm or _m"});
  expect_log_error("t,x_mm,y_mm,z_m\n0,1,2,3\n", mm, 1, 13, "z", {"'z_m' is in m", "given as mm"});
  // Cells.
  expect_log_error(head + "0.02,1,abc,3\n", mm, 4, 8, "y", {"expected a number, got 'abc'"});
  expect_log_error(head + "0.02,1,2,inf\n", mm, 4, 10, "z", {"finite", "'inf'"});
  expect_log_error(head + "0.02, ,2,3\n", mm, 4, 6, "x", {"empty cell"});
  // Time stamps out of order (and an index that is not whole).
  expect_log_error(head + "0.005,1,2,3\n", mm, 4, 1, "t", {"time 0.005 s is not after 0.01 s on line 3", "increasing"});
  expect_log_error(head + "0.01,1,2,3\n", mm, 4, 1, "t", {"not after 0.01 s"});
  PointLogFormat ix = mm;
  ix.indexed = true;
  expect_log_error("t,x,y,z\n1,0,0,0\n2.5,0,0,0\n", ix, 3, 1, "t", {"whole sample index", "'2.5'"});
  expect_log_error("t,x,y,z\n1,0,0,0\n1,0,0,0\n", ix, 3, 1, "t", {"index 1 is not after 1 on line 2"});
  // Header.
  expect_log_error("time,x,y,z\n0,0,0,0\n", mm, 1, 1, "t", {"not in the header", "'time', 'x'", "'t' or 't_s'"});
  expect_log_error("t,x,y,x_mm,z\n", mm, 1, 7, "x", {"named twice", "'x' and 'x_mm'"});
  // Too few points for a registration; empty text.
  expect_log_error("t,x,y,z\n0,0,0,0\n1,0,0,0\n", mm, 3, 1, "t", {"2 points", "at least 3"});
  expect_log_error("", mm, 1, 1, "t", {"empty text"});
  expect_log_error("# nothing\n", mm, 1, 1, "t", {"no header row"});
}

// ---- calibration moves --------------------------------------------------------------------------

TEST(Measurement, CalibrationMovesVisitEachStationThenTheTestFollows) {
  const Config config = default_config();
  const StudyTest rz = seed_tests(config.study)[2];
  const double dt = config.rig.control_period();
  const CalibrationSpec cal;
  double end = 0.0;
  const Trajectory traj = measured_test_trajectory(config.study, rz, cal, dt, end);
  const Trajectory test = test_trajectory(config.study, rz, dt);
  const auto end_tick = static_cast<std::size_t>(std::llround(end / dt));
  ASSERT_EQ(traj.poses.size(), end_tick + test.poses.size());
  // The test, shifted: the same poses, bit for bit.
  for (std::size_t k = 0; k < test.poses.size(); ++k)
    ASSERT_EQ(traj.poses[end_tick + k].to_vector(), test.poses[k].to_vector()) << k;
  // Each station (home, +x, +y, +z, home) is held for `dwell`: count the ticks at each.
  std::array<int, 5> held{};
  for (std::size_t k = 0; k <= end_tick; ++k) {
    const Vector3d p = traj.poses[k].position;
    EXPECT_EQ(traj.poses[k].rpy, Vector3d::Zero());
    if (p.isZero(0.0)) ++held[k < end_tick / 2 ? 0 : 4];
    for (int a = 0; a < 3; ++a) {
      Vector3d s = Vector3d::Zero();
      s[a] = cal.step;
      if ((p - s).cwiseAbs().maxCoeff() < 1e-15) ++held[static_cast<std::size_t>(a) + 1];
    }
  }
  for (const int h : held) EXPECT_GE(h, static_cast<int>(std::floor(cal.dwell / dt)));
}

// ---- the pipeline on synthetic logs -------------------------------------------------------------

// A short measured test: the calibration moves, then a sweep of `test` with a small amplitude.
// The pipeline's exactness is checked on a servo that settles to nanometres at the stations: the
// seed with ideal screws. The default screws' efficiency losses, a load-dependent friction, leave
// the servo a micrometre off at a station after its 0.25 s settle (theory §9), which the noise-free
// checks below would read as a registration error.
Config ideal_screws() {
  ConfigSpec spec = parse_config_spec(seed_config_yaml(), "seed.yaml");
  spec.rig.mechanism.efficiency = spec.rig.mechanism.back_efficiency = 1.0;
  return Config{Rig(spec.rig), spec.study, spec.defaulted};
}

struct ShortRun {
  Config config = ideal_screws();
  Trajectory trajectory;
  double calibration_end = 0.0;
  ShortRun(int test, double amplitude) {
    StudySpec spec = config.study;
    spec.linear_amplitude = amplitude;
    spec.angular_amplitude = amplitude;
    const StudyTest t = seed_tests(spec)[static_cast<std::size_t>(test)];
    trajectory = measured_test_trajectory(spec, t, CalibrationSpec{}, config.rig.control_period(), calibration_end);
  }
  const Rig& rig() const { return config.rig; }
};

SyntheticLog synth(const ShortRun& run, const SynthesisOptions& o) {
  SyntheticLog log;
  SimulationIssue issue;
  EXPECT_EQ(synthesize(run.rig(), run.trajectory, o, log, issue), Status::Ok) << describe(issue.status);
  return log;
}

Measurement measure(const ShortRun& run, const PointLog& log, Strategy strategy, double settle = 0.25) {
  MeasurementOptions mo;
  mo.strategy = strategy;
  mo.window.until = run.calibration_end;
  mo.window.settle = settle;
  return measure_points(run.rig().model(), timed_poses(run.trajectory), log, mo);
}

double angle(const Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

// One parameter per strategy.
class Pipeline : public ::testing::TestWithParam<Strategy> {};

TEST_P(Pipeline, NoiseFreeModelLogRecoversTheFrameAndReproducesTheSimulation) {
  const Strategy strategy = GetParam();
  const ShortRun run(2, deg2rad(10.0));  // Rz, +-10 deg
  SynthesisOptions o;
  o.strategy = strategy;
  o.noise = 0.0;
  o.rate = 1000.0;  // every tick: the statistics are over the same instants as the simulation's
  o.seed = 7;
  const SyntheticLog log = synth(run, o);
  const Measurement m = measure(run, log.log, strategy);
  // The tracker frame, to the issue's 1 um / 1 urad. Measured 2e-8 rad, and 8e-8 m at the
  // tracker's origin 3-6 m away (the rotation's lever): the servo has settled at the stations to
  // a few nanometres, the rest is exact.
  const RigidTransform& X = m.registration.X_BT;
  const double rot = angle(X.R * log.X_BT.R.transpose());
  const double pos = (X.t - log.X_BT.t).norm();
  report("frame rotation error [rad]", rot);
  report("frame origin error [m]", pos);
  EXPECT_LT(rot, 2e-7);
  EXPECT_LT(pos, 1e-6);
  EXPECT_LT(m.registration.rms_residual, 1e-7);
  EXPECT_GT(m.registration.count, 300);
  // The same physics: the measured error is the simulation's, tick by tick after the window.
  const std::vector<double> sim = simulated_errors(log.simulation, m);
  ASSERT_EQ(sim.size(), m.points.size() - m.window);
  double worst = 0.0;
  for (std::size_t k = m.window; k < m.points.size(); ++k) {
    ASSERT_EQ(m.points[k].time, log.simulation[log.ticks[k]].time);
    worst = std::max(worst, std::abs(m.points[k].error_B.norm() - sim[k - m.window]));
  }
  report("measured minus simulated error, worst point [m]", worst);
  EXPECT_LT(worst, 1e-7);
  const ErrorStats s = error_stats(sim);
  EXPECT_NEAR(m.error.max, s.max, 1e-7);
  EXPECT_NEAR(m.error.rms, s.rms, 1e-7);
  // And as `measure` reports it: the simulated run after the window has the same statistics.
  TestRun tr;
  SimulationIssue issue;
  ASSERT_EQ(run_test(run.rig(), run.trajectory, tr, issue), Status::Ok);
  keep_after(tr, m.window_end);
  const StrategyRun& same = strategy == Strategy::Compensated ? tr.compensated : tr.conventional;
  EXPECT_NEAR(m.error.max, same.total.max, 1e-7);
  EXPECT_NEAR(m.error.rms, same.total.rms, 1e-7);
  // Conventional carries the twist error; compensated only the servo's.
  if (strategy == Strategy::Conventional)
    EXPECT_GT(m.error.max, 1e-4);
  else
    EXPECT_LT(m.error.max, 3e-5);
}

INSTANTIATE_TEST_SUITE_P(Strategies, Pipeline, ::testing::Values(Strategy::Conventional, Strategy::Compensated));

TEST(Measurement, WithTrackerNoiseTheResidualMatchesIt) {
  const ShortRun run(2, deg2rad(10.0));
  SynthesisOptions o;
  o.noise = 10e-6;
  o.seed = 11;
  const SyntheticLog log = synth(run, o);
  const Measurement m = measure(run, log.log, Strategy::Compensated);
  const Registration& r = m.registration;
  const double n = r.count;
  // theory §11: E[rms^2] = sigma^2 (3N - 6) / N; sigma estimates the noise per axis. With N ~ 400,
  // its relative standard deviation is 1/sqrt(2(3N - 6)) ~ 2 %: allowed 8 %.
  report("noise estimate / noise", r.sigma / o.noise);
  EXPECT_NEAR(r.sigma / o.noise, 1.0, 0.08);
  EXPECT_NEAR(r.rms_residual / (o.noise * std::sqrt((3 * n - 6) / n)), 1.0, 0.08);
  // The frame to about sigma / sqrt(N) over the stations' spread: a micrometre, a few microradians.
  const double rot = angle(r.X_BT.R * log.X_BT.R.transpose());
  const double pos = (apply(r.X_BT, log.log.points_T[0]) - apply(log.X_BT, log.log.points_T[0])).norm();
  report("frame rotation error [rad]", rot);
  report("registered home point error [m]", pos);
  EXPECT_LT(rot, 2e-5);
  EXPECT_LT(pos, 5e-6);
  // The registration's pairs map back to their points: the worst residual is that point's.
  ASSERT_EQ(m.registered.size(), static_cast<std::size_t>(r.count));
  const MeasuredPoint& worst = m.points[m.registered[static_cast<std::size_t>(r.max_residual_index)]];
  EXPECT_TRUE(worst.registered);
  EXPECT_NEAR((apply(r.X_BT, worst.p_T) - worst.model_B).norm(), r.max_residual, 1e-15);
  // The measured error is the noise on top of the servo's own: |noise| has rms sigma sqrt(3).
  EXPECT_NEAR(m.error.rms, std::sqrt(3.0) * o.noise, 0.2 * o.noise);
}

TEST(Measurement, LeadErrorRaisesTheErrorWithItsSignAndSize) {
  // Lz +-0.2 m: a longer real lead moves the nut further than commanded, so every leg and the
  // platform overshoot: above home the point is too high, below home too low, by about the lead
  // error times the displacement (the legs' stroke is about the heave here).
  const ShortRun run(0, 0.2);
  std::array<double, 2> top{}, bottom{}, worst{};
  for (const int i : {0, 1}) {
    SynthesisOptions o;
    o.noise = 0.0;
    o.errors.lead_error.setConstant(i == 0 ? 0.005 : 0.01);
    const SyntheticLog log = synth(run, o);
    const Measurement m = measure(run, log.log, Strategy::Compensated);
    for (std::size_t k = m.window; k < m.points.size(); ++k) {
      const MeasuredPoint& p = m.points[k];
      if (p.desired[2] > 0.199) top[static_cast<std::size_t>(i)] = p.error_B.z();
      if (p.desired[2] < -0.199) bottom[static_cast<std::size_t>(i)] = p.error_B.z();
    }
    worst[static_cast<std::size_t>(i)] = m.error.max;
  }
  report("z error at +0.2 m with 0.5 % lead error [m]", top[0]);
  report("z error at -0.2 m with 0.5 % lead error [m]", bottom[0]);
  report("max error ratio, 1 % over 0.5 %", worst[1] / worst[0]);
  for (const int i : {0, 1}) {
    const double eps = i == 0 ? 0.005 : 0.01;
    EXPECT_GT(top[static_cast<std::size_t>(i)], 0.3 * eps * 0.2) << eps;
    EXPECT_LT(top[static_cast<std::size_t>(i)], 3.0 * eps * 0.2) << eps;
    EXPECT_LT(bottom[static_cast<std::size_t>(i)], -0.3 * eps * 0.2) << eps;
    EXPECT_GT(bottom[static_cast<std::size_t>(i)], -3.0 * eps * 0.2) << eps;
  }
  // First order in the error: twice the error, twice the effect.
  EXPECT_NEAR(worst[1] / worst[0], 2.0, 0.1);
  EXPECT_NEAR(top[1] / top[0], 2.0, 0.1);
}

// measure_points must throw one line naming the log and containing every one of `parts`.
void expect_measure_error(const ShortRun& run, const PointLog& log, const MeasurementOptions& mo,
                          std::initializer_list<std::string_view> parts) {
  test::expect_error_line([&] { (void)measure_points(run.rig().model(), timed_poses(run.trajectory), log, mo); },
                          "synthetic log:", parts);
}

TEST(Measurement, BadLogsForTheRunAreOneLineErrors) {
  const ShortRun run(2, deg2rad(5.0));
  SynthesisOptions o;
  o.seed = 3;
  const SyntheticLog log = synth(run, o);
  MeasurementOptions mo;
  mo.window.until = run.calibration_end;
  // A point outside the trajectory's time span: a clock offset the wrong way.
  mo.time.offset = -0.5;
  const std::size_t last = log.log.points_T.size() - 1;
  expect_measure_error(
      run, log.log, mo,
      {":" + std::to_string(log.log.lines[last - 49]) + ":1: point at t = ", "outside", "time offset"});
  mo.time.offset = 0.0;
  // A window without three points at rest: the first two points only.
  mo.window.first = 2;
  expect_measure_error(run, log.log, mo, {"lines 2-3", "only 2 of the 2 points", "at least 3"});
  // Collinear: the points at rest of the first station and the move to +x lie on a line.
  mo.window.first = 0;
  mo.window.until = 1.5;
  mo.window.settle = 0.0;
  expect_measure_error(run, log.log, mo, {"on a line", "condition"});
  // Coincident: home only.
  mo.window.until = 0.9;
  expect_measure_error(run, log.log, mo, {"all at one place"});
  // Nothing left to evaluate.
  mo.window.until = 1e3;
  expect_measure_error(run, log.log, mo, {"no point is left"});
}

// Errors blamed on an option carry its name, for the CLI's --option and Python's keyword.
TEST(Measurement, OptionErrorsNameTheirParameter) {
  const ShortRun run(2, deg2rad(5.0));
  const SyntheticLog log = synth(run, SynthesisOptions{});
  const auto parameter_of = [&](const MeasurementOptions& mo) {
    try {
      (void)measure_points(run.rig().model(), timed_poses(run.trajectory), log.log, mo);
    } catch (const ParameterError& e) {
      return e.parameter();
    } catch (const Error&) {
      return std::string("(not a ParameterError)");
    }
    return std::string("(no error)");
  };
  MeasurementOptions mo;
  mo.window.until = run.calibration_end;
  EXPECT_EQ(parameter_of(mo), "(no error)");
  mo.time.offset = -0.5;
  EXPECT_EQ(parameter_of(mo), "time_offset");
  mo.time.offset = 0.0;
  mo.window.settle = -1.0;
  EXPECT_EQ(parameter_of(mo), "settle");
  mo.window.settle = 0.25;
  mo.window.until = -1.0;
  EXPECT_EQ(parameter_of(mo), "register_until");
  mo.window.until = 1e3;
  EXPECT_EQ(parameter_of(mo), "register_until");
  mo.window.first = 2;
  EXPECT_EQ(parameter_of(mo), "register_first");
}

// A point no point of the platform can be (1e6 or 1e300 typed for a coordinate), anywhere in the
// log, at rest or not: measure and the observations of an identification name its line.
TEST(Measurement, APointOutOfThePlatformsReachIsRefusedNamingItsLine) {
  const ShortRun run(2, deg2rad(5.0));
  SynthesisOptions o;
  o.seed = 5;
  const SyntheticLog good = synth(run, o);
  MeasurementOptions mo;
  mo.window.until = run.calibration_end;
  for (const double wild : {1e6, 1e300}) {
    PointLog bad = good.log;
    bad.points_T[7].x() = wild;
    const std::string line = "synthetic log:" + std::to_string(bad.lines[7]);
    expect_measure_error(run, bad, mo, {line, "not a point of this run"});
    test::expect_error_line(
        [&] {
          (void)observations_at_rest(run.rig().model(), timed_poses(run.trajectory), bad, {}, Strategy::Compensated,
                                     0.25);
        },
        line, {"farther than", "not a point of this run"});
  }
}

// A log that is not of this run is refused, not evaluated: its registration misfit or its errors
// say so, whatever the tracker frame.
TEST(Measurement, LogsOfAnotherShapeOrMotionAreRefused) {
  const ShortRun run(2, deg2rad(5.0));
  SynthesisOptions o;
  o.seed = 4;
  const SyntheticLog good = synth(run, o);
  MeasurementOptions mo;
  mo.window.until = run.calibration_end;
  const Measurement m = measure_points(run.rig().model(), timed_poses(run.trajectory), good.log, mo);
  EXPECT_LT(m.registration.rms_residual, 1e-3);

  // Metres labelled millimetres: every coordinate 1000 times too small.
  PointLog metres = good.log;
  for (Vector3d& p : metres.points_T) p *= 1e-3;
  expect_measure_error(run, metres, mo, {"do not have the run's shape", "metres labelled _mm"});

  // Another motion after the window: half a metre of sway the run does not command.
  PointLog other = good.log;
  for (std::size_t k = m.window; k < other.points_T.size(); ++k)
    other.points_T[k].x() += 0.5 * std::sin(0.01 * static_cast<double>(k));
  expect_measure_error(run, other, mo, {"misses the run by", "another motion"});

  // One point 5 m off: within the platform's reach of the others, but farther from where the run
  // puts it than a leg is long.
  PointLog typo = good.log;
  typo.points_T.back().y() += 5.0;
  expect_measure_error(run, typo, mo, {":" + std::to_string(typo.lines.back()) + ": the point is", "maximum length"});
}

// A header whose names carry their units is found by those same names (--columns t_s,x_mm,...).
TEST(Measurement, ColumnsNamedWithTheirSuffixesAreFound) {
  PointLogFormat f;
  f.time_column = "t_s";
  f.x_column = "x_mm";
  f.y_column = "y_mm";
  f.z_column = "z_mm";
  const PointLog log = parse_point_log("t_s,x_mm,y_mm,z_mm\n0,1,2,3\n0.5,4,5,6\n1,7,8,9\n", "l.csv", f);
  ASSERT_EQ(log.points_T.size(), 3u);
  EXPECT_EQ(log.stamps[1], 0.5);
  EXPECT_LT((log.points_T[2] - Vector3d(0.007, 0.008, 0.009)).norm(), 1e-17);  // 1 ulp per coordinate
}

TEST(Measurement, SimulatedErrorsAreInterpolatedBetweenTicks) {
  std::vector<SimulationSample> s(3);
  for (int k = 0; k < 3; ++k) {
    s[static_cast<std::size_t>(k)].time = 0.001 * k;
    s[static_cast<std::size_t>(k)].error = 1e-6 * (k == 1 ? 4 : 2);
  }
  Measurement m;
  m.window = 1;
  m.points.resize(5);
  const double times[5] = {0.0, 0.0, 0.00025, 0.002, 0.003};
  for (int k = 0; k < 5; ++k) m.points[static_cast<std::size_t>(k)].time = times[k];
  const std::vector<double> e = simulated_errors(s, m);
  ASSERT_EQ(e.size(), 4u);
  EXPECT_EQ(e[0], 2e-6);
  EXPECT_DOUBLE_EQ(e[1], 2.5e-6);
  EXPECT_EQ(e[2], 2e-6);
  EXPECT_TRUE(std::isnan(e[3]));
}

// ---- stations and observations for identification ----------------------------------------------

TEST(Measurement, StationsAreReachableHeldAndReproducible) {
  const Config config = default_config();
  const Model& model = config.rig.model();
  const double dt = config.rig.control_period();
  StationsSpec spec;
  spec.count = 12;
  spec.seed = 5;
  const Trajectory traj = stations_trajectory(model, Strategy::Compensated, spec, dt);
  EXPECT_EQ(traj.poses.front().to_vector(), Vector6d::Zero());
  EXPECT_EQ(traj.poses.back().to_vector(), Vector6d::Zero());
  // Every tick inside every limit, and the runs of ticks at one pose: home, the stations, home.
  std::vector<Vector6d> held;
  int run_length = 0;
  Vector6d command;
  LimitReport limit;
  for (std::size_t k = 0; k < traj.poses.size(); ++k) {
    const Vector6d q = traj.poses[k].to_vector();
    ASSERT_EQ(motor_commands(model, traj.poses[k], Strategy::Compensated, command, limit), Status::Ok) << k;
    run_length = (k > 0 && q == traj.poses[k - 1].to_vector()) ? run_length + 1 : 1;
    if (run_length == static_cast<int>(std::floor(spec.dwell / dt))) held.push_back(q);
  }
  ASSERT_EQ(held.size(), static_cast<std::size_t>(spec.count + 2));
  for (int i = 1; i <= spec.count; ++i) {
    const Vector6d& q = held[static_cast<std::size_t>(i)];
    EXPECT_LE(q.head<3>().cwiseAbs().maxCoeff(), spec.translation);
    EXPECT_LE(q.tail<3>().cwiseAbs().maxCoeff(), spec.rotation);
    EXPECT_GT(q.head<3>().norm(), 0.0);  // every coordinate at once
  }
  // The same seed gives the same run; another seed another one.
  EXPECT_EQ(stations_trajectory(model, Strategy::Compensated, spec, dt).poses.back().to_vector(), Vector6d::Zero());
  EXPECT_EQ(stations_trajectory(model, Strategy::Compensated, spec, dt).poses[traj.poses.size() / 2].to_vector(),
            traj.poses[traj.poses.size() / 2].to_vector());
  spec.seed = 6;
  const Trajectory other = stations_trajectory(model, Strategy::Compensated, spec, dt);
  EXPECT_NE(other.poses[other.poses.size() / 2].to_vector(), traj.poses[traj.poses.size() / 2].to_vector());
}

TEST(Measurement, StationsRefuseBadSpecsInOneLine) {
  const Model model = test::seed_model();
  StationsSpec spec;
  spec.count = 0;
  test::expect_error_line([&] { (void)stations_trajectory(model, Strategy::Compensated, spec, 1e-3); },
                          "stations:", {"1 to 10000", "got 0"});
  spec.count = 3;
  spec.translation = std::nan("");
  test::expect_error_line([&] { (void)stations_trajectory(model, Strategy::Compensated, spec, 1e-3); },
                          "stations:", {"0 to 10 m", "got nan"});
  // Beyond the widest range (check_stations_spec), as large as 1e300 (a count of points along the
  // lines that would overflow an int): refused by the range's check, before a draw.
  for (const double t : {10.5, 1e300}) {
    spec.translation = t;
    test::expect_error_line([&] { (void)stations_trajectory(model, Strategy::Compensated, spec, 1e-3); },
                            "stations:", {"translation range of 0 to 10 m"});
  }
  spec.translation = 0.0;
  spec.rotation = 1e300;
  test::expect_error_line([&] { (void)stations_trajectory(model, Strategy::Compensated, spec, 1e-3); },
                          "stations:", {"rotation range of 0 to 90 deg"});
  // Inside the ranges but far outside the workspace: within +-9 m, a draw inside the seed's
  // +-0.5 m has odds of 1e-4.
  spec.translation = 9.0;
  spec.rotation = 0.0;
  test::expect_error_line([&] { (void)stations_trajectory(model, Strategy::Compensated, spec, 1e-3); },
                          "station 1:", {"1000 tries", "smaller ranges"});
}

// A stations run of the real platform (lead 5 % long, the other thread hand, offsets within
// +-1 mm, the observation point 1-3 mm off) seen by a noisy tracker: its points at rest, with
// the commands the drives got, identify every parameter within the issue's bounds.
TEST(Measurement, PointsAtRestOfAStationsRunIdentifyTheRealPlatform) {
  const Config config = default_config();
  const Rig& rig = config.rig;
  StationsSpec spec;
  spec.count = 40;
  const Trajectory traj = stations_trajectory(rig.model(), Strategy::Compensated, spec, rig.control_period());
  SynthesisOptions o;
  o.errors.lead_error.setConstant(0.05);
  o.errors.flip_twist_sign = true;
  o.errors.zero_offset = random_zero_offsets(1e-3, 11);
  o.errors.observation_offset_P = Vector3d(2e-3, -1.5e-3, 3e-3);
  o.seed = 11;
  SyntheticLog log;
  SimulationIssue issue;
  ASSERT_EQ(synthesize(rig, traj, o, log, issue), Status::Ok) << describe(issue.status);

  const ObservationSet set =
      observations_at_rest(rig.model(), timed_poses(traj), log.log, {}, Strategy::Compensated, 0.25);
  // At rest: 0.75 s of each 1 s rest at 100 Hz (76 points) at 42 poses, home twice.
  EXPECT_GT(set.observations.size(), 40u * 70u);
  EXPECT_LT(set.observations.size(), 42u * 80u);
  for (std::size_t i = 0; i < set.points.size(); i += 97) {
    // The command of the commanded pose, which at rest is the pose of the tick.
    const std::size_t tick = log.ticks[set.points[i]];
    Vector6d command;
    LimitReport limit;
    ASSERT_EQ(motor_commands(rig.model(), traj.poses[tick], Strategy::Compensated, command, limit), Status::Ok);
    EXPECT_LT((set.observations[i].motor - command).cwiseAbs().maxCoeff(), 1e-12) << i;
    EXPECT_EQ(set.observations[i].p_T, log.log.points_T[set.points[i]]);
  }
  // The basic model (the joints are right here); the synth's drives turn the screws by the nominal
  // lead's angles (the travel effect, the default).
  IdentificationOptions io;
  io.model = CalibrationModel::Basic;
  Identification id;
  ASSERT_EQ(identify(rig.model(), set.observations, id, io), Status::Ok) << id.reason;
  const double lead = rig.model().leg(0).lead * 1.05;
  const ModelSpec& c = id.corrected;
  // Measured: lead 1.2e-6 relative (sd 0.9e-6), offsets within 4.3 um (sd 4.3-7.2 um), the point
  // within 1.4 um (sd 1.4 um). The issue's bounds: 0.5 %, 20 um.
  EXPECT_LT(std::abs(c.legs[0].lead / lead - 1.0), 1e-5);
  EXPECT_EQ(id.twist_sign, -1.0);
  EXPECT_NE(c.legs[0].thread, rig.model().leg(0).thread);
  Vector6d offsets;
  for (int i = 0; i < kLegs; ++i) offsets[i] = c.legs[static_cast<std::size_t>(i)].length_offset;
  EXPECT_LT((offsets - o.errors.zero_offset).cwiseAbs().maxCoeff(), 20e-6);
  const Vector3d point = rig.model().spec().observation_P + o.errors.observation_offset_P;
  EXPECT_LT((c.observation_P - point).cwiseAbs().maxCoeff(), 10e-6);
  // Each error within 4 of its standard deviations, and the noise recovered.
  const ParameterSet& ps = id.parameters;
  Eigen::VectorXd truth_error = Eigen::VectorXd::Zero(ps.rotation_index());
  truth_error[0] = c.legs[0].lead - lead;
  truth_error.segment<kLegs>(ps.offset_index()) = offsets - o.errors.zero_offset;
  truth_error.segment<3>(ps.target_index()) = c.observation_P - point;
  for (int p = 0; p < ps.rotation_index(); ++p) {
    EXPECT_LT(std::abs(truth_error[p]), 4.0 * id.sd[p]) << ps.name(p);
    std::printf("  %-10s error %+.3g, sd %.3g\n", ps.name(p).c_str(), truth_error[p], id.sd[p]);
  }
  EXPECT_NEAR(id.sigma, o.noise, 0.05 * o.noise);
}

TEST(Measurement, TooFewPointsAtRestForAnIdentificationIsOneLine) {
  const ShortRun run(2, deg2rad(5.0));
  SynthesisOptions o;
  o.seed = 3;
  const SyntheticLog log = synth(run, o);
  PointLog few = log.log;
  few.stamps.resize(5);
  few.points_T.resize(5);
  few.lines.resize(5);
  few.stamp_columns.resize(5);
  test::expect_error_line(
      [&] {
        (void)observations_at_rest(run.rig().model(), timed_poses(run.trajectory), few, {}, Strategy::Compensated, 0.0);
      },
      "synthetic log: only 5 of the 5 points are usable", {"at least 6"});
  test::expect_error_line(
      [&] {
        (void)observations_at_rest(run.rig().model(), timed_poses(run.trajectory), log.log, {}, Strategy::Compensated,
                                   -1.0);
      },
      "synthetic log: settle time:");
}

}  // namespace
}  // namespace hexatwist
