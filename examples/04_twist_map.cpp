// SPDX-License-Identifier: BSD-3-Clause
// Twist over a workspace slice (x-y plane 0.1 m above home, yaw 10 deg): 200 x 200 poses, each with
// the twist of its legs (Eq. 7-9), the length error it causes (Eq. 10) and its compensated commands
// checked against every limit; the largest twist and length error over the poses inside the limits.
// The twin of examples/python/04_twist_map.py, which draws the maps from the same numbers.
#include <hexatwist/hexatwist.hpp>

#include <cmath>
#include <cstdio>

int main() {
  using namespace hexatwist;
  const Model model = default_model();
  constexpr int kSide = 200;
  const double step = (0.5 - -0.5) / (kSide - 1);  // x and y from -0.5 to 0.5 m, as numpy's linspace
  const auto grid = [&](int i) { return i == kSide - 1 ? 0.5 : i * step + -0.5; };

  int inside = 0, twist_leg = -1, error_leg = -1;
  double max_twist = 0.0, max_error = 0.0;  // [rad], [m]
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      Pose pose;
      pose.position = {grid(i), grid(j), 0.1};
      pose.rpy = {0.0, 0.0, deg2rad(10)};
      Vector6d command;
      LimitReport limit;
      if (motor_commands(model, pose, Strategy::Compensated, command, limit) != Status::Ok) continue;  // blank
      ++inside;
      LegState legs;
      Vector6d dtheta, error;
      if (inverse_kinematics(model, pose, legs) != Status::Ok || twist(model, legs, dtheta) != Status::Ok) return 1;
      length_error(model, dtheta, error);
      for (int k = 0; k < kLegs; ++k) {
        if (std::abs(dtheta[k]) > max_twist) max_twist = std::abs(dtheta[k]), twist_leg = k;
        if (std::abs(error[k]) > max_error) max_error = std::abs(error[k]), error_leg = k;
      }
    }
  }
  std::printf("%s\nslice z = 0.1 m, yaw = 10 deg: %d of %d poses inside the limits\n", model.spec().name.c_str(),
              inside, kSide * kSide);
  std::printf("largest |twist| %.3f deg (leg %d), largest |length error| %.4f mm (leg %d)\n", rad2deg(max_twist),
              twist_leg + 1, 1e3 * max_error, error_leg + 1);
  return inside > 0 ? 0 : 1;
}
