// SPDX-License-Identifier: BSD-3-Clause
// Internal: the inverse of a 6x6 matrix by Gauss-Jordan elimination with partial pivoting, on the
// matrix's columns as lanes.hpp's packets (lane i of column c: entry (i, c)), which is how the
// forward kinematics forms its Jacobian. Row operations on all rows at once are one multiply-add
// per column per pivot; the pivoted rows are not moved (the permutation is kept instead). Where
// the forward kinematics used a pivoted LU, a solve and the LU's inverse for the condition, one
// elimination now gives the step, the condition number and the sign of the determinant.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>

#include "kinematics/lanes.hpp"

#if HEXATWIST_LANE_WIDTH == 8
#include <immintrin.h>
#endif

namespace hexatwist::detail {

/// A 6x6 matrix as columns of packets: column c, packet k holds rows k*kWidth ... (padding rows,
/// past 5, are ignored).
struct Columns {
  lane_v c[6][kPackets];
};

/// The row operations X that take J to a permutation: X J = Q with Q(pivot_row[k], k) = 1, so that
/// row k of J^-1 = Q^T X is row pivot_row[k] of X.
struct Inverse6 {
  Columns x;           ///< X's columns in pivot order: x.c[k] is column pivot_row[k]
  int pivot_row[6];    ///< the row that column k's pivot was taken from
  double pivot_ratio;  ///< min |pivot| / max |pivot|: 0 for a singular (or non-finite) matrix
  double det_sign;     ///< sign of det J (0 when singular)
};

namespace gj {

inline lane_v lane_index(int k) noexcept {
  lane_v v;
  for (int i = 0; i < kWidth; ++i) v[i] = k * kWidth + i;
  return v;
}

/// Entry (p, c) of the matrix, on every lane.
inline lane_v broadcast_row(const lane_v (&col)[kPackets], int p) noexcept {
#if HEXATWIST_LANE_WIDTH == 8
  return reinterpret_cast<lane_v>(_mm512_permutexvar_pd(_mm512_set1_epi64(p), reinterpret_cast<__m512d>(col[0])));
#else
  return splat<lane_v>(col[p / kWidth][p % kWidth]);
#endif
}

/// The pivot of a column: the first available row (bit i of `available`) with the largest
/// |entry|; a NaN is never chosen. Returns the row, or -1 if no entry is finite and nonzero;
/// `pivot` gets the entry. (Branch-free and vector searches were measured: slower, as their
/// loads or shuffles sit on the chain from pivot to pivot, where these branches are predicted.)
inline int select_pivot(const lane_v (&col)[kPackets], unsigned available, double& pivot) noexcept {
  alignas(64) double column[kPackets * kWidth];
  std::memcpy(column, col, sizeof column);
  int p = -1;
  double best = 0.0;
  for (int i = 0; i < 6; ++i) {
    const double v = std::abs(column[i]);
    if (((available >> i) & 1u) != 0 && v > best) {
      best = v;
      p = i;
    }
  }
  if (p < 0 || !(best < INFINITY)) return -1;
  pivot = column[p];
  return p;
}

}  // namespace gj

namespace gj {

/// The elimination. False if a pivot is zero or not finite (singular).
inline bool eliminate(const Columns& J, Inverse6& out) noexcept {
  Columns a;
  unsigned available = 0x3f;  // rows not yet pivoted
  double pivot_min = INFINITY, pivot_max = 0.0, sign = 1.0;
  lane_v row[kPackets];
  for (int k = 0; k < kPackets; ++k) {
    row[k] = lane_index(k);
    // Padding rows to zero, so that they never overflow.
    const lane_v real = blend(row[k] < 6.0, splat<lane_v>(1.0), splat<lane_v>(0.0));
    for (int c = 0; c < 6; ++c) a.c[c][k] = J.c[c][k] * real;
  }
  // X starts as the identity. A row operation with pivot row p changes only the columns of X whose
  // entry in row p is nonzero: those of the rows pivoted so far, and column p, still e_p. So column
  // p_k of X is born at step k, and only the k older ones are updated then (21 column updates, not 36).
#pragma GCC unroll 6
  for (int k = 0; k < 6; ++k) {
    double pivot;
    const int p = select_pivot(a.c[k], available, pivot);  // the available row with the largest |a(i, k)|
    if (p < 0) return false;
    available &= ~(1u << p);
    out.pivot_row[k] = p;
    pivot_min = std::min(pivot_min, std::abs(pivot));
    pivot_max = std::max(pivot_max, std::abs(pivot));
    if (pivot < 0.0) sign = -sign;
    const double inv = 1.0 / pivot;
    // Row p /= pivot, every other row i -= a(i, k) * (new row p): on each column,
    // col -= m * col(p) with m(i) = a(i, k) / pivot and m(p) = 1 - 1 / pivot.
    lane_v m[kPackets];
    for (int q = 0; q < kPackets; ++q)
      m[q] = blend(row[q] == static_cast<double>(p), splat<lane_v>(1.0 - inv), a.c[k][q] * inv);
    for (int c = k + 1; c < 6; ++c) {
      const lane_v b = broadcast_row(a.c[c], p);
      for (int q = 0; q < kPackets; ++q) a.c[c][q] -= m[q] * b;
    }
    for (int j = 0; j < k; ++j) {
      const lane_v b = broadcast_row(out.x.c[j], p);
      for (int q = 0; q < kPackets; ++q) out.x.c[j][q] -= m[q] * b;
    }
    for (int q = 0; q < kPackets; ++q)
      out.x.c[k][q] =
          blend(row[q] == static_cast<double>(p), splat<lane_v>(1.0), splat<lane_v>(0.0)) - m[q];  // e_p - m
  }
  for (int k = 0; k < 6; ++k)
    for (int j = k + 1; j < 6; ++j)
      if (out.pivot_row[j] < out.pivot_row[k]) sign = -sign;  // each inversion flips the parity
  out.det_sign = sign;
  out.pivot_ratio = pivot_min / pivot_max;
  return true;
}

}  // namespace gj

/// Solves M x = b by the same elimination with b as a seventh column and no X: 21 column updates
/// where the inverse takes 36. Returns min |pivot| / max |pivot| (0, x unspecified, when M is
/// singular or not finite), as gauss_jordan.
inline double gj_solve_system(const Columns& M, const Vector6d& b, Vector6d& x) noexcept {
  Columns a;
  lane_v rhs[kPackets], row[kPackets];
  alignas(64) double padded_b[kPackets * kWidth] = {};
  for (int i = 0; i < 6; ++i) padded_b[i] = b[i];
  std::memcpy(rhs, padded_b, sizeof rhs);
  for (int k = 0; k < kPackets; ++k) {
    row[k] = gj::lane_index(k);
    const lane_v real = blend(row[k] < 6.0, splat<lane_v>(1.0), splat<lane_v>(0.0));
    for (int c = 0; c < 6; ++c) a.c[c][k] = M.c[c][k] * real;
  }
  unsigned available = 0x3f;
  int pivot_row[6];
  double pivot_min = INFINITY, pivot_max = 0.0;
#pragma GCC unroll 6
  for (int k = 0; k < 6; ++k) {
    double pivot;
    const int p = gj::select_pivot(a.c[k], available, pivot);
    if (p < 0) return 0.0;
    available &= ~(1u << p);
    pivot_row[k] = p;
    pivot_min = std::min(pivot_min, std::abs(pivot));
    pivot_max = std::max(pivot_max, std::abs(pivot));
    const double inv = 1.0 / pivot;
    // Row p /= pivot, every other row i -= a(i, k) * (new row p), as gj::eliminate.
    lane_v m[kPackets];
    for (int q = 0; q < kPackets; ++q)
      m[q] = blend(row[q] == static_cast<double>(p), splat<lane_v>(1.0 - inv), a.c[k][q] * inv);
    for (int c = k + 1; c < 6; ++c) {
      const lane_v v = gj::broadcast_row(a.c[c], p);
      for (int q = 0; q < kPackets; ++q) a.c[c][q] -= m[q] * v;
    }
    const lane_v v = gj::broadcast_row(rhs, p);
    for (int q = 0; q < kPackets; ++q) rhs[q] -= m[q] * v;
  }
  // Column k of the reduced matrix is e_{pivot_row[k]}: x_k is that row of the right side.
  std::memcpy(padded_b, rhs, sizeof rhs);
  for (int k = 0; k < 6; ++k) x[k] = padded_b[pivot_row[k]];
  return pivot_min / pivot_max;
}

/// Inverts J (columns; not modified). Returns out.pivot_ratio, min |pivot| / max |pivot|; when it
/// is 0 (singular or not finite) the rest of `out` is unspecified. The pivots are those of LU with
/// partial pivoting (lu6_factor), so the ratio means the same as lu6_factor's. (Taking the pivot
/// rows of the previous Newton step's elimination, checked by threshold pivoting, was measured:
/// no faster, as the search's branches are predicted.)
inline double gauss_jordan(const Columns& J, Inverse6& out) noexcept {
  if (gj::eliminate(J, out)) return out.pivot_ratio;
  out.pivot_ratio = 0.0;
  out.det_sign = 0.0;
  return 0.0;
}

/// x = J^-1 b from gauss_jordan's result.
inline void gj_solve(const Inverse6& inv, const Vector6d& b, Vector6d& x) noexcept {
  lane_v v[kPackets] = {};
  for (int k = 0; k < 6; ++k)
    for (int q = 0; q < kPackets; ++q) v[q] += inv.x.c[k][q] * b[inv.pivot_row[k]];
  alignas(64) double r[kPackets * kWidth];
  std::memcpy(r, v, sizeof v);
  for (int k = 0; k < 6; ++k) x[k] = r[inv.pivot_row[k]];
}

/// The largest column sum of |M|, rows 0-5 (the 1-norm of M).
inline double norm1(const Columns& m) noexcept {
  lane_v v[6][kPackets];
  for (int c = 0; c < 6; ++c)
    for (int k = 0; k < kPackets; ++k)
      v[c][k] = blend(gj::lane_index(k) < 6.0, vabs(m.c[c][k]), splat<lane_v>(0.0));  // padding rows out
#if HEXATWIST_LANE_WIDTH == 8
  // The six sums at once, by a tree of shuffles that adds neighbours, then pairs, then quads: lane c
  // of the result is the sum of column c (a transpose and row sums would take twice the shuffles).
  const v8d zero = {};
#define HEXATWIST_FOLD(a, b, i0, i1, i2, i3, i4, i5, i6, i7, j0, j1, j2, j3, j4, j5, j6, j7) \
  (__builtin_shufflevector(a, b, i0, i1, i2, i3, i4, i5, i6, i7) +                           \
   __builtin_shufflevector(a, b, j0, j1, j2, j3, j4, j5, j6, j7))
  const v8d p0 = HEXATWIST_FOLD(v[0][0], v[1][0], 0, 8, 2, 10, 4, 12, 6, 14, 1, 9, 3, 11, 5, 13, 7, 15);
  const v8d p1 = HEXATWIST_FOLD(v[2][0], v[3][0], 0, 8, 2, 10, 4, 12, 6, 14, 1, 9, 3, 11, 5, 13, 7, 15);
  const v8d p2 = HEXATWIST_FOLD(v[4][0], v[5][0], 0, 8, 2, 10, 4, 12, 6, 14, 1, 9, 3, 11, 5, 13, 7, 15);
  const v8d q0 = HEXATWIST_FOLD(p0, p1, 0, 1, 8, 9, 4, 5, 12, 13, 2, 3, 10, 11, 6, 7, 14, 15);
  const v8d q1 = HEXATWIST_FOLD(p2, zero, 0, 1, 8, 9, 4, 5, 12, 13, 2, 3, 10, 11, 6, 7, 14, 15);
  const lane_v sums[1] = {HEXATWIST_FOLD(q0, q1, 0, 1, 2, 3, 8, 9, 10, 11, 4, 5, 6, 7, 12, 13, 14, 15)};
#undef HEXATWIST_FOLD
#else
  ColumnPackets packets;
  for (int k = 0; k < kPackets; ++k) {
    lane_v col[6];
    for (int c = 0; c < 6; ++c) col[c] = v[c][k];
    packets.set(k, col);
  }
  PaddedRows rows;
  packets.rows(rows);  // row i of the transpose: column i's entries
  lane_v sums[kRowVectors];
  for (int q = 0; q < kRowVectors; ++q)
    sums[q] = ((rows[0][q] + rows[1][q]) + (rows[2][q] + rows[3][q])) + (rows[4][q] + rows[5][q]);
#endif
  return max_lane(sums);
}

/// The 1-norm condition number ||A||_1 ||A^-1||_1 from A and gauss_jordan's result (the rows of
/// X are those of A^-1, permuted, which leaves the column sums alone).
inline double gj_condition(const Columns& A, const Inverse6& inv) noexcept { return norm1(A) * norm1(inv.x); }

}  // namespace hexatwist::detail
