// Internal: solve a 6x6 linear system by Gaussian elimination with partial pivoting, unrolled at
// fixed size. Eigen's PartialPivLU goes through a dynamic-stride kernel that costs about five
// times as much at this size, which matters inside the real-time forward kinematics.
#pragma once

#include <cmath>
#include <utility>

#include "hexatwist/types.hpp"

namespace hexatwist::detail {

/// Solves A x = b. Returns min|pivot| / max|pivot| (0 for a singular A); x is meaningful only when
/// that ratio is well above the rounding level.
inline double solve6(Matrix6d A, Vector6d b, Vector6d& x) noexcept {
  double pivot_min = INFINITY, pivot_max = 0.0;
  for (int k = 0; k < 6; ++k) {
    int p = k;
    for (int i = k + 1; i < 6; ++i)
      if (std::abs(A(i, k)) > std::abs(A(p, k))) p = i;
    if (p != k) {
      A.row(k).swap(A.row(p));
      std::swap(b[k], b[p]);
    }
    const double pivot = A(k, k);
    pivot_min = std::min(pivot_min, std::abs(pivot));
    pivot_max = std::max(pivot_max, std::abs(pivot));
    if (pivot == 0.0) return 0.0;
    const double inv = 1.0 / pivot;
    for (int i = k + 1; i < 6; ++i) {
      const double f = A(i, k) * inv;
      for (int j = k + 1; j < 6; ++j) A(i, j) -= f * A(k, j);
      b[i] -= f * b[k];
    }
  }
  for (int k = 5; k >= 0; --k) {
    double s = b[k];
    for (int j = k + 1; j < 6; ++j) s -= A(k, j) * x[j];
    x[k] = s / A(k, k);
  }
  return pivot_max > 0.0 ? pivot_min / pivot_max : 0.0;
}

}  // namespace hexatwist::detail
