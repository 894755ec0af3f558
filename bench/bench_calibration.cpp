// Speed of the calibration subsystem's planner (docs/theory/calibration.md §13, "Where to measure"):
// plan_stations on the seed platform, 20 and 40 stations from the default 3000 candidates, the
// predicted accuracy of the plan and of random stations included (what `hexatwist stations` runs),
// and with the exchange off (the candidates' sensitivities and the greedy start alone). Run in
// Release: build/bench/bench_calibration (one thread each); median and worst of the repetitions.
#include "bench_support.hpp"

namespace {

using namespace hexatwist;
using namespace hexatwist::bench;

void BM_PlanStations(benchmark::State& state) {
  StationPlanSpec spec;
  spec.run.count = static_cast<int>(state.range(0));
  spec.max_sweeps = static_cast<int>(state.range(1));
  StationPlan plan;
  for (auto _ : state) {
    if (plan_stations(model(), Strategy::Compensated, spec, plan) != Status::Ok)
      state.SkipWithError(plan.reason.c_str());
    benchmark::DoNotOptimize(plan.planned.criterion);
  }
  state.counters["exchanges"] = plan.exchanges;
}
BENCHMARK(BM_PlanStations)
    ->ArgsProduct({{20, 40}, {50, 0}})
    ->ArgNames({"stations", "sweeps"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true)
    ->ComputeStatistics("max", [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); });

}  // namespace

BENCHMARK_MAIN();
