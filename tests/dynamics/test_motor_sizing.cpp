// SPDX-License-Identifier: BSD-3-Clause
// Motor sizing along a trajectory: the differences and the statistics against a hand computation
// on a heave sinusoid with exact derivatives, the terms adding up to the torque, the envelope's
// first violation, a pose limit reported with its sample, and the figure's envelope.
#include <gtest/gtest.h>

#include <cmath>

#include "hexatwist/dynamics/motor_sizing.hpp"
#include "hexatwist/io/config.hpp"

namespace hexatwist {
namespace {

const Config& seed() {
  static const Config c = default_config();
  return c;
}

constexpr double kAmplitude = 0.05;  // [m]
constexpr double kFrequency = 1.0;   // [Hz]

// z = A sin(2 pi f t) over two periods, at the control rate.
Trajectory heave_sine() {
  Trajectory t;
  t.dt = seed().rig.control_period();
  const std::size_t n = static_cast<std::size_t>(std::lround(2.0 / kFrequency / t.dt)) + 1;
  for (std::size_t k = 0; k < n; ++k) {
    Pose p;
    p.position.z() = kAmplitude * std::sin(2.0 * kPi * kFrequency * t.time(k));
    t.poses.push_back(p);
  }
  return t;
}

const MotorSizing& heave_sizing() {
  static const MotorSizing s = [] {
    MotorSizing out;
    EXPECT_EQ(size_motors(seed().rig, heave_sine(), out), Status::Ok);
    return out;
  }();
  return s;
}

// A rig like the seed's with another servo envelope.
Rig with_servo(const ServoSpec& servo) {
  const Rig& r = seed().rig;
  return Rig(r.model(), servo, r.load(), r.simulation(), r.mechanism());
}

TEST(MotorSizing, PeakAndRmsMatchAHandComputationWithExactDerivatives) {
  const Rig& rig = seed().rig;
  const Trajectory traj = heave_sine();
  const MotorSizing& sizing = heave_sizing();
  ASSERT_EQ(sizing.samples.size(), traj.poses.size());
  // The same motion with the analytic rate and acceleration, summed by hand. The differences'
  // error is (2 pi f dt)^2 / 12 relative, ~3e-6; the ends' one-sided rate and zero acceleration
  // are two samples of 2001, so the inner samples are compared.
  const double w = 2.0 * kPi * kFrequency;
  std::array<double, 6> peak{}, sum2{}, peak_speed{};
  double worst_torque = 0.0, worst_speed = 0.0;
  for (std::size_t k = 0; k < traj.poses.size(); ++k) {
    const double t = traj.time(k);
    Vector6d rate = Vector6d::Zero(), acc = Vector6d::Zero();
    rate[2] = kAmplitude * w * std::cos(w * t);
    acc[2] = -kAmplitude * w * w * std::sin(w * t);
    InverseDynamics id;
    ASSERT_EQ(inverse_dynamics(rig, platform_motion(traj.poses[k], rate, acc), id), Status::Ok);
    for (int i = 0; i < 6; ++i) {
      peak[i] = std::max(peak[i], std::abs(id.torque[i]));
      peak_speed[i] = std::max(peak_speed[i], std::abs(id.speed[i]));
      sum2[i] += id.torque[i] * id.torque[i];
    }
    if (k > 0 && k + 1 < traj.poses.size()) {
      worst_torque = std::max(worst_torque, (sizing.samples[k].torque - id.torque).cwiseAbs().maxCoeff());
      worst_speed = std::max(worst_speed, (sizing.samples[k].speed - id.speed).cwiseAbs().maxCoeff());
    }
  }
  EXPECT_LT(worst_torque, 2e-3);  // [N m], of ~10 N m
  EXPECT_LT(worst_speed, 2e-3);   // [rad/s], of ~40 rad/s
  for (int i = 0; i < 6; ++i) {
    SCOPED_TRACE(i);
    const MotorSummary& m = sizing.motors[i];
    EXPECT_NEAR(m.peak_torque, peak[i], 2e-3);
    EXPECT_NEAR(m.rms_torque, std::sqrt(sum2[i] / static_cast<double>(traj.poses.size())), 2e-3);
    EXPECT_NEAR(m.peak_speed, peak_speed[i], 2e-3);
    EXPECT_GT(m.peak_torque, m.rms_torque);
    // Heave at 1 Hz, 0.05 m: 0.31 m/s peak, some 150 rad/s of motor.
    EXPECT_GT(m.peak_speed, 50.0);
  }
}

TEST(MotorSizing, TermsAddUpToTheTorqueAndSharesAreTheirRmsOverTheTorqueRms) {
  const MotorSizing& sizing = heave_sizing();
  std::array<std::array<double, kTorqueTerms>, 6> sum2{};
  std::array<double, 6> torque2{};
  for (const MotorSample& s : sizing.samples) {
    Vector6d total = Vector6d::Zero();
    for (int t = 0; t < kTorqueTerms; ++t) {
      total += s.terms[t];
      for (int i = 0; i < 6; ++i) sum2[i][t] += s.terms[t][i] * s.terms[t][i];
    }
    ASSERT_LT((total - s.torque).cwiseAbs().maxCoeff(), 1e-9 * (1.0 + s.torque.cwiseAbs().maxCoeff())) << s.time;
    ASSERT_LT((s.power - s.torque.cwiseProduct(s.speed)).cwiseAbs().maxCoeff(),
              1e-9 * (1.0 + s.power.cwiseAbs().maxCoeff()));
    for (int i = 0; i < 6; ++i) torque2[i] += s.torque[i] * s.torque[i];
  }
  for (int i = 0; i < 6; ++i) {
    const MotorSummary& m = sizing.motors[i];
    double squares = 0.0;
    for (int t = 0; t < kTorqueTerms; ++t) {
      EXPECT_NEAR(m.share[t], std::sqrt(sum2[i][t] / torque2[i]), 1e-12) << i << " " << t;
      squares += m.share[t] * m.share[t];
    }
    // The load hangs on the motors and the heave accelerates it by 1 m/s^2 (a tenth of g).
    EXPECT_GT(m.share[static_cast<int>(TorqueTerm::Gravity)], 0.5);
    EXPECT_GT(m.share[static_cast<int>(TorqueTerm::PlatformInertia)], 0.05);
    EXPECT_GT(squares, 0.5);
    // Energy: the heave lifts and lowers the load, so every motor drives and is driven.
    EXPECT_GT(m.energy_driven, 0.0);
    EXPECT_GT(m.energy_regenerated, 0.0);
    EXPECT_GT(m.peak_power, 0.0);
  }
}

TEST(MotorSizing, TheSeedMotorCarriesTheGentleHeaveInsideItsEnvelope) {
  const MotorSizing& sizing = heave_sizing();
  for (const MotorSummary& m : sizing.motors) {
    EXPECT_EQ(m.violation.check, EnvelopeCheck::None);
    EXPECT_LT(m.peak_usage, 1.0);
    EXPECT_LT(m.speed_usage, 1.0);
  }
  EXPECT_EQ(sizing.violation.check, EnvelopeCheck::None);
}

// The first sample (legs in order) at which `bad(sample, leg)` holds.
template <class Pred>
std::pair<std::size_t, int> first_where(const MotorSizing& s, Pred bad) {
  for (std::size_t k = 0; k < s.samples.size(); ++k)
    for (int i = 0; i < 6; ++i)
      if (bad(s.samples[k], i)) return {k, i};
  return {s.samples.size(), -1};
}

TEST(MotorSizing, FlagsExactlyTheFirstSpeedViolation) {
  const MotorSizing& base = heave_sizing();
  double fastest = 0.0;
  for (const MotorSummary& m : base.motors) fastest = std::max(fastest, m.peak_speed);
  ServoSpec servo = seed().rig.servo();
  servo.max_speed = 0.9 * fastest;
  servo.peak_corner_speed = 0.5 * servo.max_speed;
  const Rig rig = with_servo(servo);
  MotorSizing s;
  ASSERT_EQ(size_motors(rig, heave_sine(), s), Status::Ok);
  const auto [k, leg] =
      first_where(s, [&](const MotorSample& x, int i) { return std::abs(x.speed[i]) > servo.max_speed; });
  ASSERT_GE(leg, 0);
  EXPECT_EQ(s.violation.check, EnvelopeCheck::Speed);
  EXPECT_EQ(s.violation.index, k);
  EXPECT_EQ(s.violation.leg, leg);
  EXPECT_DOUBLE_EQ(s.violation.time, s.samples[k].time);
  EXPECT_DOUBLE_EQ(s.violation.value, std::abs(s.samples[k].speed[leg]));
  EXPECT_DOUBLE_EQ(s.violation.bound, servo.max_speed);
  EXPECT_GT(s.motors[leg].speed_usage, 1.0);
}

TEST(MotorSizing, FlagsExactlyTheFirstPeakTorqueViolation) {
  const MotorSizing& base = heave_sizing();
  double strongest = 0.0;
  for (const MotorSummary& m : base.motors) strongest = std::max(strongest, m.peak_torque);
  ServoSpec servo = seed().rig.servo();
  servo.torque_limit = 0.95 * strongest;
  servo.peak_torque_at_max_speed = std::min(servo.peak_torque_at_max_speed, servo.torque_limit);
  servo.continuous_torque = servo.torque_limit;
  const Rig rig = with_servo(servo);
  MotorSizing s;
  ASSERT_EQ(size_motors(rig, heave_sine(), s), Status::Ok);
  const auto [k, leg] = first_where(s, [&](const MotorSample& x, int i) {
    return std::abs(x.torque[i]) > peak_torque_at(servo, std::abs(x.speed[i]));
  });
  ASSERT_GE(leg, 0);
  ASSERT_EQ(s.violation.check, EnvelopeCheck::PeakTorque);
  EXPECT_EQ(s.violation.index, k);
  EXPECT_EQ(s.violation.leg, leg);
  EXPECT_DOUBLE_EQ(s.violation.value, std::abs(s.samples[k].torque[leg]));
  EXPECT_DOUBLE_EQ(s.violation.bound, peak_torque_at(servo, std::abs(s.samples[k].speed[leg])));
  EXPECT_GT(s.motors[leg].peak_usage, 1.0);
  EXPECT_EQ(s.motors[leg].violation.index, k);
}

TEST(MotorSizing, AnRmsAboveTheContinuousRatingIsReportedAtTheEndAfterThePointwiseChecks) {
  const MotorSizing& base = heave_sizing();
  double lowest_rms = INFINITY;
  int leg = -1;
  for (int i = 0; i < 6; ++i)
    if (base.motors[i].rms_torque < lowest_rms) lowest_rms = base.motors[leg = i].rms_torque;
  ServoSpec servo = seed().rig.servo();
  servo.continuous_torque = 0.99 * lowest_rms;  // every motor fails it; leg order decides
  const Rig rig = with_servo(servo);
  MotorSizing s;
  ASSERT_EQ(size_motors(rig, heave_sine(), s), Status::Ok);
  ASSERT_EQ(s.violation.check, EnvelopeCheck::ContinuousTorque);
  EXPECT_EQ(s.violation.leg, 0);
  EXPECT_EQ(s.violation.index, s.samples.size() - 1);
  EXPECT_DOUBLE_EQ(s.violation.value, s.motors[0].rms_torque);
  EXPECT_DOUBLE_EQ(s.violation.bound, servo.continuous_torque);
  for (const MotorSummary& m : s.motors) EXPECT_GT(m.rms_usage, 1.0);
}

TEST(MotorSizing, APoseOutsideTheStrokeIsReportedWithItsSample) {
  Trajectory t;
  t.dt = seed().rig.control_period();
  for (int k = 0; k <= 1000; ++k) {
    Pose p;
    p.position.z() = 1.0 * k / 1000.0;  // home to 1 m up: beyond the legs' maximum length
    t.poses.push_back(p);
  }
  MotorSizing s;
  const Status status = size_motors(seed().rig, t, s);
  ASSERT_EQ(status, Status::StrokeAboveMax);
  EXPECT_EQ(s.status, status);
  EXPECT_GT(s.failed_index, 0u);
  EXPECT_EQ(s.samples.size(), s.failed_index);
  EXPECT_DOUBLE_EQ(s.failed_time, t.time(s.failed_index));
  EXPECT_GE(s.limit.leg, 0);
  EXPECT_GT(s.limit.value, s.limit.bound);
  // The sample before is inside the stroke.
  CommandReport r;
  EXPECT_EQ(compute_commands(seed().rig.model(), t.poses[s.failed_index - 1], r), Status::Ok);
}

TEST(MotorSizing, TooShortATrajectoryIsRefused) {
  Trajectory t;
  t.dt = 1e-3;
  t.poses.resize(1);
  MotorSizing s;
  EXPECT_EQ(size_motors(seed().rig, t, s), Status::NonFiniteInput);
}

TEST(MotorSizing, FigureHasTheOperatingPointsAndAClosedFourQuadrantEnvelope) {
  const Rig& rig = seed().rig;
  const ServoSpec& servo = rig.servo();
  const TorqueSpeedFigure fig = torque_speed_figure(rig, heave_sizing(), 16);
  for (int i = 0; i < 6; ++i) {
    ASSERT_EQ(fig.operating[i].speed.size(), heave_sizing().samples.size());
    EXPECT_EQ(fig.operating[i].torque[100], heave_sizing().samples[100].torque[i]);
  }
  const Curve& e = fig.envelope;
  ASSERT_EQ(e.speed.size(), e.torque.size());
  EXPECT_EQ(e.speed.front(), e.speed.back());
  EXPECT_EQ(e.torque.front(), e.torque.back());
  double lo_w = 0, hi_w = 0, lo_t = 0, hi_t = 0;
  bool corner = false;
  for (std::size_t j = 0; j < e.speed.size(); ++j) {
    lo_w = std::min(lo_w, e.speed[j]);
    hi_w = std::max(hi_w, e.speed[j]);
    lo_t = std::min(lo_t, e.torque[j]);
    hi_t = std::max(hi_t, e.torque[j]);
    corner = corner || (e.speed[j] == servo.peak_corner_speed && e.torque[j] == servo.torque_limit);
    EXPECT_DOUBLE_EQ(std::abs(e.torque[j]), peak_torque_at(servo, std::abs(e.speed[j])));
  }
  EXPECT_TRUE(corner);
  EXPECT_DOUBLE_EQ(hi_w, servo.max_speed);
  EXPECT_DOUBLE_EQ(lo_w, -servo.max_speed);
  EXPECT_DOUBLE_EQ(hi_t, servo.torque_limit);
  EXPECT_DOUBLE_EQ(lo_t, -servo.torque_limit);
  EXPECT_EQ(fig.continuous_torque, servo.continuous_torque);
  EXPECT_EQ(fig.max_speed, servo.max_speed);
}

}  // namespace
}  // namespace hexatwist
