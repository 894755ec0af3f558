// SPDX-License-Identifier: BSD-3-Clause
// Forward kinematics: round trips with IK (geometric and twist-aware), the residual Jacobian
// against finite differences, warm starts, and failures that are reported rather than silent.
#include <map>

#include "support.hpp"

namespace hexatwist::test {
namespace {

// FK stops at a 1e-12 m residual. Measured worst round trip: 1.0e-12 m / rad on the seed
// platform, 8.3e-12 on the random asymmetric ones (worse conditioned); issue bound 1e-10.
constexpr double kRoundTripTol = 1e-11;
constexpr double kRandomPlatformTol = 1e-10;

// Lengths of `kind` for a pose: geometric or motor-side (the compensated command).
Vector6d lengths_for(const Model& model, const Placement& x, LengthKind kind) {
  LegState st;
  EXPECT_EQ(inverse_kinematics(model, x, st), Status::Ok);
  if (kind == LengthKind::Geometric) return st.length;
  Vector6d dtheta, err;
  EXPECT_EQ(twist(model, st, dtheta), Status::Ok);
  length_error(model, dtheta, err);
  return st.length - err;
}

void round_trip(const Model& model, LengthKind kind, int count, double dpos, double drot, std::uint32_t seed,
                double tol = kRoundTripTol) {
  std::mt19937_64 rng(seed);
  int worst_iterations = 0;
  for (int n = 0; n < count; ++n) {
    const Pose p = random_valid_pose(model, rng, dpos, drot);
    const Placement x = placement_from_pose(p);
    FkResult r;
    ASSERT_EQ(forward_kinematics(model, lengths_for(model, x, kind), kind, Placement{}, r), Status::Ok)
        << "pose " << str(p) << " iterations " << r.iterations << " residual " << r.residual;
    const PoseError e = pose_error(r.placement, x);
    ASSERT_LT(e.position, tol) << str(p);
    ASSERT_LT(e.rotation, tol) << str(p);
    ASSERT_LT((r.pose.to_vector() - p.to_vector()).cwiseAbs().maxCoeff(), tol) << str(p);
    ASSERT_LE(r.residual, FkOptions{}.tolerance);
    worst_iterations = std::max(worst_iterations, r.iterations);
  }
  EXPECT_LE(worst_iterations, 12);
}

TEST(Forward, GeometricRoundTripFromHomeOnTenThousandPoses) {
  round_trip(seed_model(), LengthKind::Geometric, 10000, 0.5, deg2rad(30), kSeed);
}

TEST(Forward, TwistAwareRoundTripFromHomeOnTenThousandPoses) {
  round_trip(seed_model(), LengthKind::Motor, 10000, 0.5, deg2rad(30), kSeed + 10);
}

TEST(Forward, TwistAwareRoundTripOnRandomAsymmetricPlatforms) {
  std::mt19937_64 rng(kSeed + 11);
  for (int m = 0; m < 40; ++m) {
    const Model model = random_platform(rng);
    round_trip(model, LengthKind::Motor, 50, 0.2, deg2rad(15), kSeed + 100 + static_cast<std::uint32_t>(m),
               kRandomPlatformTol);
  }
}

TEST(Forward, WarmStartFromOneMillisecondEarlierTakesFewIterations) {
  // The benchmark's motion (bench/bench_kinematics.cpp), sampled at 1 kHz.
  FkResult r;
  Placement previous;
  int worst = 0;
  for (int k = 1; k <= 4000; ++k) {
    const double t = 1e-3 * k, w = 2 * kPi * 0.5;
    Pose p;
    p.position = Vector3d(0.2 * std::sin(w * t), 0.15 * std::sin(1.3 * w * t), 0.15 * std::sin(0.7 * w * t));
    p.rpy = Vector3d(deg2rad(6) * std::sin(0.9 * w * t), deg2rad(10) * std::sin(1.1 * w * t),
                     deg2rad(15) * std::sin(w * t));
    const Placement x = placement_from_pose(p);
    ASSERT_EQ(forward_kinematics(seed_model(), lengths_for(seed_model(), x, LengthKind::Motor), LengthKind::Motor,
                                 previous, r),
              Status::Ok);
    EXPECT_LT(pose_error(r.placement, x).position, kRoundTripTol);
    worst = std::max(worst, r.iterations);
    previous = r.placement;
  }
  EXPECT_LE(worst, 3);  // measured: 2
}

Matrix6d residual_jacobian_fd(const Model& model, const Placement& x, const Vector6d& m, LengthKind kind, double h) {
  Matrix6d J;
  LegState st;
  for (int k = 0; k < 6; ++k) {
    Vector6d d = Vector6d::Zero();
    d[k] = h;
    Vector6d fp, fm;
    EXPECT_EQ(fk_residual(model, {x.t + d.head<3>(), exp_so3(d.tail<3>()) * x.R_BP}, m, kind, st, fp, nullptr),
              Status::Ok);
    EXPECT_EQ(fk_residual(model, {x.t - d.head<3>(), exp_so3(-d.tail<3>()) * x.R_BP}, m, kind, st, fm, nullptr),
              Status::Ok);
    J.col(k) = (fp - fm) / (2 * h);
  }
  return J;
}

TEST(Forward, ResidualJacobianMatchesCentralFiniteDifferences) {
  std::mt19937_64 rng(kSeed + 12);
  for (int m = 0; m < 10; ++m) {
    const Model model = m == 0 ? seed_model() : random_platform(rng);
    for (const LengthKind kind : {LengthKind::Geometric, LengthKind::Motor}) {
      for (int n = 0; n < 20; ++n) {
        const Placement x = placement_from_pose(random_valid_pose(model, rng, 0.3, deg2rad(25)));
        const Vector6d target =
            lengths_for(model, placement_from_pose(random_valid_pose(model, rng, 0.3, deg2rad(25))), kind);
        LegState st;
        Vector6d f;
        Matrix6d J;
        ASSERT_EQ(fk_residual(model, x, target, kind, st, f, &J), Status::Ok);
        const Matrix6d J_fd = residual_jacobian_fd(model, x, target, kind, 1e-6);
        // Measured 4.3e-10 (rounding ~1e-16 * 2 m / 1e-6 dominates); 10x margin.
        EXPECT_LT((J - J_fd).cwiseAbs().maxCoeff(), 5e-9) << J << "\nvs\n" << J_fd;
      }
    }
  }
}

TEST(Forward, MotorModeDiffersFromGeometricModeByTheTwist) {
  // The same motor-side numbers read as geometric lengths give another pose: the error that
  // twist-unaware forward kinematics makes (about a millimetre at 30 deg yaw).
  Pose p;
  p.rpy[2] = deg2rad(30);
  const Vector6d m = lengths_for(seed_model(), placement_from_pose(p), LengthKind::Motor);
  FkResult geo, mot;
  ASSERT_EQ(forward_kinematics(seed_model(), m, LengthKind::Geometric, Placement{}, geo), Status::Ok);
  ASSERT_EQ(forward_kinematics(seed_model(), m, LengthKind::Motor, Placement{}, mot), Status::Ok);
  EXPECT_LT(pose_error(mot.placement, placement_from_pose(p)).position, kRoundTripTol);
  const Vector3d A = seed_model().spec().observation_P;
  const double miss =
      (platform_point_B(seed_model(), geo.placement, A) - platform_point_B(seed_model(), mot.placement, A)).norm();
  EXPECT_GT(miss, 0.5e-3);
  EXPECT_LT(miss, 5e-3);
}

TEST(Forward, MotorModeTakesTheLengthOffsetsOutAndGeometricModeIgnoresThem) {
  // Motor-side lengths m of a platform with offsets delta are m0 - delta, m0 those without: both
  // models must give the same pose for their own lengths. Geometric lengths have no offset.
  std::mt19937_64 rng(kSeed + 40);
  const Model offset = seed_with_offsets(rng, 2e-3);
  const Vector6d& delta = offset.geometry().length_offset;
  double worst = 0.0;
  for (int n = 0; n < 200; ++n) {
    const Pose p = random_valid_pose(seed_model(), rng, 0.4, deg2rad(25));
    Vector6d m0;
    LimitReport lim;
    ASSERT_EQ(motor_commands(seed_model(), p, Strategy::Compensated, m0, lim), Status::Ok);
    FkResult a, b, g;
    ASSERT_EQ(forward_kinematics(seed_model(), m0, LengthKind::Motor, Placement{}, a), Status::Ok);
    ASSERT_EQ(forward_kinematics(offset, m0 - delta, LengthKind::Motor, Placement{}, b), Status::Ok);
    const PoseError e = pose_error(a.placement, b.placement);
    worst = std::max({worst, e.position, e.rotation});
    ASSERT_EQ(forward_kinematics(offset, a.legs.length, LengthKind::Geometric, Placement{}, g), Status::Ok);
    const PoseError eg = pose_error(a.placement, g.placement);
    worst = std::max({worst, eg.position, eg.rotation});
  }
  report("pose difference [m or rad]", worst);
  EXPECT_LT(worst, 1e-11);
}

TEST(Forward, ReportsNoConvergenceWhenIterationsRunOut) {
  Pose p;
  p.position = Vector3d(0.4, -0.2, 0.3);
  p.rpy = Vector3d(0.2, -0.3, 0.4);
  const Vector6d m = lengths_for(seed_model(), placement_from_pose(p), LengthKind::Geometric);
  FkOptions o;
  o.max_iterations = 1;
  FkResult r;
  EXPECT_EQ(forward_kinematics(seed_model(), m, LengthKind::Geometric, Placement{}, r, o), Status::NoConvergence);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_GT(r.residual, o.tolerance);
}

TEST(Forward, UnreachableLengthsAreNeverReportedAsOk) {
  // Lengths no pose can produce (one leg far longer than its neighbours).
  Vector6d m = seed_model().length_home();
  m[0] = 6.0;
  FkResult r;
  const Status s = forward_kinematics(seed_model(), m, LengthKind::Geometric, Placement{}, r);
  EXPECT_NE(s, Status::Ok);
  EXPECT_GT(r.residual, 1e-6);
}

TEST(Forward, RejectsNonFiniteInput) {
  Vector6d m = seed_model().length_home();
  m[3] = std::nan("");
  FkResult r;
  EXPECT_EQ(forward_kinematics(seed_model(), m, LengthKind::Motor, Placement{}, r), Status::NonFiniteInput);
  Placement bad;
  bad.t.x() = INFINITY;
  EXPECT_EQ(forward_kinematics(seed_model(), seed_model().length_home(), LengthKind::Motor, bad, r),
            Status::NonFiniteInput);
}

// ---- robustness: step cap, assembly mode, convergence across the workspace ------------------

// A pose of the seed platform inside every limit, drawn across its reachable workspace (which
// reaches about 1 m sideways, 0.6 m up and down and 40 deg about each axis, not all at once): the
// rotation box is scaled by a uniform factor so that large displacements with small rotations are
// drawn as often as the reverse. Returns the pose and its compensated command.
Pose workspace_pose(std::mt19937_64& rng, Vector6d& command) {
  for (;;) {
    Pose p;
    p.position = Vector3d(uniform(rng, -1.0, 1.0), uniform(rng, -1.0, 1.0), uniform(rng, -0.6, 0.6));
    const double r = deg2rad(45) * uniform(rng, 0, 1);
    p.rpy = Vector3d(uniform(rng, -r, r), uniform(rng, -r, r), uniform(rng, -r, r));
    LimitReport lim;
    if (motor_commands(seed_model(), p, Strategy::Compensated, command, lim) == Status::Ok) return p;
  }
}

TEST(Forward, ConvergesFromHomeOnAHundredThousandPosesAcrossTheReachableWorkspace) {
  std::mt19937_64 rng(kSeed + 13);
  const int count = stress(100000);
  std::map<int, int> histogram;
  int ok = 0;
  double worst = 0.0;
  for (int n = 0; n < count; ++n) {
    Vector6d m;
    const Pose p = workspace_pose(rng, m);
    FkResult r;
    const Status s = forward_kinematics(seed_model(), m, LengthKind::Motor, Placement{}, r);
    const PoseError e = pose_error(r.placement, placement_from_pose(p));
    if (s == Status::Ok && e.position < kRoundTripTol && e.rotation < kRoundTripTol) {
      ++ok;
      ++histogram[r.iterations];
      worst = std::max({worst, e.position, e.rotation});
    } else {
      ADD_FAILURE() << to_string(s) << " for pose " << str(p) << " after " << r.iterations << " iterations";
    }
  }
  std::printf("  Newton iterations from home (count):");
  for (const auto& [iterations, n] : histogram) std::printf(" %d: %d", iterations, n);
  std::printf("\n");
  report("worst pose error [m or rad]", worst);
  EXPECT_GE(ok, count - count / 10000) << "below 99.99 %";  // measured: all
}

// Motor-side lengths of a pose of `model`.
Vector6d motor_lengths(const Model& model, const Pose& p) {
  return lengths_for(model, placement_from_pose(p), LengthKind::Motor);
}

TEST(Forward, ConvergesFromFarGuessesOnAsymmetricPlatforms) {
  // Guess and solution both drawn inside every limit, up to 0.4 m and 30 deg apart. Newton may
  // end on another solution with the same lengths; it must never call a pose with another
  // determinant sign than the guess's Ok, and must find the drawn pose nearly always.
  std::mt19937_64 rng(kSeed + 14);
  int total = 0, found = 0, other_mode = 0;
  for (int k = 0; k < 40; ++k) {
    const Model model = random_platform(rng);
    for (int n = 0; n < 50; ++n, ++total) {
      const Pose p = random_valid_pose(model, rng, 0.2, deg2rad(15));
      const Placement guess = placement_from_pose(random_valid_pose(model, rng, 0.2, deg2rad(15)));
      FkResult r, at_guess;
      const Status s = forward_kinematics(model, motor_lengths(model, p), LengthKind::Motor, guess, r);
      ASSERT_EQ(
          forward_kinematics(model, lengths_for(model, guess, LengthKind::Motor), LengthKind::Motor, guess, at_guess),
          Status::Ok);
      if (s == Status::AssemblyModeChanged) {
        EXPECT_NE(r.det_sign, at_guess.det_sign);
        ++other_mode;
        continue;
      }
      ASSERT_EQ(s, Status::Ok) << str(p) << " from " << str(pose_from_placement(guess));
      EXPECT_EQ(r.det_sign, at_guess.det_sign);
      EXPECT_LE(r.residual, FkOptions{}.tolerance);
      found += pose_error(r.placement, placement_from_pose(p)).position < kRandomPlatformTol;
    }
  }
  std::printf("  found the drawn pose %d of %d times; another assembly mode %d times\n", found, total, other_mode);
  EXPECT_GE(found, total * 99 / 100);  // measured: all 2000
}

TEST(Forward, ConvergesNearPoorlyConditionedSolutionsOnAsymmetricPlatforms) {
  // Poses whose Jacobian condition lies between half the limit and the limit, from home and from
  // a guess 5 mm and 0.3 deg away.
  std::mt19937_64 rng(kSeed + 15);
  int total = 0, from_home = 0;
  for (int k = 0; k < 40; ++k) {
    const Model model = random_platform(rng);
    const double bound = model.spec().limits.jacobian_condition_max;
    for (int n = 0, tries = 0; n < 10 && tries < 20000; ++tries) {
      const Pose p = random_pose(rng, 0.6, deg2rad(35));
      CommandReport c;
      double condition;
      if (compute_commands(model, p, c) != Status::Ok || jacobian_condition(model, c.legs, condition) != Status::Ok ||
          condition < 0.5 * bound)
        continue;
      ++n;
      ++total;
      Pose near = p;
      near.position += Vector3d::Constant(5e-3 / std::sqrt(3.0));
      near.rpy += Vector3d::Constant(deg2rad(0.3) / std::sqrt(3.0));
      FkResult r;
      ASSERT_EQ(forward_kinematics(model, c.compensated, LengthKind::Motor, placement_from_pose(near), r), Status::Ok)
          << str(p);
      EXPECT_LT(pose_error(r.placement, placement_from_pose(p)).position, kRandomPlatformTol) << str(p);
      EXPECT_NEAR(r.condition, condition, 1e-6 * condition);
      const Status s = forward_kinematics(model, c.compensated, LengthKind::Motor, Placement{}, r);
      from_home += s == Status::Ok && pose_error(r.placement, placement_from_pose(p)).position < kRandomPlatformTol;
    }
  }
  std::printf("  %d poses; from home %d found\n", total, from_home);
  EXPECT_GE(total, 100);
  EXPECT_GE(from_home, total * 8 / 10);  // measured: 357 of 400
}

TEST(Forward, StepCapHoldsWhereTheNewtonStepIsHuge) {
  // From a guess next to the seed's yaw-90 deg singularity the Newton step toward the yaw-30 deg
  // lengths is far longer than the platform; the first step must stay within the cap.
  Pose guess_pose;
  guess_pose.rpy[2] = deg2rad(89.99);
  const Placement guess = placement_from_pose(guess_pose);
  Pose target;
  target.rpy[2] = deg2rad(30);
  const Vector6d m = motor_lengths(seed_model(), target);
  LegState st;
  Vector6d f;
  Matrix6d J;
  ASSERT_EQ(fk_residual(seed_model(), guess, m, LengthKind::Motor, st, f, &J), Status::Ok);
  const Vector6d newton = J.partialPivLu().solve(-f);
  report("uncapped first step [m]", newton.head<3>().norm());
  EXPECT_GT(std::max(newton.head<3>().norm(), newton.tail<3>().norm()), 10.0);
  FkOptions o;
  o.max_iterations = 1;
  FkResult r;
  EXPECT_EQ(forward_kinematics(seed_model(), m, LengthKind::Motor, guess, r, o), Status::NoConvergence);
  const PoseError step = pose_error(r.placement, guess);
  EXPECT_LE(step.position, o.max_step_translation * (1 + 1e-12));
  EXPECT_LE(step.rotation, o.max_step_rotation * (1 + 1e-12));
  EXPECT_GT(step.position + step.rotation, 0.0);
}

TEST(Forward, TrackedYawSweepStaysOnItsAssemblyModeUpToTheSingularityLimit) {
  // Pure yaw 0 -> 93 deg at 1 kHz and 20 deg/s; the seed is singular at 90 deg. Ok while
  // check_limits passes; past the limit, and past the singularity, never Ok, and a failure
  // leaves the tracker. (Beyond about 94 deg the lengths equal those of a pose near 86 deg on
  // this side, inside the limit: no forward kinematics can tell them apart.)
  const Model model = seed_with_wide_limits();
  FkTracker tracker;
  FkResult r;
  double last_inside = 0.0, first_refused = -1.0;
  std::map<std::string, int> refused;
  for (int k = 0; k <= 4650; ++k) {
    Pose p;
    p.rpy[2] = deg2rad(0.02 * k);
    LegState st;
    ASSERT_EQ(inverse_kinematics(model, p, st), Status::Ok);
    LimitReport lim;
    const Status limit = check_limits(model, st, lim);
    const FkTracker before = tracker;
    const Status s = forward_kinematics_tracked(model, motor_lengths(model, p), LengthKind::Motor, tracker, r);
    if (limit == Status::Ok) {
      ASSERT_EQ(first_refused, -1.0) << "the limit let a pose back in at yaw " << rad2deg(p.rpy[2]);
      ASSERT_EQ(s, Status::Ok) << "yaw " << rad2deg(p.rpy[2]);
      ASSERT_LT(pose_error(r.placement, placement_from_pose(p)).position, kRoundTripTol);
      last_inside = p.rpy[2];
      continue;
    }
    ASSERT_EQ(limit, Status::PlatformSingularity) << "yaw " << rad2deg(p.rpy[2]);
    if (first_refused < 0) first_refused = p.rpy[2];
    ASSERT_NE(s, Status::Ok) << "yaw " << rad2deg(p.rpy[2]) << " gave yaw " << rad2deg(r.pose.rpy[2]);
    ++refused[std::string(to_string(s))];
    EXPECT_EQ(tracker.det_sign, before.det_sign);
    EXPECT_EQ(tracker.last.R_BP, before.last.R_BP);
  }
  std::printf("  last yaw inside the limits %.2f deg, first refused %.2f deg; refusals:", rad2deg(last_inside),
              rad2deg(first_refused));
  for (const auto& [status, n] : refused) std::printf(" %s %d", status.c_str(), n);
  std::printf("\n");
  EXPECT_GT(rad2deg(last_inside), 80.0);
  EXPECT_LT(rad2deg(first_refused), 89.0);
}

TEST(Forward, CrossingOntoTheOtherAssemblyModeIsReported) {
  // From guesses beyond the yaw-90 deg singularity (the other mode), lengths of poses on this
  // side: Ok only on the guess's mode; a solution on this side is AssemblyModeChanged.
  const Model model = seed_with_wide_limits();
  int changed = 0;
  for (const double guess_yaw : {92.0, 95.0, 100.0}) {
    for (const double target_yaw : {30.0, 50.0, 70.0, 80.0, 85.0}) {
      Pose guess, target;
      guess.rpy[2] = deg2rad(guess_yaw);
      target.rpy[2] = deg2rad(target_yaw);
      FkResult at_guess, r;
      ASSERT_EQ(forward_kinematics(model, motor_lengths(model, guess), LengthKind::Motor, placement_from_pose(guess),
                                   at_guess),
                Status::Ok);
      const Status s =
          forward_kinematics(model, motor_lengths(model, target), LengthKind::Motor, placement_from_pose(guess), r);
      if (s == Status::Ok) {
        EXPECT_EQ(r.det_sign, at_guess.det_sign) << guess_yaw << " -> " << target_yaw;
      }
      if (s != Status::AssemblyModeChanged) continue;
      ++changed;
      EXPECT_EQ(r.det_sign, -at_guess.det_sign);
      EXPECT_LT(pose_error(r.placement, placement_from_pose(target)).position, kRoundTripTol);
      FkTracker tracker{at_guess.placement, at_guess.det_sign, true};
      EXPECT_EQ(forward_kinematics_tracked(model, motor_lengths(model, target), LengthKind::Motor, tracker, r),
                Status::AssemblyModeChanged);
      EXPECT_EQ(tracker.last.R_BP, at_guess.placement.R_BP);
    }
  }
  // Measured: none found on this side (NoConvergence or a solution on the guess's side); the
  // line search rarely lets Newton through a singularity, and the sign check catches it when it does.
  std::printf("  AssemblyModeChanged in %d of 15 crossings\n", changed);
}

TEST(Forward, TrackedStartsFromHomeAndFollowsAMotion) {
  FkTracker tracker;
  FkResult r;
  Pose p;
  p.position = Vector3d(0.1, -0.05, 0.02);
  ASSERT_EQ(forward_kinematics_tracked(seed_model(), motor_lengths(seed_model(), p), LengthKind::Motor, tracker, r),
            Status::Ok);
  EXPECT_TRUE(tracker.valid);
  EXPECT_EQ(tracker.det_sign, r.det_sign);
  EXPECT_LT(pose_error(tracker.last, placement_from_pose(p)).position, kRoundTripTol);
  // A failure (NaN lengths) leaves the tracker.
  const FkTracker before = tracker;
  Vector6d bad = seed_model().length_home();
  bad[0] = std::nan("");
  EXPECT_EQ(forward_kinematics_tracked(seed_model(), bad, LengthKind::Motor, tracker, r), Status::NonFiniteInput);
  EXPECT_EQ(tracker.last.t, before.last.t);
}

TEST(Forward, HomeLengthsGiveHomeWithoutIterating) {
  FkResult r;
  ASSERT_EQ(forward_kinematics(seed_model(), seed_model().length_home(), LengthKind::Motor, Placement{}, r),
            Status::Ok);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_LT(r.pose.to_vector().cwiseAbs().maxCoeff(), 1e-15);
}

// From home the first Newton step takes the model's inverse at home (no elimination). The same
// solve from a guess one ulp away eliminates: both reach the pose, with the condition number and
// determinant sign of the Jacobian there -- also where one step from home is already the solution
// (no elimination then to read them from).
TEST(Forward, TheFirstStepFromHomeMatchesAnEliminatedOne) {
  const Model& model = seed_model();
  Placement beside;
  beside.t.x() = std::nextafter(0.0, 1.0);
  for (const double offset : {1e-7, 1e-3, 0.2}) {
    Pose p;
    p.position = {offset, -0.5 * offset, 0.3 * offset};
    p.rpy = {0.2 * offset, 0.1 * offset, -0.4 * offset};
    CommandReport c;
    ASSERT_EQ(compute_commands(model, p, c), Status::Ok);
    double condition;
    ASSERT_EQ(jacobian_condition(model, c.legs, condition), Status::Ok);
    Matrix6d J;
    ASSERT_EQ(length_jacobian(model, c.legs, LengthKind::Motor, J), Status::Ok);
    const double det_sign = J.determinant() > 0.0 ? 1.0 : -1.0;
    FkResult home, near;
    ASSERT_EQ(forward_kinematics(model, c.compensated, LengthKind::Motor, Placement{}, home), Status::Ok) << offset;
    ASSERT_EQ(forward_kinematics(model, c.compensated, LengthKind::Motor, beside, near), Status::Ok) << offset;
    if (offset == 1e-7) {
      EXPECT_EQ(home.iterations, 1);
    }
    EXPECT_EQ(home.iterations, near.iterations) << offset;
    for (const FkResult* r : {&home, &near}) {
      EXPECT_LT(pose_error(r->placement, placement_from_pose(p)).position, 1e-12) << offset;
      EXPECT_LT(pose_error(r->placement, placement_from_pose(p)).rotation, 1e-12) << offset;
      EXPECT_NEAR(r->condition, condition, 1e-6 * condition) << offset;
      EXPECT_EQ(r->det_sign, det_sign) << offset;
    }
  }
}

}  // namespace
}  // namespace hexatwist::test

namespace hexatwist::test {
namespace {

// A tracker set at a pose starts the next tracked solve there, on that pose's assembly mode.
TEST(Forward, ATrackerSetAtAPoseTracksFromThere) {
  const Model& model = seed_model();
  std::mt19937_64 rng(kSeed + 80);
  for (int n = 0; n < 200; ++n) {
    const Pose p = random_valid_pose(model, rng, 0.4, deg2rad(25));
    FkTracker tracker;
    ASSERT_EQ(fk_tracker_set(model, placement_from_pose(p), LengthKind::Motor, tracker), Status::Ok);
    ASSERT_TRUE(tracker.valid);
    // Its mode is the one forward kinematics finds at that pose.
    FkResult at;
    ASSERT_EQ(forward_kinematics(model, lengths_for(model, placement_from_pose(p), LengthKind::Motor),
                                 LengthKind::Motor, placement_from_pose(p), at),
              Status::Ok);
    EXPECT_EQ(tracker.det_sign, at.det_sign);
    // A pose 1 ms of fast motion away is found from there in few iterations.
    Pose q = p;
    q.position.x() += 5e-4;
    q.rpy.z() += 1e-3;
    FkResult r;
    ASSERT_EQ(forward_kinematics_tracked(model, lengths_for(model, placement_from_pose(q), LengthKind::Motor),
                                         LengthKind::Motor, tracker, r),
              Status::Ok);
    EXPECT_LE(r.iterations, 3);
    EXPECT_LT(pose_error(r.placement, placement_from_pose(q)).position, kRoundTripTol);
  }
  FkTracker untouched;
  Pose bad;
  bad.position.x() = NAN;
  EXPECT_EQ(fk_tracker_set(model, placement_from_pose(bad), LengthKind::Motor, untouched), Status::NonFiniteInput);
  EXPECT_FALSE(untouched.valid);
}

}  // namespace
}  // namespace hexatwist::test
