// SPDX-License-Identifier: BSD-3-Clause
// Speed of the mechanism's dynamics, side by side in one run: inverse dynamics per call (six
// legs), the mass matrix, the forward dynamics, the closed-loop simulation on the full model in
// simulated seconds per wall second, and (with HEXATWIST_MUJOCO) MuJoCo stepping the exported model
// at several timesteps, with the loop closure each keeps (docs/theory.md §14-15).
// Run in Release: build/bench/bench_dynamics.
#include "bench_support.hpp"

#include "hexatwist/dynamics/mechanism.hpp"
#if defined(HEXATWIST_BENCH_MUJOCO)
#include "../tests/io/mjcf_support.hpp"
#endif

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

#if defined(HEXATWIST_BENCH_MUJOCO)
// ----- MuJoCo on the exported model: mj_step along a representative motion, the motors tracking
// it with the servo's PD gains. The counters give the loop closure kept at each step (largest
// |efc_pos| of the welds): the largest timestep that keeps it within 1 um is read off
// (docs/theory.md §15).
// The motion: x and yaw rise as 1 - cos over T (from rest at home): peak 0.785 m/s and 63 deg/s.
constexpr double kDuration = 2.0;  // [s]
Placement motion_at(double t) {
  const double f = 0.5 * (1.0 - std::cos(kPi * t));  // 0 -> 1 -> 0 over 2 s
  return placement_from_pose(Pose{Vector3d(0.5 * f, 0.0, 0.0), Vector3d(0.0, 0.0, deg2rad(40.0) * f)});
}

// One mj_step per iteration at timestep state.range(0) [us]; the equalities' time constant is
// two steps, as in the exported model.
void BM_MjStep(benchmark::State& state) {
  const Rig rig = default_config().rig;
  test::MjSim sim(mjcf_model(rig));
  const double dt = static_cast<double>(state.range(0)) * 1e-6;
  sim.m->opt.timestep = dt;
  for (int e = 0; e < sim.m->neq; ++e) sim.m->eq_solref[e * mjNREF] = 2.0 * dt;
  for (int a = 0; a < sim.m->nu; ++a) sim.m->actuator_ctrllimited[a] = sim.m->actuator_forcelimited[a] = 0;
  // Reference motor angles and speeds at every step of the motion.
  const int steps = static_cast<int>(std::lround(kDuration / dt));
  std::vector<Vector6d> phi(static_cast<std::size_t>(steps) + 2);
  for (int k = 0; k < steps + 2; ++k) phi[static_cast<std::size_t>(k)] = test::motor_angles_of(rig, motion_at(k * dt));
  std::vector<int> rotor_q(6), rotor_v(6);
  Vector6d sign;
  for (int i = 0; i < 6; ++i) {
    const int j = sim.id(mjOBJ_JOINT, "leg" + std::to_string(i + 1) + "_rotor");
    rotor_q[i] = sim.m->jnt_qposadr[j];
    rotor_v[i] = sim.m->jnt_dofadr[j];
    sign[i] = test::rotor_angle(rig.model().leg(i), 1.0);
  }
  mj_resetData(sim.m, sim.d);
  int k = 0;
  double worst = 0.0;
  for (auto _ : state) {
    const auto& ref = phi[static_cast<std::size_t>(k)];
    const Vector6d rate = (phi[static_cast<std::size_t>(k) + 1] - ref) / dt;
    for (int i = 0; i < 6; ++i) {
      const double angle = sign[i] * sim.d->qpos[rotor_q[i]], speed = sign[i] * sim.d->qvel[rotor_v[i]];
      sim.d->ctrl[i] = rig.kp()[i] * (ref[i] - angle) + rig.kd()[i] * (rate[i] - speed);
    }
    mj_step(sim.m, sim.d);
    for (int r = 0; r < sim.d->nefc; ++r)
      if (sim.m->eq_type[sim.d->efc_id[r]] == mjEQ_WELD) worst = std::max(worst, std::abs(sim.d->efc_pos[r]));
    if (++k == steps) {
      k = 0;
      mj_resetData(sim.m, sim.d);
    }
  }
  state.counters["max_weld_efc_pos"] = worst;
  state.counters["sim_s_per_wall_s"] =
      benchmark::Counter(dt * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MjStep)->Arg(2000)->Arg(1000)->Arg(500)->Arg(400)->Arg(250)->Arg(100)->Unit(benchmark::kMicrosecond);

#endif

}  // namespace

BENCHMARK_MAIN();
