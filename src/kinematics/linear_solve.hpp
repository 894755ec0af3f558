// Internal: LU factorisation of a 6x6 matrix with partial pivoting, unrolled at fixed size, and
// the matching solve. Eigen's PartialPivLU goes through a dynamic-stride kernel that costs several
// times as much at this size, which matters inside the real-time forward kinematics.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "kinematics/fast_math.hpp"
#include "hexatwist/kinematics/model.hpp"
#include "hexatwist/types.hpp"

namespace hexatwist::detail {

/// P A = L U, row-major.
struct Lu6 {
  alignas(64) double a[6][8];  ///< U on and above the diagonal (below it: unspecified); columns 6
                               ///< and 7 are zero padding
  double l[6][6];              ///< L's multipliers below the diagonal (unit diagonal implied)
  int perm[6];                 ///< row k of P A is row perm[k] of A
};

/// Factorises A. Returns min|pivot| / max|pivot| (0 if A is singular); solutions are meaningful
/// only when that ratio is well above the rounding level.
inline double lu6_factor(const Matrix6d& A, Lu6& lu) noexcept {
  auto& a = lu.a;
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 8; ++j) a[i][j] = j < 6 ? A(i, j) : 0.0;  // padding 0: whole-row updates read it
    lu.perm[i] = i;
  }
  double pivot_min = INFINITY, pivot_max = 0.0;
#pragma GCC unroll 6
  for (int k = 0; k < 6; ++k) {
    int p = k;
    for (int i = k + 1; i < 6; ++i)
      if (std::abs(a[i][k]) > std::abs(a[p][k])) p = i;
    if (p != k) {
      for (int j = k; j < 6; ++j) std::swap(a[k][j], a[p][j]);  // left of k: eliminated, unused
      for (int j = 0; j < k; ++j) std::swap(lu.l[k][j], lu.l[p][j]);  // the multipliers set so far
      std::swap(lu.perm[k], lu.perm[p]);
    }
    const double pivot = a[k][k];
    pivot_min = std::min(pivot_min, std::abs(pivot));
    pivot_max = std::max(pivot_max, std::abs(pivot));
    if (pivot == 0.0) return 0.0;
    const double inv = 1.0 / pivot;
    for (int i = k + 1; i < 6; ++i) {
      // Only the columns from k+1 on matter (the solve reads U on and above the diagonal; the
      // eliminated columns are never read again). Starting at the multiple of the vector width
      // at or below k+1 keeps the range whole vectors (one per row with AVX-512, the padding
      // columns included); with k unrolled it is constant.
      const double f = a[i][k] * inv;
      constexpr int kW = sizeof(lane_v) / sizeof(double);
      for (int j = (k + 1) / kW * kW; j < 6; j += kW) {
        lane_v ri, rk;
        std::memcpy(&ri, &a[i][j], sizeof ri);
        std::memcpy(&rk, &a[k][j], sizeof rk);
        ri -= f * rk;
        std::memcpy(&a[i][j], &ri, sizeof ri);
      }
      lu.l[i][k] = f;
    }
  }
  return pivot_min / pivot_max;
}

/// Solves A x = b with the factors of lu6_factor.
inline void lu6_solve(const Lu6& lu, const Vector6d& b, Vector6d& x) noexcept {
  const auto& a = lu.a;
  double y[6];
#pragma GCC unroll 6
  for (int k = 0; k < 6; ++k) {
    double s = b[lu.perm[k]];
    for (int j = 0; j < k; ++j) s -= lu.l[k][j] * y[j];
    y[k] = s;
  }
#pragma GCC unroll 6
  for (int k = 5; k >= 0; --k) {
    double s = y[k];
    for (int j = k + 1; j < 6; ++j) s -= a[k][j] * x[j];
    x[k] = s / a[k][k];
  }
}

/// Sign of det(A) from its factors: the product of the pivots' signs and the permutation's parity.
inline double lu6_det_sign(const Lu6& lu) noexcept {
  double sign = 1.0;
  for (int k = 0; k < 6; ++k) {
    if (lu.a[k][k] < 0.0) sign = -sign;
    for (int j = k + 1; j < 6; ++j)
      if (lu.perm[j] < lu.perm[k]) sign = -sign;  // each inversion flips the parity
  }
  return sign;
}

/// 1-norm condition number ||A||_1 ||A^-1||_1 of A = J diag(1, 1, 1, s, s, s) from the factors of
/// J (lu6_factor(J) > 0): the inverse is diag(1, 1, 1, 1/s, 1/s, 1/s) J^-1. `column_sums` are the
/// column sums of |J|.
inline double lu6_scaled_condition(const Lu6& lu, const Vector6d& column_sums, double s) noexcept {
  const double norm_a = std::max(column_sums.head<3>().maxCoeff(), s * column_sums.tail<3>().maxCoeff());
  // J^-1 = U^-1 L^-1 P a whole row at a time (rows of 8, columns 6 and 7 zero), rather than one
  // column per solve: the same operations on whole vectors, a sixth of the instructions.
  // Forward: Y = L^-1 P, row k = e_perm[k] - sum_j<k l[k][j] Y_j; back: X_k = (Y_k - sum_j>k
  // a[k][j] X_j) / a[k][k]. Then ||diag(w) X||_1 = max over columns of sum_k w_k |X_k|.
  constexpr int kW = sizeof(lane_v) / sizeof(double);
  constexpr int kP = 8 / kW;  // vectors per row
  lane_v x[6][kP];
#pragma GCC unroll 6
  for (int k = 0; k < 6; ++k) {
    double e[8] = {};
    e[lu.perm[k]] = 1.0;
    for (int q = 0; q < kP; ++q) {
      std::memcpy(&x[k][q], e + q * kW, sizeof(lane_v));
      for (int j = 0; j < k; ++j) x[k][q] -= lu.l[k][j] * x[j][q];
    }
  }
  lane_v sum[kP] = {};
#pragma GCC unroll 6
  for (int k = 5; k >= 0; --k) {
    const double inv = 1.0 / lu.a[k][k];
    const double w = k < 3 ? 1.0 : 1.0 / s;
    const lane_v zero = {};
    for (int q = 0; q < kP; ++q) {
      for (int j = k + 1; j < 6; ++j) x[k][q] -= lu.a[k][j] * x[j][q];
      x[k][q] *= inv;
      const lane_v v = x[k][q];
      sum[q] += w * (v < zero ? -v : v);
    }
  }
  double norm_inv = 0.0;
  for (int q = 0; q < kP; ++q)
    for (int c = 0; c < kW; ++c) norm_inv = std::max(norm_inv, sum[q][c]);  // padding columns are 0
  return norm_a * norm_inv;
}

/// True only if the condition number that scaled_condition(J, length) computes is proven to be at
/// most `bound`; false means "not proven" (also for a singular or non-finite J), not "above". A
/// cheap sufficient test that spares the pivoted LU and its inverse where the pose is well inside
/// the limit (docs/theory.md §8): from the model's reference Y0 ~ A^-1 (the inverse at home), the
/// residual G = I - Y0 A bounds ||A^-1||_1 <= ||Y0||_1 / (1 - ||G||_1); where that is not enough,
/// once more from Y1 = (I + G) Y0, one Newton-Schulz step.
inline bool scaled_condition_below(const Matrix6d& J, double length, const ConditionReference& ref,
                                   double bound) noexcept {
  constexpr int kW = sizeof(lane_v) / sizeof(double);
  constexpr int kP = 8 / kW;  // vectors per row
  const lane_v zero = {};
  const auto abs_v = [&](lane_v v) { return v < zero ? -v : v; };
  const auto load = [](const double* p) {
    lane_v v;
    std::memcpy(&v, p, sizeof v);
    return v;
  };
  const auto lane_max = [](const lane_v (&v)[kP]) {
    double m = 0.0;
    for (int q = 0; q < kP; ++q)
      for (int c = 0; c < kW; ++c)  // padding lanes are 0; a NaN gives inf (nothing is proven)
        if (!(v[q][c] <= m)) m = v[q][c] > m ? v[q][c] : INFINITY;
    return m;
  };
  alignas(64) static constexpr double kIdentity[6][8] = {{1, 0, 0, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, 0, 0, 0},
                                                         {0, 0, 1, 0, 0, 0, 0, 0}, {0, 0, 0, 1, 0, 0, 0, 0},
                                                         {0, 0, 0, 0, 1, 0, 0, 0}, {0, 0, 0, 0, 0, 1, 0, 0}};
  alignas(64) static constexpr double kUnit[8] = {1, 1, 1, 0, 0, 0, 0, 0};
  // A = J diag(1, 1, 1, 1/length x 3) a whole row at a time, padded with zeros.
  alignas(64) double rows[6][8];
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 8; ++c) rows[i][c] = c < 6 ? J(i, c) : 0.0;
  lane_v a[6][kP], sum_a[kP] = {};
  for (int q = 0; q < kP; ++q) {
    const lane_v first = load(kUnit + q * kW);
    const lane_v col_scale = first + (1.0 / length) * (1.0 - first);
    for (int i = 0; i < 6; ++i) {
      a[i][q] = col_scale * load(&rows[i][q * kW]);
      sum_a[q] += abs_v(a[i][q]);
    }
  }
  const double norm_a = lane_max(sum_a);
  // G = I - Y A for an approximate inverse Y (rows of 8): 1-norm of G, rounding included. Each
  // entry of G rounds by less than 8 u (|Y| |A|) (u the unit roundoff); 1e-13 ||Y||_1 ||A||_1
  // covers it a hundred times over.
  alignas(64) double g[6][8];
  const auto residual_norm = [&](const double (&y)[6][8], double norm_y) {
    lane_v sum_g[kP] = {};
#pragma GCC unroll 6
    for (int i = 0; i < 6; ++i) {
      for (int q = 0; q < kP; ++q) {
        lane_v r = load(&kIdentity[i][q * kW]);
        for (int k = 0; k < 6; ++k) r -= y[i][k] * a[k][q];
        std::memcpy(&g[i][q * kW], &r, sizeof r);
        sum_g[q] += abs_v(r);
      }
    }
    return lane_max(sum_g) + 1e-13 * norm_y * norm_a;
  };
  // A^-1 = (I - G)^-1 Y, so ||A^-1||_1 <= ||Y||_1 / (1 - ||G||_1) for ||G||_1 < 1. The products,
  // the quotient and the norms' sums round by a few u: 1e-12 of slack. The proof asks for
  // 1e-9 below the bound, so that the exact number (rounding ~1e-13 relative at a condition of 50)
  // lies below the bound too, and the verdict is the exact number's.
  const double target = bound * (1.0 - 1e-9);
  const auto proven = [&](double norm_y, double norm_g) {
    return norm_g < 1.0 && norm_a * norm_y / (1.0 - norm_g) * (1.0 + 1e-12) <= target;
  };
  const double norm_g = residual_norm(ref.inverse, ref.norm);
  if (proven(ref.norm, norm_g)) return true;
  if (!(norm_g < 2.0)) return false;  // the reference is too far (or NaN): one step would not get there
  // One Newton-Schulz step, Y1 = (I + G) Y: its residual is G^2 in exact arithmetic.
  alignas(64) double y1[6][8];
  lane_v sum_y[kP] = {};
#pragma GCC unroll 6
  for (int i = 0; i < 6; ++i) {
    for (int q = 0; q < kP; ++q) {
      lane_v r = load(&ref.inverse[i][q * kW]);
      for (int k = 0; k < 6; ++k) r += g[i][k] * load(&ref.inverse[k][q * kW]);
      std::memcpy(&y1[i][q * kW], &r, sizeof r);
      sum_y[q] += abs_v(r);
    }
  }
  const double norm_y1 = lane_max(sum_y);
  return proven(norm_y1, residual_norm(y1, norm_y1));
}

/// Condition number of a platform Jacobian J [-, m] (rows [s_i, arm_i x s_i] or the motor-side
/// ones) with its rotation columns divided by `length` [m], by lu6_scaled_condition; `det_sign`
/// gets the sign of det J. An exactly singular J gives inf and sign 0.
inline double scaled_condition(const Matrix6d& J, double length, double& det_sign) noexcept {
  Lu6 lu;
  if (!(lu6_factor(J, lu) > 0.0)) {
    det_sign = 0.0;
    return INFINITY;
  }
  det_sign = lu6_det_sign(lu);
  return lu6_scaled_condition(lu, J.cwiseAbs().colwise().sum().transpose(), 1.0 / length);
}

}  // namespace hexatwist::detail
