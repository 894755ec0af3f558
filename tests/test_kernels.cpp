// The internal kernels of the real-time path: vectorised sin/cos and atan2 (src/kinematics/fast_math.hpp)
// against libm, and the fixed-size 6x6 solver (src/kinematics/linear_solve.hpp) against Eigen.
#include "kinematics/fast_math.hpp"
#include "kinematics/linear_solve.hpp"
#include "kinematics/twist_internal.hpp"
#include "hexatwist/hexatwist.hpp"

#include <Eigen/LU>

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <cstdio>
#include <random>

namespace hexatwist::detail {
namespace {

TEST(FastMath, Atan2MatchesLibmOverAllQuadrantsAndScales) {
  // Measured worst difference 4.4e-16 rad (2 ulp of pi); bound 10x.
  std::mt19937_64 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int n = 0; n < 200000; ++n) {
    Array6d y, x;
    for (int i = 0; i < kLegs; ++i) {
      const double scale = std::pow(10.0, 12 * u(rng));
      y[i] = u(rng) * scale;
      x[i] = u(rng) * (n % 3 == 0 ? scale : 1.0);
    }
    const Array6d a = atan2(y, x);
    for (int i = 0; i < kLegs; ++i) worst = std::max(worst, std::abs(a[i] - std::atan2(y[i], x[i])));
  }
  EXPECT_LT(worst, 4.5e-15);
}

TEST(FastMath, Atan2HandlesAxesZerosAndInfinity) {
  const double inf = INFINITY;
  const std::vector<std::pair<double, double>> cases{{0.0, 1.0},  {1.0, 0.0},  {0.0, -1.0}, {-1.0, 0.0}, {1.0, 1.0},
                                                     {-1.0, -1.0}, {1.0, -0.0}, {-0.0, 1.0}, {0.0, 0.0},  {1e-300, 1.0},
                                                     {1.0, 1e-300}, {inf, 1.0}, {1.0, inf},  {-1.0, -inf}};
  for (const auto& [y, x] : cases) {
    Array6d ya = Array6d::Constant(y), xa = Array6d::Constant(x);
    EXPECT_NEAR(atan2(ya, xa)[0], std::atan2(y, x), 1e-15) << "atan2(" << y << ", " << x << ")";
  }
}

TEST(FastMath, SinCosMatchLibmAndFallBackForHugeAngles) {
  std::mt19937_64 rng(2);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int n = 0; n < 200000; ++n) {
    const Vector3d a(1000 * u(rng), 10 * u(rng), u(rng));
    Vector3d s, c;
    sin_cos(a, s, c);
    for (int k = 0; k < 3; ++k) worst = std::max({worst, std::abs(s[k] - std::sin(a[k])), std::abs(c[k] - std::cos(a[k]))});
  }
  EXPECT_LT(worst, 2e-15);  // measured 2.2e-16
  const Vector3d huge(1e7, -3e9, kPi);
  Vector3d s, c;
  sin_cos(huge, s, c);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(s[k], std::sin(huge[k]));
    EXPECT_EQ(c[k], std::cos(huge[k]));
  }
  // Exact quadrant boundaries.
  for (const double a : {0.0, kPi / 2, kPi, -kPi / 2, 3 * kPi / 2, -kPi, 2 * kPi, -2.5 * kPi}) {
    sin_cos(Vector3d(a, a, a), s, c);
    EXPECT_NEAR(s[0], std::sin(a), 1e-15) << a;
    EXPECT_NEAR(c[0], std::cos(a), 1e-15) << a;
  }
}

TEST(FastMath, SmallAnglesSkipTheReductionWithTheSameResult) {
  // Within +-0.78 rad the roll-pitch-yaw rotation calls sin_cos_reduced (no range reduction):
  // there k = 0 and r = x exactly, so it must agree bit for bit with the full kernel, and with
  // libm to 1 ulp (measured 1.1e-16).
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> u(-0.78, 0.78);
  double worst = 0.0;
  for (int n = 0; n < 200000; ++n) {
    const v2d x{u(rng), n % 2 ? -0.78 : 0.78 * u(rng) * u(rng)};
    v2d s_full, c_full, s_short, c_short;
    sin_cos(x, s_full, c_full);
    sin_cos_reduced(x, s_short, c_short);
    for (int k = 0; k < 2; ++k) {
      ASSERT_EQ(std::bit_cast<std::uint64_t>(s_full[k]), std::bit_cast<std::uint64_t>(s_short[k])) << x[k];
      ASSERT_EQ(std::bit_cast<std::uint64_t>(c_full[k]), std::bit_cast<std::uint64_t>(c_short[k])) << x[k];
      worst = std::max({worst, std::abs(s_short[k] - std::sin(x[k])), std::abs(c_short[k] - std::cos(x[k]))});
    }
    const Vector3d a(x[0], x[1], -x[0]);
    Vector3d s, c;
    sin_cos(a, s, c);  // the rotation's entry point takes the shortcut here
    EXPECT_EQ(s[1], s_short[1]);
    EXPECT_EQ(c[0], c_short[0]);
  }
  EXPECT_LT(worst, 1.2e-15);
}

TEST(LinearSolve, MatchesEigenFullPivotingOnRandomSystems) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int n = 0; n < 20000; ++n) {
    Matrix6d A;
    Vector6d b;
    for (int i = 0; i < 36; ++i) A.data()[i] = u(rng);
    for (int i = 0; i < 6; ++i) b[i] = u(rng);
    Vector6d x;
    Lu6 lu;
    const double ratio = lu6_factor(A, lu);
    lu6_solve(lu, b, x);
    ASSERT_GT(ratio, 0.0);
    const Vector6d ref = A.fullPivLu().solve(b);
    // Normwise backward error |Ax - b| / (|A| |x| + |b|): a few eps for a stable elimination.
    const double backward = (A * x - b).norm() / (A.norm() * x.norm() + b.norm());
    worst = std::max(worst, backward);
    if (ratio > 1e-3) {
      EXPECT_LT((x - ref).norm(), 1e-9 * (1.0 + ref.norm())) << A;
    }
  }
  EXPECT_LT(worst, 2e-15);  // measured 1.7e-16
}

TEST(LinearSolve, ReportsSingularAndNearSingularMatrices) {
  Matrix6d A = Matrix6d::Identity();
  A(5, 5) = 0.0;
  Vector6d x;
  Lu6 lu;
  EXPECT_EQ(lu6_factor(A, lu), 0.0);
  A(5, 5) = 1e-14;
  EXPECT_NEAR(lu6_factor(A, lu), 1e-14, 1e-20);
  // Rows pivoted in the wrong order still solve.
  Matrix6d P = Matrix6d::Zero();
  for (int i = 0; i < 6; ++i) P(i, 5 - i) = i + 1.0;
  const Vector6d b = (Vector6d() << 1, 2, 3, 4, 5, 6).finished();
  ASSERT_GT(lu6_factor(P, lu), 0.1);
  lu6_solve(lu, b, x);
  EXPECT_LT((P * x - b).norm(), 1e-15);
  // One factorisation, several right-hand sides.
  const Vector6d c = (Vector6d() << -3, 0, 2, 7, 1, 1).finished();
  lu6_solve(lu, c, x);
  EXPECT_LT((P * x - c).norm(), 1e-14);
}

TEST(LinearSolve, CheapConditionProofNeverAcceptsAboveTheExactCondition) {
  // scaled_condition_below may only say yes where scaled_condition is within the bound: never
  // just below the exact number, whatever its reference (the inverse of a nearby matrix, of a far
  // one, garbage, none), and almost always at twice it from a near reference (its slack is tiny),
  // over matrices from well to badly conditioned (1 to 1e8), singular ones included.
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(-1.0, 1.0), scale(-8.0, 0.0), len(0.3, 3.0), far(-9.0, 0.5);
  int proven = 0, total = 0;
  for (int n = 0; n < 20000; ++n) {
    Matrix6d J;
    for (int i = 0; i < 36; ++i) J(i) = u(rng);
    // Shrink one direction to set the condition; every 100th matrix exactly singular.
    const Vector6d v = Vector6d::NullaryExpr([&] { return u(rng); }).normalized();
    J -= (1.0 - (n % 100 == 0 ? 0.0 : std::pow(10.0, scale(rng)))) * (J * v) * v.transpose();
    const double length = len(rng);
    // The reference: W (J + E)^-1 with |E| from 1e-9 to 3 times |J|'s entries, or garbage.
    Matrix6d E;
    for (int i = 0; i < 36; ++i) E(i) = u(rng);
    const double e = std::pow(10.0, far(rng));
    Matrix6d Y = (J + e * E).inverse();
    Y.bottomRows<3>() *= length;
    if (n % 50 == 1) Y = Matrix6d::NullaryExpr([&] { return 1e3 * u(rng); });
    ConditionReference ref;
    for (int i = 0; i < 6; ++i)
      for (int c = 0; c < 6; ++c) ref.inverse[i][c] = Y(i, c);
    ref.norm = Y.cwiseAbs().colwise().sum().maxCoeff();
    if (n % 97 == 3) ref = ConditionReference{};  // no reference
    double sign;
    const double exact = scaled_condition(J, length, sign);
    if (!std::isfinite(exact)) {
      EXPECT_FALSE(scaled_condition_below(J, length, ref, 1e300)) << J;
      continue;
    }
    EXPECT_FALSE(scaled_condition_below(J, length, ref, exact * (1.0 - 1e-9))) << exact << "\n" << J;
    if (exact < 1e6 && e < 1e-3 / exact && n % 50 != 1 && n % 97 != 3) {
      ++total;
      proven += scaled_condition_below(J, length, ref, 2.0 * exact);
    }
  }
  std::printf("  proven within twice the exact condition from a near reference: %d of %d\n", proven, total);
  EXPECT_GE(proven, total * 99 / 100);
}

TEST(LinearSolve, CheapConditionProofHoldsOverTheSeedWorkspace) {
  // From the model's reference (home), the proof succeeds for nearly every pose the seed's
  // workspace holds, and a non-finite Jacobian is never proven.
  const Model model = default_model();
  std::mt19937_64 rng(777);
  std::uniform_real_distribution<double> pos(-0.5, 0.5), rot(-deg2rad(30), deg2rad(30));
  int proven = 0, total = 0;
  while (total < 20000) {
    Pose p;
    p.position = {pos(rng), pos(rng), pos(rng)};
    p.rpy = {rot(rng), rot(rng), rot(rng)};
    CommandReport rep;
    if (compute_commands(model, p, rep) != Status::Ok) continue;
    ++total;
    proven += condition_proven_within(model, rep.legs);
  }
  std::printf("  proven over the workspace: %d of %d\n", proven, total);
  EXPECT_GE(proven, total * 999 / 1000);
  Matrix6d J = Matrix6d::Identity();
  J(2, 3) = std::nan("");
  EXPECT_FALSE(scaled_condition_below(J, 1.0, model.condition_reference(), 1e300));
}

}  // namespace
}  // namespace hexatwist::detail
