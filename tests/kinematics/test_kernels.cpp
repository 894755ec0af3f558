// SPDX-License-Identifier: BSD-3-Clause
// The internal kernels of the real-time path: vectorised sin/cos and atan2 (src/kinematics/fast_math.hpp)
// against libm, the fixed-size 6x6 LU and condition proof (src/kinematics/linear_solve.hpp) and the
// Gauss-Jordan inverse on lane columns (src/kinematics/gauss_jordan.hpp) against Eigen.
#include "hexatwist/hexatwist.hpp"
#include "kinematics/fast_math.hpp"
#include "kinematics/gauss_jordan.hpp"
#include "kinematics/lanes.hpp"
#include "kinematics/leg_effects_internal.hpp"
#include "kinematics/linear_solve.hpp"
#include "kinematics/twist_internal.hpp"
#include "support.hpp"

#include <Eigen/LU>

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <random>

namespace hexatwist::detail {
namespace {

using namespace hexatwist::test;

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
  const std::vector<std::pair<double, double>> cases{
      {0.0, 1.0},  {1.0, 0.0}, {0.0, -1.0},   {-1.0, 0.0},   {1.0, 1.0}, {-1.0, -1.0}, {1.0, -0.0},
      {-0.0, 1.0}, {0.0, 0.0}, {1e-300, 1.0}, {1.0, 1e-300}, {inf, 1.0}, {1.0, inf},   {-1.0, -inf}};
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
    for (int k = 0; k < 3; ++k)
      worst = std::max({worst, std::abs(s[k] - std::sin(a[k])), std::abs(c[k] - std::cos(a[k]))});
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

// A matrix as the lanes hold it: column c, packet k, lane l = row k * kWidth + l; the padding
// rows repeat row 0, as the legs' lanes do.
Columns columns_of(const Matrix6d& A) {
  Columns out;
  for (int c = 0; c < 6; ++c)
    for (int k = 0; k < kPackets; ++k)
      for (int l = 0; l < kWidth; ++l) {
        const int row = k * kWidth + l;
        out.c[c][k][l] = A(row < 6 ? row : 0, c);
      }
  return out;
}

// J^-1 from gauss_jordan's result (row k is row pivot_row[k] of X; X's columns in pivot order).
Matrix6d inverse_of(const Inverse6& inv) {
  Matrix6d X;
  for (int k = 0; k < 6; ++k)
    for (int i = 0; i < 6; ++i) X(i, inv.pivot_row[k]) = inv.x.c[k][i / kWidth][i % kWidth];
  Matrix6d J_inv;
  for (int k = 0; k < 6; ++k) J_inv.row(k) = X.row(inv.pivot_row[k]);
  return J_inv;
}

// A random system A x = b, entries uniform in [-1, 1].
void random_system(std::mt19937_64& rng, Matrix6d& A, Vector6d& b) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 36; ++i) A.data()[i] = u(rng);
  for (int i = 0; i < 6; ++i) b[i] = u(rng);
}

TEST(GaussJordan, MatchesEigenOnRandomMatrices) {
  // Inverse, solve, determinant sign, pivot ratio (LU's, the same pivots) and the 1-norm condition
  // number, against Eigen's full-pivoting LU and lu6_factor.
  std::mt19937_64 rng(3);
  double worst_backward = 0.0, worst_inverse = 0.0, worst_condition = 0.0;
  for (int n = 0; n < 20000; ++n) {
    Matrix6d A;
    Vector6d b;
    random_system(rng, A, b);
    Inverse6 inv;
    const double ratio = gauss_jordan(columns_of(A), inv);
    ASSERT_GT(ratio, 0.0);
    Lu6 lu;
    EXPECT_NEAR(ratio, lu6_factor(A, lu), 1e-12 * ratio) << A;
    const Eigen::FullPivLU<Matrix6d> ref(A);
    EXPECT_EQ(inv.det_sign, ref.determinant() > 0.0 ? 1.0 : -1.0) << A;
    Vector6d x;
    gj_solve(inv, b, x);
    // Normwise backward error |Ax - b| / (|A| |x| + |b|): a few eps for a stable elimination.
    worst_backward = std::max(worst_backward, (A * x - b).norm() / (A.norm() * x.norm() + b.norm()));
    const Matrix6d A_inv = ref.inverse();
    const double cond = A.cwiseAbs().colwise().sum().maxCoeff() * A_inv.cwiseAbs().colwise().sum().maxCoeff();
    worst_inverse = std::max(worst_inverse, (inverse_of(inv) - A_inv).norm() / (A_inv.norm() * cond));
    worst_condition = std::max(worst_condition, std::abs(gj_condition(columns_of(A), inv) / cond - 1.0) / cond);
  }
  std::printf("  backward error %.2g, inverse %.2g, condition %.2g\n", worst_backward, worst_inverse, worst_condition);
  // Gauss-Jordan's backward error is larger than LU's (1.7e-16 on these matrices) by up to about the
  // condition number; its forward error is LU's.
  EXPECT_LT(worst_backward, 2e-14);   // measured 1.9e-15
  EXPECT_LT(worst_inverse, 1e-15);    // measured 5.7e-17 (relative to cond * |A^-1|)
  EXPECT_LT(worst_condition, 1e-15);  // measured 8e-17 (relative error over cond)
}

TEST(GaussJordan, ReportsSingularNonFiniteAndPermutedMatrices) {
  Matrix6d A = Matrix6d::Identity();
  Inverse6 inv;
  A(5, 5) = 0.0;
  EXPECT_EQ(gauss_jordan(columns_of(A), inv), 0.0);
  EXPECT_EQ(inv.det_sign, 0.0);
  A(5, 5) = 1e-14;
  EXPECT_NEAR(gauss_jordan(columns_of(A), inv), 1e-14, 1e-20);
  A(5, 5) = NAN;
  EXPECT_EQ(gauss_jordan(columns_of(A), inv), 0.0);
  A = Matrix6d::Zero();
  EXPECT_EQ(gauss_jordan(columns_of(A), inv), 0.0);
  // Rows pivoted in the wrong order still solve, with the permutation's sign: the anti-diagonal
  // reverses six rows, three transpositions.
  Matrix6d P = Matrix6d::Zero();
  for (int i = 0; i < 6; ++i) P(i, 5 - i) = i + 1.0;
  const Vector6d b = (Vector6d() << 1, 2, 3, 4, 5, 6).finished();
  ASSERT_GT(gauss_jordan(columns_of(P), inv), 0.1);
  EXPECT_EQ(inv.det_sign, -1.0);
  Vector6d x;
  gj_solve(inv, b, x);
  EXPECT_LT((P * x - b).norm(), 2e-14);  // measured 2.2e-15 (the reciprocals 1/(i+1) round)
  // One inverse, several right-hand sides.
  const Vector6d c = (Vector6d() << -3, 0, 2, 7, 1, 1).finished();
  gj_solve(inv, c, x);
  EXPECT_LT((P * x - c).norm(), 2e-14);
  EXPECT_NEAR(gj_condition(columns_of(P), inv), 6.0 / 1.0, 1e-15);
}

TEST(GaussJordan, SolvesASystemWithoutTheInverse) {
  // gj_solve_system against the inverse's solve (the same pivots): the same backward error, the
  // same pivot ratio, and 0 for singular or non-finite matrices.
  std::mt19937_64 rng(4);
  double worst = 0.0;
  for (int n = 0; n < 20000; ++n) {
    Matrix6d A;
    Vector6d b;
    random_system(rng, A, b);
    Inverse6 inv;
    const double ratio = gauss_jordan(columns_of(A), inv);
    Vector6d x, y;
    ASSERT_EQ(gj_solve_system(columns_of(A), b, x), ratio);
    gj_solve(inv, b, y);
    worst = std::max(worst, (A * x - b).norm() / (A.norm() * x.norm() + b.norm()));
    EXPECT_LT((x - y).norm(), 1e-12 * (1.0 + y.norm()) / ratio) << A;
  }
  std::printf("  backward error %.2g\n", worst);
  EXPECT_LT(worst, 2e-14);  // measured 1.4e-15
  Matrix6d S = Matrix6d::Identity();
  S(3, 3) = 0.0;
  Vector6d x;
  EXPECT_EQ(gj_solve_system(columns_of(S), Vector6d::Ones(), x), 0.0);
  S(3, 3) = NAN;
  EXPECT_EQ(gj_solve_system(columns_of(S), Vector6d::Ones(), x), 0.0);
}

// The padded rows of A (row-major, two zeros of padding), as the limits' kernel forms them.
void padded_rows_of(const Matrix6d& A, PaddedRows& rows) {
  alignas(64) double r[6][8] = {};
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 6; ++c) r[i][c] = A(i, c);
  std::memcpy(rows, r, sizeof r);
}

TEST(LegForces, BlocksAndTheEliminationSolveTheSameSystem) {
  // finish_leg_forces solves A^T F = G' by 3x3 blocks, or by the pivoted elimination where a block
  // is nearly singular. With A = I it returns G' itself; for any A, F satisfies A^T F = G' to
  // rounding, on either branch; a singular A is SingularJacobian.
  const Config config = load_config(seed_config_yaml(), "seed");
  const Model& model = config.rig.model();
  const StaticLoadSpec& load = model.spec().static_load;
  ASSERT_TRUE(load.present);
  const LegLoads none;
  const Matrix3d R = Eigen::AngleAxisd(0.3, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  PaddedRows rows;
  padded_rows_of(Matrix6d::Identity(), rows);
  Vector6d G;
  ASSERT_EQ(finish_leg_forces(model, load, R, none, rows, G), Status::Ok);
  EXPECT_NE(G[2], 0.0);
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst_blocks = 0.0, worst_pivoted = 0.0;
  for (int n = 0; n < 2000; ++n) {
    Matrix6d A;
    for (int i = 0; i < 36; ++i) A.data()[i] = u(rng);
    // Every other draw: legs 0, 2 and 4 with coplanar axes (the first block singular), the
    // matrix still regular: the elimination's branch.
    const bool coplanar = n % 2 == 1;
    for (int i = 0; i < 6; i += 2)
      if (coplanar) A(i, 2) = 0.0;
    padded_rows_of(A, rows);
    Vector6d F;
    ASSERT_EQ(finish_leg_forces(model, load, R, none, rows, F), Status::Ok);
    const double residual = (A.transpose() * F - G).norm() / (A.norm() * F.norm() + G.norm());
    (coplanar ? worst_pivoted : worst_blocks) = std::max(coplanar ? worst_pivoted : worst_blocks, residual);
    const Vector6d exact = A.transpose().fullPivLu().solve(G);
    const double cond = A.norm() * A.inverse().norm();
    EXPECT_LT((F - exact).norm(), 1e-13 * cond * exact.norm()) << A;
  }
  std::printf("  backward error by blocks %.2g, by elimination %.2g\n", worst_blocks, worst_pivoted);
  EXPECT_LT(worst_blocks, 1e-14);   // measured 9.2e-16
  EXPECT_LT(worst_pivoted, 2e-15);  // measured 2.2e-16
  Matrix6d singular = Matrix6d::Identity();
  singular.row(4) = singular.row(1);
  padded_rows_of(singular, rows);
  Vector6d F;
  EXPECT_EQ(finish_leg_forces(model, load, R, none, rows, F), Status::SingularJacobian);
}

TEST(GaussJordan, ColumnPacketsTransposeLikeTheMatrix) {
  // The in-register transpose (eight lanes) or the copy through memory gives J's padded rows.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int n = 0; n < 100; ++n) {
    Matrix6d A;
    for (int i = 0; i < 36; ++i) A.data()[i] = u(rng);
    const Columns cols = columns_of(A);
    ColumnPackets packets;
    for (int k = 0; k < kPackets; ++k) {
      lane_v col[6];
      for (int c = 0; c < 6; ++c) col[c] = cols.c[c][k];
      packets.set(k, col);
    }
    PaddedRows rows, expected;
    packets.rows(rows);
    padded_rows(A, expected);
    for (int i = 0; i < 6; ++i)
      for (int q = 0; q < kRowVectors; ++q)
        for (int l = 0; l < kWidth; ++l) ASSERT_EQ(rows[i][q][l], expected[i][q][l]) << i << " " << q << " " << l;
  }
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

TEST(LinearSolve, CheapConditionProofWithAPerturbationHoldsForEveryMatrixWithinIt) {
  // scaled_condition_below(J, ..., bound, p) proves the bound for every A + E with ||E||_1 <= p
  // (A = J W^-1, the scaled J): checked with E random and with E pushing A towards singularity
  // (-p times the SVD's last pair, scaled to ||E||_1 = p), at bounds and perturbations around the
  // proof's edge.
  std::mt19937_64 rng(4242);
  std::uniform_real_distribution<double> u(-1.0, 1.0), scale(-3.0, 0.0), len(0.3, 3.0);
  int proven = 0;
  double worst = 0.0;  // the largest exact condition over its bound among proven cases
  for (int n = 0; n < 4000; ++n) {
    Matrix6d J;
    for (int i = 0; i < 36; ++i) J(i) = u(rng);
    const Vector6d v = Vector6d::NullaryExpr([&] { return u(rng); }).normalized();
    J -= (1.0 - std::pow(10.0, scale(rng))) * (J * v) * v.transpose();
    const double length = len(rng);
    Vector6d w_inv;
    w_inv << 1, 1, 1, 1 / length, 1 / length, 1 / length;
    const Matrix6d A = J * w_inv.asDiagonal();
    Matrix6d E0;
    for (int i = 0; i < 36; ++i) E0(i) = u(rng);
    Matrix6d Y = (J + 1e-3 * E0).inverse();
    Y.bottomRows<3>() *= length;
    ConditionReference ref;
    for (int i = 0; i < 6; ++i)
      for (int c = 0; c < 6; ++c) ref.inverse[i][c] = Y(i, c);
    ref.norm = Y.cwiseAbs().colwise().sum().maxCoeff();
    double sign;
    const double exact = scaled_condition(J, length, sign);
    if (!(exact < 1e4)) continue;
    const double norm_a = A.cwiseAbs().colwise().sum().maxCoeff();
    const Eigen::JacobiSVD<Matrix6d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Matrix6d toward = -svd.matrixU().col(5) * svd.matrixV().col(5).transpose();
    toward /= toward.cwiseAbs().colwise().sum().maxCoeff();
    for (const double rel : {1e-3, 1e-2, 3e-2, 0.1}) {
      const double p = rel * norm_a / exact;  // rel of the way to the nearest singular matrix, about
      for (const double factor : {1.2, 2.0, 5.0}) {
        const double bound = factor * exact;
        if (!scaled_condition_below(J, length, ref, bound, p)) continue;
        ++proven;
        Matrix6d random;
        for (int i = 0; i < 36; ++i) random(i) = u(rng);
        random /= random.cwiseAbs().colwise().sum().maxCoeff();
        for (const Matrix6d& E : {Matrix6d(p * toward), Matrix6d(p * random), Matrix6d(-p * toward)}) {
          const Matrix6d J_e = (A + E) * w_inv.cwiseInverse().asDiagonal();
          const double kappa = scaled_condition(J_e, length, sign);
          worst = std::max(worst, kappa / bound);
          ASSERT_LE(kappa, bound) << "p " << p << " bound " << bound << "\n" << J;
        }
      }
    }
    // Never proven where the perturbation alone could make A singular.
    EXPECT_FALSE(scaled_condition_below(J, length, ref, 1e300, 1.01 * norm_a));
    EXPECT_FALSE(scaled_condition_below(J, length, ref, 1e300, std::nan("")));
    EXPECT_FALSE(scaled_condition_below(J, length, ref, 1e300, INFINITY));
  }
  std::printf("  proven: %d; largest condition within the perturbation over its bound: %.3f\n", proven, worst);
  EXPECT_GT(proven, 10000);
}

TEST(LinearSolve, ConditionProofPerLaneGivesEachMatrixTheVerdictOfTheSingleMatrix) {
  // condition_below_lanes (a batch's poses, one matrix per lane) says for every lane what
  // condition_below says for that lane's matrix: at perturbations within a few ulp of where the
  // verdict turns (found by bisection per matrix), from references near and far (so that the
  // Newton-Schulz step decides some), with a lane left out, NaN and inf.
  std::mt19937_64 rng(777);
  std::uniform_real_distribution<double> u(-1.0, 1.0), scale(-2.0, 0.0), far(-6.0, -0.3);
  constexpr int kW = sizeof(lane_v) / sizeof(double);
  long compared = 0, proven = 0;
  for (int n = 0; n < 3000; ++n) {
    Matrix6d J;
    for (int i = 0; i < 36; ++i) J(i) = u(rng);
    const Vector6d v = Vector6d::NullaryExpr([&] { return u(rng); }).normalized();
    J -= (1.0 - std::pow(10.0, scale(rng))) * (J * v) * v.transpose();
    Matrix6d E;
    for (int i = 0; i < 36; ++i) E(i) = u(rng);
    const Matrix6d Y = (J + std::pow(10.0, far(rng)) * E).inverse();
    ConditionReference ref;
    for (int i = 0; i < 6; ++i)
      for (int c = 0; c < 6; ++c) ref.inverse[i][c] = Y(i, c);
    ref.norm = Y.cwiseAbs().colwise().sum().maxCoeff();
    double sign;
    const double bound = 1.5 * scaled_condition(J, 1.0, sign);
    if (!std::isfinite(bound)) continue;
    // Each lane: J with a small change of its own, and a perturbation at that matrix's edge.
    Matrix6d A[kW];
    double p[kW];
    for (int l = 0; l < kW; ++l) {
      Matrix6d D;
      for (int i = 0; i < 36; ++i) D(i) = u(rng);
      A[l] = J + 1e-6 * D;
      PaddedRows rows;
      padded_rows(A[l], rows);
      double lo = 0.0, hi = A[l].cwiseAbs().colwise().sum().maxCoeff();
      if (!condition_below(rows, ref, bound, lo)) {
        p[l] = l % 2 == 0 ? 0.0 : 1e-9;  // not proven at all: still compared
        continue;
      }
      for (int it = 0; it < 200 && std::nextafter(lo, hi) < hi; ++it) {
        const double mid = 0.5 * (lo + hi);
        (condition_below(rows, ref, bound, mid) ? lo : hi) = mid;
      }
      p[l] = lo;
      for (int k = 0; k < l % 5; ++k) p[l] = std::nextafter(p[l], INFINITY);  // 0-4 ulp past the last yes
    }
    if (n % 100 == 7) p[1] = std::nan("");
    if (n % 100 == 8) p[2] = INFINITY;
    lane_v a[6][6], perturbation;
    for (int l = 0; l < kW; ++l) {
      perturbation[l] = p[l];
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) a[r][c][l] = A[l](r, c);
    }
    mask_of<lane_v> todo = all_set();
    if (n % 10 == 5) todo[0] = 0;
    const mask_of<lane_v> lanes = condition_below_lanes(a, ref, bound, perturbation, todo);
    for (int l = 0; l < kW; ++l) {
      PaddedRows rows;
      padded_rows(A[l], rows);
      const bool single = condition_below(rows, ref, bound, p[l]);
      ASSERT_EQ(lanes[l] != 0, single && todo[l] != 0) << "matrix " << n << " lane " << l << " p " << p[l];
      ++compared;
      proven += single;
    }
  }
  std::printf("  %ld lanes compared, %ld proven\n", compared, proven);
  EXPECT_GT(proven, compared / 8);
  EXPECT_LT(proven, compared * 3 / 4);
}

TEST(Lanes, TwistShareBoundCoversTheMotorSideJacobiansTwistRows) {
  // twist_share_bound summed over the legs bounds ||A_m - A_g||_1, the twist's share of the scaled
  // motor-side Jacobian, on the seed platform, on random asymmetric ones (either thread hand and
  // driven side, one leg without axes), and near the U-joint singularity margin (the seed with a
  // 1 deg margin and wide stroke and bend limits); and it is not loose by more than a small factor.
  std::mt19937_64 rng(99);
  ModelSpec near_spec = seed_model().spec();
  near_spec.limits.singularity_margin = deg2rad(1.0);
  near_spec.limits.length_min = 0.5;
  near_spec.limits.length_max = 4.0;
  near_spec.limits.bend_max = deg2rad(89);
  std::vector<std::unique_ptr<Model>> models;
  models.push_back(std::make_unique<Model>(seed_model().spec()));
  models.push_back(std::make_unique<Model>(near_spec));
  for (int m = 0; m < 6; ++m) models.push_back(std::make_unique<Model>(random_platform(rng).spec()));
  ModelSpec no_axes = models.back()->spec();
  no_axes.legs[2].axis_base_B.setZero();
  no_axes.legs[2].axis_platform_P.setZero();
  no_axes.legs[2].lead = 0.0;
  models.push_back(std::make_unique<Model>(no_axes));
  double worst_ratio = 0.0, largest_share = 0.0;
  std::vector<double> ratios;
  for (std::size_t m = 0; m < models.size(); ++m) {
    const Model& model = *models[m];
    const LegLanes& g = model.geometry().lanes;
    Vector6d d;
    d << 1, 1, 1, 1 / model.condition_length(), 1 / model.condition_length(), 1 / model.condition_length();
    for (int n = 0; n < 3000; ++n) {
      const Pose p =
          m == 1 ? random_valid_pose(model, rng, 0.8, deg2rad(80)) : random_valid_pose(model, rng, 0.4, deg2rad(30));
      LegState st;
      ASSERT_EQ(inverse_kinematics(model, p, st), Status::Ok);
      Matrix6d Jm, Jg;
      ASSERT_EQ(motor_length_jacobian(model, st, Jm), Status::Ok);
      length_jacobian(st, Jg);
      const double share = ((Jm - Jg) * d.asDiagonal()).cwiseAbs().colwise().sum().maxCoeff();
      const Matrix6d share_rows = (Jm - Jg) * d.asDiagonal();
      lane_v sum = {};
      for (int k = 0; k < kPackets; ++k) {
        const lanes3 leg = load6(st.leg_B, k), ja = load_lanes(g.axis_base_B, k), jd = load6(st.axis_platform_B, k);
        const lane_v length = load6(st.length.data(), k), dot_a = dot(leg, ja), dot_d = dot(leg, jd);
        const lane_v length2 = length * length;
        const TwistTerms t = twist_terms(leg, ja, jd, dot_a, dot_d, length2);
        const lane_v leg_bound =
            twist_share_bound(model, t.x, length * t.y, dot_a, dot_d, length, length2, 1.0 / length, k);
        sum += leg_bound;
        // Leg by leg, the bound is on the larger of the two halves' Euclidean norms.
        for (int l = 0; l < kWidth && k * kWidth + l < kLegs; ++l) {
          const int i = k * kWidth + l;
          const double row = std::max(share_rows.row(i).head<3>().norm(), share_rows.row(i).tail<3>().norm());
          ASSERT_LE(row, leg_bound[l] * (1.0 + 1e-6) + 1e-13) << "model " << m << " leg " << i << " " << str(p);
        }
      }
      const double bound = sum_lanes(sum);
      // With the allowances for rounding that the command adds (compensation.cpp): the rows differ
      // by rounding even where the twist adds nothing (a leg without axes: 1e-16).
      ASSERT_LE(share, bound * (1.0 + 1e-6) + 1e-13) << "model " << m << " " << str(p);
      largest_share = std::max(largest_share, share);
      if (share > 0.0) ratios.push_back(bound / share);
    }
  }
  std::sort(ratios.begin(), ratios.end());
  worst_ratio = ratios.back();
  std::printf("  ||A_m - A_g||_1 up to %.3g; bound over it: median %.2f, worst %.2f\n", largest_share,
              ratios[ratios.size() / 2], worst_ratio);
  EXPECT_LT(ratios[ratios.size() / 2], 5.0);
  EXPECT_LT(worst_ratio, 20.0);
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
