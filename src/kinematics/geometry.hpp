// SPDX-License-Identifier: BSD-3-Clause
// Internal geometric helpers shared by the model, the twist and the limit check.
#pragma once

#include <cmath>

#include "hexatwist/types.hpp"

// Row-wise helpers below operate on all six legs at once (see LegVectors).

namespace hexatwist::detail {

/// theta = atan2(y, x) is the angle from jb = s x ja to je = s x jd about s, because s x v turns
/// the part of v normal to s by +90 deg about s: the angle jb -> je equals the angle between the
/// projections of ja and jd on the plane normal to s. y = s.(ja x jd), x = ja.jd - (ja.s)(jd.s);
/// both scale with |s x ja| |s x jd|, which vanishes only at a U-joint singularity.
struct TwistXY {
  double x;
  double y;
};

inline TwistXY twist_xy(const Vector3d& s, const Vector3d& ja, const Vector3d& jd) noexcept {
  return {ja.dot(jd) - ja.dot(s) * jd.dot(s), s.dot(ja.cross(jd))};
}

/// The cross-product matrix: skew(v) w = v x w.
inline Matrix3d skew(const Vector3d& v) noexcept {
  Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

/// Angle between two directions [rad], in [0, pi]; accurate near 0 and pi (unlike acos).
inline double angle_between(const Vector3d& a, const Vector3d& b) noexcept {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

/// Angle between a line (either sense) and an axis [rad], in [0, pi/2].
inline double line_axis_angle(const Vector3d& s, const Vector3d& a) noexcept {
  return std::atan2(s.cross(a).norm(), std::abs(s.dot(a)));
}

using Array6d = Eigen::Array<double, kLegs, 1>;

/// True if every coefficient is finite, in one vectorised sum instead of a branch each:
/// x * 0 is 0 for a finite x and NaN otherwise.
template <class Derived>
inline bool all_finite(const Eigen::MatrixBase<Derived>& m) noexcept {
  return (m.array() * 0.0).sum() == 0.0;
}

/// Row-wise dot products of two leg-vector sets.
inline Array6d dot(const LegVectors& a, const LegVectors& b) noexcept {
  return a.col(0).array() * b.col(0).array() + a.col(1).array() * b.col(1).array() +
         a.col(2).array() * b.col(2).array();
}

/// Row-wise cross products a_i x b_i.
inline LegVectors cross(const LegVectors& a, const LegVectors& b) noexcept {
  LegVectors c;
  c.col(0) = a.col(1).cwiseProduct(b.col(2)) - a.col(2).cwiseProduct(b.col(1));
  c.col(1) = a.col(2).cwiseProduct(b.col(0)) - a.col(0).cwiseProduct(b.col(2));
  c.col(2) = a.col(0).cwiseProduct(b.col(1)) - a.col(1).cwiseProduct(b.col(0));
  return c;
}

/// Each row scaled by its own factor: row i = f_i * v_i.
inline LegVectors scale_rows(const Array6d& f, const LegVectors& v) noexcept {
  return (v.array().colwise() * f).matrix();
}

/// Each row rotated: row i = (R * v_i)^T.
inline LegVectors rotate_rows(const Matrix3d& R, const LegVectors& v) noexcept {
  LegVectors out;
  for (int k = 0; k < 3; ++k) out.col(k) = R(k, 0) * v.col(0) + R(k, 1) * v.col(1) + R(k, 2) * v.col(2);
  return out;
}

}  // namespace hexatwist::detail
