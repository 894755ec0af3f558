// SPDX-License-Identifier: BSD-3-Clause
// Rigid registration of corresponding point sets (Kabsch 1976, Umeyama 1991): the rotation and
// translation that best map points measured in one frame (a laser tracker's, T) onto the same
// points known in another (the base frame B), with the fit residual and a degeneracy check.
// Theory: docs/theory.md §11.
#pragma once

#include <limits>
#include <span>
#include <string>

#include "hexatwist/status.hpp"
#include "hexatwist/types.hpp"

namespace hexatwist {

/// Rigid transform X_AB of frame B in frame A: a point p_B is at p_A = R·p_B + t.
struct RigidTransform {
  Matrix3d R = Matrix3d::Identity();  ///< orientation of B in A (R_AB)
  Vector3d t = Vector3d::Zero();      ///< origin of B in A [m, A]
};

/// p_A = X_AB·p_B for a point p_B [m, B].
Vector3d apply(const RigidTransform& X_AB, const Vector3d& p_B) noexcept;

/// X_AC = X_AB·X_BC.
RigidTransform compose(const RigidTransform& X_AB, const RigidTransform& X_BC) noexcept;

/// X_BA, the inverse of X_AB.
RigidTransform inverse(const RigidTransform& X_AB) noexcept;

/// One physical point seen in both frames.
struct PointPair {
  Vector3d p_T = Vector3d::Zero();  ///< as measured, e.g. by the laser tracker [m, T]
  Vector3d p_B = Vector3d::Zero();  ///< where the model puts it [m, B]
};

/// Settings of register_points.
struct RegistrationOptions {
  /// Largest accepted `Registration::condition`. The default 1e4 rejects point sets whose
  /// worst-determined rotation is more than 100 times less certain than the best-determined one.
  double max_condition = 1e4;
};

/// Result of register_points (caller-owned). On a failed status only `count`, and when the
/// points got that far `singular_values`, `condition` and `reflection`, are meaningful.
struct Registration {
  RigidTransform X_BT;  ///< best fit: p_B ≈ X_BT.R·p_T + X_BT.t (identity on failure)
  int count = 0;        ///< point pairs used (N)
  /// rms of the 3-D residual distances, sqrt(Σ|X_BT·p_T − p_B|² / N) [m] (per coordinate: divide by √3)
  double rms_residual = std::numeric_limits<double>::quiet_NaN();
  double max_residual = std::numeric_limits<double>::quiet_NaN();  ///< largest |X_BT·p_T − p_B| [m]
  int max_residual_index = -1;  ///< 0-based index of the pair with the largest residual
  /// Noise per coordinate estimated from the fit, sqrt(Σ|residual|² / (3N − 6)) [m]: unbiased
  /// in variance for isotropic Gaussian noise (theory §11).
  double sigma = std::numeric_limits<double>::quiet_NaN();
  /// Singular values h1 ≥ h2 ≥ h3 of the cross-covariance H = Σ (p_T − c_T)(p_B − c_B)ᵀ / N
  /// [m²]; without noise, the mean squares of the points' spread along their principal axes.
  Vector3d singular_values = Vector3d::Zero();
  /// The unconstrained best orthogonal fit was a reflection and was turned into the best proper
  /// rotation (d = −1). Harmless for (nearly) coplanar points (h3 ≈ 0); otherwise one point set
  /// is mirrored (a flipped axis), and the residual shows it.
  bool reflection = false;
  /// Condition number of the fit's rotation Hessian, (g1 + g2) / (g2 + g3) with g = (h1, h2, d·h3):
  /// 1 for an isotropic cloud, infinite for collinear points (the rotation about their line is
  /// free). Its square root is the ratio of the worst- to the best-determined rotation's
  /// standard deviation under noise.
  double condition = std::numeric_limits<double>::infinity();
};

/// Best-fit rigid transform X_BT minimising Σ|R·p_T + t − p_B|² over R ∈ SO(3), t (Kabsch/Umeyama
/// by an SVD of the cross-covariance, with the reflection fix; no scale). Returns Ok,
/// TooFewPoints (N < 3), NonFiniteInput, or DegenerateRegistration when the points in either
/// frame are coincident (spread below 1e-9 of their coordinates) or the condition exceeds
/// `options.max_condition` (nearly collinear).
[[nodiscard]] Status register_points(std::span<const PointPair> pairs, Registration& out,
                                     const RegistrationOptions& options = {}) noexcept;

/// Largest rms residual of a registration of a log's points onto the model's, as a share of the
/// model points' rms spread, for the log to be of the run (measure_points and identify decide
/// with it; MeasurementOptions and IdentificationOptions carry it).
inline constexpr double kMaxRegistrationMisfit = 0.2;

/// Why a successful registration of a log's points (p_T) onto the model's (p_B) shows the log is
/// not of the run: its rms residual above `max_misfit` times the model points' rms spread; empty
/// if it is. One sentence without the log's name (the caller's prefix): a log in other units than
/// its header says, another run's log, or another time offset. measure_points and identify word
/// the refusal with it.
std::string shape_misfit(std::span<const PointPair> pairs, const Registration& registration, double max_misfit);

}  // namespace hexatwist
