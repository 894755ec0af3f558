// SPDX-License-Identifier: BSD-3-Clause
// Model: validation of a ModelSpec (one broken thing at a time, each error a single line naming
// the leg or field), the twist gain's sign, the plain-Stewart case and the symmetric layout.
#include <cmath>
#include <initializer_list>
#include <limits>
#include <string>
#include <string_view>

#include "support.hpp"

namespace hexatwist::test {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

ModelSpec seed_spec() { return seed_model().spec(); }

// Builds a Model from `spec` expecting hexatwist::Error; returns what() ("" and a failure if
// the spec was accepted).
std::string construction_error(const ModelSpec& spec) {
  try {
    const Model model(spec);
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "the Model accepted an invalid spec";
  return {};
}

// The spec is rejected with one line that contains every one of `parts` (leg, field, reason).
void expect_rejected(const ModelSpec& spec, std::initializer_list<std::string_view> parts) {
  const std::string msg = construction_error(spec);
  SCOPED_TRACE("message: " + msg);
  EXPECT_EQ(msg.find('\n'), std::string::npos) << "not a single line";
  for (const std::string_view p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "does not name '" << p << "'";
}

// A unit vector at `angle` [rad] from the unit vector s.
Vector3d at_angle_from(const Vector3d& s, double angle) {
  return std::cos(angle) * s + std::sin(angle) * s.unitOrthogonal();
}

TEST(Model, SeedSpecIsValid) {
  EXPECT_NO_THROW(Model{seed_spec()});
  EXPECT_TRUE(seed_model().has_twist());
}

TEST(Model, RejectsZeroAxis) {
  ModelSpec spec = seed_spec();
  spec.legs[2].axis_base_B = Vector3d::Zero();
  expect_rejected(spec, {"leg 3", "base_axis", "zero"});
  spec = seed_spec();
  spec.legs[4].axis_platform_P = Vector3d(0.0, 1e-12, 0.0);
  expect_rejected(spec, {"leg 5", "platform_axis", "zero"});
}

TEST(Model, AcceptsAxisOfAnyNonZeroLength) {
  // An axis is a direction: scaling it changes nothing.
  ModelSpec spec = seed_spec();
  spec.legs[2].axis_base_B *= 1e-6;
  spec.legs[3].axis_platform_P *= 250.0;
  const Model scaled(spec);
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_NEAR(scaled.leg(i).theta_home, seed_model().leg(i).theta_home, 1e-14) << "leg " << i + 1;
    EXPECT_LT((scaled.leg(i).axis_base_B - seed_model().leg(i).axis_base_B).norm(), 1e-15) << "leg " << i + 1;
    EXPECT_LT((scaled.leg(i).axis_platform_P - seed_model().leg(i).axis_platform_P).norm(), 1e-15) << "leg " << i + 1;
  }
}

TEST(Model, RejectsAxisParallelToItsLegAtHome) {
  ModelSpec spec = seed_spec();
  spec.legs[2].axis_base_B = seed_model().leg(2).s_home_B;
  expect_rejected(spec, {"leg 3", "base_axis", "singularity margin"});
  spec = seed_spec();
  spec.legs[5].axis_platform_P = -seed_model().leg(5).s_home_B;  // P is parallel to B at home
  expect_rejected(spec, {"leg 6", "platform_axis", "singularity margin"});
}

TEST(Model, SingularityMarginIsTheBoundaryForAxesAtHome) {
  const double margin = seed_spec().limits.singularity_margin;
  const Vector3d s = seed_model().leg(1).s_home_B;
  ModelSpec spec = seed_spec();
  spec.legs[1].axis_base_B = at_angle_from(s, margin - deg2rad(0.01));
  expect_rejected(spec, {"leg 2", "base_axis"});
  spec.legs[1].axis_base_B = at_angle_from(s, margin + deg2rad(0.01));
  EXPECT_NO_THROW(Model{spec});
  spec.legs[1].axis_base_B = -at_angle_from(s, margin - deg2rad(0.01));  // the axis is a line
  expect_rejected(spec, {"leg 2", "base_axis"});
}

TEST(Model, RejectsLengthMinNotBelowLengthMax) {
  ModelSpec spec = seed_spec();
  spec.limits.length_min = 2.5;
  spec.limits.length_max = 1.4;
  expect_rejected(spec, {"limits.length_min", "limits.length_max"});
  spec.limits.length_min = spec.limits.length_max = 1.91;
  expect_rejected(spec, {"limits.length_min", "limits.length_max"});
}

TEST(Model, RejectsNonPositiveLengthMin) {
  for (const double v : {0.0, -1.0}) {
    ModelSpec spec = seed_spec();
    spec.limits.length_min = v;
    expect_rejected(spec, {"limits.length_min", "> 0"});
  }
}

TEST(Model, RejectsNonFiniteJointPositionAndAxis) {
  ModelSpec spec = seed_spec();
  spec.legs[2].base_B.y() = kNaN;
  expect_rejected(spec, {"leg 3", "base", "finite"});
  spec = seed_spec();
  spec.legs[4].platform_P.z() = kInf;
  expect_rejected(spec, {"leg 5", "platform", "finite"});
  spec = seed_spec();
  spec.legs[0].axis_platform_P.x() = -kInf;
  expect_rejected(spec, {"leg 1", "platform_axis", "finite"});
}

TEST(Model, RejectsNonFiniteLead) {
  for (const double v : {kNaN, kInf}) {
    ModelSpec spec = seed_spec();
    spec.legs[3].lead = v;
    expect_rejected(spec, {"leg 4", "lead", "finite"});
  }
}

TEST(Model, RejectsNonFiniteLengthOffsetOrOneAsLongAsTheStroke) {
  // A zero error of the motor-side length (theory §4) is finite and shorter than the stroke
  // (1.05 m on the seed); the sign is free.
  for (const double v : {kNaN, kInf, -kInf}) {
    ModelSpec spec = seed_spec();
    spec.legs[2].length_offset = v;
    expect_rejected(spec, {"leg 3", "length_offset", "finite"});
  }
  for (const double v : {1.06, -1.06, 2.0}) {
    ModelSpec spec = seed_spec();
    spec.legs[4].length_offset = v;
    expect_rejected(spec, {"leg 5", "length_offset", "stroke"});
  }
  ModelSpec spec = seed_spec();
  spec.legs[4].length_offset = -0.5;
  spec.legs[5].length_offset = 1e-3;
  const Model m(spec);
  EXPECT_EQ(m.leg(4).length_offset, -0.5);
  EXPECT_EQ(m.geometry().length_offset[5], 1e-3);
  EXPECT_EQ(m.geometry().length_offset[0], 0.0);
}

TEST(Model, RejectsLengthOffsetsThatPutTheHomeCommandOutsideTheStroke) {
  // The seed's legs are 1.910247 m at home and its stroke [1.40, 2.45] m: the motor's command
  // there, length minus offset, is inside for offsets in [-0.54, 0.51] m.
  for (const double v : {-0.55, 0.52, -1.04}) {
    ModelSpec spec = seed_spec();
    spec.legs[4].length_offset = v;
    expect_rejected(spec, {"leg 5", "length_offset", "home command", "outside the stroke"});
  }
}

TEST(Model, RejectsALeadLongerThanTheStroke) {
  for (const double v : {1.06, 1e30}) {
    ModelSpec spec = seed_spec();
    spec.legs[3].lead = v;
    expect_rejected(spec, {"leg 4", "lead", "at most the stroke"});
  }
  ModelSpec spec = seed_spec();
  spec.legs[3].lead = 1.05;  // one turn over the whole stroke: a screw still
  EXPECT_NO_THROW((void)Model(spec));
}

TEST(Model, RejectsNonFiniteOrNonPositiveHomeHeight) {
  for (const double v : {kNaN, kInf, -kInf, 0.0, -1.511}) {
    ModelSpec spec = seed_spec();
    spec.home_height = v;
    expect_rejected(spec, {"home_height"});
  }
}

TEST(Model, RejectsNonFiniteObservationPointAndPivot) {
  ModelSpec spec = seed_spec();
  spec.observation_P.x() = kNaN;
  expect_rejected(spec, {"observation_point", "finite"});
  spec = seed_spec();
  spec.pivot_P.z() = kInf;
  expect_rejected(spec, {"pivot", "finite"});
}

TEST(Model, RejectsNegativeLead) {
  ModelSpec spec = seed_spec();
  spec.legs[1].lead = -0.01;
  expect_rejected(spec, {"leg 2", "lead", ">= 0"});
}

TEST(Model, RejectsHomeLengthOutsideTheStroke) {
  // Only leg 4 is made longer than the stroke allows: the message must name it, not leg 1.
  ModelSpec spec = seed_spec();
  spec.legs[3].base_B.head<2>() *= 1.3;
  spec.limits.length_max = 0.5 * (seed_model().length_home()[0] + Model(spec).length_home()[3]);
  expect_rejected(spec, {"leg 4", "home length", "stroke"});
  spec = seed_spec();
  spec.limits.length_min = seed_model().length_home()[0] + 1e-6;
  expect_rejected(spec, {"leg 1", "home length", "stroke"});
}

TEST(Model, RejectsCoincidingJoints) {
  ModelSpec spec = seed_spec();
  spec.legs[5].platform_P = spec.legs[5].base_B - Vector3d(0.0, 0.0, spec.home_height);
  expect_rejected(spec, {"leg 6", "coincide"});
}

TEST(Model, RejectsLegsThatDoNotHoldThePlatform) {
  // Six vertical legs: nothing resists a horizontal push or a yaw.
  ModelSpec vertical = seed_spec();
  for (LegSpec& leg : vertical.legs) leg.platform_P = leg.base_B;
  expect_rejected(vertical, {"legs", "do not hold"});
  // Legs in identical pairs: three distinct legs cannot fix six degrees of freedom.
  ModelSpec pairs = seed_spec();
  for (int i = 1; i < kLegs; i += 2)
    pairs.legs[static_cast<std::size_t>(i)] = pairs.legs[static_cast<std::size_t>(i - 1)];
  expect_rejected(pairs, {"legs", "do not hold"});
}

TEST(Model, RejectsBendMaxOutsideZeroToNinetyDegrees) {
  for (const double v : {0.0, -0.1, kPi / 2 + 1e-9, kPi, kNaN}) {
    ModelSpec spec = seed_spec();
    spec.limits.bend_max = v;
    expect_rejected(spec, {"limits.bend_max"});
  }
  ModelSpec spec = seed_spec();
  spec.limits.bend_max = kPi / 2;
  EXPECT_NO_THROW(Model{spec});
}

TEST(Model, RejectsSingularityMarginOutsideZeroToNinetyDegrees) {
  for (const double v : {0.0, -0.1, kPi / 2, kInf, kNaN}) {
    ModelSpec spec = seed_spec();
    spec.limits.singularity_margin = v;
    expect_rejected(spec, {"limits.singularity_margin"});
  }
}

TEST(Model, ZeroLeadWithoutAxesIsAPlainStewartPlatform) {
  ModelSpec spec = seed_spec();
  for (LegSpec& leg : spec.legs) {
    leg.lead = 0.0;
    leg.axis_base_B.setZero();
    leg.axis_platform_P.setZero();
  }
  const Model plain(spec);
  EXPECT_FALSE(plain.has_twist());
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_EQ(plain.leg(i).twist_gain, 0.0) << "leg " << i + 1;
    EXPECT_TRUE(std::isnan(plain.leg(i).theta_home)) << "leg " << i + 1;
  }
  // Without a twist term the motor commands are the leg lengths.
  std::mt19937_64 rng(kSeed + 10);
  CommandReport r;
  for (int n = 0; n < 100; ++n) {
    const Pose p = random_valid_pose(plain, rng, 0.4, deg2rad(20));
    ASSERT_EQ(compute_commands(plain, p, r), Status::Ok) << str(p);
    EXPECT_EQ(r.compensated, r.conventional) << str(p);
    EXPECT_EQ(r.compensated, r.legs.length) << str(p);
  }
}

TEST(Model, OneLeadedLegMakesTheModelTwist) {
  ModelSpec spec = seed_spec();
  for (LegSpec& leg : spec.legs) leg.lead = 0.0;
  EXPECT_FALSE(Model(spec).has_twist());
  spec.legs[4].lead = 0.005;
  EXPECT_TRUE(Model(spec).has_twist());
}

// First principles of a screw and its nut, independent of the library: for a right-hand (hand =
// +1) thread, turning the nut by +a about the axis relative to the screw moves it lead*a/2pi along
// the axis. Driven at the base, the housing carries the screw (turned by the motor angle qm) and
// the rod the nut; driven at the platform, the rod carries the screw and the housing the nut.
// Returns real length minus motor-side length for a rod-to-housing twist dtheta.
double screw_nut_length_error(double hand, DrivenSide side, double lead, double qm, double dtheta) {
  const double k = hand * lead / (2.0 * kPi);
  if (side == DrivenSide::Base) {
    const double extension = k * (dtheta - qm);  // nut (rod) relative to screw (housing)
    const double motor_side = k * (0.0 - qm);    // the same with no twist: what the encoder implies
    return extension - motor_side;
  }
  const double extension = -k * (0.0 - (dtheta + qm));  // screw (rod) relative to nut (housing)
  const double motor_side = -k * (0.0 - qm);
  return extension - motor_side;
}

TEST(Model, TwistGainFollowsScrewAndNutMechanicsForEveryThreadAndDrivenSide) {
  // The thread hand sets the sign; the driven side does not (docs/theory.md §4).
  ModelSpec spec = seed_spec();
  const std::array<ThreadSense, 2> hands{ThreadSense::Right, ThreadSense::Left};
  const std::array<DrivenSide, 2> sides{DrivenSide::Base, DrivenSide::Platform};
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
    leg.lead = 0.002 * (i + 1);
    leg.thread = hands[static_cast<std::size_t>(i % 2)];
    leg.driven = sides[static_cast<std::size_t>((i / 2) % 2)];
  }
  const Model model(spec);
  for (int i = 0; i < kLegs; ++i) {
    const LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
    const double hand = leg.thread == ThreadSense::Right ? 1.0 : -1.0;
    for (const double qm : {0.0, 3.7, -12.0}) {
      for (const double dtheta : {0.3, -0.7}) {
        EXPECT_NEAR(model.leg(i).twist_gain * dtheta, screw_nut_length_error(hand, leg.driven, leg.lead, qm, dtheta),
                    1e-15)
            << "leg " << i + 1;
      }
    }
    EXPECT_EQ(model.leg(i).twist_sign, hand) << "leg " << i + 1;
  }
}

TEST(Model, SymmetricLegsReproduceTheSeedLayoutByHand) {
  const double r3 = std::sqrt(3.0);
  const ModelSpec& spec = seed_spec();
  // Leg 1: base pair (1,6) at 60 deg, tangent (-sqrt3/2, 1/2); leg 1 sits db/2 = 0.15 back
  // along it: 1.5 (1/2, sqrt3/2) - 0.15 (-sqrt3/2, 1/2). Platform pair (1,2) at 0 deg, leg 1
  // da/2 = 0.1 forward along (0, 1).
  EXPECT_LT((spec.legs[0].base_B - Vector3d(0.75 + 0.075 * r3, 0.75 * r3 - 0.075, 0.0)).norm(), 1e-15);
  EXPECT_LT((spec.legs[0].platform_P - Vector3d(1.2, 0.1, 0.0)).norm(), 1e-15);
  EXPECT_LT((spec.legs[0].axis_base_B - Vector3d(-0.5 * r3, 0.5, 0.0)).norm(), 1e-15);
  EXPECT_LT((spec.legs[0].axis_platform_P - Vector3d(0.0, 1.0, 0.0)).norm(), 1e-15);
  // Leg 4: base pair (4,5) at 180 deg, tangent (0, -1), leg 4 forward: (-1.5, -0.15). Platform
  // pair (3,4) at 240 deg, tangent (sqrt3/2, -1/2), leg 4 back: 1.2 (-1/2, -sqrt3/2) - 0.1 tangent.
  EXPECT_LT((spec.legs[3].base_B - Vector3d(-1.5, -0.15, 0.0)).norm(), 1e-15);
  EXPECT_LT((spec.legs[3].platform_P - Vector3d(-0.6 - 0.05 * r3, -0.6 * r3 + 0.05, 0.0)).norm(), 1e-15);
  // Cross-check against the numbers printed by `hexatwist config`.
  EXPECT_LT((spec.legs[0].base_B - Vector3d(0.879904, 1.224038, 0.0)).norm(), 1e-6);
}

TEST(Model, SymmetricLegsFormPairsAboutTheirCentres) {
  // Every pair of joints is d apart, centred on its pair angle at radius R, along the tangent.
  SymmetricSpec s;
  s.Ra = 1.2, s.Rb = 1.5, s.da = 0.2, s.db = 0.3, s.H = 1.511;
  const PerLeg<LegSpec> legs = symmetric_legs(s);
  const std::array<std::array<int, 2>, 3> base_pairs{{{0, 5}, {1, 2}, {3, 4}}};
  const std::array<std::array<int, 2>, 3> platform_pairs{{{0, 1}, {2, 3}, {4, 5}}};
  for (std::size_t k = 0; k < 3; ++k) {
    const Vector3d& b1 = legs[static_cast<std::size_t>(base_pairs[k][0])].base_B;
    const Vector3d& b2 = legs[static_cast<std::size_t>(base_pairs[k][1])].base_B;
    const double beta = s.base_pair_angles[k];
    EXPECT_NEAR((b1 - b2).norm(), s.db, 1e-15) << "base pair " << k;
    EXPECT_LT((0.5 * (b1 + b2) - s.Rb * Vector3d(std::cos(beta), std::sin(beta), 0.0)).norm(), 1e-15) << k;
    EXPECT_NEAR((b1 - b2).normalized().dot(Vector3d(std::cos(beta), std::sin(beta), 0.0)), 0.0, 1e-15) << k;
    const Vector3d& p1 = legs[static_cast<std::size_t>(platform_pairs[k][0])].platform_P;
    const Vector3d& p2 = legs[static_cast<std::size_t>(platform_pairs[k][1])].platform_P;
    const double alpha = s.platform_pair_angles[k];
    EXPECT_NEAR((p1 - p2).norm(), s.da, 1e-15) << "platform pair " << k;
    EXPECT_LT((0.5 * (p1 + p2) - s.Ra * Vector3d(std::cos(alpha), std::sin(alpha), 0.0)).norm(), 1e-15) << k;
  }
  for (const LegSpec& leg : legs) {
    // Fixed axes are unit tangents: horizontal and perpendicular to their joint's pair radius.
    EXPECT_NEAR(leg.axis_base_B.norm(), 1.0, 1e-15);
    EXPECT_NEAR(leg.axis_platform_P.norm(), 1.0, 1e-15);
    EXPECT_EQ(leg.axis_base_B.z(), 0.0);
    EXPECT_EQ(leg.lead, 0.0);  // left for the caller
  }
}

TEST(Model, SeedHomeLengthIs1p910247MetresOnEveryLeg) {
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_NEAR(seed_model().leg(i).length_home, 1.910247, 5e-7) << "leg " << i + 1;
    EXPECT_EQ(seed_model().length_home()[i], seed_model().leg(i).length_home);
  }
}

TEST(Model, SeedHomeDirectionIsTheUnitLegVector) {
  const Model& m = seed_model();
  const Vector3d home(0.0, 0.0, m.spec().home_height);
  for (int i = 0; i < kLegs; ++i) {
    const Vector3d L = home + m.leg(i).platform_P - m.leg(i).base_B;
    EXPECT_LT((m.leg(i).s_home_B * m.leg(i).length_home - L).norm(), 1e-15) << "leg " << i + 1;
    EXPECT_NEAR(m.leg(i).axis_base_B.norm(), 1.0, 1e-15);
  }
}

}  // namespace
}  // namespace hexatwist::test

namespace hexatwist::test {
namespace {

// The seed with a real lead `scale` times the drives' (theory §4) and the drives' reference at
// `home` (NaN = the default).
Model seed_with_drive_scale(double scale, const Vector6d& home) {
  ModelSpec spec = seed_model().spec();
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
    leg.drive_lead = leg.lead;
    leg.lead *= scale;
    leg.home_command = home[i];
  }
  return Model(spec);
}

TEST(Model, DriveReferenceDefaultsToTheHomeCommandAndMapsTravelOneToOne) {
  const Model& seed = seed_model();
  EXPECT_FALSE(seed.has_drive_scale());
  EXPECT_EQ(seed.home_command(), seed.length_home() - seed.geometry().length_offset);
  const Vector6d m = seed.length_home() + Vector6d::LinSpaced(-0.1, 0.1);
  EXPECT_EQ(seed.travel_from_motor(m), m);  // without a scale the map is the identity, bit for bit
  EXPECT_EQ(seed.motor_from_travel(m), m);
}

TEST(Model, DriveScaleMapsCommandsAboutTheReferenceAndBack) {
  // u = h + s (m - h): the reference reads the same in both; a length away from it is scaled by s.
  Vector6d home = seed_model().length_home() + Vector6d::LinSpaced(-2e-3, 3e-3);
  const Model model = seed_with_drive_scale(1.025, home);
  ASSERT_TRUE(model.has_drive_scale());
  EXPECT_EQ(model.home_command(), home);
  EXPECT_DOUBLE_EQ(model.leg(2).drive_scale, 1.025);
  EXPECT_LE((model.travel_from_motor(home) - home).cwiseAbs().maxCoeff(), 1e-15);
  const Vector6d m = home + Vector6d::LinSpaced(-0.2, 0.25);
  const Vector6d u = model.travel_from_motor(m);
  for (int i = 0; i < kLegs; ++i) EXPECT_NEAR(u[i] - home[i], 1.025 * (m[i] - home[i]), 1e-15) << "leg " << i + 1;
  EXPECT_LE((model.motor_from_travel(u) - m).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Model, DriveScaleAndReferenceOutOfRangeAreRejectedNamingTheLeg) {
  ModelSpec spec = seed_model().spec();
  spec.legs[3].drive_lead = 0.0;
  expect_rejected(spec, {"leg 4", "drive_lead", "> 0"});
  spec.legs[3].drive_lead = kInf;
  expect_rejected(spec, {"leg 4", "drive_lead", "finite"});
  spec.legs[3].drive_lead = 3.0 * spec.legs[3].lead;  // a scale of 1/3: another screw, not a lead error
  expect_rejected(spec, {"leg 4", "drive_lead", "within 50 %"});
  spec = seed_model().spec();
  spec.legs[1].lead = 0.0;
  spec.legs[1].drive_lead = 0.01;
  expect_rejected(spec, {"leg 2", "drive_lead", "needs the real lead"});
  spec = seed_model().spec();
  spec.legs[5].home_command = spec.limits.length_max + 1e-3;
  expect_rejected(spec, {"leg 6", "home_command", "outside the stroke"});
  spec.legs[5].home_command = kNaN;  // NaN is "not given"
  EXPECT_NO_THROW(Model{spec});
}

}  // namespace
}  // namespace hexatwist::test
