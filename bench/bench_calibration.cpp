// SPDX-License-Identifier: BSD-3-Clause
// Speed of the calibration (issue 21: "the geometric identification of 40 stations in <= 2 s"):
// identify on the points at rest of a synthetic 40-station run, the geometric model (40
// parameters, both thread senses, 5-fold cross-validation, 1000 poses of predicted accuracy) and
// the basic model, and the steps a user sees around it; and where to measure (theory §13): the
// station planner as `hexatwist stations` runs it. The data are made once, through the same
// chain as `hexatwist synth` and `identify` (closed loop, real platform, tracker noise).
#include <benchmark/benchmark.h>

#include "bench_support.hpp"

namespace hexatwist::bench {
namespace {

struct StationsData {
  Config config = default_config();
  Trajectory trajectory;
  SyntheticLog log;
  ObservationSet observations;
};

// With `effects`, issue 27's real machine: the legs warm by 2 K over the run, 200 N/um under the
// load, 50 um of play, joints off by up to 1 mm.
StationsData make_stations_data(bool effects) {
  StationsData d;
  const Rig& rig = d.config.rig;
  StationsSpec spec;
  spec.count = 40;
  spec.seed = 3;
  d.trajectory = stations_trajectory(rig.model(), Strategy::Compensated, spec, rig.control_period());
  SynthesisOptions o;
  o.errors.lead_error.setConstant(0.02);
  o.errors.zero_offset = random_zero_offsets(0.5e-3, 9);
  o.errors.observation_offset_P = Vector3d(2e-3, -1.5e-3, 3e-3);
  random_geometry_errors(rig.model(), 1e-3, 0.0, 9, o.errors);
  if (effects) {
    o.errors.stiffness.setConstant(2.0e8);
    o.errors.play.setConstant(50e-6);
    o.errors.length_expansion = 11.5e-6;
    o.errors.lead_expansion = 11.5e-6;
    o.temperature_rise.setConstant(2.0);
  }
  o.seed = 9;
  SimulationIssue issue;
  if (synthesize(rig, d.trajectory, o, d.log, issue) != Status::Ok) std::abort();
  d.observations =
      observations_at_rest(rig.model(), timed_poses(d.trajectory), d.log.log, {}, Strategy::Compensated, 0.25);
  return d;
}

const StationsData& stations_data() {
  static const StationsData data = make_stations_data(false);
  return data;
}

const StationsData& stations_data_with_effects() {
  static const StationsData data = make_stations_data(true);
  return data;
}

void identify_with(benchmark::State& state, const IdentificationOptions& options,
                   const StationsData& d = stations_data()) {
  const Model& model = d.config.rig.model();
  Identification id;
  for (auto _ : state) {
    if (identify(model, d.observations.observations, id, options) != Status::Ok) {
      state.SkipWithError(id.reason.c_str());
      break;
    }
    benchmark::DoNotOptimize(id.estimate.data());
  }
  state.counters["observations"] = static_cast<double>(d.observations.observations.size());
  state.counters["parameters"] = static_cast<double>(id.parameters.size());
}

// What `hexatwist identify` runs by default: the geometric model with its decisions, the
// cross-validation and the predicted accuracy.
void BM_IdentifyGeometry40Stations(benchmark::State& state) { identify_with(state, IdentificationOptions{}); }
BENCHMARK(BM_IdentifyGeometry40Stations)->Unit(benchmark::kMillisecond)->Apply(add_statistics);

// Issue 27: identify with every effect for 40 stations in <= 2 s, as `hexatwist identify` runs it
// by default on the real machine's log (--effects auto: the forward selection's trial fits, then
// the fit with load, play and heat, its cross-validation and accuracy map).
void BM_IdentifyWithEveryEffect40Stations(benchmark::State& state) {
  IdentificationOptions o;
  o.auto_effects = true;
  identify_with(state, o, stations_data_with_effects());
  Identification id;
  IdentificationOptions check = o;
  check.folds = 0;
  check.accuracy_poses = 0;
  (void)identify(stations_data_with_effects().config.rig.model(),
                 stations_data_with_effects().observations.observations, id, check);
  state.SetLabel(id.parameters.effects().names());
}
BENCHMARK(BM_IdentifyWithEveryEffect40Stations)->Unit(benchmark::kMillisecond)->Apply(add_statistics);

// The same with the effects named (--effects heat,load,play): no selection.
void BM_IdentifyWithEveryEffectNamed40Stations(benchmark::State& state) {
  IdentificationOptions o;
  o.effects = effect_fit("heat,load,play");
  identify_with(state, o, stations_data_with_effects());
}
BENCHMARK(BM_IdentifyWithEveryEffectNamed40Stations)->Unit(benchmark::kMillisecond)->Apply(add_statistics);

// The fit and its decisions alone (no cross-validation, no accuracy map).
void BM_IdentifyGeometryFitOnly(benchmark::State& state) {
  IdentificationOptions o;
  o.folds = 0;
  o.accuracy_poses = 0;
  identify_with(state, o);
}
BENCHMARK(BM_IdentifyGeometryFitOnly)->Unit(benchmark::kMillisecond)->Apply(add_statistics);

// The points at rest and their commands, from the log and the run (before identify).
void BM_ObservationsAtRest(benchmark::State& state) {
  const StationsData& d = stations_data();
  const TimedPoses commanded = timed_poses(d.trajectory);
  for (auto _ : state) {
    ObservationSet set =
        observations_at_rest(d.config.rig.model(), commanded, d.log.log, {}, Strategy::Compensated, 0.25);
    benchmark::DoNotOptimize(set.observations.data());
  }
}
BENCHMARK(BM_ObservationsAtRest)->Unit(benchmark::kMillisecond)->Apply(add_statistics);

// plan_stations on the seed platform, 20 and 40 stations from the default 3000 candidates, the
// predicted accuracy of the plan and of random stations included (what `hexatwist stations` runs),
// and with the exchange off (the candidates' sensitivities and the greedy start alone).
void BM_PlanStations(benchmark::State& state) {
  StationPlanSpec spec;
  spec.run.count = static_cast<int>(state.range(0));
  spec.max_sweeps = static_cast<int>(state.range(1));
  StationPlan plan;
  for (auto _ : state) {
    if (plan_stations(model(), Strategy::Compensated, spec, plan) != Status::Ok) {
      state.SkipWithError(plan.reason.c_str());
      break;
    }
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
}  // namespace hexatwist::bench

BENCHMARK_MAIN();
