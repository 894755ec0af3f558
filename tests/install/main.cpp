// SPDX-License-Identifier: BSD-3-Clause
// Uses the installed library: compensated commands for a pose, then twist-aware forward
// kinematics must return that pose. Exit code 0 only if it does.
#include <hexatwist/hexatwist.hpp>

#include <cstdio>

int main() {
  const hexatwist::Model model = hexatwist::default_model();
  hexatwist::Pose pose;
  pose.position = {0.05, -0.02, 0.1};
  pose.rpy = {0.0, 0.0, hexatwist::deg2rad(20.0)};
  hexatwist::Vector6d command;
  hexatwist::LimitReport limit;
  if (hexatwist::motor_commands(model, pose, hexatwist::Strategy::Compensated, command, limit) != hexatwist::Status::Ok)
    return 1;
  hexatwist::FkResult fk;
  if (hexatwist::forward_kinematics(model, command, hexatwist::LengthKind::Motor, hexatwist::Placement{}, fk) !=
      hexatwist::Status::Ok)
    return 2;
  const double err = (fk.pose.to_vector() - pose.to_vector()).cwiseAbs().maxCoeff();
  std::printf("round trip error %.3g\n", err);
  return err < 1e-9 ? 0 : 3;
}
