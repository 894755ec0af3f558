// SPDX-License-Identifier: BSD-3-Clause
// Speed of the design subsystem (docs/theory/design.md §16-18): one membership test of the
// workspace searches, a column search, the seed's workspace volume, a map point, the design of the
// seed's U-joint axes, one (platform, pose) of the tolerance study and the norm of a 3-D normal
// vector's CDF. Run in Release: build/bench/bench_design (one thread each).
#include "bench_support.hpp"

namespace {

using namespace hexatwist;
using namespace hexatwist::bench;

void BM_WorkspaceMembership(benchmark::State& state) {
  const std::vector<Pose>& poses = random_poses();
  std::size_t k = 0;
  Vector6d command;
  LimitReport report;
  for (auto _ : state) {
    const Status s = motor_commands(model(), poses[k++ % poses.size()], Strategy::Compensated, command, report);
    benchmark::DoNotOptimize(s);
  }
}
BENCHMARK(BM_WorkspaceMembership)->Apply(add_statistics);

void BM_ColumnSearch(benchmark::State& state) {
  Box box;
  (void)workspace_bounds(model(), Vector3d::Zero(), box);
  std::vector<LineInterval> intervals;
  for (auto _ : state) {
    (void)line_intervals(model(), Vector3d::Zero(), Vector3d(0.1, -0.2, 0), Vector3d::UnitZ(), box.lower.z(),
                         box.upper.z(), WorkspaceOptions{}, intervals);
    benchmark::DoNotOptimize(intervals.data());
  }
}
BENCHMARK(BM_ColumnSearch)->Apply(add_statistics)->Unit(benchmark::kMicrosecond);

void BM_WorkspaceVolume(benchmark::State& state) {
  WorkspaceVolume v;
  for (auto _ : state) {
    (void)workspace_volume(model(), Vector3d::Zero(), VolumeOptions{}, v);
    benchmark::DoNotOptimize(v.volume);
  }
}
BENCHMARK(BM_WorkspaceVolume)->Unit(benchmark::kMillisecond)->Iterations(1);

void BM_MapPoint(benchmark::State& state) {
  const std::vector<Pose>& poses = random_poses();
  std::size_t k = 0;
  MapPoint p;
  for (auto _ : state) {
    (void)map_point(model(), poses[k++ % poses.size()], Strategy::Compensated, p);
    benchmark::DoNotOptimize(p.margin);
  }
}
BENCHMARK(BM_MapPoint)->Apply(add_statistics);

void BM_DesignAxes(benchmark::State& state) {
  RequiredWorkspace w;
  (void)required_workspace(model(), StudySpec{}, RequiredWorkspaceSpec{}, Strategy::Compensated, w);
  AxisDesign d;
  for (auto _ : state) {
    (void)design_axes(model(), w.poses, DesignOptions{}, d);
    benchmark::DoNotOptimize(d.objective_after);
  }
}
BENCHMARK(BM_DesignAxes)->Unit(benchmark::kMillisecond)->Iterations(1);

// One (platform, pose) pair: 20 platforms over 200 poses a call, the time per pair.
void BM_TolerancePair(benchmark::State& state) {
  const std::vector<Pose> poses(random_poses().begin(), random_poses().begin() + 200);
  ToleranceOptions o;
  ToleranceLinear linear;
  (void)tolerance_linear(model(), poses, o.sigmas, linear);
  ToleranceChunk c;
  std::uint64_t first = 0;
  for (auto _ : state) {
    (void)tolerance_chunk(model(), poses, o, first, 20, c, &linear);
    first += 20;
    benchmark::DoNotOptimize(c.max_point.data());
  }
  state.SetItemsProcessed(state.iterations() * 20 * 200);
}
BENCHMARK(BM_TolerancePair)->Unit(benchmark::kMillisecond)->Apply(add_statistics);

void BM_GaussianNormCdf(benchmark::State& state) {
  Matrix3d L;
  L << 1.0, 0, 0, 0.4, 0.3, 0, -0.2, 0.1, 0.05;
  const Matrix3d C = 1e-8 * L * L.transpose();
  double r = 1e-4;
  for (auto _ : state) {
    benchmark::DoNotOptimize(gaussian_norm_cdf(C, r));
    r = r < 3e-4 ? r * 1.01 : 1e-4;
  }
}
BENCHMARK(BM_GaussianNormCdf)->Apply(add_statistics);

}  // namespace

BENCHMARK_MAIN();
