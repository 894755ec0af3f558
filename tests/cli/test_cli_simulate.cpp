// SPDX-License-Identifier: BSD-3-Clause
// hexatwist study and simulate: the report of the closed-loop simulation.
#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

TEST(Cli, SimulateWritesTheWholeReport) {
  const std::string csv = write_file("heave.csv", heave_csv());
  const std::filesystem::path out = temp_dir() / "sim-out";
  const Outcome r = run({"simulate", "--trajectory", csv, "--out", out.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("compensated"), std::string::npos);
  const YAML::Node s = YAML::LoadFile((out / "summary.json").string());
  ASSERT_EQ(s["tests"].size(), 1u);
  const YAML::Node t = s["tests"][0];
  EXPECT_EQ(t["name"].as<std::string>(), "heave");
  EXPECT_EQ(t["samples"].as<int>(), 1501);
  const double comp_twist = t["compensated"]["max_error_twist_only"].as<double>();
  const double conv_twist = t["conventional"]["max_error_twist_only"].as<double>();
  EXPECT_LT(comp_twist, 1e-9);
  EXPECT_GT(conv_twist, 1e-5);  // 5 deg of yaw: ~0.24 mm at the edge
  EXPECT_LE(t["compensated"]["max_error_total"].as<double>() - t["compensated"]["max_error_tracking_only"].as<double>(),
            1e-6);
  for (const char* f :
       {"heave_conventional.csv", "heave_compensated.csv", "summary.md", "heave_error.svg", "heave_legs.svg"})
    EXPECT_TRUE(std::filesystem::exists(out / f)) << f;
  EXPECT_TRUE(is_png(out / "heave_error.png"));
  EXPECT_TRUE(is_png(out / "heave_legs.png"));
  // The CSV: a header and one row per control tick; its first seven columns read back as a
  // trajectory (t_s, desired pose in m and rad).
  const std::string series = read_file(out / "heave_compensated.csv");
  EXPECT_EQ(std::count(series.begin(), series.end(), '\n'), 1502);
  EXPECT_EQ(series.rfind("t_s,desired_x_m,", 0), 0u);
  EXPECT_NE(series.find(",error_total_m,error_twist_only_m,error_tracking_only_m\n"), std::string::npos);
  std::filesystem::remove_all(out);
}

TEST(Cli, SimulateBadCsvNamesLineAndColumn) {
  std::string text = heave_csv();
  const std::string bad = write_file("bad.csv", replace_line(text, 4, "0.02,0,0,abc,0,0,0"));
  expect_error(run({"simulate", "--trajectory", bad, "--out", (temp_dir() / "x").string(), "--no-figures"}), 2,
               {bad + ":4:10:", "column 'z'"});
  const std::string back = write_file("back.csv", replace_line(text, 5, "0.01,0,0,0,0,0,0"));
  expect_error(run({"simulate", "--trajectory", back, "--no-figures"}), 2, {back + ":5:", "not after"});
  const std::string nan = write_file("nan.csv", replace_line(text, 6, "0.04,0,0,nan,0,0,0"));
  expect_error(run({"simulate", "--trajectory", nan, "--no-figures"}), 2, {nan + ":6:10:", "column 'z'", "finite"});
  expect_error(run({"simulate", "--trajectory", (temp_dir() / "none.csv").string()}), 2, {"--trajectory", "none.csv"});
  EXPECT_FALSE(std::filesystem::exists(temp_dir() / "x"));
}

TEST(Cli, SimulateOutsideALimitRunsNothing) {
  const std::string csv = write_file("high.csv", heave_csv(900.0));  // z = 0.9 m: legs too long
  const std::filesystem::path out = temp_dir() / "high-out";
  const Outcome r = run({"simulate", "--trajectory", csv, "--out", out.string()});
  expect_error(r, 3, {csv + ": t = 0.917 s", "leg 2", "above the maximum", "nothing was simulated"});
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(Cli, StudyRunsTheChosenTestsAndRefusesUnknownOnes) {
  const std::filesystem::path out = temp_dir() / "study-out";
  const Outcome r = run({"study", "--tests", "Rz", "--no-figures", "--no-csv", "--out", out.string()});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("Rz"), std::string::npos);
  const YAML::Node s = YAML::LoadFile((out / "summary.json").string());
  ASSERT_EQ(s["tests"].size(), 1u);
  const YAML::Node conv = s["tests"][0]["conventional"];
  // Yaw 30 deg: about 1.4 mm at the platform edge from the twist alone.
  EXPECT_GT(conv["max_error_twist_only"].as<double>(), 1.3e-3);
  EXPECT_LT(conv["max_error_twist_only"].as<double>(), 1.5e-3);
  EXPECT_FALSE(std::filesystem::exists(out / "Rz_error.png"));
  EXPECT_FALSE(std::filesystem::exists(out / "Rz_compensated.csv"));
  EXPECT_TRUE(std::filesystem::exists(out / "summary.md"));
  std::filesystem::remove_all(out);
  expect_error(run({"study", "--tests", "Lq"}), 2, {"--tests", "'Lq'"});
  // A motor that cannot hold the load: refused before anything runs.
  const std::string weak =
      write_file("weak.yaml", std::string(hexatwist::test::kSymmetricYaml) +
                                  "servo:\n  torque_limit: 3\n  peak_torque_at_max_speed: 2\n  continuous_torque: 2\n");
  // 4.92 N m for the platform, the rest for the legs' own weight.
  const Outcome held = run({"study", "--config", weak, "--out", out.string()});
  expect_error(
      held, 3,
      {"Lz: t = 0.000 s", "leg 1", "holding the load takes 5.2", "servo.torque_limit", "nothing was simulated"});
  EXPECT_FALSE(std::filesystem::exists(out));
  // A small machine: the default sweeps leave its stroke, and the message names the key that sets them
  // (not for the motor's limits above, which the amplitude does not cause).
  EXPECT_EQ(held.err.find("amplitude"), std::string::npos) << held.err;
  const std::string small = write_file("small.yaml",
                                       "symmetric: {Ra: 0.12, Rb: 0.15, da: 0.02, db: 0.03, H: 0.15}\n"
                                       "screw: {lead: 0.002, thread: right, driven_side: base}\n"
                                       "limits: {length_min: 0.12, length_max: 0.22, bend_max_deg: 40, "
                                       "singularity_margin_deg: 5}\n");
  expect_error(run({"study", "--config", small, "--tests", "Rz", "--out", out.string()}), 3,
               {"Rz: t = ", "limits.length_max", "nothing was simulated", "+-30 deg", "study.angular_amplitude_deg",
                "smaller amplitude"});
  expect_error(run({"study", "--config", small, "--tests", "Lx", "--out", out.string()}), 3,
               {"Lx: t = ", "+-0.5 m", "study.linear_amplitude"});
  EXPECT_FALSE(std::filesystem::exists(out));
  const std::string file = write_file("blocked", "a file, not a folder");
  expect_error(run({"study", "--tests", "Rz", "--no-figures", "--out", file}), 4, {"--out", file});
}

TEST(CliSimulate, ATrajectoryTooLongToSampleNamesTheOptionAndFileNotTheRoutine) {
  const std::string csv = write_file("eon.csv", "t,x,y,z,roll,pitch,yaw\n0,0,0,0,0,0,0\n1e9,0,0,0.001,0,0,0\n");
  const Outcome r = run({"simulate", "--trajectory", csv, "--no-figures", "--out", (temp_dir() / "eon").string()});
  expect_error(r, 2, {"--trajectory: ", "eon.csv: ", "1e+09 s", "samples"});
  EXPECT_EQ(r.err.find("resample"), std::string::npos) << r.err;
}

TEST(CliSimulate, ATrajectoryShorterThanOneControlPeriodIsRefused) {
  const std::string csv = write_file("blink.csv", "t,x,y,z,roll,pitch,yaw\n0,0,0,0,0,0,0\n0.0005,0,0,0.001,0,0,0\n");
  expect_error(run({"simulate", "--trajectory", csv, "--no-figures", "--out", (temp_dir() / "blink").string()}), 2,
               {"--trajectory", "blink.csv", "less than one control period"});
}

}  // namespace
