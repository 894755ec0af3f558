// SPDX-License-Identifier: BSD-3-Clause
// Trajectories: the jerk-limited move keeps its limits, starts and ends at rest, is time-optimal
// and self-consistent (finite differences); the sweep test motion; CSV poses with units and
// located errors; Hermite resampling exact on lines, parabolas and the input samples.
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <limits>
#include <string>
#include <string_view>

#include "support.hpp"

namespace hexatwist::test {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();

double log_uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::exp(uniform(rng, std::log(lo), std::log(hi)));
}

std::string str(const MotionLimits& l, double distance) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "distance %.17g, limits v %.17g a %.17g j %.17g", distance, l.velocity, l.acceleration,
                l.jerk);
  return buf;
}

// ---- jerk-limited move ----------------------------------------------------------------------

// Which limits a move reaches, from its segment times.
enum class Reached { Neither, AccelerationOnly, VelocityOnly, Both };

Reached reached(const JerkLimitedMove& m) {
  const std::array<double, 8> s = m.switch_times();
  const bool a = s[2] > s[1], v = s[4] > s[3];
  return a ? (v ? Reached::Both : Reached::AccelerationOnly) : (v ? Reached::VelocityOnly : Reached::Neither);
}

// A random move of the wanted kind: log-uniform limits, and a distance on the side of the case
// boundaries (2 A^3 / J^2 for the acceleration, D(V) for the velocity) that the kind needs.
struct Case {
  double distance;
  MotionLimits limits;
};
Case random_case(std::mt19937_64& rng, Reached kind) {
  for (;;) {
    MotionLimits l{log_uniform(rng, 1e-2, 1e2), log_uniform(rng, 1e-2, 1e2), log_uniform(rng, 1e-2, 1e3)};
    const double V = l.velocity, A = l.acceleration, J = l.jerk;
    const bool a_at_full_speed = V * J > A * A;  // reaching V takes the acceleration to A
    const double d_a = 2.0 * A * A * A / (J * J);
    const double d_v = a_at_full_speed ? V * (V / A + A / J) : 2.0 * V * std::sqrt(V / J);
    double lo = 0.0, hi = 0.0;
    switch (kind) {
      case Reached::Neither:  // including tiny distances
        hi = std::min(d_a, d_v), lo = hi * 1e-12;
        break;
      case Reached::AccelerationOnly:
        if (!a_at_full_speed || d_v < d_a * 1.001) continue;
        lo = d_a, hi = d_v;
        break;
      case Reached::VelocityOnly:
        if (a_at_full_speed) continue;
        lo = d_v, hi = d_v * 1e3;
        break;
      case Reached::Both:
        if (!a_at_full_speed || V * J < A * A * 1.001) continue;
        lo = d_v, hi = d_v * 1e3;
        break;
    }
    const double d = log_uniform(rng, lo * 1.0000001, hi * 0.9999999);
    return {uniform(rng, 0, 1) < 0.5 ? -d : d, l};
  }
}

// Dense sample times of a move: every switching instant, just before and after it, and a grid.
std::vector<double> dense_times(const JerkLimitedMove& m, int grid) {
  std::vector<double> ts;
  for (const double s : m.switch_times())
    for (const double f : {-1e-9, 0.0, 1e-9}) ts.push_back(s + f * m.duration());
  for (int k = 0; k <= grid; ++k) ts.push_back(m.duration() * k / grid);
  return ts;
}

TEST(Trajectory, MoveCasesAreClassifiedAsTheLimitsPredict) {
  // random_case draws each kind from the closed-form case boundaries; the move must agree.
  std::mt19937_64 rng(kSeed + 200);
  for (int n = 0; n < stress(2000); ++n) {
    const auto kind = static_cast<Reached>(n % 4);
    const Case c = random_case(rng, kind);
    const JerkLimitedMove m(c.distance, c.limits);
    EXPECT_EQ(reached(m), kind) << str(c.limits, c.distance);
  }
}

TEST(Trajectory, MoveNeverExceedsItsLimits) {
  // Segment values (at and around every switch) and a dense grid. The peaks equal the limit up to
  // rounding when it is reached: measured relative excess 4.4e-16 (velocity), 2.2e-16
  // (acceleration), 0 (jerk: exactly +-J); allowed 5e-15, 5e-15 and 0.
  std::mt19937_64 rng(kSeed + 201);
  double worst_v = 0.0, worst_a = 0.0, worst_j = 0.0;
  for (int n = 0; n < stress(2000); ++n) {
    const Case c = random_case(rng, static_cast<Reached>(n % 4));
    const JerkLimitedMove m(c.distance, c.limits);
    for (const double t : dense_times(m, 500)) {
      const MotionSample s = m.sample(t);
      worst_v = std::max(worst_v, std::abs(s.velocity) / c.limits.velocity - 1.0);
      worst_a = std::max(worst_a, std::abs(s.acceleration) / c.limits.acceleration - 1.0);
      worst_j = std::max(worst_j, std::abs(s.jerk) / c.limits.jerk - 1.0);
      ASSERT_LE(std::abs(s.velocity), c.limits.velocity * (1 + 5e-15)) << str(c.limits, c.distance) << " t " << t;
      ASSERT_LE(std::abs(s.acceleration), c.limits.acceleration * (1 + 5e-15))
          << str(c.limits, c.distance) << " t " << t;
      ASSERT_LE(std::abs(s.jerk), c.limits.jerk) << str(c.limits, c.distance) << " t " << t;
    }
  }
  report("relative velocity excess", worst_v);
  report("relative acceleration excess", worst_a);
  report("relative jerk excess", worst_j);
}

TEST(Trajectory, MoveStartsAndEndsAtRestExactlyAtTheDistance) {
  // Halfway the move is at half the distance with zero acceleration, up to rounding: measured
  // worst |p - D/2| = 7.3e-16 |D| and |a| = 0.38 eps J T; allowed 8e-15 |D| and 4 eps J T.
  std::mt19937_64 rng(kSeed + 202);
  double worst_p = 0.0, worst_a = 0.0;
  for (int n = 0; n < stress(2000); ++n) {
    const Case c = random_case(rng, static_cast<Reached>(n % 4));
    const JerkLimitedMove m(c.distance, c.limits);
    SCOPED_TRACE(str(c.limits, c.distance));
    ASSERT_GT(m.duration(), 0.0);
    EXPECT_EQ(m.distance(), c.distance);
    for (const double t : {-1.0, 0.0}) {  // before the start: clamped
      const MotionSample s = m.sample(t);
      EXPECT_EQ(s.position, 0.0);
      EXPECT_EQ(s.velocity, 0.0);
      EXPECT_EQ(s.acceleration, 0.0);
    }
    for (const double t : {m.duration(), m.duration() + 1.0}) {  // after the end: clamped
      const MotionSample s = m.sample(t);
      EXPECT_EQ(s.position, c.distance);
      EXPECT_EQ(s.velocity, 0.0);
      EXPECT_EQ(s.acceleration, 0.0);
    }
    const MotionSample mid = m.sample(0.5 * m.duration());
    const double ep = std::abs(mid.position - 0.5 * c.distance) / std::abs(c.distance);
    const double ea = std::abs(mid.acceleration) / (kEps * c.limits.jerk * m.duration());
    worst_p = std::max(worst_p, ep);
    worst_a = std::max(worst_a, ea);
    EXPECT_LT(ep, 8e-15);
    EXPECT_LT(ea, 4.0);
  }
  report("relative error of the halfway position", worst_p);
  report("halfway acceleration / (eps J T)", worst_a);
}

TEST(Trajectory, ZeroDistanceIsAnEmptyMove) {
  const JerkLimitedMove m(0.0, {1.0, 2.0, 10.0});
  EXPECT_EQ(m.duration(), 0.0);
  for (const double t : {-1.0, 0.0, 1.0}) {
    const MotionSample s = m.sample(t);
    EXPECT_EQ(s.position, 0.0);
    EXPECT_EQ(s.velocity, 0.0);
    EXPECT_EQ(s.acceleration, 0.0);
    EXPECT_EQ(s.jerk, 0.0);
  }
}

TEST(Trajectory, TinyDistancesEndExactlyWithinTheLimits) {
  // Down to the smallest normal doubles: neither limit is reached, D = 2 J Tj^3, T = 4 Tj.
  const MotionLimits l{1.0, 2.0, 10.0};
  for (const double d : {1e-300, -1e-200, 1e-100, 1e-30, 1e-12}) {
    const JerkLimitedMove m(d, l);
    EXPECT_EQ(reached(m), Reached::Neither) << d;
    EXPECT_NEAR(m.duration(), 4.0 * std::cbrt(std::abs(d) / 20.0), 4 * kEps * m.duration()) << d;
    EXPECT_EQ(m.sample(m.duration()).position, d);
    for (const double t : dense_times(m, 100)) {
      const MotionSample s = m.sample(t);
      ASSERT_LE(std::abs(s.velocity), l.velocity);
      ASSERT_LE(std::abs(s.acceleration), l.acceleration);
      ASSERT_LE(std::abs(s.position), std::abs(d)) << d << " t " << t;
    }
  }
}

TEST(Trajectory, TrajectoryTimesAndDuration) {
  Trajectory tr;
  tr.t0 = 2.0, tr.dt = 0.5;
  EXPECT_EQ(tr.duration(), 0.0);
  tr.poses.resize(1);
  EXPECT_EQ(tr.duration(), 0.0);
  tr.poses.resize(5);
  EXPECT_EQ(tr.duration(), 2.0);
  EXPECT_EQ(tr.time(0), 2.0);
  EXPECT_EQ(tr.time(4), 4.0);
}

TEST(Trajectory, MoveDurationsMatchTheHandComputedCases) {
  // V = 1, A = 2, J = 10, D = 1: Tj = A/J = 0.2, Ta = Tj + V/A = 0.7, cruise D/V - Ta = 0.3,
  // T = 2 Ta + 0.3 = 1.7 (both limits reached, the trapezoid with rounded corners). Measured
  // errors of this and the cases below: 2.2e-16, 2.2e-16, 5.6e-17, 1.8e-15 s (1 ulp of 10.2).
  const MotionLimits l{1.0, 2.0, 10.0};
  const JerkLimitedMove both(1.0, l);
  EXPECT_NEAR(both.duration(), 1.7, 2e-15);
  const std::array<double, 8> s = both.switch_times();
  const std::array<double, 8> expected{0.0, 0.2, 0.5, 0.7, 1.0, 1.2, 1.5, 1.7};
  for (std::size_t k = 0; k < 8; ++k) EXPECT_NEAR(s[k], expected[k], 2e-15) << "switch " << k;
  EXPECT_NEAR(both.sample(0.85).velocity, 1.0, 2e-15);
  EXPECT_NEAR(both.sample(0.35).acceleration, 2.0, 2e-15);

  // D = 0.5: V not reached (D(V) = 0.7), A is (D >= 2 A^3/J^2 = 0.16). The ramps meet at the
  // peak velocity v with D = v (Tj + v/A): v^2 + 0.4 v - 1 = 0, v = (sqrt(4.16) - 0.4)/2 =
  // 0.8198039..., T = 2 (Tj + v/A) = 0.4 + v.
  const JerkLimitedMove a_only(0.5, l);
  const double v = (std::sqrt(4.16) - 0.4) / 2;
  EXPECT_NEAR(a_only.duration(), 0.4 + v, 2e-15);
  EXPECT_NEAR(a_only.sample(0.5 * a_only.duration()).velocity, v, 2e-15);

  // D = 0.01: neither (D < 0.16): D = 2 J Tj^3, Tj = (0.0005)^(1/3), T = 4 Tj.
  const JerkLimitedMove neither(0.01, l);
  EXPECT_NEAR(neither.duration(), 4.0 * 0.07937005259840998, 5e-16);

  // V = 0.1 < A^2/J = 0.4: the acceleration stops at sqrt(V J) = 1; Tj = sqrt(V/J) = 0.1,
  // D(V) = 2 V Tj = 0.02, cruise 1/0.1 - 0.2 = 9.8, T = 0.4 + 9.8 = 10.2.
  const JerkLimitedMove v_only(1.0, {0.1, 2.0, 10.0});
  EXPECT_NEAR(v_only.duration(), 10.2, 2e-14);
  EXPECT_NEAR(v_only.sample(0.1).acceleration, 1.0, 2e-15);
  // A NaN time is not clamped into a plausible sample.
  const MotionSample bad = v_only.sample(std::numeric_limits<double>::quiet_NaN());
  EXPECT_TRUE(std::isnan(bad.position) && std::isnan(bad.velocity) && std::isnan(bad.acceleration) &&
              std::isnan(bad.jerk));
}

TEST(Trajectory, MoveIsBangZeroBang) {
  // The time-optimal structure (Pontryagin): the jerk is always at +-J, or 0 only on an arc where
  // the acceleration (|a| = A) or the velocity (|v| = V, a = 0) is at its limit.
  std::mt19937_64 rng(kSeed + 203);
  for (int n = 0; n < stress(500); ++n) {
    const Case c = random_case(rng, static_cast<Reached>(n % 4));
    const JerkLimitedMove m(c.distance, c.limits);
    for (int k = 0; k <= 1000; ++k) {
      const MotionSample s = m.sample(m.duration() * (k + 0.5) / 1001.0);
      if (std::abs(s.jerk) == c.limits.jerk) continue;
      ASSERT_EQ(s.jerk, 0.0) << str(c.limits, c.distance);
      const bool on_a = std::abs(std::abs(s.acceleration) / c.limits.acceleration - 1.0) < 1e-14;
      const bool on_v = s.acceleration == 0.0 && std::abs(std::abs(s.velocity) / c.limits.velocity - 1.0) < 1e-14;
      ASSERT_TRUE(on_a || on_v) << str(c.limits, c.distance) << " a " << s.acceleration << " v " << s.velocity;
    }
  }
}

TEST(Trajectory, MoveDurationGrowsContinuouslyWithDistance) {
  // Across the case boundaries (A reached from 2 A^3/J^2 = 0.16, V from 0.7) the duration rises
  // without jumps: a step of 0.1% in distance changes it by less than 0.1%.
  const MotionLimits l{1.0, 2.0, 10.0};
  double previous = 0.0;
  for (double d = 1e-6; d < 10.0; d *= 1.001) {
    const double T = JerkLimitedMove(d, l).duration();
    ASSERT_GT(T, previous) << "distance " << d;
    if (previous > 0.0) {
      ASSERT_LT(T / previous, 1.001) << "distance " << d;
    }
    previous = T;
  }
}

TEST(Trajectory, FiniteDifferencesOfTheMoveMatchItsDerivatives) {
  // Central differences with step h = 1e-3 Tj. Their error is J h^2/6 (position -> velocity,
  // cubic pieces) or up to J h/2 where the step straddles a switch (velocity -> acceleration),
  // plus rounding of the differenced values, ~eps |value| / h, and of the time, ~eps t.
  // Measured worst ratio of the error to that model: 1.4 (velocity; 2.5 over 300x the cases),
  // 1.0 (acceleration); allowed 15 and 10. A wrong derivative would show as an error of the
  // order of the peak value, ~1e6 times the model.
  std::mt19937_64 rng(kSeed + 204);
  double worst_v = 0.0, worst_a = 0.0;
  for (int n = 0; n < stress(1000); ++n) {
    const Case c = random_case(rng, static_cast<Reached>(n % 4));
    const JerkLimitedMove m(c.distance, c.limits);
    const double h = 1e-3 * m.switch_times()[1];
    const double J = c.limits.jerk;
    const double v_peak = std::abs(m.sample(0.5 * m.duration()).velocity);
    const double a_peak = std::abs(m.sample(m.switch_times()[1]).acceleration);
    for (double t : dense_times(m, 200)) {
      t = std::clamp(t, h, m.duration() - h);
      // The step actually taken (t +- h rounds when t >> h); t is its midpoint to within eps t.
      const double step = (t + h) - (t - h);
      const MotionSample s = m.sample(t), lo = m.sample(t - h), hi = m.sample(t + h);
      const double dv = std::abs((hi.position - lo.position) / step - s.velocity);
      const double da = std::abs((hi.velocity - lo.velocity) / step - s.acceleration);
      const double model_v = J * h * h / 6 + kEps * std::abs(c.distance) / h + kEps * (v_peak + t * a_peak);
      const double model_a = J * h / 2 + kEps * v_peak / h + kEps * (a_peak + t * J);
      worst_v = std::max(worst_v, dv / model_v);
      worst_a = std::max(worst_a, da / model_a);
      ASSERT_LE(dv, 15 * model_v) << str(c.limits, c.distance) << " t " << t;
      ASSERT_LE(da, 10 * model_a) << str(c.limits, c.distance) << " t " << t;
    }
  }
  report("velocity finite-difference error / model", worst_v);
  report("acceleration finite-difference error / model", worst_a);
}

TEST(Trajectory, NegativeDistanceMirrorsThePositiveMove) {
  std::mt19937_64 rng(kSeed + 205);
  for (int n = 0; n < stress(500); ++n) {
    const Case c = random_case(rng, static_cast<Reached>(n % 4));
    const JerkLimitedMove pos(std::abs(c.distance), c.limits), neg(-std::abs(c.distance), c.limits);
    ASSERT_EQ(pos.duration(), neg.duration());
    for (const double t : dense_times(pos, 50)) {
      const MotionSample a = pos.sample(t), b = neg.sample(t);
      ASSERT_EQ(b.position, -a.position) << str(c.limits, c.distance) << " t " << t;
      ASSERT_EQ(b.velocity, -a.velocity);
      ASSERT_EQ(b.acceleration, -a.acceleration);
      ASSERT_EQ(b.jerk, -a.jerk);
    }
  }
}

// The constructor must throw; returns what().
template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error";
  return {};
}

TEST(Trajectory, BadLimitsAreErrorsThatNameTheField) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(error_of([] { JerkLimitedMove(1.0, {1.0, 2.0, -1.0}); }), "motion limits: jerk must be > 0, got -1");
  EXPECT_EQ(error_of([] { JerkLimitedMove(1.0, {0.0, 2.0, 1.0}); }), "motion limits: velocity must be > 0, got 0");
  EXPECT_EQ(error_of([&] {
              JerkLimitedMove(1.0, {1.0, nan, 1.0});
            }),
            "motion limits: acceleration must be finite, got nan");
  EXPECT_EQ(error_of([&] { JerkLimitedMove(1.0, {1.0, 1.0, inf}); }), "motion limits: jerk must be finite, got inf");
  EXPECT_EQ(error_of([&] {
              JerkLimitedMove(inf, {1.0, 1.0, 1.0});
            }),
            "jerk-limited move: distance must be finite, got inf");
  EXPECT_EQ(error_of([&] {
              JerkLimitedMove(nan, {1.0, 1.0, 1.0});
            }),
            "jerk-limited move: distance must be finite, got nan");
  // A move whose times overflow a double.
  EXPECT_NE(error_of([] { JerkLimitedMove(1e300, {1e-300, 1.0, 1.0}); }).find("out of the range"), std::string::npos);
}

// ---- sweep ----------------------------------------------------------------------------------

TEST(Trajectory, SweepVisitsBothAmplitudesAndOnlyMovesItsCoordinate) {
  const MotionLimits l{0.2, 0.5, 2.0};
  for (int coordinate = 0; coordinate < 6; ++coordinate) {
    SCOPED_TRACE("coordinate " + std::to_string(coordinate));
    const double amplitude = coordinate < 3 ? 0.15 : deg2rad(10.0);
    const Trajectory tr = sweep_trajectory(coordinate, amplitude, l, 1.0, 0.01);
    ASSERT_GE(tr.poses.size(), 2u);
    EXPECT_EQ(tr.t0, 0.0);
    EXPECT_EQ(tr.dt, 0.01);
    EXPECT_EQ(tr.poses.front().to_vector(), Vector6d::Zero());
    EXPECT_EQ(tr.poses.back().to_vector(), Vector6d::Zero());
    double hi = 0.0, lo = 0.0;
    for (std::size_t k = 0; k < tr.poses.size(); ++k) {
      const Vector6d q = tr.poses[k].to_vector();
      for (int c = 0; c < 6; ++c) {
        if (c == coordinate) continue;
        ASSERT_EQ(q[c], 0.0) << "sample " << k << " coordinate " << c;
      }
      hi = std::max(hi, q[coordinate]);
      lo = std::min(lo, q[coordinate]);
    }
    // The dwells are sampled: the extremes are reached exactly.
    EXPECT_EQ(hi, amplitude);
    EXPECT_EQ(lo, -amplitude);
  }
}

TEST(Trajectory, SweepFollowsItsMovesAndDwells) {
  // Independent timeline from the three moves; the sample count is the total rounded up.
  const MotionLimits l{0.2, 0.5, 2.0};
  const double a = 0.15, dwell = 0.7, dt = 0.003;
  const Trajectory tr = sweep_trajectory(2, a, l, dwell, dt);
  const JerkLimitedMove out(a, l), across(-2 * a, l);
  const double T1 = out.duration(), T2 = across.duration();
  const double total = 4 * dwell + 2 * T1 + T2;
  EXPECT_EQ(tr.poses.size(), static_cast<std::size_t>(std::ceil(total / dt)) + 1);
  EXPECT_GE(tr.duration(), total);
  EXPECT_LT(tr.duration() - dt, total);
  for (std::size_t k = 0; k < tr.poses.size(); ++k) {
    const double t = tr.time(k), z = tr.poses[k].position.z();
    double expected;
    if (t < dwell)
      expected = 0.0;
    else if (t < dwell + T1 + dwell)
      expected = out.sample(t - dwell).position;
    else if (t < 3 * dwell + T1 + T2)
      expected = a + across.sample(t - (2 * dwell + T1)).position;
    else
      expected = -a + out.sample(t - (3 * dwell + T1 + T2)).position;
    ASSERT_NEAR(z, expected, 1e-15) << "sample " << k << " t " << t;  // measured 0; 1e-15 = 35 ulp
  }
  // Mean velocity between samples stays within the limit (mean value theorem); measured relative
  // excess 7.5e-14 (rounding of the difference of positions / dt), allowed 1e-12.
  for (std::size_t k = 1; k < tr.poses.size(); ++k)
    ASSERT_LE(std::abs(tr.poses[k].position.z() - tr.poses[k - 1].position.z()) / dt, l.velocity * (1 + 1e-12))
        << "sample " << k;
}

TEST(Trajectory, SweepOfAWholeNumberOfPeriodsEndsOnTheLastPeriod) {
  // Amplitude 1, V 1, A 2, J 10: moves of 1.7 s, 2.7 s (distance 2: cruise 2 - 0.7 = 1.3 s) and
  // 1.7 s; with 4 dwells of 0.5 s the total is 8.1 s = 81 periods of 0.1 s: 82 samples, not 83.
  const Trajectory tr = sweep_trajectory(0, 1.0, {1.0, 2.0, 10.0}, 0.5, 0.1);
  EXPECT_EQ(tr.poses.size(), 82u);
  EXPECT_NEAR(tr.duration(), 8.1, 1e-12);
  // Zero dwell is allowed: the three moves back to back.
  const Trajectory tight = sweep_trajectory(0, 1.0, {1.0, 2.0, 10.0}, 0.0, 0.1);
  EXPECT_EQ(tight.poses.size(), 62u);
  EXPECT_EQ(tight.poses.back().to_vector(), Vector6d::Zero());
}

TEST(Trajectory, BadSweepArgumentsAreErrors) {
  const MotionLimits l{1.0, 1.0, 1.0};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const auto expect = [](const std::string& msg, std::string_view part) {
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
  };
  expect(error_of([&] { sweep_trajectory(6, 0.1, l, 1.0, 0.01); }), "coordinate: expected 0..5");
  expect(error_of([&] { sweep_trajectory(-1, 0.1, l, 1.0, 0.01); }), "got -1");
  expect(error_of([&] { sweep_trajectory(0, 0.0, l, 1.0, 0.01); }), "amplitude: expected a finite number > 0, got 0");
  expect(error_of([&] { sweep_trajectory(0, -0.1, l, 1.0, 0.01); }), "amplitude");
  expect(error_of([&] { sweep_trajectory(0, nan, l, 1.0, 0.01); }), "amplitude");
  expect(error_of([&] { sweep_trajectory(0, 0.1, l, -1.0, 0.01); }), "dwell: expected a finite time >= 0 s, got -1");
  expect(error_of([&] { sweep_trajectory(0, 0.1, l, 1.0, 0.0); }), "dt: expected a finite period > 0 s, got 0");
  expect(error_of([&] { sweep_trajectory(0, 0.1, l, 1.0, nan); }), "dt");
  expect(error_of([&] {
           sweep_trajectory(0, 0.1, {1.0, -2.0, 1.0}, 1.0, 0.01);
         }),
         "motion limits: acceleration must be > 0, got -2");
  expect(error_of([&] { sweep_trajectory(0, 0.1, l, 1e6, 1e-6); }), "samples");
}

// ---- CSV ------------------------------------------------------------------------------------

TEST(Trajectory, CsvWithUnitSuffixesIsConvertedToSi) {
  const std::string text =
      "\xEF\xBB\xBF# a comment line\r\n"
      "  t_s , x_mm, y_m, z, roll_rad, pitch_deg, yaw\r\n"
      "\r\n"
      "0.0,  12.5, 0.25, 0.5, 0.1, 90, 45\r\n"
      "   # indented comment\r\n"
      "0.5, -1e3, -0.25, +0.125, -0.2, -30, -180\r\n"
      "\t1.25\t,0,0,0,0,0,0";  // no final line break
  const TimedPoses tp = parse_trajectory_csv(text, "good.csv");
  ASSERT_EQ(tp.t.size(), 3u);
  ASSERT_EQ(tp.poses.size(), 3u);
  EXPECT_EQ(tp.lines, (std::vector<int>{4, 6, 7}));
  EXPECT_EQ(tp.t, (std::vector<double>{0.0, 0.5, 1.25}));
  Vector6d q0, q1;
  q0 << 0.0125, 0.25, 0.5, 0.1, kPi / 2, kPi / 4;
  q1 << -1.0, -0.25, 0.125, -0.2, -kPi / 6, -kPi;
  EXPECT_LT((tp.poses[0].to_vector() - q0).cwiseAbs().maxCoeff(), 1e-16);  // measured 0 (below 1 ulp: exact)
  EXPECT_LT((tp.poses[1].to_vector() - q1).cwiseAbs().maxCoeff(), 1e-16);
  EXPECT_EQ(tp.poses[2].to_vector(), Vector6d::Zero());
}

TEST(Trajectory, CsvWithoutSuffixesIsMetresAndDegrees) {
  const TimedPoses tp = parse_trajectory_csv("t,x,y,z,roll,pitch,yaw\n0,1,2,3,180,90,-90\n1,0,0,0,0,0,0\n", "p.csv");
  Vector6d q;
  q << 1, 2, 3, kPi, kPi / 2, -kPi / 2;
  EXPECT_LT((tp.poses[0].to_vector() - q).cwiseAbs().maxCoeff(), 1e-16);
}

TEST(Trajectory, CsvInSiUnitsReadsBackExactly) {
  // hexatwist's own output form (_m, _rad, 17 digits) round-trips every double.
  std::mt19937_64 rng(kSeed + 206);
  std::string text = "t_s,x_m,y_m,z_m,roll_rad,pitch_rad,yaw_rad\n";
  std::vector<Pose> poses;
  char buf[64];
  for (int k = 0; k < 50; ++k) {
    poses.push_back(random_pose(rng, 0.5, 1.0));
    std::snprintf(buf, sizeof buf, "%.17g", 0.01 * k);
    text += buf;
    for (int c = 0; c < 6; ++c) {
      std::snprintf(buf, sizeof buf, ",%.17g", poses.back().to_vector()[c]);
      text += buf;
    }
    text += "\n";
  }
  const TimedPoses tp = parse_trajectory_csv(text, "out.csv");
  ASSERT_EQ(tp.poses.size(), poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_EQ(tp.t[k], 0.01 * static_cast<double>(k));
    EXPECT_EQ(tp.poses[k].to_vector(), poses[k].to_vector()) << "row " << k;
  }
}

TEST(Trajectory, FormattedCsvReadsBackToTheSameDoublesWithTheLastSampleKept) {
  // format_trajectory_csv is parse_trajectory_csv's inverse, every `every` samples and the last one.
  std::mt19937_64 rng(kSeed + 207);
  Trajectory tr;
  tr.t0 = 0.25;
  tr.dt = 0.001;
  for (int k = 0; k < 23; ++k) tr.poses.push_back(random_pose(rng, 0.5, 1.0));
  for (const std::size_t every : {std::size_t{1}, std::size_t{5}, std::size_t{22}, std::size_t{100}}) {
    const TimedPoses back = parse_trajectory_csv(format_trajectory_csv(tr, every), "run.csv");
    std::vector<std::size_t> rows;
    for (std::size_t k = 0; k < tr.poses.size(); k += every) rows.push_back(k);
    if (rows.back() != tr.poses.size() - 1) rows.push_back(tr.poses.size() - 1);
    ASSERT_EQ(back.poses.size(), rows.size()) << "every " << every;
    for (std::size_t r = 0; r < rows.size(); ++r) {
      EXPECT_EQ(back.t[r], tr.time(rows[r])) << "every " << every << ", row " << r;
      EXPECT_EQ(back.poses[r].to_vector(), tr.poses[rows[r]].to_vector()) << "every " << every << ", row " << r;
    }
  }
}

// parse_trajectory_csv must throw one line starting "bad.csv:<line>:<column>: column '<name>':"
// and containing every one of `parts`.
void expect_csv_error(const std::string& text, int line, int column, std::string_view name,
                      std::initializer_list<std::string_view> parts = {}) {
  SCOPED_TRACE(text);
  expect_error_line(
      [&] { (void)parse_trajectory_csv(text, "bad.csv"); },
      "bad.csv:" + std::to_string(line) + ":" + std::to_string(column) + ": column '" + std::string(name) + "':",
      parts);
}

const std::string kHeader = "t, x, y, z, roll, pitch, yaw\n";
const std::string kRow0 = "0, 0, 0, 0, 0, 0, 0\n";

TEST(Trajectory, CsvHeaderErrorsSayWhatIsExpected) {
  expect_csv_error("", 1, 1, "t", {"empty text", "t, x, y, z, roll, pitch, yaw"});
  expect_csv_error("# only a comment\n\n", 1, 1, "t", {"no header row"});
  // A data row where the header should be.
  expect_csv_error(kRow0 + kRow0, 1, 1, "t", {"expected 't' or 't_s'", "got '0'"});
  expect_csv_error("t,x,y,z,roll,pitch,psi\n" + kRow0, 1, 20, "yaw", {"'yaw', 'yaw_deg' or 'yaw_rad'", "got 'psi'"});
  expect_csv_error("t, x_cm, y, z, roll, pitch, yaw\n" + kRow0, 1, 4, "x", {"'x', 'x_m' or 'x_mm'", "got 'x_cm'"});
  expect_csv_error("t,y,x,z,roll,pitch,yaw\n" + kRow0, 1, 3, "x", {"as column 2", "got 'y'"});
  expect_csv_error("t,x,y\n" + kRow0, 1, 6, "z", {"missing from the header"});
  expect_csv_error("t,x,y,z,roll,pitch,yaw,speed\n" + kRow0, 1, 24, "yaw", {"extra column 'speed'"});
  expect_csv_error("t;x;y;z;roll;pitch;yaw\n", 1, 1, "t", {"separated by commas"});
}

TEST(Trajectory, CsvRowErrorsNameLineColumnAndField) {
  // Line 3 (after the header and a good row); columns count characters from 1.
  const std::string head = kHeader + kRow0;
  expect_csv_error(head + "1, 0, 0, 0, 0, abc, 0\n", 3, 16, "pitch", {"expected a number, got 'abc'"});
  expect_csv_error(head + "1, 0, 0, 0, 0, 0, 1.5x\n", 3, 19, "yaw", {"got '1.5x'"});
  expect_csv_error(head + "1, 0, 0, nan, 0, 0, 0\n", 3, 10, "z", {"finite", "'nan'"});
  expect_csv_error(head + "1, 0, 0, 0, -inf, 0, 0\n", 3, 13, "roll", {"finite", "'-inf'"});
  expect_csv_error(head + "1, 1e999, 0, 0, 0, 0, 0\n", 3, 4, "x", {"out of range", "'1e999'"});
  expect_csv_error(head + "1, 0,  , 0, 0, 0, 0\n", 3, 6, "y", {"empty cell"});
  expect_csv_error(head + "1, 0, 0, 0, 0\n", 3, 14, "pitch", {"5 cells, expected 7"});
  expect_csv_error(head + "1, 0, 0, 0, 0, 0, 0, 9\n", 3, 22, "yaw", {"extra cell '9'", "8 cells"});
  // CRLF: the carriage return is not part of the last cell.
  expect_csv_error(kHeader + "0,0,0,0,0,0,0\r\n1,0,0,0,0,0,x\r\n", 3, 13, "yaw", {"got 'x'"});
  // A UTF-8 character counts as one column.
  expect_csv_error(head + "1, 0, 0, 0, 0, 0, \xC3\xA9\n", 3, 19, "yaw", {"got '\xC3\xA9'"});
  expect_csv_error(head + "1, 0, 0, 0, 0, 0, \xC3\xA9, x\n", 3, 22, "yaw", {"extra cell 'x'"});
}

TEST(Trajectory, CsvTimesMustIncrease) {
  expect_csv_error(kHeader + "# comment\n1.3, 0,0,0,0,0,0\n\n  1.2, 0,0,0,0,0,0\n", 5, 3, "t",
                   {"time 1.2 s is not after 1.3 s on line 3"});
  expect_csv_error(kHeader + kRow0 + "0, 1,0,0,0,0,0\n", 3, 1, "t", {"time 0 s is not after 0 s on line 2"});
}

TEST(Trajectory, CsvNeedsTwoRows) {
  expect_csv_error(kHeader, 1, 1, "t", {"0 data rows", "at least 2"});
  expect_csv_error(kHeader + "\n# c\n" + kRow0 + "\n", 4, 1, "t", {"1 data row;", "at least 2"});
}

// ---- resampling -----------------------------------------------------------------------------

// Samples of q(t) at the times `t`, each coordinate a different polynomial of degree `degree`.
TimedPoses polynomial_samples(const std::vector<double>& t, int degree) {
  TimedPoses tp;
  tp.t = t;
  for (const double ti : t) {
    Vector6d q;
    for (int c = 0; c < 6; ++c) {
      const double a0 = 0.1 * (c + 1), a1 = 0.3 - 0.1 * c, a2 = degree >= 2 ? 0.05 * (c - 2.5) : 0.0;
      q[c] = a0 + a1 * ti + a2 * ti * ti;
    }
    tp.poses.push_back(Pose::from_vector(q));
  }
  return tp;
}

Vector6d polynomial_at(double t, int degree) { return polynomial_samples({t}, degree).poses[0].to_vector(); }

std::vector<double> random_times(std::mt19937_64& rng, int n) {
  std::vector<double> t{uniform(rng, -1, 1)};
  for (int k = 1; k < n; ++k) t.push_back(t.back() + uniform(rng, 0.02, 0.5));
  return t;
}

TEST(Trajectory, ResampleReproducesLines) {
  // Uneven random times: the harmonic mean of equal secants is the secant, so the cubic is the
  // line itself. Measured worst error 8.9e-16 with values up to ~15; allowed 1e-14.
  std::mt19937_64 rng(kSeed + 207);
  double worst = 0.0;
  for (int n = 0; n < stress(200); ++n) {
    const int count = n % 5 == 0 ? 2 : 3 + n % 20;  // two samples: the secant
    const TimedPoses tp = polynomial_samples(random_times(rng, count), 1);
    const double dt = uniform(rng, 0.001, 0.1);
    const Trajectory tr = resample(tp, dt);
    ASSERT_EQ(tr.t0, tp.t.front());
    ASSERT_EQ(tr.dt, dt);
    for (std::size_t k = 0; k < tr.poses.size(); ++k) {
      // The last tick may lie after the last sample: it holds the last pose.
      const double e =
          (tr.poses[k].to_vector() - polynomial_at(std::min(tr.time(k), tp.t.back()), 1)).cwiseAbs().maxCoeff();
      worst = std::max(worst, e);
      ASSERT_LT(e, 1e-14) << "sample " << k << " t " << tr.time(k);
    }
  }
  report("resampled line error", worst);
}

TEST(Trajectory, ResampleNeverOvershootsTheSamples) {
  // Waypoints: rest, a move, a hold, a move back, uneven spacing, random heights. On every
  // interval the curve stays between its two samples (a hold stays exactly flat).
  std::mt19937_64 rng(kSeed + 209);
  for (int n = 0; n < stress(100); ++n) {
    TimedPoses tp;
    double t = 0.0;
    for (int k = 0; k < 12; ++k) {
      tp.t.push_back(t);
      Vector6d q;
      for (int c = 0; c < 6; ++c) q[c] = (k % 4 == 1 || k % 4 == 2) ? uniform(rng, -1.0, 1.0) : 0.0;
      if (k % 4 == 2) q = tp.poses.back().to_vector();  // hold
      tp.poses.push_back(Pose::from_vector(q));
      t += uniform(rng, 0.02, 3.0);
    }
    const Trajectory tr = resample(tp, 0.01);
    std::size_t i = 0;
    for (std::size_t k = 0; k < tr.poses.size(); ++k) {
      while (i + 2 < tp.t.size() && tp.t[i + 1] <= tr.time(k)) ++i;
      const Vector6d a = tp.poses[i].to_vector(), b = tp.poses[i + 1].to_vector(), x = tr.poses[k].to_vector();
      for (int c = 0; c < 6; ++c) {
        ASSERT_GE(x[c], std::min(a[c], b[c]) - 1e-15) << n << " " << k << " " << c;
        ASSERT_LE(x[c], std::max(a[c], b[c]) + 1e-15) << n << " " << k << " " << c;
      }
    }
  }
}

TEST(Trajectory, ResampleDoesNotReproduceACubic) {
  // A cubic is only approximated (this proves the line test above is not trivially exact).
  TimedPoses tp;
  for (int k = 0; k <= 8; ++k) {
    const double t = 0.5 * k;
    tp.t.push_back(t);
    tp.poses.push_back(Pose::from_vector(Vector6d::Constant(t * t * t)));
  }
  const Trajectory tr = resample(tp, 0.05);
  double worst = 0.0;
  for (std::size_t k = 0; k < tr.poses.size(); ++k) {
    const double t = tr.time(k);
    worst = std::max(worst, std::abs(tr.poses[k].position.x() - t * t * t));
  }
  EXPECT_GT(worst, 1e-4);
  EXPECT_LT(worst, 0.1);
}

TEST(Trajectory, ResampleHitsTheInputSamplesOnTheGrid) {
  std::mt19937_64 rng(kSeed + 208);
  // Dyadic times on a dyadic grid (exact), and decimal times on a decimal grid (k * 0.1 is not
  // exactly the written 0.3: the grid time snaps to the input time within 1e-9 dt).
  for (const double dt : {0.25, 0.1}) {
    SCOPED_TRACE("dt " + std::to_string(dt));
    const std::vector<int> steps{0, 2, 3, 7, 8, 12, 20};
    TimedPoses tp;
    tp.t = dt == 0.25 ? std::vector<double>{0.0, 0.5, 0.75, 1.75, 2.0, 3.0, 5.0}
                      : std::vector<double>{0.0, 0.2, 0.3, 0.7, 0.8, 1.2, 2.0};
    for (std::size_t i = 0; i < steps.size(); ++i) tp.poses.push_back(random_pose(rng, 0.5, 1.0));
    const Trajectory tr = resample(tp, dt);
    ASSERT_EQ(tr.poses.size(), 21u);
    for (std::size_t i = 0; i < steps.size(); ++i)
      EXPECT_EQ(tr.poses[static_cast<std::size_t>(steps[i])].to_vector(), tp.poses[i].to_vector())
          << "input sample " << i;
  }
}

TEST(Trajectory, ResampleGridEndingBetweenTicksKeepsTheLastPoseOnTheNextTick) {
  TimedPoses tp = polynomial_samples({1.0, 1.4, 2.05}, 2);
  const Trajectory tr = resample(tp, 0.1);  // 1.05 s: 11 periods, the last at 2.1 s holds the pose of 2.05 s
  EXPECT_EQ(tr.t0, 1.0);
  ASSERT_EQ(tr.poses.size(), 12u);
  EXPECT_NEAR(tr.time(11), 2.1, 1e-15);
  EXPECT_NEAR(tr.duration(), 1.1, 1e-15);
  EXPECT_EQ(tr.poses.back().to_vector(), tp.poses.back().to_vector());
  // A span of a whole number of periods up to rounding ends on the last sample.
  const Trajectory whole = resample(polynomial_samples({0.0, 0.35, 0.7}, 2), 0.1);
  ASSERT_EQ(whole.poses.size(), 8u);
  EXPECT_EQ(whole.poses.back().to_vector(), polynomial_at(0.7, 2));
}

TEST(Trajectory, ResampleIsContinuousInSlopeAtTheKnots) {
  // C1: at an interior input time the one-sided difference quotients from the left and from the
  // right differ by about q'' dt, so halving dt halves the difference; a jump in slope would not
  // shrink (ratio near 1). Measured ratio 0.500155; allowed 0.5 +- 2e-3.
  std::mt19937_64 rng(kSeed + 209);
  TimedPoses tp;
  tp.t = {0.0, 0.25, 0.5, 0.75, 1.0};
  for (std::size_t i = 0; i < tp.t.size(); ++i) tp.poses.push_back(random_pose(rng, 0.5, 1.0));
  const auto slope_jump = [&](int per_segment) {
    const double dt = 0.25 / per_segment;
    const Trajectory tr = resample(tp, dt);
    double worst = 0.0;
    for (const int knot : {1, 2, 3}) {
      const auto k = static_cast<std::size_t>(knot * per_segment);
      const Vector6d left = (tr.poses[k].to_vector() - tr.poses[k - 1].to_vector()) / dt;
      const Vector6d right = (tr.poses[k + 1].to_vector() - tr.poses[k].to_vector()) / dt;
      worst = std::max(worst, (left - right).cwiseAbs().maxCoeff());
    }
    return worst;
  };
  const double coarse = slope_jump(1024), fine = slope_jump(2048);
  std::printf("  measured slope jump ratio at half the period: %.6f\n", fine / coarse);
  EXPECT_GT(coarse, 0.0);
  EXPECT_NEAR(fine / coarse, 0.5, 2e-3);
}

TEST(Trajectory, BadResampleInputsAreErrors) {
  const TimedPoses good = polynomial_samples({0.0, 1.0}, 1);
  const auto expect = [](const std::string& msg, std::string_view part) {
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
  };
  expect(error_of([&] { (void)resample(good, 0.0); }), "dt: expected a finite period > 0 s, got 0");
  expect(error_of([&] { (void)resample(good, -1.0); }), "got -1");
  expect(error_of([&] { (void)resample(good, std::numeric_limits<double>::quiet_NaN()); }), "dt");
  expect(error_of([&] { (void)resample(polynomial_samples({0.0}, 1), 0.1); }), "at least 2 samples, got 1");
  TimedPoses mismatch = good;
  mismatch.poses.pop_back();
  expect(error_of([&] { (void)resample(mismatch, 0.1); }), "2 times but 1 poses");
  TimedPoses backwards = polynomial_samples({0.0, 1.0, 1.0}, 1);
  backwards.lines = {2, 3, 4};
  expect(error_of([&] { (void)resample(backwards, 0.1); }), "sample 2 (line 4): time 1 s is not after 1 s");
  TimedPoses bad_pose = good;
  bad_pose.poses[1].rpy.x() = std::numeric_limits<double>::infinity();
  expect(error_of([&] { (void)resample(bad_pose, 0.1); }), "sample 1: pose is not finite");
  expect(error_of([&] { (void)resample(polynomial_samples({0.0, 1e3}, 1), 1e-6); }), "samples");
  // Finite samples whose rate of change overflows a double (found by fuzz/fuzz_trajectory_csv.cpp).
  TimedPoses huge = polynomial_samples({0.0, 0.25, 0.6}, 1);
  huge.lines = {3, 5, 7};
  huge.poses[1].position.y() = 1e308;
  expect(error_of([&] { (void)resample(huge, 0.01); }),
         "between sample 0 (line 3) and sample 1 (line 5): the interpolation overflows");
}

// ---- waypoints and interpolation -------------------------------------------------------------

TEST(Trajectory, WaypointMovesAreStraightJerkLimitedAndHeld) {
  // Home, a 3-D translation, another, home: every sample on its segment, at the distance the
  // jerk-limited move gives, the waypoints held for the dwell, the end exact.
  const auto expect = [](const std::string& msg, std::string_view part) {
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
  };
  std::array<Vector6d, 4> w;
  w[0].setZero();
  w[1] << 0.1, -0.2, 0.05, 0, 0, 0;
  w[2] << -0.1, 0.0, 0.15, 0, 0, 0;
  w[3].setZero();
  const MotionLimits limits{0.2, 0.5, 2.5};
  const double dwell = 0.3, dt = 1e-3;
  const Trajectory tr = waypoint_trajectory(w, limits, dwell, dt);
  double t = dwell, worst = 0.0;
  std::size_t k = 0;
  for (std::size_t m = 0; m + 1 < w.size(); ++m) {
    const Vector6d d = w[m + 1] - w[m];
    const JerkLimitedMove move(d.norm(), limits);
    for (; k < tr.poses.size() && tr.time(k) < t + move.duration() + dwell; ++k) {
      const double s = move.sample(tr.time(k) - t).position;
      const Vector6d expected = w[m] + d.normalized() * s;
      worst = std::max(worst, (tr.poses[k].to_vector() - expected).cwiseAbs().maxCoeff());
      if (tr.time(k) < t) {
        ASSERT_EQ(tr.poses[k].to_vector(), tr.poses[k > 0 ? k - 1 : 0].to_vector()) << "held";
      }
    }
    t += move.duration() + dwell;
  }
  report("waypoint sample off its move [m]", worst);
  EXPECT_LT(worst, 1e-15);
  EXPECT_EQ(tr.poses.back().to_vector(), w.back());
  EXPECT_NEAR(tr.duration(), t, dt);
  expect(error_of([&] { (void)waypoint_trajectory(std::span(w).first(1), limits, dwell, dt); }), "at least 2");
  w[1][2] = std::numeric_limits<double>::quiet_NaN();
  expect(error_of([&] { (void)waypoint_trajectory(w, limits, dwell, dt); }), "waypoint 2 is not finite");
}

TEST(Trajectory, InterpolateIsTheResampledCurveAtAnyTime) {
  const auto expect = [](const std::string& msg, std::string_view part) {
    EXPECT_NE(msg.find(part), std::string::npos) << msg;
  };
  std::mt19937_64 rng(kSeed + 213);
  for (int n = 0; n < stress(50); ++n) {
    const TimedPoses tp = polynomial_samples(random_times(rng, 3 + n % 10), 2);
    const double dt = uniform(rng, 0.01, 0.1);
    const Trajectory tr = resample(tp, dt);
    // On the grid: resample's poses, bit for bit (the grid times that are not input times).
    std::vector<double> grid;
    for (std::size_t k = 0; k < tr.poses.size(); ++k) grid.push_back(std::min(tr.time(k), tp.t.back()));
    const std::vector<Pose> at_grid = interpolate(tp, grid);
    for (std::size_t k = 0; k < grid.size(); ++k)
      ASSERT_LT((at_grid[k].to_vector() - tr.poses[k].to_vector()).cwiseAbs().maxCoeff(), 1e-15) << k;
    // At the input times: the input poses exactly.
    const std::vector<Pose> at_samples = interpolate(tp, tp.t);
    for (std::size_t i = 0; i < tp.t.size(); ++i) ASSERT_EQ(at_samples[i].to_vector(), tp.poses[i].to_vector());
  }
  const TimedPoses tp = polynomial_samples({0.0, 1.0, 2.0}, 1);
  const std::vector<double> outside{0.5, 2.5};
  expect(error_of([&] { (void)interpolate(tp, outside); }),
         "time 2.5 s (number 2) is outside the samples' span [0, 2] s");
  EXPECT_EQ(timed_poses(resample(tp, 0.5)).t, (std::vector<double>{0.0, 0.5, 1.0, 1.5, 2.0}));
}

}  // namespace
}  // namespace hexatwist::test
