// SPDX-License-Identifier: BSD-3-Clause
// The log's clock from the rests (log_clock.hpp): a log recorded on a clock of its own (another
// start, another rate, noise at rest) is put back on the run's time within its reported
// uncertainty; a log of another run, or one with too few rests, is refused with a reason.
#include <gtest/gtest.h>

#include <random>

#include "hexatwist/calibration/log_clock.hpp"
#include "hexatwist/calibration/stations.hpp"
#include "hexatwist/io/config.hpp"
#include "hexatwist/kinematics/pose.hpp"
#include "hexatwist/motion/trajectory.hpp"

namespace hexatwist {
namespace {

TimedPoses timed(const Trajectory& run) {
  TimedPoses c;
  for (std::size_t k = 0; k < run.poses.size(); ++k) {
    c.t.push_back(run.time(k));
    c.poses.push_back(run.poses[k]);
  }
  return c;
}

// The tracker's log of `run`: a target on the platform (as point A, off its origin, so that rotations
// move it too) in a tracker frame turned and moved, with
// `noise` [m] per axis, sampled at 100 Hz on the log's clock (t_log = offset + scale t_run) from
// `from` to `to` of the run's time.
PointLog tracker_log(const Trajectory& run, double offset, double scale, double from, double to, double noise,
                     std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, noise);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vector3d(0.2, -0.3, 1.0).normalized()).toRotationMatrix();
  const Vector3d shift(3.0, -1.5, 0.4);
  PointLog log;
  log.source = "tracker.csv";
  log.target_names = {"A"};
  for (double t_log = offset + scale * from; t_log <= offset + scale * to; t_log += 0.01) {
    const double t = (t_log - offset) / scale;
    const auto k = static_cast<std::size_t>(std::lround((t - run.t0) / run.dt));
    const Pose& pose = run.poses[std::min(k, run.poses.size() - 1)];
    const Vector3d p = R * (pose.position + rotation_from_rpy(pose.rpy) * Vector3d(0.3, -0.2, 0.15)) + shift;
    log.stamps.push_back(t_log);
    log.points_T.push_back(p + Vector3d(n(rng), n(rng), n(rng)));
    log.targets.push_back(0);
    log.lines.push_back(static_cast<int>(log.stamps.size()) + 1);
  }
  return log;
}

Trajectory station_run_of(std::uint64_t seed) {
  const Model model = default_model();
  StationsSpec spec;
  spec.count = 15;
  spec.seed = seed;
  return stations_trajectory(model, Strategy::Compensated, spec, 1e-3);
}

TEST(LogClock, ALogOnAClockOfItsOwnIsPutBackOnTheRunsTimeWithinItsUncertainty) {
  const Trajectory run = station_run_of(3);
  const TimedPoses commanded = timed(run);
  int k = 0;
  for (const auto& [offset, scale, from, to] :
       std::vector<std::array<double, 4>>{{12.345, 1.0, 0.4, run.duration() - 0.3},  // started late into the first rest
                                          {-3.2, 1.0 + 2e-4, 0.0, run.duration()},   // a clock 200 ppm fast
                                          {1000.0, 1.0 - 5e-4, 0.7, run.duration() - 0.6}}) {  // both ends cut
    const PointLog log = tracker_log(run, offset, scale, from, to, 10e-6, 11 + k++);
    ClockFit fit;
    ASSERT_EQ(fit_log_clock(commanded, log, {}, ClockFitOptions{}, fit), Status::Ok) << fit.reason;
    EXPECT_EQ(fit.run_rests, 17);  // home, 15 stations, home
    EXPECT_EQ(fit.matched, fit.log_rests - 2);
    EXPECT_GE(fit.matched, 13);
    // Within 4 standard deviations of the truth, and those about 10 ms and 100 ppm: the still
    // target is found a few tens of ms into and out of each rest, by how fast the move into it
    // and the move out of it carry the target (measured: worst misfit 31-37 ms, offset sd 7-11 ms).
    EXPECT_NEAR(fit.offset, offset, 4 * fit.offset_sd + 1e-4) << fit.offset_sd;
    EXPECT_NEAR(fit.scale, scale, 4 * fit.scale_sd + 1e-7) << fit.scale_sd;
    EXPECT_LT(fit.offset_sd, 0.02);
    EXPECT_LT(fit.scale_sd, 1e-3);
    EXPECT_LT(fit.worst, 0.06);
    // The alignment puts every stamp back on the run's time.
    const std::vector<double> t = trajectory_times(log, fit.alignment());
    for (std::size_t i = 0; i < t.size(); i += 97) EXPECT_NEAR(t[i], (log.stamps[i] - offset) / scale, 0.02) << i;
  }
}

TEST(LogClock, ALogOfAnotherRunOrWithTooFewRestsIsRefusedWithAReason) {
  const Trajectory run = station_run_of(3);
  const TimedPoses commanded = timed(run);
  ClockFit fit;
  const PointLog other = tracker_log(station_run_of(4), 5.0, 1.0, 0.3, station_run_of(4).duration() - 0.3, 10e-6, 2);
  EXPECT_EQ(fit_log_clock(commanded, other, {}, ClockFitOptions{}, fit), Status::InvalidArgument);
  EXPECT_NE(fit.reason.find("do not"), std::string::npos) << fit.reason;
  EXPECT_NE(fit.reason.find("another run"), std::string::npos) << fit.reason;
  // The first few seconds only: two rests inside.
  const PointLog short_log = tracker_log(run, 0.0, 1.0, 0.0, 6.0, 10e-6, 3);
  EXPECT_EQ(fit_log_clock(commanded, short_log, {}, ClockFitOptions{}, fit), Status::InvalidArgument);
  EXPECT_NE(fit.reason.find("at least 5 are needed"), std::string::npos) << fit.reason;
}

}  // namespace
}  // namespace hexatwist
