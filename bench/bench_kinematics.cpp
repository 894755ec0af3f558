// Real-time path timings: compensated commands, warm and cold twist-aware forward kinematics.
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

}  // namespace

BENCHMARK_MAIN();
