// SPDX-License-Identifier: BSD-3-Clause
// platform_config_yaml: a platform written into a configuration's YAML in the legs form loads back
// to exactly that platform (every double round trips), keeps every other section, writes a leg's
// own screw keys only where they differ, records the drives' reference, and refuses bad text.
#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <string>

#include "support.hpp"
#include "yaml_text.hpp"

namespace hexatwist::test {
namespace {

const std::string kRigSections =
    "servo:\n"
    "  max_speed_rpm: 1500\n"
    "  kp: 100\n"
    "load:\n"
    "  mass: 900\n"
    "study:\n"
    "  linear: {velocity: 0.1, acceleration: 0.4, jerk: 2}\n";

// What an identification changes: every joint and axis a little, per-leg leads and hands, the
// drives' scale and reference, offsets, the observation point (digits that must round trip).
ModelSpec identified_of(const Model& nominal) {
  ModelSpec c = nominal.spec();
  c.name += " (identified from: 'a log.csv' # not a comment)";  // quoted as YAML needs
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = c.legs[static_cast<std::size_t>(i)];
    const double f = 1e-3 * (0.1 + 0.123456789 * i);
    leg.base_B += Vector3d(f, -0.7 * f, 0.3 * f);
    leg.platform_P += Vector3d(-0.4 * f, f, -0.2 * f);
    leg.axis_base_B += Vector3d(0.01 * f, 0.02, -0.003);
    leg.axis_platform_P += Vector3d(-0.015, 0.01 * f, 0.004);
    leg.drive_lead = 0.010;
    leg.lead = 0.0105123456789 + 1e-5 * (i == 3);
    leg.thread = i == 2 ? ThreadSense::Right : ThreadSense::Left;
    leg.length_offset = f * (i % 2 == 0 ? 1 : -1);
    leg.home_command = nominal.home_command()[i] + 0.1 * f;
  }
  c.observation_P = Vector3d(1.2031234567, -0.0021, 0.00123);
  return c;
}

// The written text loads to exactly `want`, and everything else as the original.
void expect_written(const std::string& original, const std::string& source) {
  const Config before = load_config(original, source);
  const ModelSpec want = identified_of(before.rig.model());
  const std::string text = platform_config_yaml(original, source, want, "line one\nline two", true);
  EXPECT_EQ(text.rfind("# line one\n# line two\n", 0), 0u) << text;
  EXPECT_EQ(text.find("symmetric"), std::string::npos) << "the legs form replaces the symmetric block";
  const Config after = load_config(text, "written.yaml");
  const Model& got = after.rig.model();
  EXPECT_EQ(got.spec().name, want.name);
  EXPECT_EQ(got.spec().home_height, want.home_height);
  EXPECT_EQ(got.spec().observation_P, want.observation_P);  // exact: numbers round trip
  EXPECT_EQ(got.spec().pivot_P, want.pivot_P);
  EXPECT_EQ(got.spec().limits.length_max, want.limits.length_max);
  EXPECT_EQ(got.spec().limits.bend_max, want.limits.bend_max);
  for (std::size_t i = 0; i < kLegs; ++i) {
    SCOPED_TRACE("leg " + std::to_string(i + 1));
    const LegSpec& g = got.spec().legs[i];
    const LegSpec& w = want.legs[i];
    EXPECT_EQ(g.lead, w.lead);
    EXPECT_EQ(g.thread, w.thread);
    EXPECT_EQ(g.driven, w.driven);
    EXPECT_EQ(g.length_offset, w.length_offset);
    EXPECT_EQ(g.base_B, w.base_B);
    EXPECT_EQ(g.platform_P, w.platform_P);
    EXPECT_EQ(g.axis_base_B, w.axis_base_B);
    EXPECT_EQ(g.axis_platform_P, w.axis_platform_P);
    EXPECT_EQ(g.drive_lead, w.drive_lead);
    EXPECT_EQ(g.home_command, w.home_command);
  }
  // The other sections are kept.
  EXPECT_EQ(after.rig.servo().torque_limit, before.rig.servo().torque_limit);
  EXPECT_EQ(after.rig.servo().max_speed, before.rig.servo().max_speed);
  EXPECT_EQ(after.rig.servo().encoder_counts, before.rig.servo().encoder_counts);
  EXPECT_EQ(after.rig.load().mass, before.rig.load().mass);
  EXPECT_EQ(after.rig.control_period(), before.rig.control_period());
  EXPECT_EQ(after.study.linear.jerk, before.study.linear.jerk);
  EXPECT_EQ(after.study.dwell, before.study.dwell);
  // Writing again with the same platform changes nothing.
  EXPECT_EQ(platform_config_yaml(text, "written.yaml", want, "line one\nline two", true), text);
}

TEST(PlatformYaml, TheSeedInTheSymmetricFormBecomesTheLegsFormOfThePlatform) {
  expect_written(std::string(seed_config_yaml()), "seed.yaml");
}

std::string seed_legs_file() {
  std::ifstream in(std::string(HEXATWIST_SOURCE_DIR) + "/configs/seed-legs.yaml", std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  EXPECT_FALSE(text.str().empty()) << "configs/seed-legs.yaml";
  return text.str();
}

TEST(PlatformYaml, ALegsFileWithRigSectionsKeepsThem) { expect_written(seed_legs_file() + kRigSections, "legs.yaml"); }

TEST(PlatformYaml, ALegsOwnScrewKeysAreWrittenOnlyWhereTheyDifferFromTheBlock) {
  const ModelSpec want = identified_of(seed_model());
  const std::string text = platform_config_yaml(std::string(seed_config_yaml()), "seed.yaml", want, "", true);
  // Leg 3 is right-handed against the block's left, leg 4 has its own lead: once each.
  std::size_t count = 0;
  for (std::size_t at = text.find("thread: right"); at != std::string::npos; at = text.find("thread: right", at + 1))
    ++count;
  EXPECT_EQ(count, 1u) << text;
  EXPECT_NE(text.find("lead: " + fmt::format("{}", want.legs[3].lead)), std::string::npos) << text;
}

TEST(PlatformYaml, HomeCommandsAreWrittenWhenAskedOrGiven) {
  ModelSpec spec = seed_model().spec();
  const std::string seed(seed_config_yaml());
  EXPECT_EQ(platform_config_yaml(seed, "seed.yaml", spec, "", false).find("home_commands"), std::string::npos);
  const std::string with = platform_config_yaml(seed, "seed.yaml", spec, "", true);
  EXPECT_EQ(load_model(with, "with.yaml").home_command(), seed_model().home_command());
  spec.legs[2].home_command = 1.95;
  EXPECT_EQ(load_model(platform_config_yaml(seed, "seed.yaml", spec, "", false), "x.yaml").home_command()[2], 1.95);
}

TEST(PlatformYaml, BadTextAndAPlatformThatIsNoModelAreRefused) {
  const ModelSpec spec = seed_model().spec();
  expect_error_line([&] { (void)platform_config_yaml("screw: [", "bad.yaml", spec, "", true); }, "bad.yaml:");
  ModelSpec broken = spec;
  broken.legs[3].lead = -1.0;
  expect_error_line([&] { (void)platform_config_yaml(std::string(seed_config_yaml()), "seed.yaml", broken, "", true); },
                    "leg 4: lead:");
}

}  // namespace
}  // namespace hexatwist::test
