// SPDX-License-Identifier: BSD-3-Clause
// hexatwist ik: the commands of one pose, and the pose errors every command shares.
#include <fmt/format.h>

#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

// ---- ik --------------------------------------------------------------------------------------

TEST(Cli, IkJsonReportsEveryLegWithConsistentCommands) {
  const Outcome r = run({"ik", "--pose=0.05,-0.02,0.1,3,-2,5", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");
  const YAML::Node j = json(r);
  EXPECT_EQ(j["status"].as<std::string>(), "ok");
  EXPECT_TRUE(j["limit"].IsNull());
  ASSERT_TRUE(j["legs"].IsSequence());
  ASSERT_EQ(j["legs"].size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    const YAML::Node leg = j["legs"][i];
    SCOPED_TRACE("leg " + std::to_string(i + 1));
    EXPECT_EQ(leg["leg"].as<int>(), static_cast<int>(i) + 1);
    for (const char* key : {"length", "twist", "length_error", "command_conventional", "command_compensated"})
      ASSERT_TRUE(leg[key].IsScalar()) << key;
    const double length = leg["length"].as<double>();
    EXPECT_GT(length, 1.4);
    EXPECT_LT(length, 2.45);
    EXPECT_EQ(leg["command_conventional"].as<double>(), length);
    // Eq. (12): compensated = length - length_error; the JSON numbers round-trip exactly.
    EXPECT_NEAR(leg["command_compensated"].as<double>(), length - leg["length_error"].as<double>(), 1e-12);
    EXPECT_NE(leg["length_error"].as<double>(), 0.0);
    // Eq. (10) with the seed's +lead/2pi: length_error = 0.01/2pi * twist.
    EXPECT_NEAR(leg["length_error"].as<double>(), 0.010 / (2 * kPi) * leg["twist"].as<double>(), 1e-15);
  }
}

TEST(Cli, IkHeaveTwistsLegsOneAndTwoOppositely) {
  const Outcome r = run({"ik", "--pose=0,0,0.3,0,0,0", "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<double> twist = leg_values(json(r), "twist");
  ASSERT_EQ(twist.size(), 6u);
  EXPECT_GT(std::abs(twist[0]), deg2rad(1.0));
  EXPECT_NEAR(twist[0], -twist[1], 1e-12);
}

TEST(Cli, IkTextOutputHasOneRowPerLeg) {
  const Outcome r = run({"ik", "--pose=0,0,0.1,0,0,10"});
  ASSERT_EQ(r.code, 0) << r.err;
  for (int i = 1; i <= 6; ++i) EXPECT_NE(r.out.find("\n  " + std::to_string(i) + "  "), std::string::npos) << i;
  EXPECT_NE(r.out.find("status: ok"), std::string::npos);
}

TEST(Cli, AHeaderSaysWhichSectionsAreTheSeedsDefaults) {
  // A configuration of the geometry alone: each report's first line says its drives and load are the
  // seed's; the seed's own file (every section given) says nothing.
  const std::string geometry = write_file("geometry-only.yaml", hexatwist::test::kSymmetricYaml);
  const std::string with_load =
      write_file("with-load.yaml", hexatwist::test::kSymmetricYaml + "load: {mass: 900}\nmechanism: {}\n");
  const std::string note = "(servo, load and mechanism: the seed's defaults, not in the file)";
  const auto first_line = [](const Outcome& r) { return r.out.substr(0, r.out.find('\n')); };
  for (const std::vector<std::string>& command :
       {std::vector<std::string>{"ik", "--pose=0,0,0.1,0,0,10"},
        {"fk", "--lengths=1.8,1.8,1.8,1.8,1.8,1.8"},
        {"stations", "--count", "14", "--out", (temp_dir() / "notes-run.csv").string()}}) {
    std::vector<std::string> args = command;
    args.insert(args.end(), {"--config", geometry});
    const Outcome r = run(args);
    ASSERT_EQ(r.code, 0) << command[0] << ": " << r.err;
    EXPECT_NE(first_line(r).find(note), std::string::npos) << first_line(r);
    args.back() = with_load;
    const Outcome l = run(args);
    ASSERT_EQ(l.code, 0) << l.err;
    EXPECT_NE(first_line(l).find("(servo: the seed's defaults, not in the file)"), std::string::npos) << first_line(l);
    args.back() = HEXATWIST_SOURCE_DIR "/configs/seed.yaml";
    const Outcome s = run(args);
    ASSERT_EQ(s.code, 0) << s.err;
    EXPECT_EQ(s.out.find("defaults"), std::string::npos) << first_line(s);
  }
}

TEST(Cli, IkSaysWhyACalibratedConfigurationsCommandIsNotTheLength) {
  // Zero offsets (as identify writes them): the conventional command is the length less the offset,
  // and the report says so with the largest difference; the seed's own report has no such note.
  const std::string calibrated = write_file(
      "offsets.yaml", hexatwist::test::kSymmetricYaml + "length_offsets: [0.0021, -0.0005, 0, 0, 0, 0.0013]\n");
  const Outcome r = run({"ik", "--pose=0,0,0.1,0,0,10", "--config", calibrated});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("note: command_conv differs from length by up to 2.100 mm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("zero offset (length_offsets, up to 2.100 mm)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("home_commands"), std::string::npos) << r.out;
  const Outcome s = run({"ik", "--pose=0,0,0.1,0,0,10"});
  ASSERT_EQ(s.code, 0) << s.err;
  EXPECT_EQ(s.out.find("note:"), std::string::npos) << s.out;
}

TEST(Cli, NegativeNumbersWorkWithAndWithoutEquals) {
  const Outcome eq = run({"ik", "--pose=-0.1,0,0,0,0,-5", "--json"});
  const Outcome space = run({"ik", "--pose", "-0.1,0,0,0,0,-5", "--json"});
  ASSERT_EQ(eq.code, 0) << eq.err;
  ASSERT_EQ(space.code, 0) << space.err;
  EXPECT_EQ(eq.out, space.out);
  EXPECT_EQ(json(eq)["pose"][0].as<double>(), -0.1);
  EXPECT_NEAR(json(eq)["pose"][5].as<double>(), deg2rad(-5.0), 1e-15);
}

// ---- bad input -------------------------------------------------------------------------------

TEST(Cli, PoseWithFiveNumbersIsBadInput) {
  const Outcome r = run({"ik", "--pose=0,0,0,0,0"});
  expect_error(r, 2, {"--pose", "6"});
  EXPECT_EQ(r.out, "");
}

TEST(Cli, NonNumberInPoseIsBadInput) {
  expect_error(run({"ik", "--pose=0,0,abc,0,0,0"}), 2, {"--pose", "'abc'", "value 3"});
  expect_error(run({"ik", "--pose=0,0,0.1.2,0,0,0"}), 2, {"--pose", "'0.1.2'"});
  expect_error(run({"ik", "--pose=0,0,,0,0,0"}), 2, {"--pose", "value 3"});
  expect_error(run({"ik", "--pose=+-1,0,0,0,0,0"}), 2, {"--pose", "'+-1'"});
}

TEST(Cli, NanOrInfInPoseIsBadInput) {
  for (const char* v : {"nan", "inf", "-inf", "NaN"})
    expect_error(run({"ik", std::string("--pose=0,") + v + ",0,0,0,0"}), 2, {"--pose", "value 2", "finite"});
  expect_error(run({"ik", "--pose=1e999,0,0,0,0,0"}), 2, {"--pose", "range"});
}

TEST(Cli, NewlineInAnArgumentStillGivesOneLine) { expect_error(run({"ik", "--pose=0,0\n,0,0,0,0"}), 2, {"--pose"}); }

TEST(Cli, PoseOutsideALimitExitsThreeAndEmitsNoCommand) {
  const Outcome r = run({"ik", "--pose=0,0,0.9,0,0,0", "--json"});
  expect_error(r, 3, {"leg 1", "limits.length_max"});
  const YAML::Node j = json(r);
  EXPECT_EQ(j["status"].as<std::string>(), "stroke_above_max");
  EXPECT_EQ(j["limit"]["leg"].as<int>(), 1);
  EXPECT_GT(j["limit"]["value"].as<double>(), j["limit"]["bound"].as<double>());
  ASSERT_EQ(j["legs"].size(), 6u);
  for (const auto& leg : j["legs"]) {
    EXPECT_TRUE(leg["command_conventional"].IsNull());
    EXPECT_TRUE(leg["command_compensated"].IsNull());
    EXPECT_TRUE(leg["length"].IsScalar());  // the geometry is still reported
  }
  // Text output: no command either.
  const Outcome text = run({"ik", "--pose=0,0,0.9,0,0,0"});
  expect_error(text, 3, {"leg 1", "limits.length_max"});
  EXPECT_NE(text.out.find("status: stroke_above_max"), std::string::npos);
}

}  // namespace

// ---- the legs' effects (theory §4b) ----------------------------------------------------------

// The seed configuration with a leg_effects block (it has the load that a stiffness needs).
std::string seed_with_effects(const std::string& name, const std::string& block) {
  std::ifstream in(std::string(HEXATWIST_SOURCE_DIR) + "/configs/seed.yaml");
  std::stringstream s;
  s << in.rdbuf() << "\nleg_effects:\n" << block;
  return write_file(name, s.str());
}

TEST(Cli, IkWithLegEffectsReportsEachEffectAndCompensatesIt) {
  const std::string config =
      seed_with_effects("effects.yaml", "  stiffness: 2.0e8\n  length_expansion: 11.5e-6\n  lead_expansion: 11.0e-6\n");
  const Outcome plain = run({"ik", "--pose=0.05,0,0.1,0,0,5", "--json"});
  const Outcome warm = run({"ik", "--config", config, "--pose=0.05,0,0.1,0,0,5", "--temperature-c", "22", "--json"});
  ASSERT_EQ(plain.code, 0) << plain.err;
  ASSERT_EQ(warm.code, 0) << warm.err;
  const YAML::Node p = json(plain), w = json(warm);
  for (std::size_t i = 0; i < 6; ++i) {
    SCOPED_TRACE("leg " + std::to_string(i + 1));
    const YAML::Node leg = w["legs"][i];
    EXPECT_EQ(leg["temperature"].as<double>(), 22.0);
    EXPECT_LT(leg["force"].as<double>(), -2.0e3) << "the load compresses every leg (2.9 kN here)";
    // The command is the rigid one less the effects' growth, to the lead's expansion of it.
    const double shift = p["legs"][i]["command_compensated"].as<double>() - leg["command_compensated"].as<double>();
    EXPECT_NEAR(shift, leg["effect"].as<double>(), 1e-9);
    EXPECT_NEAR(leg["effect"].as<double>(),
                leg["effect_load"].as<double>() + leg["effect_thermal"].as<double>() + leg["effect_play"].as<double>(),
                1e-15);
    EXPECT_GT(leg["effect_thermal"].as<double>(), 40e-6) << "2 K on a 1.9 m steel leg";
  }
  const Outcome text = run({"ik", "--config", config, "--temperature-c", "22"});
  EXPECT_NE(text.out.find("leg effects"), std::string::npos) << text.out;
  for (const char* bad : {"500", "nan", "1,2,3"}) {
    const Outcome r = run({"ik", "--config", config, "--temperature-c", bad});
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_EQ(r.err.rfind("hexatwist: error: --temperature-c", 0), 0u) << r.err;
  }
}

TEST(Cli, FkOfWarmLegsInvertsIkAtTheSameTemperatures) {
  const std::string config =
      seed_with_effects("warm.yaml", "  stiffness: 2.0e8\n  length_expansion: 11.5e-6\n  lead_expansion: 11.0e-6\n");
  const std::string temperatures = "24,26,21.5,30,19,23";
  const Outcome ik =
      run({"ik", "--config", config, "--pose=0.05,-0.02,0.1,2,-1,5", "--temperature-c", temperatures, "--json"});
  ASSERT_EQ(ik.code, 0) << ik.err;
  std::string motor;
  for (std::size_t i = 0; i < 6; ++i)
    motor += (i ? "," : "") + fmt::format("{:.17g}", json(ik)["legs"][i]["command_compensated"].as<double>());
  const Outcome warm =
      run({"fk", "--config", config, "--motor", "--lengths", motor, "--temperature-c", temperatures, "--json"});
  const Outcome cold = run({"fk", "--config", config, "--motor", "--lengths", motor, "--json"});
  ASSERT_EQ(warm.code, 0) << warm.err;
  ASSERT_EQ(cold.code, 0) << cold.err;
  const double expected[6] = {0.05, -0.02, 0.1, 2 * kPi / 180, -kPi / 180, 5 * kPi / 180};
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_NEAR(json(warm)["pose"][k].as<double>(), expected[k], 1e-10) << "coordinate " << k;
  }
  // The warm command on legs at the reference temperature: the legs are shorter, the platform lower.
  EXPECT_LT(json(cold)["pose"][2].as<double>(), 0.1 - 30e-6);
  const Outcome geometric = run({"fk", "--config", config, "--lengths", motor, "--temperature-c", "22"});
  EXPECT_EQ(geometric.code, 2);
  EXPECT_NE(geometric.err.find("--temperature-c"), std::string::npos) << geometric.err;
}

TEST(Cli, LinuxcncHandsThePlayToLinuxcncsBacklashCompensation) {
  // Each joint's BACKLASH (the play in motor-side length, mm) and the module told to leave it out;
  // the joints' homes are those of the legs without it (the headless LinuxCNC test runs the INI).
  const std::string config =
      seed_with_effects("play.yaml", "  play: [50.0e-6, 40.0e-6, 60.0e-6, 50.0e-6, 20.0e-6, 80.0e-6]\n");
  const Outcome r = run({"linuxcnc", "--config", config});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find(" play=backlash\n"), std::string::npos) << r.out;
  const std::size_t joint5 = r.out.find("[JOINT_5]");
  ASSERT_NE(joint5, std::string::npos);
  EXPECT_NE(r.out.find("BACKLASH = 0.080000000", joint5), std::string::npos) << r.out.substr(joint5, 600);
  EXPECT_NE(r.out.find("BACKLASH = 0.050000000"), std::string::npos);
  const Outcome plain = run({"linuxcnc"});
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_EQ(plain.out.find("BACKLASH"), std::string::npos);
  EXPECT_EQ(plain.out.find("play=backlash"), std::string::npos);
  // The same homes as the seed's: play changes no command at home.
  const auto homes = [](const std::string& ini) {
    std::string h;
    for (std::size_t at = ini.find("\nHOME = "); at != std::string::npos; at = ini.find("\nHOME = ", at + 1))
      h += ini.substr(at, ini.find('\n', at + 1) - at);
    return h;
  };
  EXPECT_EQ(homes(r.out), homes(plain.out));
}

TEST(Cli, IdentifyNamesAnUnknownEffect) {
  const Outcome r = run({"identify", "--points", "x.csv", "--test", "Rz", "--effects", "load,warp"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--effects"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'warp'"), std::string::npos) << r.err;
}
