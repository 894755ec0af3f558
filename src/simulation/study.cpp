// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/simulation/study.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <tuple>

#include "hexatwist/error.hpp"

namespace hexatwist {

std::vector<StudyTest> seed_tests(const StudySpec& spec) {
  return {
      {"Lz", "translation along z", 2, spec.linear_amplitude},
      {"Lx", "translation along x", 0, spec.linear_amplitude},
      {"Rz", "rotation about z", 5, spec.angular_amplitude},
      {"Ry", "rotation about y", 4, spec.angular_amplitude},
  };
}

namespace {

void study_range(double v, double lo, double hi, const char* field, const char* unit, bool lo_closed = false) {
  if (std::isfinite(v) && (lo_closed ? v >= lo : v > lo) && v <= hi) return;
  throw Error(
      fmt::format("{}: expected {} {:g} and at most {:g} {}, got {}", field, lo_closed ? ">=" : ">", lo, hi, unit, v));
}

}  // namespace

void check_study(const StudySpec& spec, double dt) {
  study_range(spec.linear_amplitude, 0.0, 100.0, "study.linear_amplitude", "m");
  study_range(rad2deg(spec.angular_amplitude), 0.0, 180.0, "study.angular_amplitude_deg", "deg");
  study_range(spec.dwell, 0.0, 3600.0, "study.dwell", "s", true);
  for (const bool linear : {true, false}) {
    const MotionLimits& m = linear ? spec.linear : spec.angular;
    const double scale = linear ? 1.0 : rad2deg(1.0);
    const char* unit = linear ? "m" : "deg";
    const std::string block = linear ? "study.linear" : "study.angular_deg";
    for (const auto& [value, key, per] :
         {std::tuple{m.velocity, "velocity", "/s"}, std::tuple{m.acceleration, "acceleration", "/s^2"},
          std::tuple{m.jerk, "jerk", "/s^3"}})
      study_range(scale * value, 0.0, 1e6, (block + "." + key).c_str(), fmt::format("{}{}", unit, per).c_str());
    // The sweep home -> +a -> -a -> home with four rests, in samples at the control period.
    const double amplitude = linear ? spec.linear_amplitude : spec.angular_amplitude;
    const double duration = 4.0 * spec.dwell + 2.0 * JerkLimitedMove(amplitude, m).duration() +
                            JerkLimitedMove(2.0 * amplitude, m).duration();
    if (!(duration / dt + 1.0 <= static_cast<double>(kMaxTrajectorySamples)))
      throw Error(
          fmt::format("{}: a test takes {:.6g} s with these limits: more than {} samples at the control period "
                      "{:g} s; give a larger velocity, acceleration or jerk",
                      block, duration, kMaxTrajectorySamples, dt));
  }
}

StudyTest study_test(const StudySpec& spec, std::string_view name) {
  for (StudyTest& t : seed_tests(spec))
    if (t.name == name) return t;
  std::string shown;
  for (const char c : name.substr(0, 40)) {
    const auto u = static_cast<unsigned char>(c);
    shown += u < 0x20 || u == 0x7f ? fmt::format("\\x{:02x}", u) : std::string(1, c);
  }
  throw Error(fmt::format("unknown test '{}'; expected Lz, Lx, Rz or Ry", shown));
}

Trajectory test_trajectory(const StudySpec& spec, const StudyTest& test, double dt) {
  const MotionLimits& limits = test.coordinate < 3 ? spec.linear : spec.angular;
  return sweep_trajectory(test.coordinate, test.amplitude, limits, spec.dwell, dt);
}

ErrorStats error_stats(const std::vector<double>& series) noexcept {
  ErrorStats s;
  double sum2 = 0.0;
  for (const double e : series) {
    s.max = std::max(s.max, e);
    sum2 += e * e;
  }
  if (!series.empty()) s.rms = std::sqrt(sum2 / static_cast<double>(series.size()));
  return s;
}

RunMetrics run_metrics(const Rig& rig, const std::vector<SimulationSample>& samples) noexcept {
  RunMetrics m;
  for (const SimulationSample& s : samples) {
    const double torque = s.torque.cwiseAbs().maxCoeff();
    m.max_torque = std::max(m.max_torque, torque);
    m.saturated_ticks += torque >= rig.servo().torque_limit ? 1 : 0;
    m.max_following_error = std::max(m.max_following_error, (s.command - s.motor).cwiseAbs().maxCoeff());
    const Matrix3d dR = rotation_from_rpy(s.actual.tail<3>()) * rotation_from_rpy(s.desired.tail<3>()).transpose();
    m.max_orientation_error = std::max(m.max_orientation_error, Eigen::AngleAxisd(dR).angle());
  }
  return m;
}

namespace {

// The statistics of a run from its samples and its twist-free series.
void summarize(TestRun& run) {
  const ErrorStats tracking = error_stats(run.tracking_only);
  for (StrategyRun* out : {&run.conventional, &run.compensated}) {
    const std::size_t n = out->samples.size();
    std::vector<double> total(n), twist_only(n);
    for (std::size_t k = 0; k < n; ++k) {
      total[k] = out->samples[k].error;
      twist_only[k] = out->samples[k].error_twist_only;
    }
    out->total = error_stats(total);
    out->twist_only = error_stats(twist_only);
    out->tracking_only = tracking;
  }
}

}  // namespace

Status run_test(const Rig& rig, const Trajectory& trajectory, TestRun& run, SimulationIssue& issue,
                const std::function<void(std::size_t, std::size_t)>& progress) {
  const std::size_t n = trajectory.poses.size();
  SimulationOptions options;
  int part = 0;
  if (progress) options.progress = [&](std::size_t done, std::size_t) { progress(part * n + done, 3 * n); };

  std::vector<SimulationSample> samples;
  options.twist_in_plant = false;
  if (const Status s = simulate(rig, trajectory, options, samples, issue); s != Status::Ok) return s;
  run.tracking_only.resize(samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k) run.tracking_only[k] = samples[k].error;

  options.twist_in_plant = true;
  for (const Strategy strategy : {Strategy::Conventional, Strategy::Compensated}) {
    ++part;
    options.strategy = strategy;
    StrategyRun& out = strategy == Strategy::Conventional ? run.conventional : run.compensated;
    if (const Status s = simulate(rig, trajectory, options, out.samples, issue); s != Status::Ok) return s;
  }
  summarize(run);
  return Status::Ok;
}

void keep_after(TestRun& run, double t) {
  const auto& ticks = run.conventional.samples;
  std::size_t drop = 0;
  while (drop < ticks.size() && ticks[drop].time <= t) ++drop;
  const auto cut = [drop](auto& v) {
    v.erase(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(std::min(drop, v.size())));
  };
  cut(run.conventional.samples);
  cut(run.compensated.samples);
  cut(run.tracking_only);
  summarize(run);
}

}  // namespace hexatwist
