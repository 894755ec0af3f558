// SPDX-License-Identifier: BSD-3-Clause
// Quick start: compensated motor commands for a pose, and the pose they really produce.
#include <hexatwist/hexatwist.hpp>

#include <cstdio>

int main() {
  using namespace hexatwist;
  const Model model = default_model();  // the seed platform, lead 10 mm (configs/seed.yaml)

  Pose pose;                           // relative to home
  pose.position = {0.0, 0.0, 0.1};     // [m]
  pose.rpy = {0.0, 0.0, deg2rad(30)};  // roll, pitch, yaw [rad]

  Vector6d conventional, compensated;  // motor-side lengths [m]
  LimitReport limit;
  if (motor_commands(model, pose, Strategy::Conventional, conventional, limit) != Status::Ok ||
      motor_commands(model, pose, Strategy::Compensated, compensated, limit) != Status::Ok) {
    std::printf("leg %d: %s\n", limit.leg + 1, describe(limit.status).data());
    return 1;
  }

  // Where does the platform really go? Twist-aware forward kinematics from the motor side.
  const Vector3d A = model.spec().observation_P;  // point "A" on the platform edge
  const Vector3d wanted = platform_point_B(model, placement_from_pose(pose), A);
  for (const auto& [name, command] : {std::pair{"conventional", conventional}, std::pair{"compensated", compensated}}) {
    FkResult fk;
    if (forward_kinematics(model, command, LengthKind::Motor, Placement{}, fk) != Status::Ok) return 2;
    const double miss = (platform_point_B(model, fk.placement, A) - wanted).norm();
    std::printf("%-12s  leg 1 command %.6f m   point A misses by %.4f mm\n", name, command[0], 1e3 * miss);
  }
  return 0;
}
