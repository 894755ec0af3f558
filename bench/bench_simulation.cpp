// Speed of the closed-loop simulation: simulated seconds per wall-clock second, for one run of a
// seed test (the default study is 12 such runs) and for one control tick.
#include <benchmark/benchmark.h>

#include <algorithm>

#include "hexatwist/hexatwist.hpp"

namespace {

using namespace hexatwist;

void add_statistics(benchmark::internal::Benchmark* b) {
  b->Repetitions(5)->ReportAggregatesOnly(true)->ComputeStatistics(
      "max", [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); });
  b->Unit(benchmark::kMillisecond);
}

// One compensated run of a seed test (Lz or Rz) with twist in the plant; the counter
// "sim_s_per_wall_s" is simulated time over wall time.
void BM_SimulateSeedTest(benchmark::State& state) {
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
BENCHMARK(BM_SimulateSeedTest)->Arg(0)->Arg(2)->Apply(add_statistics);

}  // namespace

BENCHMARK_MAIN();
