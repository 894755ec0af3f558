// SPDX-License-Identifier: BSD-3-Clause
// hexatwist config and --config: the resolved model, and configuration errors named by file, line and field.
#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

// ---- config ----------------------------------------------------------------------------------

TEST(Cli, ConfigJsonListsSixLegs) {
  const Outcome r = run({"config", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const YAML::Node j = json(r);
  EXPECT_EQ(j["status"].as<std::string>(), "ok");
  ASSERT_EQ(j["legs"].size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(j["legs"][i]["leg"].as<int>(), static_cast<int>(i) + 1);
    EXPECT_NEAR(j["legs"][i]["length_home"].as<double>(), 1.910247, 5e-7);
    EXPECT_EQ(j["legs"][i]["base"].size(), 3u);
  }
  // The servo numbers study/simulate use: gains from the 10 Hz poles, kp = 3 J w^2.
  const YAML::Node sv = j["servo"];
  ASSERT_TRUE(sv.IsMap());
  const double J = sv["nominal_inertia"][0].as<double>(), w = 2 * kPi * 10.0;
  EXPECT_NEAR(sv["kp"][0].as<double>(), 3 * J * w * w, 1e-9 * sv["kp"][0].as<double>());
  // The torque that holds the whole mechanism at home, as the simulation checks it (#24: 4.92 N m
  // for the platform and payload alone, the rest for the legs' own weight).
  EXPECT_NEAR(sv["holding_torque_home"][0].as<double>(), 5.26, 0.01);
  // A plain Stewart platform (lead 0) has no servo to simulate, and says why.
  const std::string plain = write_file("plain.yaml", replace_line(kSymmetric, 9, "  lead: 0"));
  const Outcome p = run({"config", "--config", plain});
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_NE(p.out.find("servo (study, simulate): not usable:"), std::string::npos) << p.out;
  EXPECT_NE(p.out.find("needs a lead screw"), std::string::npos) << p.out;
}

TEST(Cli, ConfigFileInLegsFormGivesTheDefaultIk) {
  // Joints and axes read back from `config --json`, written as a legs-form file: same IK.
  const std::string file = write_file("legs.yaml", seed_legs_yaml());
  const std::string pose = "--pose=0.03,0.02,-0.04,2,-4,6";
  const Outcome a = run({"ik", pose, "--json"});
  const Outcome b = run({"ik", pose, "--json", "--config=" + file});
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_EQ(b.code, 0) << b.err;
  const std::vector<double> la = leg_values(json(a), "command_compensated");
  const std::vector<double> lb = leg_values(json(b), "command_compensated");
  for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(la[i], lb[i], 1e-15) << "leg " << i + 1;
}

TEST(Cli, ConfigFileSettingsReachTheModel) {
  const std::string file =
      write_file("left.yaml", replace_line(replace_line(kSymmetric, 9, "  lead: 0.004"), 10, "  thread: left"));
  const Outcome r = run({"config", "--json", "--config=" + file});
  ASSERT_EQ(r.code, 0) << r.err;
  const YAML::Node j = json(r);
  EXPECT_EQ(j["name"].as<std::string>(), "test platform");
  for (const auto& leg : j["legs"]) EXPECT_NEAR(leg["twist_gain"].as<double>(), -0.004 / (2 * kPi), 1e-18);
}

TEST(Cli, MissingConfigFileIsBadInput) {
  const std::string missing = (temp_dir() / "does_not_exist.yaml").string();
  expect_error(run({"ik", "--config=" + missing}), 2, {"--config", missing});
  expect_error(run({"ik", "--config=" + temp_dir().string()}), 2, {"--config", "directory"});
}

TEST(Cli, MalformedYamlConfigNamesFileAndLine) {
  const std::string file = write_file("malformed.yaml", replace_line(kSymmetric, 4, "  Rb: 1.5: 3"));
  expect_error(run({"ik", "--config=" + file}), 2, {file + ":4:", "YAML"});
}

TEST(Cli, ConfigErrorsNameFileLineAndField) {
  struct Case {
    const char* name;
    std::string yaml;
    int line;
    const char* field;
  };
  const std::string legs = seed_legs_yaml();
  const std::vector<Case> cases{
      {"missing_key", replace_line(kSymmetric, 7, ""), 2, "symmetric.H"},
      {"string", replace_line(kSymmetric, 4, "  Rb: wide"), 4, "symmetric.Rb"},
      {"nan", replace_line(kSymmetric, 6, "  db: .nan"), 6, "symmetric.db"},
      {"min_above_max", replace_line(kSymmetric, 13, "  length_min: 2.5"), 13, "limits.length_min"},
      {"zero_axis", replace_line(legs, legs_line(2, 2), "    base_axis: [0, 0, 0]"), legs_line(2, 2),
       "legs[2] (leg 3).base_axis"},
      {"unknown_key", replace_line(kSymmetric, 3, "  Rq: 1.2"), 3, "symmetric.Rq"},
      {"sideways", replace_line(kSymmetric, 10, "  thread: sideways"), 10, "screw.thread"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string file = write_file(std::string(c.name) + ".yaml", c.yaml);
    expect_error(run({"ik", "--config=" + file}), 2, {file + ":" + std::to_string(c.line) + ":", c.field});
  }
}

TEST(Cli, AxisParallelToItsLegIsBadInput) {
  const YAML::Node c = json(run({"config", "--json"}));
  const std::string yaml =
      replace_line(seed_legs_yaml(), legs_line(4, 3), "    platform_axis: " + vec(c["legs"][4]["direction_home"]));
  const std::string file = write_file("parallel.yaml", yaml);
  expect_error(run({"config", "--config=" + file}), 2,
               {file + ":" + std::to_string(legs_line(4, 3)) + ":", "legs[4] (leg 5).platform_axis", "singularity"});
}

TEST(CliConfig, ALeadLongerThanTheStrokeIsRefusedAtLoad) {
  const std::string bad = write_file("lead1e30.yaml", replace_line(kSymmetric, 9, "  lead: 1e30"));
  expect_error(run({"config", "--config", bad}), 2, {"lead1e30.yaml:9:", "lead", "stroke"});
}

TEST(CliConfig, LengthOffsetsThatPutHomeOutsideTheStrokeAreRefusedAtLoad) {
  const std::string bad = write_file("offset-home.yaml", kSymmetric + "length_offsets: [-0.9, 0, 0, 0, 0, 0]\n");
  expect_error(run({"config", "--config", bad}), 2, {"offset-home.yaml:17:", "length_offset", "outside the stroke"});
}

}  // namespace
