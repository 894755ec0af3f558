// SPDX-License-Identifier: BSD-3-Clause
// hexatwist dynamics: motor sizing along a trajectory.
#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

// ---- hexatwist dynamics: motor sizing along a trajectory ----

TEST(CliDynamics, TheExampleWritesCsvJsonAndFigureAndExceedsTheSeedMotorsSpeed) {
  const std::string example = std::string(HEXATWIST_SOURCE_DIR) + "/examples/motion_simulator.csv";
  const std::filesystem::path out = temp_dir() / "dyn-example";
  const Outcome r = run({"dynamics", "--trajectory", example, "--out", out.string()});
  // 65 deg/s of yaw and 63 deg/s of roll need legs faster than the seed's 0.5 m/s (3000 rpm at
  // 10 mm lead): exit 3, and the report is kept.
  expect_error(r, 3,
               {"motion_simulator.csv", "motor envelope exceeded", "leg 4 at t = 0.930 s", "motor speed",
                "above the maximum 3000 rpm"});
  EXPECT_NE(r.out.find("envelope: EXCEEDED: leg 4 at t = 0.930 s"), std::string::npos) << r.out;
  const YAML::Node s = YAML::LoadFile((out / "summary.json").string());
  EXPECT_EQ(s["envelope"].as<std::string>(), "exceeded");
  EXPECT_EQ(s["first_violation"]["check"].as<std::string>(), "speed");
  EXPECT_EQ(s["first_violation"]["leg"].as<int>(), 4);
  EXPECT_NEAR(s["first_violation"]["time"].as<double>(), 0.930, 1e-9);
  EXPECT_EQ(s["samples"].as<int>(), 4001);
  ASSERT_EQ(s["legs"].size(), 6u);
  for (const YAML::Node& leg : s["legs"]) {
    EXPECT_GT(leg["peak_torque"].as<double>(), leg["rms_torque"].as<double>());
    EXPECT_GT(leg["peak_speed"].as<double>(), 314.16);  // every motor beyond 3000 rpm
    EXPECT_FALSE(leg["speed_ok"].as<bool>());
    EXPECT_GT(leg["share"]["gravity"].as<double>(), 0.3);
  }
  const std::string csv = read_file(out / "motion_simulator_dynamics.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4002);
  EXPECT_EQ(csv.rfind("t_s,torque_1_Nm,speed_1_rad_s,power_1_W,", 0), 0u);
  EXPECT_NE(csv.find(",friction_6_Nm\n"), std::string::npos);
  EXPECT_TRUE(is_png(out / "motion_simulator_torque_speed.png"));
  EXPECT_TRUE(std::filesystem::exists(out / "motion_simulator_torque_speed.svg"));
  std::filesystem::remove_all(out);
}

TEST(CliDynamics, AGentleMotionIsInsideTheEnvelope) {
  const std::string csv = write_file("gentle.csv", heave_csv());
  const std::filesystem::path out = temp_dir() / "dyn-gentle";
  const Outcome r = run({"dynamics", "--trajectory", csv, "--out", out.string(), "--no-figures"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("envelope: ok"), std::string::npos) << r.out;
  const YAML::Node s = YAML::LoadFile((out / "summary.json").string());
  EXPECT_EQ(s["envelope"].as<std::string>(), "ok");
  EXPECT_TRUE(s["first_violation"].IsNull());
  EXPECT_EQ(s["samples"].as<int>(), 1501);
  EXPECT_TRUE(std::filesystem::exists(out / "gentle_dynamics.csv"));
  EXPECT_FALSE(std::filesystem::exists(out / "gentle_torque_speed.png"));
  std::filesystem::remove_all(out);
}

TEST(CliDynamics, AWeakMotorExitsThreeNamingLegTimeAndTheTorqueCheck) {
  const std::string csv = write_file("gentle2.csv", heave_csv());
  const std::string weak = write_file(
      "weak-motor.yaml", std::string(hexatwist::test::kSymmetricYaml) +
                             "servo:\n  torque_limit: 5.5\n  continuous_torque: 5\n  peak_torque_at_max_speed: 4\n");
  const std::filesystem::path out = temp_dir() / "dyn-weak";
  const Outcome r = run({"dynamics", "--trajectory", csv, "--config", weak, "--out", out.string(), "--no-figures"});
  expect_error(r, 3, {"gentle2.csv", "motor envelope exceeded", "leg ", " at t = ", "torque", "N m is above"});
  const YAML::Node s = YAML::LoadFile((out / "summary.json").string());
  const YAML::Node v = s["first_violation"];
  ASSERT_TRUE(v.IsMap());
  EXPECT_NE(r.err.find(fmt_leg_time(v["leg"].as<int>(), v["time"].as<double>())), std::string::npos) << r.err;
  EXPECT_GT(v["value"].as<double>(), v["bound"].as<double>());
  std::filesystem::remove_all(out);
}

TEST(CliDynamics, BadInputAndLimitsLeaveNoOutputs) {
  const std::filesystem::path out = temp_dir() / "dyn-none";
  const std::string bad = write_file("dyn-bad.csv", replace_line(heave_csv(), 4, "0.02,0,0,abc,0,0,0"));
  expect_error(run({"dynamics", "--trajectory", bad, "--out", out.string()}), 2, {bad + ":4:10:", "column 'z'"});
  expect_error(run({"dynamics", "--trajectory", (temp_dir() / "none.csv").string(), "--out", out.string()}), 2,
               {"--trajectory", "none.csv"});
  const std::string high = write_file("dyn-high.csv", heave_csv(900.0));
  expect_error(run({"dynamics", "--trajectory", high, "--out", out.string()}), 3,
               {high + ": t = 0.917 s", "leg 2", "above the maximum", "nothing was written"});
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliDynamics, AFigureThatCannotBeDrawnLeavesNoFileOfTheSet) {
  const std::string csv = write_file("dyn-fig.csv", heave_csv());
  const std::filesystem::path out = temp_dir() / "dyn-fig";
  ::setenv("HEXATWIST_GNUPLOT", "/bin/false", 1);
  const Outcome r = run({"dynamics", "--trajectory", csv, "--out", out.string()});
  ::unsetenv("HEXATWIST_GNUPLOT");
  expect_error(r, 4, {"gnuplot"});
  EXPECT_TRUE(!std::filesystem::exists(out) || std::filesystem::is_empty(out));
  std::filesystem::remove_all(out);
}

}  // namespace
