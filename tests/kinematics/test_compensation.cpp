// SPDX-License-Identifier: BSD-3-Clause
// Compensation (Eq. 10-12): exact through twist-aware forward kinematics, signs of the twist
// term, and commands never emitted outside a limit.
#include "support.hpp"

#include <cstring>

namespace hexatwist::test {
namespace {

TEST(Compensation, CompensatedCommandsReachTheCommandedPoseExactly) {
  // Feed the compensated commands to twist-aware FK (the plant's real pose for those motor-side
  // lengths): the commanded pose comes back. Issue bound 1e-9 m; measured 1.0e-12 m (seed) and
  // 8.3e-12 m (random platforms), the level at which FK stops.
  std::mt19937_64 rng(kSeed + 20);
  for (int m = 0; m < 11; ++m) {
    const Model model = m == 0 ? seed_model() : random_platform(rng);
    const int count = m == 0 ? 2000 : 100;
    for (int n = 0; n < count; ++n) {
      const Pose p =
          m == 0 ? random_valid_pose(model, rng, 0.5, deg2rad(30)) : random_valid_pose(model, rng, 0.2, deg2rad(15));
      Vector6d cmd;
      LimitReport lim;
      ASSERT_EQ(motor_commands(model, p, Strategy::Compensated, cmd, lim), Status::Ok) << str(p);
      FkResult r;
      ASSERT_EQ(forward_kinematics(model, cmd, LengthKind::Motor, Placement{}, r), Status::Ok) << str(p);
      const PoseError e = pose_error(r.placement, placement_from_pose(p));
      const Vector3d A = model.spec().observation_P;
      const double obs =
          (platform_point_B(model, r.placement, A) - platform_point_B(model, placement_from_pose(p), A)).norm();
      const double tol = m == 0 ? 1e-11 : 1e-10;
      EXPECT_LT(e.position, tol) << str(p);
      EXPECT_LT(e.rotation, tol) << str(p);
      EXPECT_LT(obs, tol) << str(p);
    }
  }
}

TEST(Compensation, ConventionalCommandsMissThePoseByTheTwist) {
  // With the twist ignored the platform lands elsewhere: for the seed's 30 deg yaw, about 1 mm
  // at the observation point; the miss grows with the yaw.
  double previous = 0.0;
  for (const double yaw_deg : {5.0, 10.0, 20.0, 30.0}) {
    Pose p;
    p.rpy[2] = deg2rad(yaw_deg);
    Vector6d cmd;
    LimitReport lim;
    ASSERT_EQ(motor_commands(seed_model(), p, Strategy::Conventional, cmd, lim), Status::Ok);
    FkResult r;
    ASSERT_EQ(forward_kinematics(seed_model(), cmd, LengthKind::Motor, Placement{}, r), Status::Ok);
    const Vector3d A = seed_model().spec().observation_P;
    const double miss =
        (platform_point_B(seed_model(), r.placement, A) - platform_point_B(seed_model(), placement_from_pose(p), A))
            .norm();
    EXPECT_GT(miss, previous) << yaw_deg;
    previous = miss;
  }
  EXPECT_GT(previous, 0.5e-3);
  EXPECT_LT(previous, 5e-3);
}

TEST(Compensation, LengthErrorIsLeadTimesTwistOverTwoPiWithTheThreadHandSign) {
  const Vector6d dtheta = (Vector6d() << 0.1, -0.2, 0.3, -0.4, 0.5, -0.6).finished();
  const auto error_for = [&](ThreadSense thread, DrivenSide side) {
    ModelSpec spec = seed_model().spec();
    for (LegSpec& l : spec.legs) {
      l.thread = thread;
      l.driven = side;
    }
    Vector6d e;
    length_error(Model(spec), dtheta, e);
    return e;
  };
  const Vector6d expected = 0.010 * dtheta / (2 * kPi);  // Eq. (10), lead 10 mm
  EXPECT_LT((error_for(ThreadSense::Right, DrivenSide::Base) - expected).cwiseAbs().maxCoeff(), 1e-18);
  EXPECT_LT((error_for(ThreadSense::Left, DrivenSide::Base) + expected).cwiseAbs().maxCoeff(), 1e-18);
  // The driven side does not change the sign (docs/theory.md §4; tests/kinematics/test_model.cpp derives it).
  EXPECT_LT((error_for(ThreadSense::Right, DrivenSide::Platform) - expected).cwiseAbs().maxCoeff(), 1e-18);
  EXPECT_LT((error_for(ThreadSense::Left, DrivenSide::Platform) + expected).cwiseAbs().maxCoeff(), 1e-18);
}

TEST(Compensation, RealTimeCommandsAgreeWithTheFullReport) {
  std::mt19937_64 rng(kSeed + 21);
  for (int n = 0; n < 500; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.5, deg2rad(30));
    CommandReport rep;
    ASSERT_EQ(compute_commands(seed_model(), p, rep), Status::Ok);
    Vector6d conv, comp;
    LimitReport lim;
    ASSERT_EQ(motor_commands(seed_model(), p, Strategy::Conventional, conv, lim), Status::Ok);
    ASSERT_EQ(motor_commands(seed_model(), p, Strategy::Compensated, comp, lim), Status::Ok);
    EXPECT_EQ(conv, rep.conventional);
    EXPECT_LT((comp - rep.compensated).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((rep.conventional - rep.compensated - rep.length_error).cwiseAbs().maxCoeff(), 1e-15);
  }
}

TEST(Compensation, RealTimePathAndFullReportReachTheSameLimitDecision) {
  // Poses well past the limits too: both paths must name the same status, leg and value.
  std::mt19937_64 rng(kSeed + 22);
  int rejected = 0;
  for (int n = 0; n < 3000; ++n) {
    const Pose p = random_pose(rng, 0.8, deg2rad(45));
    CommandReport rep;
    const Status full = compute_commands(seed_model(), p, rep);
    Vector6d cmd;
    LimitReport lim;
    const Status rt = motor_commands(seed_model(), p, Strategy::Compensated, cmd, lim);
    ASSERT_EQ(rt, full) << str(p);
    EXPECT_EQ(lim.leg, rep.limit.leg) << str(p);
    EXPECT_EQ(lim.value, rep.limit.value) << str(p);
    rejected += rt != Status::Ok;
  }
  EXPECT_GT(rejected, 1000);  // the sample reaches far outside the limits
  EXPECT_LT(rejected, 2990);  // ... and inside them
}

// The command as it was before the cheap condition proof: every limit of check_limits, but the
// platform singularity decided by the exact condition number (jacobian_condition) at every pose.
Status reference_command(const Model& model, const Pose& p, Strategy strategy, Vector6d& command, LimitReport& r) {
  r = LimitReport{};
  if (!p.is_finite()) return r.status = Status::NonFiniteInput;
  LegState legs;
  if (const Status s = inverse_kinematics(model, p, legs); s != Status::Ok) return r.status = s;
  if (const Status s = check_limits(model, legs, r); s != Status::Ok && s != Status::PlatformSingularity) return s;
  double c;
  if (const Status s = jacobian_condition(model, legs, c); s != Status::Ok) {
    r = LimitReport{s, -1, c, model.spec().limits.jacobian_condition_max};
    return s;
  }
  r = LimitReport{};
  Vector6d dtheta = Vector6d::Zero();
  if (strategy == Strategy::Compensated && model.has_twist()) {
    if (const Status s = twist(model, legs, dtheta); s != Status::Ok) return r.status = s;
    const Vector6d cmd =
        legs.length - model.geometry().length_offset - model.geometry().twist_gain.cwiseProduct(dtheta);
    if (const Status s = check_stroke(model, cmd, r); s != Status::Ok) return s;
    command = cmd;
  } else {
    command = legs.length - model.geometry().length_offset;
  }
  return Status::Ok;
}

TEST(Compensation, CheapConditionProofLeavesEveryVerdictBitForBit) {
  // The proof that the condition is within the limit only spares the exact number: statuses and
  // reports are those of the exact number at every pose, bit for bit, and so is which commands
  // are written. Poses inside
  // the workspace, far outside it, and around the seed's yaw-90 singularity (with the default
  // limits, and with stroke and bend widened so that the condition limit is what refuses).
  ModelSpec wide_spec = seed_model().spec();
  wide_spec.limits.length_min = 0.5;
  wide_spec.limits.length_max = 4.0;
  wide_spec.limits.bend_max = deg2rad(89);
  const Model wide(wide_spec);
  std::mt19937_64 rng(kSeed + 61);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  long ok = 0, singular = 0, n = stress(200000);
  for (long i = 0; i < n; ++i) {
    const int kind = static_cast<int>(i % 4);
    const Model& model = kind == 3 ? wide : seed_model();
    Pose p;
    if (kind == 0) {
      p.position = {0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng)};
      p.rpy = {deg2rad(30) * u(rng), deg2rad(30) * u(rng), deg2rad(30) * u(rng)};
    } else if (kind == 1) {
      p.position = {1.5 * u(rng), 1.5 * u(rng), 1.5 * u(rng)};
      p.rpy = {kPi * u(rng), kPi * u(rng), kPi * u(rng)};
    } else {
      p.position = {0.05 * u(rng), 0.05 * u(rng), 0.05 * u(rng)};
      p.rpy = {deg2rad(3) * u(rng), deg2rad(3) * u(rng), (u(rng) < 0 ? -1 : 1) * deg2rad(90 + 15 * u(rng))};
    }
    for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional}) {
      Vector6d cmd = Vector6d::Constant(-7.0), ref_cmd = Vector6d::Constant(-7.0);
      LimitReport r, ref_r;
      const Status s = motor_commands(model, p, strategy, cmd, r);
      const Status ref = reference_command(model, p, strategy, ref_cmd, ref_r);
      ASSERT_EQ(s, ref) << str(p) << " kind " << kind;
      ASSERT_EQ(r.status, ref_r.status) << str(p);
      ASSERT_EQ(r.leg, ref_r.leg) << str(p);
      ASSERT_TRUE(std::memcmp(&r.value, &ref_r.value, sizeof(double)) == 0)
          << str(p) << " " << r.value << " " << ref_r.value;
      ASSERT_EQ(r.bound, ref_r.bound) << str(p);
      // The command itself comes before the condition in both (the fast path's lanes differ from
      // the reference's LegState by rounding): written or not alike, and the same to rounding.
      ASSERT_EQ(cmd == Vector6d::Constant(-7.0), ref_cmd == Vector6d::Constant(-7.0)) << str(p);
      ASSERT_LT((cmd - ref_cmd).cwiseAbs().maxCoeff(), 1e-12) << str(p);
      ok += s == Status::Ok;
      singular += s == Status::PlatformSingularity;
    }
  }
  std::printf("  %ld poses: %ld commands Ok, %ld refused for the platform singularity\n", n, ok, singular);
  EXPECT_GT(ok, n / 4);
  EXPECT_GT(singular, n / 20);
}

TEST(Compensation, CheapConditionProofLeavesEveryVerdictOnAsymmetricPlatforms) {
  // The same on random asymmetric platforms (tilted axes, leads up to 20 mm or 0.2 m, either thread hand
  // and driven side), their condition limit set at 1.3 times the condition at home so that it
  // refuses many of the poses: the real-time path proves the motor-side condition from the
  // geometric Jacobian and a bound on the twist's share, and must never accept a pose that the
  // exact number refuses, nor refuse one it accepts.
  std::mt19937_64 rng(kSeed + 63);
  long ok = 0, singular = 0, n = 0;
  for (int m = 0; m < 30; ++m) {
    const Model base = random_platform(rng);
    LegState home;
    ASSERT_EQ(inverse_kinematics(base, Placement{}, home), Status::Ok);
    double home_condition = 0.0;
    ASSERT_EQ(jacobian_condition(base, home, home_condition), Status::Ok);
    ModelSpec spec = base.spec();
    // Every other platform with ten times the lead (0.02-0.2 m): there the twist's share of the
    // Jacobian moves the condition number by tens of percent, and a proof that ignored it fails.
    if (m % 2 == 1)
      for (LegSpec& leg : spec.legs) leg.lead *= 10.0;
    const Model with_lead(spec);
    ASSERT_EQ(inverse_kinematics(with_lead, Placement{}, home), Status::Ok);
    ASSERT_EQ(jacobian_condition(with_lead, home, home_condition), Status::Ok);
    spec.limits.jacobian_condition_max = 1.3 * home_condition;
    const Model model(spec);
    for (int i = 0; i < stress(2000); ++i, ++n) {
      const Pose p = random_pose(rng, 0.3, deg2rad(25));
      for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional}) {
        Vector6d cmd = Vector6d::Constant(-7.0), ref_cmd = Vector6d::Constant(-7.0);
        LimitReport r, ref_r;
        const Status s = motor_commands(model, p, strategy, cmd, r);
        const Status ref = reference_command(model, p, strategy, ref_cmd, ref_r);
        ASSERT_EQ(s, ref) << "platform " << m << " " << str(p);
        ASSERT_EQ(r.leg, ref_r.leg) << str(p);
        ASSERT_TRUE(std::memcmp(&r.value, &ref_r.value, sizeof(double)) == 0) << str(p);
        ASSERT_EQ(cmd == Vector6d::Constant(-7.0), ref_cmd == Vector6d::Constant(-7.0)) << str(p);
        ok += s == Status::Ok;
        singular += s == Status::PlatformSingularity;
      }
    }
  }
  std::printf("  %ld poses on 30 platforms: %ld commands Ok, %ld refused for the platform singularity\n", n, ok,
              singular);
  EXPECT_GT(ok, n / 4);
  EXPECT_GT(singular, n / 20);
}

TEST(Compensation, BothCommandsTakeTheLengthOffsetsOut) {
  // A leg whose real length is its motor-side length + delta is commanded delta shorter, with
  // the twist compensated or not; the compensated command still lands exactly on the pose.
  std::mt19937_64 rng(kSeed + 21);
  const Model offset = seed_with_offsets(rng, 1e-3);
  const Vector6d& delta = offset.geometry().length_offset;
  for (int n = 0; n < 200; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.4, deg2rad(25));
    CommandReport plain, shifted;
    ASSERT_EQ(compute_commands(seed_model(), p, plain), Status::Ok) << str(p);
    ASSERT_EQ(compute_commands(offset, p, shifted), Status::Ok) << str(p);
    EXPECT_LT((shifted.conventional - (plain.conventional - delta)).cwiseAbs().maxCoeff(), 1e-15) << str(p);
    EXPECT_LT((shifted.compensated - (plain.compensated - delta)).cwiseAbs().maxCoeff(), 1e-15) << str(p);
    for (const Strategy strategy : {Strategy::Conventional, Strategy::Compensated}) {
      Vector6d command;
      LimitReport lim;
      ASSERT_EQ(motor_commands(offset, p, strategy, command, lim), Status::Ok) << str(p);
      EXPECT_EQ(command, strategy == Strategy::Conventional ? shifted.conventional : shifted.compensated);
    }
    FkResult r;
    ASSERT_EQ(forward_kinematics(offset, shifted.compensated, LengthKind::Motor, Placement{}, r), Status::Ok);
    const PoseError e = pose_error(r.placement, placement_from_pose(p));
    EXPECT_LT(std::max(e.position, e.rotation), 1e-11) << str(p);
  }
}

TEST(Compensation, CommandsThroughADriveScaleMoveTheNutAsTheRealLeadDemands) {
  // A real lead 2.5 % longer than the drives' (theory §4): the commands m are the drives' numbers,
  // the nut travels u = h + s (m - h), and u is what the real lead's kinematics ask for. Motor-side
  // forward kinematics of m lands on the pose.
  std::mt19937_64 rng(kSeed + 22);
  ModelSpec real_spec = seed_model().spec();
  for (LegSpec& leg : real_spec.legs) leg.lead *= 1.025;
  const Model real(real_spec);  // the nut's kinematics, commands in travel
  ModelSpec spec = real_spec;
  for (int i = 0; i < kLegs; ++i) {
    spec.legs[static_cast<std::size_t>(i)].drive_lead = seed_model().leg(i).lead;
    spec.legs[static_cast<std::size_t>(i)].home_command = real.length_home()[i] + 1e-3 * (i - 2.5);
  }
  const Model driven(spec);
  for (int n = 0; n < 200; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.3, deg2rad(20));
    CommandReport travel, drive;
    ASSERT_EQ(compute_commands(real, p, travel), Status::Ok) << str(p);
    ASSERT_EQ(compute_commands(driven, p, drive), Status::Ok) << str(p);
    EXPECT_LT((driven.travel_from_motor(drive.compensated) - travel.compensated).cwiseAbs().maxCoeff(), 1e-15);
    EXPECT_LT((driven.travel_from_motor(drive.conventional) - travel.conventional).cwiseAbs().maxCoeff(), 1e-15);
    // The scale acts about the reference: m - h = (u - h) / 1.025.
    const Vector6d h = driven.home_command();
    for (int i = 0; i < kLegs; ++i)
      EXPECT_NEAR(drive.compensated[i] - h[i], (travel.compensated[i] - h[i]) / 1.025, 1e-15) << "leg " << i + 1;
    for (const Strategy strategy : {Strategy::Conventional, Strategy::Compensated}) {
      Vector6d command;
      LimitReport lim;
      ASSERT_EQ(motor_commands(driven, p, strategy, command, lim), Status::Ok) << str(p);
      EXPECT_EQ(command, strategy == Strategy::Conventional ? drive.conventional : drive.compensated);
    }
    FkResult r;
    ASSERT_EQ(forward_kinematics(driven, drive.compensated, LengthKind::Motor, Placement{}, r), Status::Ok);
    const PoseError e = pose_error(r.placement, placement_from_pose(p));
    EXPECT_LT(std::max(e.position, e.rotation), 1e-11) << str(p);
  }
}

TEST(Compensation, ZeroLeadMakesBothStrategiesEqual) {
  ModelSpec spec = seed_model().spec();
  for (LegSpec& l : spec.legs) l.lead = 0.0;
  const Model plain(spec);
  EXPECT_FALSE(plain.has_twist());
  Pose p;
  p.rpy[2] = deg2rad(25);
  Vector6d conv, comp;
  LimitReport lim;
  ASSERT_EQ(motor_commands(plain, p, Strategy::Conventional, conv, lim), Status::Ok);
  ASSERT_EQ(motor_commands(plain, p, Strategy::Compensated, comp, lim), Status::Ok);
  EXPECT_EQ(conv, comp);
}

TEST(Compensation, NoCommandIsWrittenOutsideALimit) {
  Pose p;
  p.position.z() = 0.8;  // legs longer than 2.45 m
  Vector6d cmd = Vector6d::Constant(-1.0);
  LimitReport lim;
  EXPECT_EQ(motor_commands(seed_model(), p, Strategy::Compensated, cmd, lim), Status::StrokeAboveMax);
  EXPECT_EQ(cmd, Vector6d::Constant(-1.0));
  EXPECT_EQ(lim.status, Status::StrokeAboveMax);
  EXPECT_GE(lim.leg, 0);
  EXPECT_GT(lim.value, lim.bound);
  p.position.z() = std::nan("");
  EXPECT_EQ(motor_commands(seed_model(), p, Strategy::Conventional, cmd, lim), Status::NonFiniteInput);
  EXPECT_EQ(cmd, Vector6d::Constant(-1.0));
}

TEST(Compensation, CompensatedCommandIsCheckedAgainstTheStrokeToo) {
  // A pose whose geometric lengths are inside the stroke but whose compensated command is not:
  // shrink the stroke to just cover the pose's lengths.
  Pose p;
  p.rpy[2] = deg2rad(30);  // twist ~40 deg, length error ~+1.1 mm: commands are shorter than lengths
  LegState st;
  ASSERT_EQ(inverse_kinematics(seed_model(), p, st), Status::Ok);
  ModelSpec spec = seed_model().spec();
  spec.limits.length_min = st.length.minCoeff() - 1e-4;
  const Model tight(spec);
  Vector6d cmd;
  LimitReport lim;
  EXPECT_EQ(motor_commands(tight, p, Strategy::Conventional, cmd, lim), Status::Ok);
  EXPECT_EQ(motor_commands(tight, p, Strategy::Compensated, cmd, lim), Status::StrokeBelowMin);
  CommandReport rep;
  EXPECT_EQ(compute_commands(tight, p, rep), Status::StrokeBelowMin);
}

TEST(Compensation, EachStrategyHasOneNameThatParsesBack) {
  for (const Strategy s : {Strategy::Conventional, Strategy::Compensated}) {
    Strategy back = s == Strategy::Conventional ? Strategy::Compensated : Strategy::Conventional;
    EXPECT_TRUE(parse_strategy(to_string(s), back)) << to_string(s);
    EXPECT_EQ(back, s);
  }
  EXPECT_EQ(to_string(Strategy::Compensated), "compensated");
  EXPECT_EQ(to_string(Strategy::Conventional), "conventional");
  Strategy kept = Strategy::Conventional;
  for (const char* bad : {"Compensated", "compensated ", "comp", "", "conventional\n"}) {
    EXPECT_FALSE(parse_strategy(bad, kept)) << bad;
    EXPECT_EQ(kept, Strategy::Conventional);
  }
}

}  // namespace
}  // namespace hexatwist::test
