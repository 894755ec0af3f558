// SPDX-License-Identifier: BSD-3-Clause
// Internal: the six legs side by side, one leg per lane, in the widest double vector the target
// has: one packet of eight lanes with AVX-512, two of four with AVX, three of two with SSE2 or
// NEON (lanes 6 and 7, where they exist, repeat leg 0, so they pass or fail every test with it
// and need no mask). Inverse kinematics, the limit tests and the twist are written once here,
// per packet, and shared by the functions that fill a LegState (kinematics.cpp, limits.cpp,
// twist.cpp) and by the real-time command (compensation.cpp), which keeps everything in
// registers. (GCC's generic eight-lane vectors on AVX2 spill to the stack: 3.5x slower.)
#pragma once

#include <cstring>

#include "hexatwist/kinematics/kinematics.hpp"
#include "hexatwist/kinematics/model.hpp"
#include "kinematics/fast_math.hpp"
#include "kinematics/linear_solve.hpp"

namespace hexatwist::detail {

using lane_m = mask_of<lane_v>;
using lanes3 = vec3<lane_v>;
/// Legs per packet, and packets for the six legs.
inline constexpr int kWidth = sizeof(lane_v) / sizeof(double);
inline constexpr int kPackets = (kLegs + kWidth - 1) / kWidth;
static_assert(kPackets * kWidth <= 8, "LegLanes holds eight lanes");

/// Legs k*kWidth ... of a 6-vector (or a column of a 6-row matrix); lanes past leg 5 repeat leg 0.
/// Built from whole 2- and 4-lane loads and shuffles: element-wise it cost a third of the
/// forward kinematics.
inline lane_v load6(const double* p, int k) noexcept {
  const auto load = [](const double* q, auto v) {
    std::memcpy(&v, q, sizeof v);
    return v;
  };
#if HEXATWIST_LANE_WIDTH == 2
  return load(p + 2 * k, v2d{});
#else
  const v4d tail = __builtin_shufflevector(load(p + 4, v2d{}), load(p, v2d{}), 0, 1, 2, 2);  // legs 4, 5, 0, 0
#if HEXATWIST_LANE_WIDTH == 4
  return k == 0 ? load(p, v4d{}) : tail;
#else
  (void)k;  // one packet
  return __builtin_shufflevector(load(p, v4d{}), tail, 0, 1, 2, 3, 4, 5, 6, 7);
#endif
#endif
}
/// Writes the legs of packet k (not the padding) into p[0..5], as whole 2- and 4-lane stores
/// (a partial copy of the vector went through the stack).
inline void store6(double* p, lane_v v, int k) noexcept {
#if HEXATWIST_LANE_WIDTH == 2
  std::memcpy(p + 2 * k, &v, sizeof v);
#elif HEXATWIST_LANE_WIDTH == 4
  if (k == 0) {
    std::memcpy(p, &v, sizeof v);
  } else {
    const v2d legs45 = __builtin_shufflevector(v, v, 0, 1);
    std::memcpy(p + 4, &legs45, sizeof legs45);
  }
#else
  (void)k;  // one packet
  const v4d legs0123 = __builtin_shufflevector(v, v, 0, 1, 2, 3);
  const v2d legs45 = __builtin_shufflevector(v, v, 4, 5);
  std::memcpy(p, &legs0123, sizeof legs0123);
  std::memcpy(p + 4, &legs45, sizeof legs45);
#endif
}
/// The rows of a LegVectors (leg i in lane i).
inline lanes3 load6(const LegVectors& m, int k) noexcept {
  return {load6(m.data(), k), load6(m.data() + kLegs, k), load6(m.data() + 2 * kLegs, k)};
}
inline void store6(LegVectors& m, const lanes3& v, int k) noexcept {
  store6(m.data(), v.x, k);
  store6(m.data() + kLegs, v.y, k);
  store6(m.data() + 2 * kLegs, v.z, k);
}
/// Packet k of a quantity of the model's LegLanes.
inline lane_v load_lanes(const double (&a)[8], int k) noexcept {
  lane_v v;
  std::memcpy(&v, a + k * kWidth, sizeof v);
  return v;
}
inline lanes3 load_lanes(const double (&a)[3][8], int k) noexcept {
  return {load_lanes(a[0], k), load_lanes(a[1], k), load_lanes(a[2], k)};
}

/// Every lane set.
inline lane_m all_set() noexcept { return bits(splat<lane_v>(0.0)) == bits(splat<lane_v>(0.0)); }
/// True if every lane of m is set.
template <class M>
inline bool all_lanes(M m) noexcept {
  constexpr int width = sizeof(M) / sizeof(double);
  if constexpr (width == 8) {
    const auto m4 = __builtin_shufflevector(m, m, 0, 1, 2, 3) & __builtin_shufflevector(m, m, 4, 5, 6, 7);
    const auto m2 = __builtin_shufflevector(m4, m4, 0, 1) & __builtin_shufflevector(m4, m4, 2, 3);
    return (m2[0] & m2[1]) != 0;
  } else if constexpr (width == 4) {
    const auto m2 = __builtin_shufflevector(m, m, 0, 1) & __builtin_shufflevector(m, m, 2, 3);
    return (m2[0] & m2[1]) != 0;
  } else {
    return (m[0] & m[1]) != 0;
  }
}

/// The legs of packet k at one placement, Eq. (1)-(4).
struct LegsAt {
  lanes3 arm;            ///< R_BP * arm_P [m, B]
  lanes3 axis_platform;  ///< R_BP * jd_P [-, B]
  lanes3 leg;            ///< L_i [m, B]
  lane_v length2;        ///< |L_i|^2 [m^2]
  lane_v length;         ///< |L_i| [m]
};

/// The same from the legs' constants as vectors (one leg per lane, or one leg in every lane for a
/// batch of poses, batch.cpp) and the platform's origin pivot_home + t [m, B]; R_BP a Matrix3d or
/// a LaneRotation.
template <class M>
inline LegsAt legs_at(const M& R_BP, const lanes3& origin_B, const lanes3& arm_P, const lanes3& axis_platform_P,
                      const lanes3& base_B) noexcept {
  LegsAt out;
  out.arm = rotate(R_BP, arm_P);
  out.axis_platform = rotate(R_BP, axis_platform_P);
  // L_i = (pivot_home + t) + R_BP * arm_P,i - base_B,i.
  out.leg = {(out.arm.x - base_B.x) + origin_B.x, (out.arm.y - base_B.y) + origin_B.y,
             (out.arm.z - base_B.z) + origin_B.z};
  out.length2 = dot(out.leg, out.leg);
  out.length = vsqrt(out.length2);
  return out;
}

inline LegsAt legs_at(const Model& model, const Matrix3d& R_BP, const Vector3d& t, int k) noexcept {
  const LegLanes& g = model.geometry().lanes;
  const Vector3d origin_B = model.pivot_home_B() + t;
  const lanes3 origin = {splat<lane_v>(origin_B.x()), splat<lane_v>(origin_B.y()), splat<lane_v>(origin_B.z())};
  return legs_at(R_BP, origin, load_lanes(g.arm_P, k), load_lanes(g.axis_platform_P, k), load_lanes(g.base_B, k));
}

/// What the pose limits test, per leg, for leg directions u = scale * s (u = s, scale = 1, or
/// u = L, scale = |L|, which spares a division): stroke, U-joint bend as cosines to the home
/// direction seen from each end, and singularity as (s . axis)^2 against cos^2(margin); no
/// trigonometry.
struct LimitTerms {
  lane_v length;        ///< |L_i| [m]
  lane_v scale;         ///< |u|
  lane_v cos_base;      ///< u . s_home_B = scale * cos(bend at the base)
  lane_v cos_platform;  ///< u . (R_BP s_home_B): the same seen from the platform
  lane_v dot_a;         ///< u . ja (0 for legs without axes)
  lane_v dot_d;         ///< u . jd (0 for legs without axes)
};

/// The same for home directions `home` [-, B] as vectors, R_BP a Matrix3d or a LaneRotation.
template <class M>
inline LimitTerms limit_terms(const M& R_BP, const lanes3& u, lane_v scale, lane_v length, lane_v dot_a, lane_v dot_d,
                              const lanes3& home) noexcept {
  return {length, scale, dot(u, home), dot(u, rotate(R_BP, home)), dot_a, dot_d};
}

inline LimitTerms limit_terms(const Model& model, const Matrix3d& R_BP, const lanes3& u, lane_v scale, lane_v length,
                              lane_v dot_a, lane_v dot_d, int k) noexcept {
  return limit_terms(R_BP, u, scale, length, dot_a, dot_d, load_lanes(model.geometry().lanes.s_home_B, k));
}

/// Lanes within every pose limit, bounds included with the tolerance of limits.hpp (the Model's
/// accepted bounds: check_limits compares the same numbers). NaN fails. With scale = 1 the tests
/// are exactly those of unit vectors.
inline lane_m within_limits(const Model& model, const LimitTerms& t) noexcept {
  const lane_v cos_bend = model.cos_bend_max() * t.scale;
  const lane_v cos2_margin = model.cos2_singularity_margin() * (t.scale * t.scale);
  return (t.length >= model.length_min_accepted()) & (t.length <= model.length_max_accepted()) &
         (t.cos_base >= cos_bend) & (t.cos_platform >= cos_bend) & (t.dot_a * t.dot_a <= cos2_margin) &
         (t.dot_d * t.dot_d <= cos2_margin);
}

/// Lanes whose command is within the stroke, ends included with the tolerance of limits.hpp. NaN
/// fails.
inline lane_m within_stroke(const Model& model, lane_v command) noexcept {
  return (command >= model.length_min_accepted()) & (command <= model.length_max_accepted());
}

/// The twist terms of each leg: the coordinates of docs/theory.md §3, theta = atan2(y, x), and
/// ja x jd, which the Jacobian reuses. For a leg direction u = scale * s, with ja_u = ja . u and
/// jd_u = jd . u (the caller's) and u2 = scale^2, x comes out scaled by scale^2 and y by scale.
/// (Small on purpose: GCC keeps a larger struct of vectors in memory.)
struct TwistTerms {
  lanes3 ja_x_jd;
  lane_v x, y;
};

inline TwistTerms twist_terms(const lanes3& u, const lanes3& ja, const lanes3& jd, lane_v ja_u, lane_v jd_u,
                              lane_v u2) noexcept {
  TwistTerms t;
  t.ja_x_jd = cross(ja, jd);
  t.x = u2 * dot(ja, jd) - ja_u * jd_u;
  t.y = dot(u, t.ja_x_jd);
  return t;
}

/// Squared |s x ja| |s x jd| below which the U-joint's cross axis (Eq. 8) is undefined.
inline constexpr double kSingularSin2 = 1e-24;

/// Lanes away from a U-joint singularity or without axes, for (x, y) scaled by sqrt(unit2)
/// (1 for unit vectors). NaN fails.
/// `has_axes` 1 for legs with axes, else 0.
inline lane_m twist_regular(lane_v x, lane_v y, lane_v unit2, lane_v has_axes) noexcept {
  return (x * x + y * y) + (1.0 - has_axes) * unit2 >= kSingularSin2 * unit2;
}
inline lane_m twist_regular(const Model& model, lane_v x, lane_v y, lane_v unit2, int k) noexcept {
  return twist_regular(x, y, unit2, load_lanes(model.geometry().lanes.has_axes, k));
}

/// The twist theta - theta_home (relative) or theta (absolute) in one atan2: (x, y) rotated by
/// -theta_home. Zero for legs without axes.
/// With cos and sin of theta_home (c0, s0) and has_axes as vectors: theta - theta_home.
inline lane_v twist_angle(lane_v x, lane_v y, lane_v c0, lane_v s0, lane_v has_axes) noexcept {
  return atan2(y * c0 - x * s0, x * c0 + y * s0) * has_axes;
}
inline lane_v twist_angle(const Model& model, lane_v x, lane_v y, bool relative, int k) noexcept {
  const LegLanes& g = model.geometry().lanes;
  const lane_v c0 = relative ? load_lanes(g.cos_theta_home, k) : splat<lane_v>(1.0);
  const lane_v s0 = relative ? load_lanes(g.sin_theta_home, k) : splat<lane_v>(0.0);
  return twist_angle(x, y, c0, s0, load_lanes(g.has_axes, k));
}

/// The rows of packet k of the twist Jacobian (motor = false) or of the motor-side length
/// Jacobian [s^T, (arm x s)^T] - twist_gain * (twist Jacobian) (motor = true), docs/theory.md §5,
/// as six column vectors (lane i: leg i's row). From the unit leg direction s, 1/|L|, the arm, the
/// joint axes ja, jd, ja.s, jd.s and the twist terms of s (twist_terms with u = s, u2 = 1). Where
/// a leg is near a U-joint singularity (twist_regular fails) its row is unspecified.
inline void jacobian_columns(const Model& model, const lanes3& s, lane_v inv_length, const lanes3& arm,
                             const lanes3& ja, const lanes3& jd, lane_v ja_s, lane_v jd_s, const TwistTerms& t,
                             bool motor, int k, lane_v (&col)[6]) noexcept {
  const LegLanes& g = model.geometry().lanes;
  const lane_v mask = load_lanes(g.has_axes, k);
  // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2), with the partials of y and x in s and jd:
  // dy/ds = ja x jd, dx/ds = -(jd.s) ja - (ja.s) jd, dy/djd = s x ja, dx/djd = ja - (ja.s) s.
  // Legs without axes have x = y = 0: give them n2 = 1 and mask their rows to zero.
  const lane_v n2 = t.x * t.x + t.y * t.y + (1.0 - mask);
  const lane_v weight = mask / n2;  // one division for both
  const lane_v fx = weight * t.x, fy = weight * t.y;
  const lanes3 dx_ds = (-jd_s) * ja - ja_s * jd;
  const lanes3 g_s = fx * t.ja_x_jd - fy * dx_ds;
  const lanes3 g_jd = fx * cross(s, ja) - fy * (ja - ja_s * s);
  // s = L/|L|: ds = (I - s s^T) dL / |L|; dL = dt + dw x arm; djd = dw x jd.
  const lanes3 a = inv_length * (g_s - dot(g_s, s) * s);
  const lanes3 b = cross(arm, a) + cross(jd, g_jd);
  const lane_v twist_col[6] = {a.x, a.y, a.z, b.x, b.y, b.z};
  if (!motor) {
    for (int c = 0; c < 6; ++c) col[c] = twist_col[c];
    return;
  }
  const lane_v gain = load_lanes(g.twist_gain, k);
  const lanes3 arm_x_s = cross(arm, s);
  const lane_v length_col[6] = {s.x, s.y, s.z, arm_x_s.x, arm_x_s.y, arm_x_s.z};
  for (int c = 0; c < 6; ++c) col[c] = length_col[c] - gain * twist_col[c];
}

/// Per leg, a bound on what the twist adds to the scaled motor-side Jacobian, for the condition
/// proof (docs/theory.md §8): with A_m = A_g - E (A_g the geometric rows [s^T, (arm x s)^T / l_c],
/// E = diag(twist_gain) (twist Jacobian) diag(1, 1, 1, 1/l_c x 3)), ||E||_1 <= the sum of the lanes.
/// From the twist terms of the leg vector L (twist_terms with u = L: x, and y already multiplied by
/// |L|, both then scaled by |L|^2), L.ja, L.jd, |L|, |L|^2 and 1/|L|; the triangle inequality on
/// jacobian_columns' terms, without forming them. Near a U-joint singularity it grows like
/// 1/(x^2 + y^2); NaN stays NaN. Lanes 6 and 7 give 0.
/// `has_axes`, `arm_ratio` and `gain_bound` are LegLanes' has_axes, arm_ratio and twist_gain_bound
/// as vectors.
inline lane_v twist_share_bound(const Model& model, lane_v x, lane_v y, lane_v dot_a, lane_v dot_d, lane_v length,
                                lane_v length2, lane_v inv_length, lane_v has_axes, lane_v arm_ratio,
                                lane_v gain_bound) noexcept {
  const lane_v ax = vabs(x), ay = vabs(y);
  // With w = 1/(x^2 + y^2) (legs without axes: 1, and a zero gain): |a| <= |L| w (|x| + |y| (|ja.s| +
  // |jd.s|)) for the translation part a, |g_jd| <= |L|^2 w (|x| + |y|), |b| <= |arm| |a| + |g_jd|.
  const lane_v w = 1.0 / ((x * x + y * y) + (1.0 - has_axes));
  const lane_v a = length * w * (ax + ay * ((vabs(dot_a) + vabs(dot_d)) * inv_length));
  const lane_v b_scaled = arm_ratio * a + (length2 * w * (ax + ay)) * (1.0 / model.condition_length());
  return gain_bound * (a > b_scaled ? a : b_scaled);
}
inline lane_v twist_share_bound(const Model& model, lane_v x, lane_v y, lane_v dot_a, lane_v dot_d, lane_v length,
                                lane_v length2, lane_v inv_length, int k) noexcept {
  const LegLanes& g = model.geometry().lanes;
  return twist_share_bound(model, x, y, dot_a, dot_d, length, length2, inv_length, load_lanes(g.has_axes, k),
                           load_lanes(g.arm_ratio, k), load_lanes(g.twist_gain_bound, k));
}

/// The sum of the lanes.
inline double sum_lanes(lane_v v) noexcept {
#if HEXATWIST_LANE_WIDTH == 8
  const v4d v4 = __builtin_shufflevector(v, v, 0, 1, 2, 3) + __builtin_shufflevector(v, v, 4, 5, 6, 7);
  const v2d v2 = __builtin_shufflevector(v4, v4, 0, 1) + __builtin_shufflevector(v4, v4, 2, 3);
#elif HEXATWIST_LANE_WIDTH == 4
  const v2d v2 = __builtin_shufflevector(v, v, 0, 1) + __builtin_shufflevector(v, v, 2, 3);
#else
  const v2d v2 = v;
#endif
  return v2[0] + v2[1];
}

/// A 6x6 matrix gathered packet by packet as columns (lane i: row i, as jacobian_columns gives
/// them), read out as padded rows (linear_solve.hpp): kept in registers and transposed there with
/// one eight-lane packet, else through its column-major storage.
class ColumnPackets {
 public:
  void set(int k, const lane_v (&col)[6]) noexcept {
#if HEXATWIST_LANE_WIDTH == 8
    (void)k;  // one packet
    for (int c = 0; c < 6; ++c) cols_[c] = col[c];
#else
    for (int c = 0; c < 6; ++c) store6(m_.data() + kLegs * c, col[c], k);
#endif
  }
  void rows(PaddedRows& out) const noexcept {
#if HEXATWIST_LANE_WIDTH == 8
    padded_rows(cols_, out);
#else
    padded_rows(m_, out);
#endif
  }

 private:
#if HEXATWIST_LANE_WIDTH == 8
  v8d cols_[6];
#else
  Matrix6d m_;
#endif
};

}  // namespace hexatwist::detail
