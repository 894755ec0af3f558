// SPDX-License-Identifier: BSD-3-Clause
// Writing a designed configuration (platform_yaml.hpp): the axes put in, every other key kept, a
// symmetric block turned into the same platform's legs, and designs that change more refused.
#include "hexatwist/io/platform_yaml.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "hexatwist/design/axis_design.hpp"
#include "hexatwist/io/config.hpp"
#include "support.hpp"

namespace hexatwist {
namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

AxisTurns some_turns() {
  AxisTurns t;
  for (int i = 0; i < kLegs; ++i) {
    t.base[i] = deg2rad(80.0 + 3 * i) * (i % 2 ? -1 : 1);
    t.platform[i] = deg2rad(70.0 - 2 * i);
    t.base_tilt[i] = deg2rad(i == 4 ? 5.0 : 0.0);
  }
  return t;
}

void expect_same_but_axes(const Config& written, const Config& original, const ModelSpec& designed) {
  const ModelSpec& w = written.rig.model().spec();
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_EQ(w.legs[i].axis_base_B, designed.legs[i].axis_base_B) << "leg " << i + 1;
    EXPECT_EQ(w.legs[i].axis_platform_P, designed.legs[i].axis_platform_P);
    EXPECT_EQ(w.legs[i].base_B, designed.legs[i].base_B);
    EXPECT_EQ(w.legs[i].platform_P, designed.legs[i].platform_P);
    EXPECT_EQ(w.legs[i].lead, designed.legs[i].lead);
  }
  EXPECT_EQ(w.home_height, designed.home_height);
  EXPECT_EQ(w.observation_P, designed.observation_P);
  EXPECT_EQ(w.limits.bend_max, designed.limits.bend_max);
  // The other sections kept.
  EXPECT_EQ(written.rig.servo().torque_limit, original.rig.servo().torque_limit);
  EXPECT_EQ(written.rig.load().mass, original.rig.load().mass);
  EXPECT_EQ(written.study.angular_amplitude, original.study.angular_amplitude);
}

TEST(DesignedConfig, TheSymmetricSeedBecomesItsLegsWithTheDesignedAxes) {
  const std::string text(seed_config_yaml());
  const Config original = load_config(text, "seed.yaml");
  const ModelSpec designed = turned_axes(original.rig.model().spec(), some_turns());
  const std::string out = designed_config_yaml(text, "seed.yaml", designed, "designed by a test\nsecond line");
  EXPECT_EQ(out.rfind("# designed by a test\n# second line\n", 0), 0u);
  EXPECT_EQ(out.find("symmetric:"), std::string::npos);
  const Config written = load_config(out, "written");
  expect_same_but_axes(written, original, designed);
  // The same platform otherwise: lengths at a pose agree exactly.
  LegState a, b;
  Pose p;
  p.position = Vector3d(0.1, 0.2, -0.1);
  p.rpy = Vector3d(0.1, 0.0, 0.2);
  ASSERT_EQ(inverse_kinematics(written.rig.model(), p, a), Status::Ok);
  ASSERT_EQ(inverse_kinematics(original.rig.model(), p, b), Status::Ok);
  EXPECT_EQ(a.length, b.length);
}

TEST(DesignedConfig, TheLegsFormKeepsEveryOtherKeyInPlace) {
  const std::string text = read_file(std::string(HEXATWIST_SOURCE_DIR) + "/configs/seed-legs.yaml");
  const Config original = load_config(text, "seed-legs.yaml");
  const ModelSpec designed = turned_axes(original.rig.model().spec(), some_turns());
  const std::string out = designed_config_yaml(text, "seed-legs.yaml", designed, "");
  expect_same_but_axes(load_config(out, "written"), original, designed);
  // Key order kept: name, then the legs before the limits as in the file.
  EXPECT_LT(out.find("name:"), out.find("legs:"));
  EXPECT_EQ(out.find("legs:") < out.find("limits:"), text.find("legs:") < text.find("limits:"));
}

TEST(DesignedConfig, RefusesADesignThatMovesAJointAndTextThatDoesNotLoad) {
  const std::string text(seed_config_yaml());
  ModelSpec designed = load_model(text, "seed.yaml").spec();
  designed.legs[3].platform_P.x() += 1e-3;
  test::expect_error_line([&] { (void)designed_config_yaml(text, "seed.yaml", designed, ""); },
                          "seed.yaml:", {"leg 4: platform", "only the U-joint axes"});
  test::expect_error_line([&] { (void)designed_config_yaml("legs: [", "bad.yaml", designed, ""); }, "bad.yaml:");
}

}  // namespace
}  // namespace hexatwist
