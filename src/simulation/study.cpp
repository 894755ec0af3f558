#include "hexatwist/simulation/study.hpp"

#include <algorithm>
#include <cmath>

namespace hexatwist {

std::vector<StudyTest> seed_tests(const StudySpec& spec) {
  return {
      {"Lz", "translation along z", 2, spec.linear_amplitude},
      {"Lx", "translation along x", 0, spec.linear_amplitude},
      {"Rz", "rotation about z", 5, spec.angular_amplitude},
      {"Ry", "rotation about y", 4, spec.angular_amplitude},
  };
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
