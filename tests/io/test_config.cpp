// SPDX-License-Identifier: BSD-3-Clause
// Config: YAML text to Model. The seed file gives the default model, the `legs` form of the seed
// gives the same kinematics, per-leg screw settings override the screw block, and every bad
// input is one line naming "file:line" and the field path.
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <string_view>

#include "support.hpp"
#include "yaml_text.hpp"

namespace hexatwist::test {
namespace {

// ---- YAML text helpers ----------------------------------------------------------------------

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string vec(const Vector3d& v) {
  std::ostringstream os;
  os.precision(17);
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

const std::string& kSymmetric = kSymmetricYaml;

// A model in the `legs` form. Layout: 1 name, 2 home_height, 3-6 screw, 7-11 limits, 12 "legs:",
// then four lines per leg i (0-based) from line 13 + 4 i: base, platform, base_axis, platform_axis.
constexpr int kLegsKeyLine = 12;
enum LegLine { kBase = 0, kPlatform = 1, kBaseAxis = 2, kPlatformAxis = 3 };
constexpr int leg_line(int i, LegLine field) { return 13 + 4 * i + field; }

std::string legs_yaml(const ModelSpec& spec) {
  std::ostringstream os;
  os.precision(17);
  os << "name: legs form\n"
     << "home_height: " << spec.home_height << "\n"
     << "screw:\n"
     << "  lead: " << spec.legs[0].lead << "\n"
     << "  thread: " << (spec.legs[0].thread == ThreadSense::Right ? "right" : "left") << "\n"
     << "  driven_side: " << (spec.legs[0].driven == DrivenSide::Base ? "base" : "platform") << "\n"
     << "limits:\n"
     << "  length_min: " << spec.limits.length_min << "\n"
     << "  length_max: " << spec.limits.length_max << "\n"
     << "  bend_max_deg: " << rad2deg(spec.limits.bend_max) << "\n"
     << "  singularity_margin_deg: " << rad2deg(spec.limits.singularity_margin) << "\n"
     << "legs:\n";
  for (const LegSpec& leg : spec.legs)
    os << "  - base: " << vec(leg.base_B) << "\n"
       << "    platform: " << vec(leg.platform_P) << "\n"
       << "    base_axis: " << vec(leg.axis_base_B) << "\n"
       << "    platform_axis: " << vec(leg.axis_platform_P) << "\n";
  return os.str();
}

const std::string& seed_legs_yaml() {
  static const std::string text = legs_yaml(seed_model().spec());
  return text;
}

// load_model(yaml, "bad.yaml") must throw; returns what() ("" and a failure if it loaded).
std::string load_error(const std::string& yaml) {
  try {
    (void)load_model(yaml, "bad.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "loaded without error:\n" << yaml;
  return {};
}

// The error is one line that starts with "bad.yaml:<line>:" and contains every one of `parts`.
void expect_error(const std::string& yaml, int line, std::initializer_list<std::string_view> parts) {
  const std::string msg = load_error(yaml);
  SCOPED_TRACE("message: " + msg);
  EXPECT_EQ(msg.find('\n'), std::string::npos) << "not a single line";
  const std::string where = "bad.yaml:" + std::to_string(line) + ":";
  EXPECT_EQ(msg.rfind(where, 0), 0u) << "does not start with " << where;
  for (const std::string_view p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "does not name '" << p << "'";
}

// Same leg geometry, limits and screw settings.
void expect_same_model(const Model& a, const Model& b) {
  const ModelSpec &sa = a.spec(), &sb = b.spec();
  EXPECT_EQ(sa.home_height, sb.home_height);
  EXPECT_EQ(sa.limits.length_min, sb.limits.length_min);
  EXPECT_EQ(sa.limits.length_max, sb.limits.length_max);
  EXPECT_EQ(sa.limits.bend_max, sb.limits.bend_max);
  EXPECT_EQ(sa.limits.singularity_margin, sb.limits.singularity_margin);
  EXPECT_EQ(sa.observation_P, sb.observation_P);
  EXPECT_EQ(sa.pivot_P, sb.pivot_P);
  EXPECT_EQ(a.has_twist(), b.has_twist());
  for (int i = 0; i < kLegs; ++i) {
    SCOPED_TRACE("leg " + std::to_string(i + 1));
    const Leg &la = a.leg(i), &lb = b.leg(i);
    EXPECT_EQ(la.base_B, lb.base_B);
    EXPECT_EQ(la.platform_P, lb.platform_P);
    EXPECT_EQ(la.axis_base_B, lb.axis_base_B);
    EXPECT_EQ(la.axis_platform_P, lb.axis_platform_P);
    EXPECT_EQ(la.s_home_B, lb.s_home_B);
    EXPECT_EQ(la.length_home, lb.length_home);
    EXPECT_EQ(la.theta_home, lb.theta_home);
    EXPECT_EQ(la.lead, lb.lead);
    EXPECT_EQ(la.twist_gain, lb.twist_gain);
    EXPECT_EQ(la.thread, lb.thread);
    EXPECT_EQ(la.driven, lb.driven);
  }
}

// ---- valid configurations -------------------------------------------------------------------

TEST(Config, SeedFileGivesTheDefaultModel) {
  const std::string text = read_file(HEXATWIST_SOURCE_DIR "/configs/seed.yaml");
  expect_same_model(load_model(text, "seed.yaml"), default_model());
  EXPECT_EQ(std::string(seed_config_yaml()), text) << "the embedded seed differs from configs/seed.yaml";
}

TEST(Config, SeedLegsFileIsTheSeedPlatformInTheLegsForm) {
  // configs/seed-legs.yaml writes the seed's vectors to 15 significant digits: lengths and twists
  // agree to the rounding of those digits (measured 2.0e-15 m, 2.7e-15 rad); bound 5e-14.
  const Model legs = load_model(read_file(HEXATWIST_SOURCE_DIR "/configs/seed-legs.yaml"), "seed-legs.yaml");
  std::mt19937_64 rng(kSeed + 70);
  for (int n = 0; n < 200; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.5, deg2rad(30));
    CommandReport a, b;
    ASSERT_EQ(compute_commands(seed_model(), p, a), Status::Ok);
    ASSERT_EQ(compute_commands(legs, p, b), Status::Ok) << str(p);
    EXPECT_LT((a.legs.length - b.legs.length).cwiseAbs().maxCoeff(), 5e-14) << str(p);
    EXPECT_LT((a.twist - b.twist).cwiseAbs().maxCoeff(), 5e-14) << str(p);
    EXPECT_LT((a.compensated - b.compensated).cwiseAbs().maxCoeff(), 5e-14) << str(p);
  }
  EXPECT_EQ(legs.spec().observation_P, seed_model().spec().observation_P);
  EXPECT_EQ(legs.spec().limits.length_max, seed_model().spec().limits.length_max);
}

TEST(Config, SeedFileIsTheDocumentedSymmetricPlatform) {
  // Ra 1.2, Rb 1.5, da 0.2, db 0.3, H 1.511 m; lead 10 mm, right hand, driven at the base.
  SymmetricSpec s;
  s.Ra = 1.2, s.Rb = 1.5, s.da = 0.2, s.db = 0.3, s.H = 1.511;
  const PerLeg<LegSpec> legs = symmetric_legs(s);
  const Model model = default_model();
  const ModelSpec& seed = model.spec();
  EXPECT_EQ(seed.home_height, 1.511);
  EXPECT_EQ(seed.limits.length_min, 1.40);
  EXPECT_EQ(seed.limits.length_max, 2.45);
  EXPECT_NEAR(rad2deg(seed.limits.bend_max), 40.0, 1e-12);
  EXPECT_NEAR(rad2deg(seed.limits.singularity_margin), 5.0, 1e-12);
  for (int i = 0; i < kLegs; ++i) {
    const auto k = static_cast<std::size_t>(i);
    EXPECT_EQ(seed.legs[k].base_B, legs[k].base_B) << "leg " << i + 1;
    EXPECT_EQ(seed.legs[k].platform_P, legs[k].platform_P) << "leg " << i + 1;
    EXPECT_EQ(seed.legs[k].axis_base_B, legs[k].axis_base_B) << "leg " << i + 1;
    EXPECT_EQ(seed.legs[k].axis_platform_P, legs[k].axis_platform_P) << "leg " << i + 1;
    EXPECT_EQ(seed.legs[k].lead, 0.010);
    EXPECT_EQ(seed.legs[k].thread, ThreadSense::Right);
    EXPECT_EQ(seed.legs[k].driven, DrivenSide::Base);
  }
}

TEST(Config, SymmetricTextOfTheTestsIsTheSeedGeometry) {
  // The base text the error tests break one line at a time is valid.
  const Model m = load_model(kSymmetric, "good.yaml");
  for (int i = 0; i < kLegs; ++i) EXPECT_EQ(m.leg(i).length_home, seed_model().leg(i).length_home);
  EXPECT_EQ(m.spec().name, "test platform");
}

TEST(Config, LegsFormOfTheSeedGivesTheSameLengthsAndTwists) {
  // Cross-form round trip: the seed's joints and axes written out as six explicit legs.
  const Model legs = load_model(seed_legs_yaml(), "legs.yaml");
  ASSERT_TRUE(legs.has_twist());
  std::mt19937_64 rng(kSeed + 20);
  double worst_length = 0.0, worst_twist = 0.0;
  for (int n = 0; n < 300; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.4, deg2rad(25));
    LegState sa, sb;
    Vector6d ta, tb;
    ASSERT_EQ(inverse_kinematics(seed_model(), p, sa), Status::Ok);
    ASSERT_EQ(inverse_kinematics(legs, p, sb), Status::Ok);
    ASSERT_EQ(twist(seed_model(), sa, ta), Status::Ok);
    ASSERT_EQ(twist(legs, sb, tb), Status::Ok);
    worst_length = std::max(worst_length, (sa.length - sb.length).cwiseAbs().maxCoeff());
    worst_twist = std::max(worst_twist, (ta - tb).cwiseAbs().maxCoeff());
    EXPECT_GT(ta.cwiseAbs().maxCoeff(), 0.0) << str(p);  // the comparison is not 0 == 0
  }
  // 17 significant digits round-trip every double: measured 0 m and 0 rad.
  EXPECT_LE(worst_length, 1e-15);
  EXPECT_LE(worst_twist, 1e-15);
}

TEST(Config, PerLegScrewSettingsOverrideTheScrewBlock) {
  // Screw block: 10 mm, right, base. Leg 2: 4 mm lead; leg 3: left hand; leg 5: driven at the
  // platform; leg 6: left hand and driven at the platform.
  std::string yaml = seed_legs_yaml();
  const auto add = [&](int i, const std::string& extra) {
    const int n = leg_line(i, kPlatformAxis);
    yaml = replace_line(yaml, n, line_of(yaml, n) + "\n    " + extra);
  };
  // Bottom up, so that the line numbers above stay valid.
  add(5, "thread: left\n    driven_side: platform");
  add(4, "driven_side: platform");
  add(2, "thread: left");
  add(1, "lead: 0.004");
  const Model m = load_model(yaml, "override.yaml");
  const double g = 0.010 / (2.0 * kPi);
  // The thread hand sets the sign of the twist term; the driven side does not (theory.md §4).
  const std::array<double, kLegs> expected{g, 0.004 / (2.0 * kPi), -g, g, g, -g};
  for (int i = 0; i < kLegs; ++i)
    EXPECT_NEAR(m.leg(i).twist_gain, expected[static_cast<std::size_t>(i)], 1e-18) << "leg " << i + 1;
  EXPECT_EQ(m.leg(1).lead, 0.004);
  EXPECT_EQ(m.leg(2).thread, ThreadSense::Left);
  EXPECT_EQ(m.leg(2).driven, DrivenSide::Base);
  EXPECT_EQ(m.leg(4).thread, ThreadSense::Right);
  EXPECT_EQ(m.leg(4).driven, DrivenSide::Platform);
}

TEST(Config, LengthOffsetsGiveEveryLegItsZeroErrorInEitherForm) {
  const std::string offsets = "length_offsets: [0.001, -0.0005, 0, 2.5e-4, -1e-3, 3e-6]\n";
  const std::array<double, kLegs> expected{0.001, -0.0005, 0.0, 2.5e-4, -1e-3, 3e-6};
  for (const std::string& form : {kSymmetric, seed_legs_yaml()}) {
    const Model m = load_model(form + offsets, "offsets.yaml");
    for (int i = 0; i < kLegs; ++i) EXPECT_EQ(m.leg(i).length_offset, expected[static_cast<std::size_t>(i)]) << i;
    // Nothing else changes.
    const Model plain = load_model(form, "plain.yaml");
    expect_same_model(m, plain);
    EXPECT_EQ(plain.geometry().length_offset, Vector6d::Zero());
  }
}

TEST(Config, BadLengthOffsetsAreLocated) {
  const int line = 17;  // appended after kSymmetric's 16 lines
  expect_error(kSymmetric + "length_offsets: [0, 0, 0]\n", line, {"field 'length_offsets'", "6 numbers", "got 3"});
  expect_error(kSymmetric + "length_offsets: 0.001\n", line, {"field 'length_offsets'", "6 numbers", "scalar"});
  expect_error(kSymmetric + "length_offsets: [0, 0, x, 0, 0, 0]\n", line, {"field 'length_offsets[2]'", "number"});
  // The model's own check (shorter than the stroke), at the entry it came from.
  expect_error(kSymmetric + "length_offsets: [0, 0, 0, 1.5, 0, 0]\n", line, {"field 'length_offsets[3]'", "stroke"});
}

TEST(Config, DriveLeadAndHomeCommandsGiveTheDrivesScaleAndReference) {
  // screw.drive_lead for every leg, a leg's own lead with its own drive_lead, home_commands for all.
  std::string yaml = seed_legs_yaml();
  yaml = replace_line(yaml, 4, line_of(yaml, 4) + "\n  drive_lead: 0.0098");
  // Leg 3 (one line further down now): its own lead 0.0102 and drive lead 0.0100; leg 5: its own
  // lead only, so no scale.
  const int shift = 1;
  yaml = replace_line(yaml, leg_line(4, kPlatformAxis) + shift,
                      line_of(yaml, leg_line(4, kPlatformAxis) + shift) + "\n    lead: 0.011");
  yaml = replace_line(yaml, leg_line(2, kPlatformAxis) + shift,
                      line_of(yaml, leg_line(2, kPlatformAxis) + shift) + "\n    lead: 0.0102\n    drive_lead: 0.0100");
  yaml += "home_commands: [1.91, 1.911, 1.912, 1.909, 1.9105, 1.9095]\n";
  const Model m = load_model(yaml, "drive.yaml");
  const std::array<double, kLegs> scale{0.010 / 0.0098, 0.010 / 0.0098, 0.0102 / 0.0100, 0.010 / 0.0098, 1.0,
                                        0.010 / 0.0098};
  for (int i = 0; i < kLegs; ++i) EXPECT_DOUBLE_EQ(m.leg(i).drive_scale, scale[static_cast<std::size_t>(i)]) << i;
  EXPECT_EQ(m.home_command(), (Vector6d() << 1.91, 1.911, 1.912, 1.909, 1.9105, 1.9095).finished());
  // Without them: no scale, and the reference is the command at home.
  const Model plain = load_model(seed_legs_yaml(), "plain.yaml");
  EXPECT_FALSE(plain.has_drive_scale());
  EXPECT_EQ(plain.home_command(), plain.length_home());
}

TEST(Config, BadDriveLeadsAndHomeCommandsAreLocated) {
  const int line = 17;  // appended after kSymmetric's 16 lines
  expect_error(kSymmetric + "home_commands: [1.9, 1.9]\n", line, {"field 'home_commands'", "6 numbers", "got 2"});
  expect_error(kSymmetric + "home_commands: [1.9, 1.9, 1.9, 1.9, 1.9, 9]\n", line,
               {"field 'home_commands[5]'", "outside the stroke"});
  std::string yaml = replace_line(kSymmetric, 9, line_of(kSymmetric, 9) + "\n  drive_lead: 0");
  expect_error(yaml, 10, {"field 'screw.drive_lead'", "> 0"});
  yaml = replace_line(kSymmetric, 9, line_of(kSymmetric, 9) + "\n  drive_lead: 0.1");
  expect_error(yaml, 10, {"field 'screw.drive_lead'", "within 50 %"});
}

TEST(Config, ZeroLeadLegsFormNeedsNoAxesAndNoThread) {
  // A plain Stewart platform: joints only.
  std::string yaml =
      "home_height: 1.511\n"
      "screw:\n"
      "  lead: 0\n"
      "limits: {length_min: 1.4, length_max: 2.45}\n"
      "legs:\n";
  for (const LegSpec& leg : seed_model().spec().legs)
    yaml += "  - {base: " + vec(leg.base_B) + ", platform: " + vec(leg.platform_P) + "}\n";
  const Model plain = load_model(yaml, "plain.yaml");
  EXPECT_FALSE(plain.has_twist());
  EXPECT_EQ(plain.spec().name, "plain.yaml");  // no name: the source
  std::mt19937_64 rng(kSeed + 21);
  for (int n = 0; n < 50; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.4, deg2rad(25));
    LegState sa, sb;
    ASSERT_EQ(inverse_kinematics(seed_model(), p, sa), Status::Ok);
    ASSERT_EQ(inverse_kinematics(plain, p, sb), Status::Ok);
    EXPECT_LE((sa.length - sb.length).cwiseAbs().maxCoeff(), 1e-15) << str(p);
  }
}

TEST(Config, ZeroLeadSymmetricFormNeedsNoThread) {
  const std::string yaml = erase_lines(replace_line(kSymmetric, 9, "  lead: 0"), 10, 11);
  const Model m = load_model(yaml, "plain.yaml");
  EXPECT_FALSE(m.has_twist());
}

TEST(Config, DefaultLimitsAreThirtyDegreesBendAndFiveDegreesMargin) {
  const Model m = load_model(erase_lines(kSymmetric, 15, 16), "defaults.yaml");
  EXPECT_NEAR(rad2deg(m.spec().limits.bend_max), 30.0, 1e-12);
  EXPECT_NEAR(rad2deg(m.spec().limits.singularity_margin), 5.0, 1e-12);
}

TEST(Config, JacobianConditionLimitIsOptionalAndValidated) {
  EXPECT_EQ(load_model(kSymmetric, "default.yaml").spec().limits.jacobian_condition_max, kDefaultJacobianConditionMax);
  EXPECT_EQ(seed_model().spec().limits.jacobian_condition_max, 50.0);  // configs/seed.yaml lists it
  const Model m = load_model(kSymmetric + "  jacobian_condition_max: 30\n", "thirty.yaml");
  EXPECT_EQ(m.spec().limits.jacobian_condition_max, 30.0);
  expect_error(kSymmetric + "  jacobian_condition_max: 1\n", 17, {"field 'limits.jacobian_condition_max'", "> 1"});
  expect_error(kSymmetric + "  jacobian_condition_max: .nan\n", 17, {"field 'limits.jacobian_condition_max'"});
  expect_error(kSymmetric + "  jacobian_condition_max: many\n", 17,
               {"field 'limits.jacobian_condition_max'", "'many'"});
  expect_error(kSymmetric + "  jacobian_condition_max: 4\n", 17, {"field 'limits.jacobian_condition_max'", "home"});
}

TEST(Config, ParseModelSpecLeavesValidationToModel) {
  // parse_model_spec reads; the Model validates. load_model does both and locates the error.
  const std::string yaml = replace_line(kSymmetric, 13, "  length_min: 2.5");
  const ModelSpec spec = parse_model_spec(yaml, "bad.yaml");
  EXPECT_EQ(spec.limits.length_min, 2.5);
  EXPECT_THROW(Model{spec}, Error);
}

// ---- bad input: one line, file:line, field path ---------------------------------------------

TEST(Config, SyntaxErrorNamesItsLine) {
  expect_error(replace_line(kSymmetric, 4, "  Rb: 1.5: 3"), 4, {"YAML syntax error"});
  expect_error(replace_line(kSymmetric, 4, " Rb: 1.5"), 4, {"YAML syntax error"});
  expect_error(replace_line(kSymmetric, 5, "\tda: 0.2"), 5, {"YAML syntax error"});
}

TEST(Config, TextThatYamlCppReadsAsEndlessDocumentsIsASyntaxError) {
  // yaml-cpp 0.7 alone never ends on these (found by fuzz/fuzz_config.cpp).
  expect_error(",name: {a!b}\n", 1, {"YAML syntax error", "unexpected ','"});
  expect_error("!tag ,\n", 1, {"YAML syntax error", "unexpected ','"});
  expect_error(kSymmetric + "---\n,\n", 18, {"YAML syntax error", "unexpected ','"});
}

TEST(Config, MissingKeyPointsAtTheBlockThatLacksIt) {
  expect_error(erase_lines(kSymmetric, 7, 7), 2, {"field 'symmetric.H'", "missing"});
  expect_error(erase_lines(kSymmetric, 13, 13), 12, {"field 'limits.length_min'", "missing"});
  expect_error(erase_lines(kSymmetric, 12, 16), 1, {"field 'limits'", "missing"});
  expect_error(erase_lines(seed_legs_yaml(), leg_line(3, kPlatform), leg_line(3, kPlatform)), leg_line(3, kBase),
               {"field 'legs[3] (leg 4).platform'", "missing"});
  expect_error(erase_lines(seed_legs_yaml(), 2, 2), 1, {"field 'home_height'", "missing"});
}

TEST(Config, TextWhereANumberBelongsIsRejected) {
  expect_error(replace_line(kSymmetric, 4, "  Rb: wide"), 4, {"field 'symmetric.Rb'", "number", "'wide'"});
  expect_error(replace_line(kSymmetric, 14, "  length_max: 2.45m"), 14, {"field 'limits.length_max'", "'2.45m'"});
  expect_error(replace_line(kSymmetric, 13, "  length_min: [1.4]"), 13, {"field 'limits.length_min'", "a list"});
  const int n = leg_line(2, kPlatform);
  expect_error(replace_line(seed_legs_yaml(), n, "    platform: [1, two, 0]"), n,
               {"field 'legs[2] (leg 3).platform[1]'", "'two'"});
  expect_error(replace_line(seed_legs_yaml(), n, "    platform: [1, 0]"), n,
               {"field 'legs[2] (leg 3).platform'", "three numbers"});
}

TEST(Config, EmptyValueIsReportedOnItsOwnLine) {
  // yaml-cpp marks an empty value at the next key; the message must still point at "Rb:".
  expect_error(replace_line(kSymmetric, 4, "  Rb:"), 4, {"field 'symmetric.Rb'"});
  expect_error(replace_line(kSymmetric, 16, "  singularity_margin_deg:"), 16,
               {"field 'limits.singularity_margin_deg'"});
}

TEST(Config, NanAndInfAreRejected) {
  for (const char* v : {".nan", ".NaN", ".inf", "-.inf", "+.Inf"}) {
    SCOPED_TRACE(v);
    expect_error(replace_line(kSymmetric, 7, std::string("  H: ") + v), 7, {"field 'symmetric.H'", "finite", v});
    const int n = leg_line(1, kBase);
    expect_error(replace_line(seed_legs_yaml(), n, std::string("  - base: [0.9, ") + v + ", 0]"), n,
                 {"field 'legs[1] (leg 2).base[1]'", "finite"});
  }
}

TEST(Config, ZeroAxisInLegsFormNamesTheLegAndLine) {
  const int n = leg_line(2, kBaseAxis);
  ASSERT_EQ(line_of(seed_legs_yaml(), n).rfind("    base_axis: ", 0), 0u);
  expect_error(replace_line(seed_legs_yaml(), n, "    base_axis: [0, 0, 0]"), n,
               {"field 'legs[2] (leg 3).base_axis'", "zero"});
}

TEST(Config, AxisParallelToItsLegAtHomeNamesTheLegAndLine) {
  const int n = leg_line(2, kBaseAxis);
  expect_error(replace_line(seed_legs_yaml(), n, "    base_axis: " + vec(seed_model().leg(2).s_home_B)), n,
               {"field 'legs[2] (leg 3).base_axis'", "singularity margin"});
  const int m = leg_line(5, kPlatformAxis);
  ASSERT_EQ(line_of(seed_legs_yaml(), m).rfind("    platform_axis: ", 0), 0u);
  expect_error(replace_line(seed_legs_yaml(), m, "    platform_axis: " + vec(-seed_model().leg(5).s_home_B)), m,
               {"field 'legs[5] (leg 6).platform_axis'", "singularity margin"});
}

TEST(Config, LengthMinAboveLengthMaxIsRejected) {
  expect_error(replace_line(kSymmetric, 13, "  length_min: 2.5"), 13, {"field 'limits.length_min'", "length_max"});
  expect_error(replace_line(kSymmetric, 13, "  length_min: -1"), 13, {"field 'limits.length_min'", "> 0"});
}

TEST(Config, OtherModelErrorsAreLocated) {
  expect_error(replace_line(kSymmetric, 15, "  bend_max_deg: 100"), 15, {"field 'limits.bend_max_deg'", "90"});
  expect_error(replace_line(kSymmetric, 9, "  lead: -0.01"), 9, {"field 'screw.lead'", ">= 0"});
  // A derived (symmetric) leg outside the stroke: the block it came from, and the leg.
  expect_error(replace_line(kSymmetric, 14, "  length_max: 1.9"), 2, {"field 'symmetric'", "leg 1", "stroke"});
  // Two legs in the same place in the legs form: the platform is not held.
  std::string yaml = seed_legs_yaml();
  for (int f = kBase; f <= kPlatformAxis; ++f)
    yaml = replace_line(yaml, leg_line(1, LegLine(f)), line_of(yaml, leg_line(0, LegLine(f))));
  expect_error(yaml, kLegsKeyLine, {"field 'legs'", "do not hold"});
}

TEST(Config, UnknownKeyIsRejected) {
  expect_error(replace_line(kSymmetric, 3, "  Rq: 1.2"), 3, {"field 'symmetric.Rq'", "unknown key", "Ra"});
  expect_error(replace_line(kSymmetric, 12, "limit:"), 12, {"field 'limit'", "unknown key", "limits"});
  const int n = leg_line(4, kBaseAxis);
  expect_error(replace_line(seed_legs_yaml(), n, "    base_axes: [1, 0, 0]"), n,
               {"field 'legs[4] (leg 5).base_axes'", "unknown key"});
}

TEST(Config, KeyGivenTwiceIsRejected) {
  // yaml-cpp would silently keep the first value.
  expect_error(replace_line(kSymmetric, 9, "  lead: 0.010\n  lead: 0.005"), 10,
               {"field 'screw.lead'", "twice", "line 9"});
}

TEST(Config, LegsListMustHoldSixLegs) {
  const std::string five = erase_lines(seed_legs_yaml(), leg_line(5, kBase), leg_line(5, kPlatformAxis));
  expect_error(five, kLegsKeyLine, {"field 'legs'", "exactly 6", "got 5"});
  const std::string seven = seed_legs_yaml() + erase_lines(seed_legs_yaml(), 1, kLegsKeyLine + 20);
  expect_error(seven, kLegsKeyLine, {"field 'legs'", "exactly 6", "got 7"});
  const std::string scalar = erase_lines(seed_legs_yaml(), kLegsKeyLine, leg_line(5, kPlatformAxis)) + "legs: 6\n";
  expect_error(scalar, kLegsKeyLine, {"field 'legs'", "exactly 6"});
}

TEST(Config, SymmetricAndLegsTogetherAreRejected) {
  // The later of the two is reported, with the line of the other.
  const std::string both = seed_legs_yaml() + "symmetric: {Ra: 1.2, Rb: 1.5, da: 0.2, db: 0.3, H: 1.511}\n";
  expect_error(both, kLegsKeyLine + 4 * kLegs + 1, {"field 'symmetric'", "'legs' (line 12)", "exactly one"});
}

TEST(Config, NeitherSymmetricNorLegsIsRejected) {
  expect_error(erase_lines(kSymmetric, 2, 7), 1, {"exactly one of 'symmetric'", "neither"});
}

TEST(Config, ThreadMustBeRightOrLeft) {
  expect_error(replace_line(kSymmetric, 10, "  thread: sideways"), 10,
               {"field 'screw.thread'", "right or left", "'sideways'"});
  expect_error(replace_line(kSymmetric, 11, "  driven_side: middle"), 11,
               {"field 'screw.driven_side'", "base or platform"});
}

TEST(Config, ThreadAndDrivenSideAreRequiredWhenLeadIsPositive) {
  expect_error(erase_lines(kSymmetric, 10, 10), 8, {"field 'screw.thread'", "missing"});
  expect_error(erase_lines(kSymmetric, 11, 11), 8, {"field 'screw.driven_side'", "missing"});
  // A leg's own lead > 0 needs a thread too, when the screw block (lead 0) gives none.
  std::string yaml = seed_legs_yaml();
  const int n = leg_line(3, kPlatformAxis);
  yaml = replace_line(yaml, n, line_of(yaml, n) + "\n    lead: 0.01");
  yaml = erase_lines(replace_line(yaml, 4, "  lead: 0"), 5, 6);  // leg 4 moves up two lines
  expect_error(yaml, leg_line(3, kBase) - 2, {"field 'legs[3] (leg 4).thread'", "missing"});
}

TEST(Config, EmptyDocumentIsRejected) {
  for (const char* text : {"", "# nothing but a comment\n", "\n\n"}) {
    SCOPED_TRACE(text);
    expect_error(text, 1, {"empty document"});
  }
}

TEST(Config, NonMappingDocumentAndSecondDocumentAreRejected) {
  expect_error("- 1\n- 2\n", 1, {"expected a mapping"});
  expect_error(kSymmetric + "---\nname: again\n", 18, {"one YAML document"});  // the second one's first line
}

TEST(Config, MultiLineValueInAMessageStaysOneLine) {
  expect_error(replace_line(kSymmetric, 4, "  Rb: |\n    1.5\n    wide"), 4, {"field 'symmetric.Rb'", "\\n"});
  expect_error(replace_line(kSymmetric, 3, "  ? |\n    R\n    a\n  : 1.2"), 3, {"unknown key"});
}

}  // namespace
}  // namespace hexatwist::test

namespace hexatwist {
namespace {

const std::string kRigSections =
    "servo:\n"                                                  // 17
    "  max_speed_rpm: 1500\n"                                   // 18
    "  kp: 100\n"                                               // 19
    "  ki: 1000\n"                                              // 20
    "  kd: 0.5\n"                                               // 21
    "load:\n"                                                   // 22
    "  mass: 900\n"                                             // 23
    "  inertia: [100, 200, 300]\n"                              // 24
    "simulation:\n"                                             // 25
    "  control_rate_hz: 2000\n"                                 // 26
    "  plant_step: 1.0e-4\n"                                    // 27
    "study:\n"                                                  // 28
    "  angular_amplitude_deg: 20\n"                             // 29
    "  linear: {velocity: 0.1, acceleration: 0.4, jerk: 2}\n";  // 30

std::string config_error(const std::string& yaml) {
  try {
    (void)load_config(yaml, "rig.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Config, TheSectionsLeftToTheSeedsDefaultsAreNamed) {
  // kRigSections gives servo and load; the mechanism is left out, as the geometry alone leaves all three.
  EXPECT_EQ(load_config(test::kSymmetricYaml + kRigSections, "rig.yaml").defaulted,
            std::vector<std::string>{"mechanism"});
  EXPECT_EQ(load_config(test::kSymmetricYaml, "geometry.yaml").defaulted,
            (std::vector<std::string>{"servo", "load", "mechanism"}));
  EXPECT_TRUE(default_config().defaulted.empty());  // the seed gives every section
  EXPECT_EQ(parse_config_spec(test::kSymmetricYaml + "load: {mass: 10}\n", "l.yaml").defaulted,
            (std::vector<std::string>{"servo", "mechanism"}));
}

TEST(Config, RigSectionsReachTheRigInSiUnits) {
  const Config c = load_config(test::kSymmetricYaml + kRigSections, "rig.yaml");
  EXPECT_NEAR(c.rig.servo().max_speed, 1500 * 2 * kPi / 60, 1e-12);
  EXPECT_EQ(c.rig.kp()[0], 100);
  EXPECT_EQ(c.rig.ki()[5], 1000);
  EXPECT_EQ(c.rig.kd()[2], 0.5);
  EXPECT_EQ(c.rig.load().mass, 900);
  EXPECT_EQ(c.rig.load().inertia, Vector3d(100, 200, 300));
  EXPECT_EQ(c.rig.load().center_of_mass_P, LoadSpec{}.center_of_mass_P);  // not given: default
  EXPECT_DOUBLE_EQ(c.rig.control_period(), 0.5e-3);
  EXPECT_EQ(c.rig.substeps(), 5);
  EXPECT_NEAR(c.study.angular_amplitude, deg2rad(20), 1e-15);
  EXPECT_EQ(c.study.linear.jerk, 2);
  EXPECT_EQ(c.study.dwell, StudySpec{}.dwell);
}

TEST(Config, SeedFileSpellsOutTheDefaults) {
  // configs/seed.yaml lists every servo, load, simulation and study key with its default value.
  const Config c = default_config();
  const ServoSpec d;
  EXPECT_EQ(c.rig.servo().motor_inertia, d.motor_inertia);
  EXPECT_EQ(c.rig.servo().screw_inertia, d.screw_inertia);
  EXPECT_EQ(c.rig.servo().viscous_friction, d.viscous_friction);
  EXPECT_EQ(c.rig.servo().torque_limit, d.torque_limit);
  EXPECT_NEAR(c.rig.servo().max_speed, d.max_speed, 1e-12);
  EXPECT_EQ(c.rig.servo().encoder_counts, d.encoder_counts);
  EXPECT_EQ(c.rig.servo().pole_frequency, d.pole_frequency);
  EXPECT_EQ(c.rig.load().mass, LoadSpec{}.mass);
  EXPECT_EQ(c.rig.load().center_of_mass_P, LoadSpec{}.center_of_mass_P);
  EXPECT_EQ(c.rig.load().inertia, LoadSpec{}.inertia);
  EXPECT_EQ(c.rig.simulation().plant_step, SimulationSpec{}.plant_step);
  const StudySpec s;
  EXPECT_EQ(c.study.linear.velocity, s.linear.velocity);
  EXPECT_NEAR(c.study.angular.jerk, s.angular.jerk, 1e-12);
  EXPECT_NEAR(c.study.angular_amplitude, s.angular_amplitude, 1e-15);
  EXPECT_EQ(c.study.dwell, s.dwell);
}

TEST(Config, RigSectionErrorsNameLineAndField) {
  const std::string base = test::kSymmetricYaml + kRigSections;
  const struct {
    int line;
    const char* text;
    const char* expect;
  } cases[] = {
      {18, "  max_speed_rpm: -5", "rig.yaml:18:18: field 'servo.max_speed_rpm': expected > 0"},
      {18, "  max_speed: 5", "rig.yaml:18:3: field 'servo.max_speed': unknown key"},
      {19, "  kp: 0", "rig.yaml:19:7: field 'servo.kp': expected > 0 when ki or kd is given"},
      {23, "  mass: heavy", "rig.yaml:23:9: field 'load.mass': expected a number"},
      {24, "  inertia: [100, 200]", "rig.yaml:24:"},
      {27, "  plant_step: 0.01",
       "rig.yaml:27:15: field 'simulation.plant_step': 0.01 s is longer than the control period"},
      {30, "  linear: {velocity: 0.1, acceleration: 0, jerk: 2}", "field 'study.linear.acceleration': expected > 0"},
  };
  for (const auto& c : cases) {
    const std::string msg = config_error(test::replace_line(base, c.line, c.text));
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.text << "\n  got: " << msg;
  }
  // The servo needs a screw on every leg.
  EXPECT_NE(config_error(test::replace_line(base, 9, "  lead: 0")).find("needs a lead screw"), std::string::npos);
}

// ---- every numeric field of the schema (#22) -------------------------------------------------

// A number's place in a document: the keys (and list indices) from the top.
using Path = std::vector<std::string>;

std::string dotted(const Path& path) {
  std::string s;
  for (const std::string& k : path) s += k[0] == '[' ? k : (s.empty() ? k : "." + k);
  return s;
}

// Every scalar of `node` that reads as a number, with its path.
void numbers_of(const YAML::Node& node, Path& at, std::vector<Path>& out) {
  if (node.IsMap()) {
    for (const auto& kv : node) {
      at.push_back(kv.first.Scalar());
      numbers_of(kv.second, at, out);
      at.pop_back();
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      at.push_back("[" + std::to_string(i) + "]");
      numbers_of(node[i], at, out);
      at.pop_back();
    }
  } else if (double v = 0.0; node.IsScalar() && YAML::convert<double>::decode(node, v)) {
    out.push_back(at);
  }
}

// `text` with the scalar at `path` replaced by `value` (comments are dropped).
std::string with_number(const std::string& text, const Path& path, const std::string& value) {
  YAML::Node root = YAML::Load(text);
  std::vector<YAML::Node> chain{root};
  for (const std::string& k : path)
    chain.push_back(k[0] == '[' ? chain.back()[std::stoul(k.substr(1))] : chain.back()[k]);
  chain.back() = YAML::Load(value.empty() ? "''" : value);
  YAML::Emitter e;
  e << root;
  return e.c_str();
}

// The configuration works: the drives' derived numbers are finite, home is commanded and held, and
// each study test fits its bound.
std::string not_meaningful(const Config& c) {
  const Rig& rig = c.rig;
  for (const Vector6d* v : {&rig.kp(), &rig.ki(), &rig.kd(), &rig.nominal_inertia(), &rig.motor_gain()})
    if (!v->allFinite() || (v->array() < 0.0).any()) return "a derived gain or inertia is not finite and >= 0";
  Vector6d hold;
  if (holding_torque(rig, Pose{}, hold) != Status::Ok || !hold.allFinite()) return "no finite holding torque at home";
  CommandReport report;
  if (compute_commands(rig.model(), Pose{}, report) != Status::Ok || !report.compensated.allFinite())
    return "home cannot be commanded";
  for (const StudyTest& t : seed_tests(c.study))
    if (test_trajectory(c.study, t, rig.control_period()).poses.size() > kMaxTrajectorySamples)
      return "a study test is too long";
  return {};
}

TEST(Config, EveryNumericFieldOfTheSchemaLoadsOrIsRefusedNamingItself) {
  // The seed with every optional key (drive lead, home commands), in both layouts (per-leg screws).
  const std::string symmetric = std::string(seed_config_yaml()) + "home_commands: [1.7, 2.3, 1.7, 2.3, 1.7, 2.3]\n";
  std::string legs = test::read_file(std::string(HEXATWIST_SOURCE_DIR) + "/configs/seed-legs.yaml");
  {
    YAML::Node root = YAML::Load(legs);
    root["screw"]["drive_lead"] = 0.0101;
    root["legs"][0]["lead"] = 0.010;
    root["legs"][0]["drive_lead"] = 0.0099;
    YAML::Emitter e;
    e << root;
    legs = e.c_str();
  }
  ASSERT_NO_THROW(load_config(symmetric, "symmetric.yaml"));
  ASSERT_NO_THROW(load_config(legs, "legs.yaml"));
  int fields = 0, loaded = 0, refused = 0;
  for (const std::string& text : {symmetric, legs}) {
    std::vector<Path> paths;
    Path at;
    numbers_of(YAML::Load(text), at, paths);
    for (const Path& path : paths) {
      ++fields;
      for (const char* value : {".nan", ".inf", "-.inf", "0", "-1", "1e300", ""}) {
        const std::string field = dotted(path);
        SCOPED_TRACE(field + " = '" + value + "'");
        const std::string bad = with_number(text, path, value);
        try {
          const Config c = load_config(bad, "t.yaml");
          const std::string why = not_meaningful(c);
          EXPECT_EQ(why, "") << "loads, but " << why;
          ++loaded;
        } catch (const Error& e) {
          const std::string msg = e.what();
          ++refused;
          EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
          // Named at the field itself, or (an entry of a list, a value of a derived layout) at the
          // list or block that holds it.
          std::string named;
          for (Path p = path; !p.empty() && named.empty(); p.pop_back())
            if (msg.find(dotted(p)) != std::string::npos) named = dotted(p);
          EXPECT_FALSE(named.empty()) << msg;
          // Never at an unrelated field: the top-level key of the message is the field's own.
          EXPECT_NE(msg.find("field '" + path[0]), std::string::npos) << msg;
        }
      }
    }
  }
  std::printf("  %d numeric fields, %d values loaded, %d refused\n", fields, loaded, refused);
  EXPECT_GT(fields, 100);
}

}  // namespace
}  // namespace hexatwist
