// SPDX-License-Identifier: BSD-3-Clause
// Internal: LU factorisation of a 6x6 matrix with partial pivoting, unrolled at fixed size, and
// the matching solve. Eigen's PartialPivLU goes through a dynamic-stride kernel that costs several
// times as much at this size, which matters inside the real-time forward kinematics.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "hexatwist/kinematics/model.hpp"
#include "hexatwist/types.hpp"
#include "kinematics/fast_math.hpp"

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
      for (int j = k; j < 6; ++j) std::swap(a[k][j], a[p][j]);        // left of k: eliminated, unused
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
    for (int q = 0; q < kP; ++q) {
      for (int j = k + 1; j < 6; ++j) x[k][q] -= lu.a[k][j] * x[j][q];
      x[k][q] *= inv;
      const lane_v v = x[k][q];
      sum[q] += w * vabs(v);
    }
  }
  double norm_inv = 0.0;
  for (int q = 0; q < kP; ++q)
    for (int c = 0; c < kW; ++c) norm_inv = std::max(norm_inv, sum[q][c]);  // padding columns are 0
  return norm_a * norm_inv;
}

/// Vectors per row of eight doubles (six entries and two zeros of padding).
inline constexpr int kRowVectors = 8 * sizeof(double) / sizeof(lane_v);
/// The rows of a 6x6 matrix, each padded with zeros to eight doubles.
using PaddedRows = lane_v[6][kRowVectors];

/// The padded rows of J from its column-major storage.
inline void padded_rows(const Matrix6d& J, PaddedRows& rows) noexcept {
  alignas(64) double r[6][8];
  for (int i = 0; i < 6; ++i)
    for (int c = 0; c < 8; ++c) r[i][c] = c < 6 ? J(i, c) : 0.0;
  std::memcpy(rows, r, sizeof r);
}

#if HEXATWIST_LANE_WIDTH == 8
/// The padded rows of a matrix from its six columns, each one eight-lane vector whose lanes 0-5 are
/// the column (lanes 6 and 7 are dropped): an 8x8 transpose in registers, three rounds of
/// shuffles, where the copy through memory stalled on store forwarding.
inline void padded_rows(const v8d (&cols)[6], PaddedRows& rows) noexcept {
  const v8d zero = {};
  const auto pairs = [](v8d a, v8d b, v8d& even, v8d& odd) {
    even = __builtin_shufflevector(a, b, 0, 8, 2, 10, 4, 12, 6, 14);
    odd = __builtin_shufflevector(a, b, 1, 9, 3, 11, 5, 13, 7, 15);
  };
  const auto quads = [](v8d a, v8d b, v8d& low, v8d& high) {
    low = __builtin_shufflevector(a, b, 0, 1, 8, 9, 4, 5, 12, 13);
    high = __builtin_shufflevector(a, b, 2, 3, 10, 11, 6, 7, 14, 15);
  };
  v8d t0, t1, t2, t3, t4, t5, u0, u1, u2, u3, u4, u5, u6, u7;
  pairs(cols[0], cols[1], t0, t1);  // t0: lanes 0, 2, 4, 6 of columns 0 and 1; t1: lanes 1, 3, 5, 7
  pairs(cols[2], cols[3], t2, t3);
  pairs(cols[4], cols[5], t4, t5);
  quads(t0, t2, u0, u2);  // u0: lanes 0 and 4 of columns 0-3; u2: lanes 2 and 6
  quads(t1, t3, u1, u3);
  quads(t4, zero, u4, u6);  // columns 4, 5 and the zero padding columns
  quads(t5, zero, u5, u7);
  rows[0][0] = __builtin_shufflevector(u0, u4, 0, 1, 2, 3, 8, 9, 10, 11);
  rows[1][0] = __builtin_shufflevector(u1, u5, 0, 1, 2, 3, 8, 9, 10, 11);
  rows[2][0] = __builtin_shufflevector(u2, u6, 0, 1, 2, 3, 8, 9, 10, 11);
  rows[3][0] = __builtin_shufflevector(u3, u7, 0, 1, 2, 3, 8, 9, 10, 11);
  rows[4][0] = __builtin_shufflevector(u0, u4, 4, 5, 6, 7, 12, 13, 14, 15);
  rows[5][0] = __builtin_shufflevector(u1, u5, 4, 5, 6, 7, 12, 13, 14, 15);
}
#endif

/// The largest lane of v[0..kRowVectors), or inf if a lane is NaN.
inline double max_lane(const lane_v (&v)[kRowVectors]) noexcept {
  lane_v m = v[0];
  for (int q = 1; q < kRowVectors; ++q) m = m > v[q] ? m : v[q];
  const lane_v inf = splat<lane_v>(INFINITY);
  for (int q = 0; q < kRowVectors; ++q) m = v[q] == v[q] ? m : inf;  // NaN anywhere: inf
#if HEXATWIST_LANE_WIDTH == 8
  const v4d m4 = __builtin_shufflevector(m, m, 0, 1, 2, 3) > __builtin_shufflevector(m, m, 4, 5, 6, 7)
                     ? __builtin_shufflevector(m, m, 0, 1, 2, 3)
                     : __builtin_shufflevector(m, m, 4, 5, 6, 7);
  const v2d m2 = __builtin_shufflevector(m4, m4, 0, 1) > __builtin_shufflevector(m4, m4, 2, 3)
                     ? __builtin_shufflevector(m4, m4, 0, 1)
                     : __builtin_shufflevector(m4, m4, 2, 3);
#elif HEXATWIST_LANE_WIDTH == 4
  const v2d m2 = __builtin_shufflevector(m, m, 0, 1) > __builtin_shufflevector(m, m, 2, 3)
                     ? __builtin_shufflevector(m, m, 0, 1)
                     : __builtin_shufflevector(m, m, 2, 3);
#else
  const v2d m2 = m;
#endif
  return m2[0] > m2[1] ? m2[0] : m2[1];
}

/// True only if the 1-norm condition number of A = J diag(1, 1, 1, 1/length x 3), the number that
/// scaled_condition(J, length) computes, is proven to be at most `bound`; false means "not
/// proven" (also for a singular or non-finite A), not "above". A
/// cheap sufficient test that spares the pivoted LU and its inverse where the pose is well inside
/// the limit (docs/theory.md §8): from the model's reference Y0 ~ A^-1 (the inverse at home), the
/// residual G = I - Y0 A bounds ||A^-1||_1 <= ||Y0||_1 / (1 - ||G||_1); where that is not enough,
/// once more from Y1 = (I + G) Y0, one Newton-Schulz step. A comes as its padded rows. With
/// `perturbation` = p > 0 the proof is for every matrix within p of A in the 1-norm (A + E with
/// ||E||_1 <= p: ||I - Y (A + E)||_1 <= ||G||_1 + ||Y||_1 p and ||A + E||_1 <= ||A||_1 + p); the
/// command proves the motor-side Jacobian from the geometric one and a bound on the twist's share.
inline bool condition_below(const PaddedRows& a, const ConditionReference& ref, double bound,
                            double perturbation = 0.0) noexcept {
  constexpr int kW = sizeof(lane_v) / sizeof(double);
  constexpr int kP = kRowVectors;
  const lane_v zero = {};
  const auto load = [](const double* p) {
    lane_v v;
    std::memcpy(&v, p, sizeof v);
    return v;
  };
  alignas(64) static constexpr double kIdentity[6][8] = {{1, 0, 0, 0, 0, 0, 0, 0}, {0, 1, 0, 0, 0, 0, 0, 0},
                                                         {0, 0, 1, 0, 0, 0, 0, 0}, {0, 0, 0, 1, 0, 0, 0, 0},
                                                         {0, 0, 0, 0, 1, 0, 0, 0}, {0, 0, 0, 0, 0, 1, 0, 0}};
  if (!(perturbation < INFINITY)) return false;  // also NaN
  // ||A||_1 without a NaN test of its own: a NaN in A reaches every column of G below.
  lane_v sum_a[kP];
  for (int q = 0; q < kP; ++q)
    sum_a[q] = (vabs(a[0][q]) + vabs(a[1][q])) + (vabs(a[2][q]) + vabs(a[3][q])) + (vabs(a[4][q]) + vabs(a[5][q]));
  const double norm_a = max_lane(sum_a) + perturbation;
  // G = I - Y A for an approximate inverse Y (rows of 8): 1-norm of G, rounding included. Each
  // entry of G rounds by less than 8 u (|Y| |A|) (u the unit roundoff); 1e-13 ||Y||_1 ||A||_1
  // covers it a hundred times over.
  alignas(64) double g[6][8];
  const auto residual_norm = [&](const double(&y)[6][8], double norm_y) {
    lane_v abs_g[6][kP];
#pragma GCC unroll 6
    for (int i = 0; i < 6; ++i) {
      for (int q = 0; q < kP; ++q) {
        // Two chains of three products, then their sum: half the latency of one chain of six.
        lane_v r0 = load(&kIdentity[i][q * kW]), r1 = zero;
        for (int k = 0; k < 3; ++k) r0 -= y[i][k] * a[k][q];
        for (int k = 3; k < 6; ++k) r1 -= y[i][k] * a[k][q];
        const lane_v r = r0 + r1;
        std::memcpy(&g[i][q * kW], &r, sizeof r);
        abs_g[i][q] = vabs(r);
      }
    }
    lane_v sum_g[kP];
    for (int q = 0; q < kP; ++q)
      sum_g[q] = (abs_g[0][q] + abs_g[1][q]) + (abs_g[2][q] + abs_g[3][q]) + (abs_g[4][q] + abs_g[5][q]);
    return max_lane(sum_g) + norm_y * perturbation + 1e-13 * norm_y * norm_a;
  };
  // A^-1 = (I - G)^-1 Y, so ||A^-1||_1 <= ||Y||_1 / (1 - ||G||_1) for ||G||_1 < 1. The products,
  // 1 - ||G||_1 and the norms' sums round by a few u: 1e-12 of slack. The proof asks for
  // 1e-9 below the bound, so that the exact number (rounding ~1e-13 relative at a condition of 50)
  // lies below the bound too, and the verdict is the exact number's.
  const double target = bound * (1.0 - 1e-9);
  const auto proven = [&](double norm_y, double norm_g) {
    // norm_a norm_y / (1 - norm_g) <= target, multiplied out (no division on the critical path).
    return norm_g < 1.0 && norm_a * norm_y * (1.0 + 1e-12) <= target * (1.0 - norm_g);
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
      sum_y[q] += vabs(r);
    }
  }
  const double norm_y1 = max_lane(sum_y);
  return proven(norm_y1, residual_norm(y1, norm_y1));
}

/// The largest of six columns per lane, inf where one is NaN (max_lane, lane by lane).
inline lane_v column_max(const lane_v (&v)[6]) noexcept {
  lane_v m = v[0];
  for (int c = 1; c < 6; ++c) m = m > v[c] ? m : v[c];
  const lane_v inf = splat<lane_v>(INFINITY);
  for (int c = 0; c < 6; ++c) m = v[c] == v[c] ? m : inf;
  return m;
}

/// condition_below for a 6x6 matrix per lane (lane p: the matrix of pose p of a batch, a[row][column])
/// with a perturbation per lane: the same operations in the same order on each lane's numbers, so
/// that each lane's verdict is condition_below's for that matrix. Lanes outside `todo` come out
/// false.
inline mask_of<lane_v> condition_below_lanes(const lane_v (&a)[6][6], const ConditionReference& ref, double bound,
                                             lane_v perturbation, mask_of<lane_v> todo) noexcept {
  using lane_m = mask_of<lane_v>;
  constexpr int kW = sizeof(lane_v) / sizeof(double);
  todo &= perturbation < INFINITY;  // also NaN
  lane_v sum_a[6];
  for (int c = 0; c < 6; ++c)
    sum_a[c] = (vabs(a[0][c]) + vabs(a[1][c])) + (vabs(a[2][c]) + vabs(a[3][c])) + (vabs(a[4][c]) + vabs(a[5][c]));
  const lane_v norm_a = column_max(sum_a) + perturbation;
  lane_v g[6][6];
  const auto residual_norm = [&](const auto& y, auto norm_y) {
    lane_v sum_g[6];
    for (int i = 0; i < 6; ++i) {
      for (int c = 0; c < 6; ++c) {
        lane_v r0 = splat<lane_v>(i == c ? 1.0 : 0.0), r1 = {};
        for (int k = 0; k < 3; ++k) r0 -= y(i, k) * a[k][c];
        for (int k = 3; k < 6; ++k) r1 -= y(i, k) * a[k][c];
        g[i][c] = r0 + r1;
      }
    }
    for (int c = 0; c < 6; ++c)
      sum_g[c] = (vabs(g[0][c]) + vabs(g[1][c])) + (vabs(g[2][c]) + vabs(g[3][c])) + (vabs(g[4][c]) + vabs(g[5][c]));
    return column_max(sum_g) + norm_y * perturbation + 1e-13 * norm_y * norm_a;
  };
  const double target = bound * (1.0 - 1e-9);
  const auto proven = [&](auto norm_y, lane_v norm_g) {
    return (norm_g < 1.0) & (norm_a * norm_y * (1.0 + 1e-12) <= target * (1.0 - norm_g));
  };
  const lane_v norm_g = residual_norm([&](int i, int k) { return ref.inverse[i][k]; }, ref.norm);
  lane_m result = todo & proven(ref.norm, norm_g);
  const lane_m step = todo & ~result & (norm_g < 2.0);
  bool any_step = false;
  for (int p = 0; p < kW; ++p) any_step |= step[p] != 0;
  if (!any_step) return result;
  // One Newton-Schulz step, Y1 = (I + G) Y0.
  lane_v y1[6][6], sum_y[6] = {};
  for (int i = 0; i < 6; ++i) {
    for (int c = 0; c < 6; ++c) {
      lane_v r = splat<lane_v>(ref.inverse[i][c]);
      for (int k = 0; k < 6; ++k) r += g[i][k] * ref.inverse[k][c];
      y1[i][c] = r;
      sum_y[c] += vabs(r);
    }
  }
  const lane_v norm_y1 = column_max(sum_y);
  const lane_v norm_g1 = residual_norm([&](int i, int k) { return y1[i][k]; }, norm_y1);
  return result | (step & proven(norm_y1, norm_g1));
}

/// condition_below for A = J diag(1, 1, 1, 1/length x 3), J in its column-major storage.
inline bool scaled_condition_below(const Matrix6d& J, double length, const ConditionReference& ref, double bound,
                                   double perturbation = 0.0) noexcept {
  Matrix6d A = J;
  A.rightCols<3>() *= 1.0 / length;
  PaddedRows a;
  padded_rows(A, a);
  return condition_below(a, ref, bound, perturbation);
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
