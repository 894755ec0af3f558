// Speed of the mechanism's dynamics: inverse dynamics per call (six legs), the mass matrix, the
// forward dynamics, and the closed-loop simulation on the full model in simulated seconds per
// wall second. Run in Release: build/bench/bench_dynamics.
#include "bench_support.hpp"

#include "hexatwist/mechanism.hpp"

namespace {

using namespace hexatwist;
using namespace hexatwist::bench;

const Rig& rig() {
  static const Config c = default_config();
  return c.rig;
}

// Motions at the random poses, with velocities and accelerations of a fast motion simulator
// (up to 1 m/s, 90 deg/s, 5 m/s^2, 300 deg/s^2).
const std::vector<PlatformMotion>& motions() {
  static const std::vector<PlatformMotion> out = [] {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<PlatformMotion> m;
    for (const Pose& p : random_poses()) {
      Vector6d rate, acc;
      for (int k = 0; k < 3; ++k) rate[k] = u(rng), acc[k] = 5.0 * u(rng);
      for (int k = 3; k < 6; ++k) rate[k] = deg2rad(90) * u(rng), acc[k] = deg2rad(300) * u(rng);
      m.push_back(platform_motion(p, rate, acc));
    }
    return m;
  }();
  return out;
}

void BM_InverseDynamics(benchmark::State& state) {
  const auto& m = motions();
  InverseDynamics out;
  std::size_t i = 0;
  for (auto _ : state) {
    const Status s = inverse_dynamics(rig(), m[i++ & 1023], out);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(out.torque);
  }
}
BENCHMARK(BM_InverseDynamics)->Apply(add_statistics);

void BM_MassMatrix(benchmark::State& state) {
  const auto& m = motions();
  Matrix6d M;
  std::size_t i = 0;
  for (auto _ : state) {
    const Status s = mechanism_mass_matrix(rig(), m[i++ & 1023].placement, M);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(M);
  }
}
BENCHMARK(BM_MassMatrix)->Apply(add_statistics);

void BM_ForwardDynamics(benchmark::State& state) {
  const auto& m = motions();
  const Vector6d torque = Vector6d::Constant(5.0);
  Vector6d acc;
  std::size_t i = 0;
  for (auto _ : state) {
    const PlatformMotion& x = m[i++ & 1023];
    const Status s = forward_dynamics(rig(), x.placement, x.velocity, torque, acc);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(acc);
  }
}
BENCHMARK(BM_ForwardDynamics)->Apply(add_statistics);

// One compensated closed-loop run of a seed test (0 = Lz, 2 = Rz) on the full mechanism.
void BM_ClosedLoopSimulation(benchmark::State& state) {
  const Config config = default_config();
  const StudyTest test = seed_tests(config.study)[static_cast<std::size_t>(state.range(0))];
  const Trajectory trajectory = test_trajectory(config.study, test, config.rig.control_period());
  std::vector<SimulationSample> samples;
  SimulationIssue issue;
  for (auto _ : state) {
    if (simulate(config.rig, trajectory, {}, samples, issue) != Status::Ok) state.SkipWithError("simulation failed");
    benchmark::DoNotOptimize(samples.data());
  }
  state.SetLabel(test.name);
  state.counters["sim_s_per_wall_s"] =
      benchmark::Counter(trajectory.duration() * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ClosedLoopSimulation)->Arg(0)->Arg(2)->Apply([](benchmark::internal::Benchmark* b) {
  add_statistics(b);
  b->Unit(benchmark::kMillisecond);
});

}  // namespace

BENCHMARK_MAIN();
