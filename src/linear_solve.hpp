// Internal: LU factorisation of a 6x6 matrix with partial pivoting, unrolled at fixed size, and
// the matching solve. Eigen's PartialPivLU goes through a dynamic-stride kernel that costs several
// times as much at this size, which matters inside the real-time forward kinematics.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "fast_math.hpp"
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
/// J (lu6_factor(J) > 0): the inverse is diag(1, 1, 1, 1/s, 1/s, 1/s) J^-1, one column per solve.
/// `column_sums` are the column sums of |J|.
inline double lu6_scaled_condition(const Lu6& lu, const Vector6d& column_sums, double s) noexcept {
  const double norm_a = std::max(column_sums.head<3>().maxCoeff(), s * column_sums.tail<3>().maxCoeff());
  double norm_inv = 0.0;
  Vector6d e, x;
#pragma GCC unroll 6
  for (int j = 0; j < 6; ++j) {
    e.setZero();
    e[j] = 1.0;
    lu6_solve(lu, e, x);
    norm_inv = std::max(norm_inv, x.head<3>().cwiseAbs().sum() + x.tail<3>().cwiseAbs().sum() / s);
  }
  return norm_a * norm_inv;
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
