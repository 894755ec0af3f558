// SPDX-License-Identifier: BSD-3-Clause
// Motor sizing along the fast motion-simulator cue examples/motion_simulator.csv, as `hexatwist
// dynamics` does: the inverse dynamics of the whole mechanism at every control tick, each motor's
// peaks and largest torque parts, and where the cue leaves the seed motor's envelope. The twin of
// examples/python/07_motor_sizing.py, which draws the torque-speed plane.
//
//   example_07_motor_sizing [EXAMPLES_DIR]      (default: this source folder, from any working directory)
#include <hexatwist/hexatwist.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <numeric>
#include <string>

namespace {

int size_along(const std::string& dir) {
  using namespace hexatwist;
  const std::string path = dir + "/motion_simulator.csv";
  const Config config = default_config();  // the seed: 3 kW-class servo motors, 1500 kg load
  const Rig& rig = config.rig;
  const Trajectory cue = resample(parse_trajectory_csv(read_text_file(path, "trajectory", kMaxDataBytes), path),
                                  rig.control_period());  // at the control rate, as the drives see it

  MotorSizing sizing;
  if (const Status s = size_motors(rig, cue, sizing); s != Status::Ok) {
    std::printf("t = %.3f s, leg %d: %s\n", sizing.failed_time, sizing.limit.leg + 1, describe(s).data());
    return 1;
  }
  constexpr double rpm = 60.0 / (2.0 * kPi);
  const bool exceeded = sizing.violation.check != EnvelopeCheck::None;
  std::printf("%zu samples at %.0f Hz; envelope: %s\n", sizing.samples.size(), 1 / cue.dt,
              exceeded ? "exceeded" : "ok");
  std::printf("leg  peak torque [N m]  RMS [N m]  peak speed [rpm]  peak power [W]  largest parts\n");
  for (int leg = 0; leg < kLegs; ++leg) {
    const MotorSummary& m = sizing.motors[static_cast<std::size_t>(leg)];
    std::array<int, kTorqueTerms> order{};
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return m.share[a] > m.share[b]; });
    std::printf("%3d  %17.1f  %9.1f  %16.0f  %14.0f  %s %.0f%%, %s %.0f%%\n", leg + 1, m.peak_torque, m.rms_torque,
                m.peak_speed * rpm, m.peak_power, to_string(static_cast<TorqueTerm>(order[0])).data(),
                100 * m.share[order[0]], to_string(static_cast<TorqueTerm>(order[1])).data(), 100 * m.share[order[1]]);
  }
  if (exceeded) {
    // Expected on this cue: the seed motor is too slow for it (the CLI exits with 3 and says the same).
    const EnvelopeViolation& v = sizing.violation;
    const bool speed = v.check == EnvelopeCheck::Speed;
    std::printf("first violation: leg %d at t = %.3f s, %s: %.1f %s > %.1f %s\n", v.leg + 1, v.time,
                to_string(v.check).data(), v.value * (speed ? rpm : 1.0), speed ? "rpm" : "N m",
                v.bound * (speed ? rpm : 1.0), speed ? "rpm" : "N m");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return size_along(argc > 1 ? argv[1] : HEXATWIST_EXAMPLES_DIR);
  } catch (const hexatwist::Error& e) {  // a missing or unreadable data file: say which, as the CLI does
    std::fprintf(stderr, "example_07_motor_sizing: %s\n", e.what());
    return 1;
  }
}
