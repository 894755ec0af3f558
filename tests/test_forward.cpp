// Forward kinematics: round trips with IK (geometric and twist-aware), the residual Jacobian
// against finite differences, warm starts, and failures that are reported rather than silent.
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
    p.rpy = Vector3d(deg2rad(6) * std::sin(0.9 * w * t), deg2rad(10) * std::sin(1.1 * w * t), deg2rad(15) * std::sin(w * t));
    const Placement x = placement_from_pose(p);
    ASSERT_EQ(forward_kinematics(seed_model(), lengths_for(seed_model(), x, LengthKind::Motor), LengthKind::Motor, previous, r),
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
    EXPECT_EQ(fk_residual(model, {x.t + d.head<3>(), exp_so3(d.tail<3>()) * x.R_BP}, m, kind, st, fp, nullptr), Status::Ok);
    EXPECT_EQ(fk_residual(model, {x.t - d.head<3>(), exp_so3(-d.tail<3>()) * x.R_BP}, m, kind, st, fm, nullptr), Status::Ok);
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
        const Vector6d target = lengths_for(model, placement_from_pose(random_valid_pose(model, rng, 0.3, deg2rad(25))), kind);
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
  const double miss = (platform_point_B(seed_model(), geo.placement, A) - platform_point_B(seed_model(), mot.placement, A)).norm();
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

TEST(Forward, HomeLengthsGiveHomeWithoutIterating) {
  FkResult r;
  ASSERT_EQ(forward_kinematics(seed_model(), seed_model().length_home(), LengthKind::Motor, Placement{}, r), Status::Ok);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_LT(r.pose.to_vector().cwiseAbs().maxCoeff(), 1e-15);
}

}  // namespace
}  // namespace hexatwist::test
