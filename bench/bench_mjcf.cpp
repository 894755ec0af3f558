// Speed of MuJoCo on the exported model (hexatwist mjcf, docs/theory.md §15): mj_step along a
// representative motion, the motors tracking it with the servo's PD gains, for several timesteps.
// The counters give the loop closure kept at each step (largest |efc_pos| of the welds), so that
// the largest timestep that keeps it within 1 um can be read off: the study of docs/theory.md §15.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "../tests/mjcf_support.hpp"

namespace {

using namespace hexatwist;

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

}  // namespace

BENCHMARK_MAIN();
