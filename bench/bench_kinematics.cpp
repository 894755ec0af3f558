// Real-time path timings: compensated commands, warm and cold twist-aware forward kinematics.
// Run in Release: build/bench/bench_kinematics. Each benchmark repeats 15 times and reports the
// median, the worst repetition (max) and the best (min) of the per-call mean.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <vector>

#include "hexatwist/hexatwist.hpp"

namespace {

using namespace hexatwist;

const Model& model() {
  static const Model m = default_model();
  return m;
}

// Poses inside every limit, spread over the seed's test range (+-0.5 m, +-30 deg).
const std::vector<Pose>& random_poses() {
  static const std::vector<Pose> poses = [] {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> pos(-0.5, 0.5), rot(-deg2rad(30), deg2rad(30));
    std::vector<Pose> out;
    CommandReport rep;
    while (out.size() < 1024) {
      Pose p;
      p.position = {pos(rng), pos(rng), pos(rng)};
      p.rpy = {rot(rng), rot(rng), rot(rng)};
      if (compute_commands(model(), p, rep) == Status::Ok) out.push_back(p);
    }
    return out;
  }();
  return poses;
}

// A realistic motion sampled at 1 kHz: all six axes moving (up to 0.2 m and 15 deg, 0.35-0.65 Hz),
// inside every limit.
struct Motion {
  std::vector<Placement> poses;
  std::vector<Vector6d> motor;  // compensated commands = the motor-side lengths of each pose
};
const Motion& motion() {
  static const Motion m = [] {
    Motion out;
    for (int k = 0; k < 10000; ++k) {
      const double t = 1e-3 * k, w = 2 * kPi * 0.5;
      Pose p;
      p.position = {0.2 * std::sin(w * t), 0.15 * std::sin(1.3 * w * t), 0.15 * std::sin(0.7 * w * t)};
      p.rpy = {deg2rad(6) * std::sin(0.9 * w * t), deg2rad(10) * std::sin(1.1 * w * t), deg2rad(15) * std::sin(w * t)};
      Vector6d cmd;
      LimitReport lim;
      if (motor_commands(model(), p, Strategy::Compensated, cmd, lim) != Status::Ok) std::abort();
      out.poses.push_back(placement_from_pose(p));
      out.motor.push_back(cmd);
    }
    return out;
  }();
  return m;
}

void add_statistics(benchmark::internal::Benchmark* b) {
  b->Repetitions(15)->ReportAggregatesOnly(true)->ComputeStatistics("max", [](const std::vector<double>& v) {
    return *std::max_element(v.begin(), v.end());
  })->ComputeStatistics("min", [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); });
}

// Motor commands for one strategy, cycling through the random poses.
void commands(benchmark::State& state, Strategy strategy) {
  const auto& poses = random_poses();
  Vector6d cmd;
  LimitReport lim;
  std::size_t i = 0;
  for (auto _ : state) {
    const Status s = motor_commands(model(), poses[i++ & 1023], strategy, cmd, lim);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(cmd);
  }
}

void BM_CompensatedCommand(benchmark::State& state) { commands(state, Strategy::Compensated); }
BENCHMARK(BM_CompensatedCommand)->Apply(add_statistics);

void BM_ConventionalCommand(benchmark::State& state) { commands(state, Strategy::Conventional); }
BENCHMARK(BM_ConventionalCommand)->Apply(add_statistics);

void BM_TwistAwareFkWarm(benchmark::State& state) {
  // From the pose 1 ms earlier on the motion, as a servo loop at 1 kHz does.
  const Motion& m = motion();
  FkResult r;
  std::size_t k = 1;
  long iterations = 0;
  for (auto _ : state) {
    const Status s = forward_kinematics(model(), m.motor[k], LengthKind::Motor, m.poses[k - 1], r);
    benchmark::DoNotOptimize(s);
    iterations += r.iterations;
    if (++k == m.poses.size()) k = 1;
  }
  state.counters["newton_iterations"] = benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_TwistAwareFkWarm)->Apply(add_statistics);

void BM_TwistAwareFkCold(benchmark::State& state) {
  // From home to poses anywhere in the seed's test range.
  const auto& poses = random_poses();
  std::vector<Vector6d> cmds;
  for (const Pose& p : poses) {
    Vector6d c;
    LimitReport lim;
    if (motor_commands(model(), p, Strategy::Compensated, c, lim) != Status::Ok) std::abort();
    cmds.push_back(c);
  }
  FkResult r;
  std::size_t i = 0;
  long iterations = 0;
  for (auto _ : state) {
    const Status s = forward_kinematics(model(), cmds[i++ & 1023], LengthKind::Motor, Placement{}, r);
    benchmark::DoNotOptimize(s);
    iterations += r.iterations;
  }
  state.counters["newton_iterations"] = benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_TwistAwareFkCold)->Apply(add_statistics);

void BM_GeometricFkWarm(benchmark::State& state) {
  const Motion& m = motion();
  std::vector<Vector6d> lengths;
  for (const Placement& x : m.poses) {
    LegState st;
    if (inverse_kinematics(model(), x, st) != Status::Ok) std::abort();
    lengths.push_back(st.length);
  }
  FkResult r;
  std::size_t k = 1;
  for (auto _ : state) {
    const Status s = forward_kinematics(model(), lengths[k], LengthKind::Geometric, m.poses[k - 1], r);
    benchmark::DoNotOptimize(s);
    if (++k == m.poses.size()) k = 1;
  }
}
BENCHMARK(BM_GeometricFkWarm)->Apply(add_statistics);

}  // namespace

BENCHMARK_MAIN();
