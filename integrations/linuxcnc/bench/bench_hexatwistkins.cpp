// SPDX-License-Identifier: BSD-3-Clause
// The LinuxCNC module's kinematics functions called directly, as LinuxCNC's motion calls them:
// kinematicsInverse for a world pose (mm, deg), and kinematicsForward warm from the previous
// solution along a 1 kHz motion, and cold (after a failure motion passes the home pose). Beside
// them, the C API and the library calls they wrap, to show what the module adds. Release:
// build/integrations/linuxcnc/bench/bench_hexatwistkins.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <vector>

#include "hexatwist/c/hexatwist.h"

// LinuxCNC's EmcPose (emcpos.h: PmCartesian tran; a, b, c; u, v, w), laid out the same.
struct WorldPose {
  double x, y, z, a, b, c, u, v, w;
};

extern "C" {
int rtapi_app_main(void);
int kinematicsInverse(const WorldPose* world, double* joints, const unsigned long* iflags, unsigned long* fflags);
int kinematicsForward(const double* joints, WorldPose* world, const unsigned long* fflags, unsigned long* iflags);
int kinematicsHome(WorldPose* world, double* joints, unsigned long* fflags, unsigned long* iflags);
}

namespace {

constexpr double kHomeZ = 1511.0;  // the seed platform's home height [mm]

// A motion simulator's motion at 1 kHz (the library benchmark's): world poses and their joints.
struct Motion {
  std::vector<WorldPose> world;
  std::vector<std::vector<double>> joints;
};

const Motion& motion() {
  static const Motion m = [] {
    if (rtapi_app_main() != 0) std::abort();  // the embedded seed platform, compensated, mm
    Motion out;
    unsigned long f = 0, i = 0;
    WorldPose home{0, 0, kHomeZ, 0, 0, 0, 0, 0, 0};
    std::vector<double> j(6);
    if (kinematicsHome(&home, j.data(), &f, &i) != 0) std::abort();
    const double w = 2 * 3.14159265358979323846 * 0.5;
    for (int k = 0; k <= 4000; ++k) {
      const double t = 1e-3 * k;
      WorldPose p{200 * std::sin(w * t),
                  150 * std::sin(1.3 * w * t),
                  kHomeZ + 150 * std::sin(0.7 * w * t),
                  6 * std::sin(0.9 * w * t),
                  10 * std::sin(1.1 * w * t),
                  15 * std::sin(w * t),
                  0,
                  0,
                  0};
      if (kinematicsInverse(&p, j.data(), &i, &f) != 0) std::abort();
      out.world.push_back(p);
      out.joints.push_back(j);
    }
    return out;
  }();
  return m;
}

void add_statistics(benchmark::internal::Benchmark* b) {
  b->Repetitions(15)->ReportAggregatesOnly(true)->ComputeStatistics("max", [](const std::vector<double>& v) {
    double m = v[0];
    for (double x : v) m = std::max(m, x);
    return m;
  });
}

void BM_ModuleInverse(benchmark::State& state) {
  const Motion& m = motion();
  double joints[6];
  unsigned long f = 0, i = 0;
  std::size_t k = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(kinematicsInverse(&m.world[k], joints, &i, &f));
    benchmark::DoNotOptimize(joints);
    if (++k == m.world.size()) k = 0;
  }
}
BENCHMARK(BM_ModuleInverse)->Apply(add_statistics);

void BM_ModuleForwardWarm(benchmark::State& state) {
  // As motion does every servo cycle: the previous cycle's solution is the start.
  const Motion& m = motion();
  unsigned long f = 0, i = 0;
  std::size_t k = 1;
  WorldPose world = m.world[0];
  for (auto _ : state) {
    benchmark::DoNotOptimize(kinematicsForward(m.joints[k].data(), &world, &f, &i));
    if (++k == m.world.size()) {
      k = 1;
      world = m.world[0];
      state.PauseTiming();
      kinematicsForward(m.joints[0].data(), &world, &f, &i);  // the module's own tracker back to the start
      state.ResumeTiming();
    }
  }
}
BENCHMARK(BM_ModuleForwardWarm)->Apply(add_statistics);

void BM_CApiCompensatedCommand(benchmark::State& state) {
  // The C API's real-time command on the same poses, SI (what kinematicsInverse adds: the full
  // report for its pins, units).
  static hexatwist_model* model = hexatwist_model_default(nullptr, 0);
  const Motion& m = motion();
  double command[6];
  std::size_t k = 0;
  for (auto _ : state) {
    const WorldPose& p = m.world[k];
    const double pose[6] = {p.x / 1000,
                            p.y / 1000,
                            p.z / 1000 - kHomeZ / 1000,
                            p.a * 0.017453292519943295,
                            p.b * 0.017453292519943295,
                            p.c * 0.017453292519943295};
    benchmark::DoNotOptimize(hexatwist_motor_commands(model, pose, HEXATWIST_COMPENSATED, command, nullptr));
    if (++k == m.world.size()) k = 0;
  }
}
BENCHMARK(BM_CApiCompensatedCommand)->Apply(add_statistics);

}  // namespace

BENCHMARK_MAIN();
