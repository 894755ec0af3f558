// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/registration.hpp"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

namespace hexatwist {

namespace {

// A point set whose rms distance from its centroid is below this fraction of its largest
// coordinate norm is taken as coincident: its centred coordinates would keep fewer than about
// seven significant digits (rounding of 2.2e-16 against 1e-9), too few to define a direction.
constexpr double kCoincidentRatio = 1e-9;

struct Svd3 {
  Matrix3d U, V;  // H = U diag(h) Vᵀ
  Vector3d h;     // singular values, descending
};

// GCC 12 cannot see that the caller has checked H to be finite, and warns that the SVD's early
// return for non-finite input would leave the singular values unset.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
Svd3 svd3(const Matrix3d& H) noexcept {
  const Eigen::JacobiSVD<Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return {svd.matrixU(), svd.matrixV(), svd.singularValues()};
}
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

}  // namespace

Vector3d apply(const RigidTransform& X_AB, const Vector3d& p_B) noexcept { return X_AB.R * p_B + X_AB.t; }

RigidTransform compose(const RigidTransform& X_AB, const RigidTransform& X_BC) noexcept {
  return {X_AB.R * X_BC.R, X_AB.R * X_BC.t + X_AB.t};
}

RigidTransform inverse(const RigidTransform& X_AB) noexcept {
  const Matrix3d R_BA = X_AB.R.transpose();
  return {R_BA, -(R_BA * X_AB.t)};
}

Status register_points(std::span<const PointPair> pairs, Registration& out,
                       const RegistrationOptions& options) noexcept {
  out = Registration{};
  const std::size_t n = pairs.size();
  out.count = static_cast<int>(n);
  if (n < 3) return Status::TooFewPoints;
  for (const PointPair& pair : pairs) {
    if (!pair.p_T.allFinite() || !pair.p_B.allFinite()) return Status::NonFiniteInput;
  }
  const double inv_n = 1.0 / static_cast<double>(n);

  // Centroids first, then the cross-covariance of the centred points (two passes: a tracker
  // several metres away would otherwise cancel digits in Σ p pᵀ − N c cᵀ).
  Vector3d c_T = Vector3d::Zero(), c_B = Vector3d::Zero();
  for (const PointPair& pair : pairs) {
    c_T += pair.p_T;
    c_B += pair.p_B;
  }
  c_T *= inv_n;
  c_B *= inv_n;
  Matrix3d H = Matrix3d::Zero();
  double spread2_T = 0.0, spread2_B = 0.0, scale_T = 0.0, scale_B = 0.0;
  for (const PointPair& pair : pairs) {
    const Vector3d a = pair.p_T - c_T, b = pair.p_B - c_B;
    H.noalias() += a * b.transpose();
    spread2_T += a.squaredNorm();
    spread2_B += b.squaredNorm();
    scale_T = std::max(scale_T, pair.p_T.norm());
    scale_B = std::max(scale_B, pair.p_B.norm());
  }
  H *= inv_n;
  // Coordinates so large that their squares overflow.
  if (!H.allFinite() || !std::isfinite(spread2_T) || !std::isfinite(spread2_B)) return Status::NonFiniteInput;

  // H = U S Vᵀ; the best orthogonal R maximises tr(R H): R = V Uᵀ. If that is a reflection,
  // the best proper rotation flips the direction of the smallest singular value (Umeyama 1991).
  const Svd3 svd = svd3(H);
  const Matrix3d& U = svd.U;
  const Matrix3d& V = svd.V;
  const Vector3d& h = svd.h;
  const double d = (V.determinant() * U.determinant() < 0.0) ? -1.0 : 1.0;
  out.singular_values = h;
  out.reflection = d < 0.0;

  // The rotation Hessian at the optimum has eigenvalues g_j + g_k with g = (h1, h2, d h3)
  // (theory §11); their ratio says how well the points pin the rotation about each axis.
  const double weakest = h[1] + d * h[2], strongest = h[0] + h[1];
  out.condition = weakest > 0.0 ? strongest / weakest : std::numeric_limits<double>::infinity();

  const bool coincident = spread2_T * inv_n <= (kCoincidentRatio * scale_T) * (kCoincidentRatio * scale_T) ||
                          spread2_B * inv_n <= (kCoincidentRatio * scale_B) * (kCoincidentRatio * scale_B);
  if (coincident || !(out.condition <= options.max_condition)) return Status::DegenerateRegistration;

  Matrix3d R = V;
  R.col(2) *= d;
  R = R * U.transpose();
  out.X_BT = {R, c_B - R * c_T};

  // Residuals straight from the points, not from Σ|a|² + Σ|b|² − 2 tr(D S), which cancels.
  double sum2 = 0.0;
  out.max_residual = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const double e2 = (apply(out.X_BT, pairs[k].p_T) - pairs[k].p_B).squaredNorm();
    sum2 += e2;
    if (e2 > out.max_residual * out.max_residual || out.max_residual_index < 0) {
      out.max_residual = std::sqrt(e2);
      out.max_residual_index = static_cast<int>(k);
    }
  }
  out.rms_residual = std::sqrt(sum2 * inv_n);
  out.sigma = std::sqrt(sum2 / static_cast<double>(3 * n - 6));
  return Status::Ok;
}

std::string shape_misfit(std::span<const PointPair> pairs, const Registration& registration, double max_misfit) {
  Vector3d mean = Vector3d::Zero();
  for (const PointPair& p : pairs) mean += p.p_B;
  if (pairs.empty()) return {};
  mean /= static_cast<double>(pairs.size());
  double sum = 0.0;
  for (const PointPair& p : pairs) sum += (p.p_B - mean).squaredNorm();
  const double spread = std::sqrt(sum / static_cast<double>(pairs.size()));
  if (registration.rms_residual <= max_misfit * spread) return {};
  return fmt::format(
      "the log's points do not have the run's shape: the registration leaves {:.4g} mm rms over points that spread "
      "{:.4g} mm rms (more than {:g} %): a log in other units than its header says (metres labelled _mm?), another "
      "run's log, or another time offset",
      1e3 * registration.rms_residual, 1e3 * spread, 100.0 * max_misfit);
}

}  // namespace hexatwist
