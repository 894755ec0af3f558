// SPDX-License-Identifier: BSD-3-Clause
// Rig validation: every bad number is refused with the field named; derived numbers are right.
#include <gtest/gtest.h>

#include <functional>

#include "hexatwist/dynamics/rig.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/io/config.hpp"

namespace hexatwist {
namespace {

std::string error_of(const std::function<void(RigSpec&)>& edit) {
  RigSpec spec;
  spec.model = parse_model_spec(seed_config_yaml(), "seed");
  edit(spec);
  try {
    Rig rig(spec);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Rig, RefusesBadNumbersNamingTheField) {
  EXPECT_EQ(error_of([](RigSpec&) {}), "");
  EXPECT_EQ(error_of([](RigSpec& s) { s.servo.motor_inertia = 0; }).rfind("servo.motor_inertia: expected > 0", 0), 0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.servo.screw_inertia = -1; }).rfind("servo.screw_inertia:", 0), 0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.servo.torque_limit = NAN; }).rfind("servo.torque_limit:", 0), 0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.servo.encoder_counts = 1000.5; }).rfind("servo.encoder_counts:", 0), 0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.servo.gear_ratio = 0; }).rfind("servo.gear_ratio:", 0), 0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.servo.ki = 10; }).rfind("servo.kp: expected > 0 when", 0), 0u);
  EXPECT_EQ(
      error_of([](RigSpec& s) { s.servo.pole_frequency = 200; }).rfind("servo.pole_frequency: 200 Hz is too high", 0),
      0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.load.mass = -3; }).rfind("load.mass:", 0), 0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.load.inertia.y() = 0; }).rfind("load.inertia:", 0), 0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.simulation.control_rate = 0; }).rfind("simulation.control_rate:", 0), 0u);
  EXPECT_EQ(error_of([](RigSpec& s) {
              s.simulation.plant_step = 0.002;
            }).rfind("simulation.plant_step: 0.002 s is longer", 0),
            0u);
  // Steps too short for the count of steps per period to fit an int (found by fuzzing: the
  // conversion came before the check), and just past the allowed count.
  EXPECT_EQ(error_of([](RigSpec& s) {
              s.simulation.plant_step = 1e-40;
            }).rfind("simulation.plant_step: 1e-40 s gives more than 10000 steps per control period", 0),
            0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.simulation.plant_step = 0.99e-7; }).rfind("simulation.plant_step:", 0), 0u);
  EXPECT_EQ(error_of([](RigSpec& s) { s.simulation.plant_step = 1e-7; }), "");
  EXPECT_EQ(error_of([](RigSpec& s) { s.model.legs[2].lead = 0; }).rfind("leg 3: lead:", 0), 0u);
}

TEST(Rig, DerivedNumbers) {
  RigSpec spec;
  spec.model = parse_model_spec(seed_config_yaml(), "seed");
  spec.servo.gear_ratio = 2.0;
  spec.simulation.plant_step = 0.3e-3;  // does not divide 1 ms: four steps of 0.25 ms
  const Rig rig(spec);
  EXPECT_EQ(rig.substeps(), 4);
  EXPECT_DOUBLE_EQ(rig.plant_step(), 0.25e-3);
  EXPECT_NEAR(rig.motor_gain()[0], 0.010 / (2 * kPi * 2.0), 1e-18);
  EXPECT_DOUBLE_EQ(rig.drive_inertia(), spec.servo.motor_inertia + spec.servo.screw_inertia / 4.0);
  // The reflected load adds to the drive inertia, equally for legs 120 deg apart; mirror-image
  // legs differ slightly, since the twist term (one thread hand) is not mirror-symmetric.
  const Vector6d& J = rig.nominal_inertia();
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_GT(J[i], rig.drive_inertia());
    EXPECT_NEAR(J[i], J[(i + 2) % kLegs], 1e-12 * J[0]);
    EXPECT_NEAR(J[i], J[0], 1e-3 * J[0]);
  }
}

}  // namespace
}  // namespace hexatwist
