// SPDX-License-Identifier: BSD-3-Clause
// Real-time path timings: compensated commands, warm and cold twist-aware forward kinematics; and
// batches of 10^6 poses across the lanes (batch.hpp) beside the same poses one call at a time.
// Run in Release: build/bench/bench_kinematics. Each benchmark repeats 15 times and reports the
// median, the worst repetition (max) and the best (min) of the per-call mean.
#include "bench_support.hpp"

namespace {

using namespace hexatwist;
using namespace hexatwist::bench;

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
  state.counters["newton_iterations"] =
      benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
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
  state.counters["newton_iterations"] =
      benchmark::Counter(static_cast<double>(iterations), benchmark::Counter::kAvgIterations);
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

// 10^6 poses as an (N, 6) array, drawn as bench/python/bench_python.py draws them (+-0.2 m,
// +-0.15 rad, uniform; about 80 % inside every limit of the seed), or only those inside.
const std::vector<double>& batch_rows(bool inside_only) {
  static const auto make = [](bool inside) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<double> rows;
    rows.reserve(6'000'000);
    CommandReport rep;
    while (rows.size() < 6'000'000) {
      Vector6d q;
      for (int k = 0; k < 6; ++k) q[k] = u(rng) * (k < 3 ? 0.2 : 0.15);
      if (inside && compute_commands(model(), Pose::from_vector(q), rep) != Status::Ok) continue;
      rows.insert(rows.end(), q.data(), q.data() + 6);
    }
    return rows;
  };
  static const std::vector<double> mixed = make(false), inside = make(true);
  return inside_only ? inside : mixed;
}

// Per-pose time of a batch benchmark: the time per iteration divided by the poses.
void per_pose(benchmark::State& state, std::size_t poses) {
  state.counters["per_pose"] = benchmark::Counter(
      static_cast<double>(poses), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void batch_commands(benchmark::State& state, Strategy strategy, bool inside_only) {
  const std::vector<double>& rows = batch_rows(inside_only);
  const std::size_t n = rows.size() / 6;
  std::vector<double> commands(rows.size());
  std::vector<LimitReport> reports(n);
  long ok = 0;
  for (auto _ : state) {
    const Status s = motor_commands_batch(model(), rows, strategy, commands, reports);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(commands.data());
  }
  for (const LimitReport& r : reports) ok += r.status == Status::Ok;
  state.counters["ok"] = static_cast<double>(ok) / static_cast<double>(n);
  per_pose(state, n);
}

// The same 10^6 poses one motor_commands call each, as the batch path replaces.
void BM_SinglePoseLoopCompensated1e6(benchmark::State& state) {
  const std::vector<double>& rows = batch_rows(false);
  const std::size_t n = rows.size() / 6;
  std::vector<double> commands(rows.size());
  for (auto _ : state) {
    Vector6d c;
    LimitReport r;
    for (std::size_t i = 0; i < n; ++i) {
      const Pose p = Pose::from_vector(Eigen::Map<const Vector6d>(rows.data() + 6 * i));
      if (motor_commands(model(), p, Strategy::Compensated, c, r) == Status::Ok)
        std::copy(c.data(), c.data() + 6, commands.data() + 6 * i);
    }
    benchmark::DoNotOptimize(commands.data());
  }
  per_pose(state, n);
}
BENCHMARK(BM_SinglePoseLoopCompensated1e6)->Apply(add_statistics)->Unit(benchmark::kMillisecond);

void BM_BatchCompensated1e6(benchmark::State& state) { batch_commands(state, Strategy::Compensated, false); }
BENCHMARK(BM_BatchCompensated1e6)->Apply(add_statistics)->Unit(benchmark::kMillisecond);

void BM_BatchCompensatedInside1e6(benchmark::State& state) { batch_commands(state, Strategy::Compensated, true); }
BENCHMARK(BM_BatchCompensatedInside1e6)->Apply(add_statistics)->Unit(benchmark::kMillisecond);

void BM_BatchConventional1e6(benchmark::State& state) { batch_commands(state, Strategy::Conventional, false); }
BENCHMARK(BM_BatchConventional1e6)->Apply(add_statistics)->Unit(benchmark::kMillisecond);

void BM_BatchLengths1e6(benchmark::State& state) {
  const std::vector<double>& rows = batch_rows(false);
  const std::size_t n = rows.size() / 6;
  std::vector<double> lengths(rows.size());
  std::vector<Status> status(n);
  for (auto _ : state) {
    const Status s = leg_lengths_batch(model(), rows, lengths, status);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(lengths.data());
  }
  per_pose(state, n);
}
BENCHMARK(BM_BatchLengths1e6)->Apply(add_statistics)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
