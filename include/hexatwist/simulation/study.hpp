// SPDX-License-Identifier: BSD-3-Clause
// The paper's study (§4, Table 1, Figs. 6-9): four sweeps from home, each simulated with the
// conventional and the compensated command, and the observation error split into what the twist
// does, what the servo does, and what the closed loop does.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "hexatwist/simulation/simulation.hpp"

namespace hexatwist {

/// The tests' motion (defaults: the seed's stated range, speeds of a large motion platform).
struct StudySpec {
  double linear_amplitude = 0.5;                                       ///< sweep amplitude of the translations [m]
  double angular_amplitude = deg2rad(30.0);                            ///< sweep amplitude of the rotations [rad]
  MotionLimits linear{0.2, 0.5, 2.5};                                  ///< [m/s, m/s^2, m/s^3]
  MotionLimits angular{deg2rad(15.0), deg2rad(45.0), deg2rad(180.0)};  ///< [rad/s, rad/s^2, rad/s^3]
  double dwell = 0.5;                                                  ///< rest before, between and after the moves [s]
};

/// One of the paper's tests: a sweep of one pose coordinate through +-amplitude.
struct StudyTest {
  std::string name;         ///< "Lz", "Lx", "Rz", "Ry" (the paper's names)
  std::string description;  ///< "translation along z", ...
  int coordinate = 0;       ///< 0..5 = x, y, z, roll, pitch, yaw
  double amplitude = 0.0;   ///< [m or rad]
};

/// Checks the study's numbers against their plausible ranges (configs/seed.yaml lists them):
/// linear_amplitude in (0, 100] m, angular_amplitude in (0, 180] deg, each velocity, acceleration
/// and jerk in (0, 1e6] (m or deg per s, s^2, s^3), dwell in [0, 3600] s, and every test at most
/// kMaxTrajectorySamples samples long at the control period `dt` [s] (a jerk of 1e-12 m/s^3 makes a
/// move of days). Throws Error "study.<field>: ..." with the configuration's key (study.linear,
/// study.angular_deg.jerk, ...).
void check_study(const StudySpec& spec, double dt);

/// The paper's four tests in Table 1's order: Lz, Lx, Rz, Ry. Throws Error for a bad spec.
std::vector<StudyTest> seed_tests(const StudySpec& spec);

/// The test named `name` ("Lz", "Lx", "Rz" or "Ry") of seed_tests(spec). Throws Error "unknown test
/// 'NAME'; expected Lz, Lx, Rz or Ry" for another name (the CLI and Python put the argument's name before it).
StudyTest study_test(const StudySpec& spec, std::string_view name);

/// The test's trajectory: home -> +amplitude -> -amplitude -> home, jerk-limited, sampled every dt.
Trajectory test_trajectory(const StudySpec& spec, const StudyTest& test, double dt);

/// Largest and root-mean-square value of an error series [m].
struct ErrorStats {
  double max = 0.0;
  double rms = 0.0;
};
ErrorStats error_stats(const std::vector<double>& series) noexcept;

/// One strategy's run and its three errors.
struct StrategyRun {
  std::vector<SimulationSample> samples;  ///< the closed loop, tick by tick
  ErrorStats total;                       ///< closed loop as simulated
  ErrorStats twist_only;                  ///< perfect servos, quasi-static: what the twist alone does
  ErrorStats tracking_only;  ///< the same servos with no twist in the plant (the same run for both strategies)
};

/// What a strategy's run did besides its errors: the study's table, summary.json and Python's study()
/// report these.
struct RunMetrics {
  double max_torque = 0.0;             ///< largest |motor torque| of any leg at any tick [N m]
  std::size_t saturated_ticks = 0;     ///< ticks with some motor at servo.torque_limit [-]
  double max_following_error = 0.0;    ///< largest |motor-side target - true motor-side length| of any leg [m]
  double max_orientation_error = 0.0;  ///< largest angle between the real and the commanded orientation [rad]
};

/// The metrics of a run's ticks (`rig` gives the torque limit).
RunMetrics run_metrics(const Rig& rig, const std::vector<SimulationSample>& samples) noexcept;

/// A test's results.
struct TestRun {
  StrategyRun conventional;
  StrategyRun compensated;
  std::vector<double> tracking_only;  ///< observation error of the twist-free run, per tick [m]
};

/// Runs the three simulations of a trajectory: twist-free (tracking only), conventional and
/// compensated. Stops at the first failure (issue says where).
[[nodiscard]] Status run_test(const Rig& rig, const Trajectory& trajectory, TestRun& run, SimulationIssue& issue,
                              const std::function<void(std::size_t, std::size_t)>& progress = {});

/// Keeps the ticks of a run after time `t` [s] (e.g. a measured test after its calibration moves:
/// the part that is compared with the measurement) and recomputes its statistics over them.
void keep_after(TestRun& run, double t);

}  // namespace hexatwist
