// SPDX-License-Identifier: BSD-3-Clause
// Internal: sin/cos and atan2 accurate to a few ulp, vectorised over the six legs.
// libm's scalar calls (~25 ns each on the 2.1 GHz test machine) would dominate the real-time
// budget, and Eigen 3.4's select() compiles to scalar branches, so these kernels use GCC/Clang
// vector extensions with bitwise blends, for any lane count: two or four doubles for a few
// angles, the machine's widest vector for the legs (src/kinematics/lanes.hpp). Both use exact range reduction followed
// by a Taylor series (sin, cos) or its Pade approximant (atan), truncated where the error is
// below 1e-17; tests/kinematics/test_kernels.cpp checks them against libm.
#pragma once

#include <cmath>
#include <cstring>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "kinematics/geometry.hpp"

namespace hexatwist::detail {

using v2d = double __attribute__((vector_size(16)));
using v4d = double __attribute__((vector_size(32)));
using v8d = double __attribute__((vector_size(64)));
/// The widest double vector of the target (src/kinematics/lanes.hpp, src/kinematics/linear_solve.hpp).
#if defined(__AVX512F__)
#define HEXATWIST_LANE_WIDTH 8
using lane_v = v8d;
#elif defined(__AVX__)
#define HEXATWIST_LANE_WIDTH 4
using lane_v = v4d;
#else
#define HEXATWIST_LANE_WIDTH 2
using lane_v = v2d;
#endif
/// Lane mask of a vector type: all ones or all zeros per lane.
template <class V>
using mask_of = decltype(V{} < V{});
using v2m = mask_of<v2d>;

template <class M>
struct DoubleOf;  // the double vector with the lanes of mask type M
template <>
struct DoubleOf<mask_of<v2d>> {
  using type = v2d;
};
template <>
struct DoubleOf<mask_of<v4d>> {
  using type = v4d;
};
template <>
struct DoubleOf<mask_of<v8d>> {
  using type = v8d;
};

template <class V>
inline mask_of<V> bits(V a) noexcept {
  return reinterpret_cast<mask_of<V>>(a);
}
template <class M>
inline typename DoubleOf<M>::type from_bits(M m) noexcept {
  return reinterpret_cast<typename DoubleOf<M>::type>(m);
}
template <class V>
inline V blend(mask_of<V> mask, V if_true, V if_false) noexcept {
  return from_bits((bits(if_true) & mask) | (bits(if_false) & ~mask));
}
/// Every lane a (a - 0 keeps the sign of a = -0, which 0 + a would lose).
template <class V>
inline V splat(double a) noexcept {
  return a - V{};
}
/// The sign bit of each lane, alone.
template <class V>
inline mask_of<V> sign_bits(V a) noexcept {
  return bits(a) & bits(splat<V>(-0.0));
}
template <class V>
inline V vabs(V a) noexcept {
  return from_bits(bits(a) & ~bits(splat<V>(-0.0)));
}
/// c where the mask is set, else 0.
template <class M>
inline typename DoubleOf<M>::type masked(M mask, double c) noexcept {
  return from_bits(mask & bits(splat<typename DoubleOf<M>::type>(c)));
}

/// Square root of each lane (NaN for a negative one); vector extensions have none of their own.
inline v2d vsqrt(v2d a) noexcept {
#if defined(__SSE2__)
  return reinterpret_cast<v2d>(_mm_sqrt_pd(reinterpret_cast<__m128d>(a)));
#else
  return v2d{std::sqrt(a[0]), std::sqrt(a[1])};
#endif
}
#if defined(__AVX__)
inline v4d vsqrt(v4d a) noexcept { return reinterpret_cast<v4d>(_mm256_sqrt_pd(reinterpret_cast<__m256d>(a))); }
#endif
#if defined(__AVX512F__)
inline v8d vsqrt(v8d a) noexcept {
  // The masked form: GCC 12 warns of the undefined vector _mm512_sqrt_pd passes through.
  return reinterpret_cast<v8d>(_mm512_maskz_sqrt_pd(0xFF, reinterpret_cast<__m512d>(a)));
}
#endif

/// A 3-vector per lane (lane k: leg k), as three vectors of x, y and z. Per-leg code written on
/// these keeps every intermediate in registers; the equivalent expressions on whole LegVectors
/// went through memory temporaries and out-of-line helpers.
template <class V>
struct vec3 {
  V x, y, z;
};
template <class V>
inline V dot(const vec3<V>& a, const vec3<V>& b) noexcept {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class V>
inline vec3<V> cross(const vec3<V>& a, const vec3<V>& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class V>
inline vec3<V> operator*(V f, const vec3<V>& a) noexcept {
  return {f * a.x, f * a.y, f * a.z};
}
template <class V>
inline vec3<V> operator+(const vec3<V>& a, const vec3<V>& b) noexcept {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class V>
inline vec3<V> operator-(const vec3<V>& a, const vec3<V>& b) noexcept {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
/// R times each lane's vector: R a Matrix3d (one rotation for every lane) or a LaneRotation (one
/// per lane).
template <class M, class V>
inline vec3<V> rotate(const M& R, const vec3<V>& v) noexcept {
  return {R(0, 0) * v.x + R(0, 1) * v.y + R(0, 2) * v.z, R(1, 0) * v.x + R(1, 1) * v.y + R(1, 2) * v.z,
          R(2, 0) * v.x + R(2, 1) * v.y + R(2, 2) * v.z};
}

/// atan2 of each lane, in [-pi, pi] (-pi only for y = -0), atan2(+-0, +0) = +-0. Error below 2 ulp of pi.
template <class V>
inline V atan2(V y, V x) noexcept {
  const V ax = vabs(x), ay = vabs(y);
  const auto swap = ay > ax;
  const V hi = blend(swap, ay, ax), lo = blend(swap, ax, ay);
  // First octant: a = atan(lo/hi) in [0, pi/4]. Above pi/8 use atan(t) = pi/4 + atan((t-1)/(t+1))
  // so that |z| <= tan(pi/8) below.
  const auto upper = lo > 0.41421356237309503 * hi;
  const V num = lo - from_bits(upper & bits(hi));
  const V den = blend(hi > 0.0, hi, splat<V>(1.0)) + from_bits(upper & bits(lo));
  const V z = num / den;
  const V w = z * z;
  // atan(z) = z + z w q(w), q the near-minimax polynomial (Chebyshev fit in 60-digit arithmetic)
  // of degree 10 for (atan(sqrt(w))/sqrt(w) - 1)/w on [0, tan(pi/8)^2]: relative error of z q
  // below 4e-18 with the coefficients rounded to double. A polynomial instead of a rational
  // approximation keeps a second division off the critical path; Estrin's scheme (w^2, w^4,
  // w^8) keeps the chain of dependent multiply-adds short.
  const V w2 = w * w, w4 = w2 * w2, w8 = w4 * w4;
  const V q =
      ((-0.3333333333333312 + 0.19999999999940893 * w) + w2 * (-0.14285714279250245 + 0.11111110744919658 * w)) +
      w4 * ((-0.09090896809064027 + 0.07692045330902225 * w) + w2 * (-0.06662951813629191 + 0.05846878297330872 * w)) +
      w8 * ((-0.05035102456601552 + 0.03796525745386593 * w) + w2 * -0.017805397205419446);
  V a = (z + (z * w) * q) + masked(upper, kPi / 4);
  // Unfold: swapped octant a -> pi/2 - a; x < 0: a -> pi - a; y < 0 (sign bit): a -> -a.
  a = masked(swap, kPi / 2) + from_bits(bits(a) ^ (swap & bits(splat<V>(-0.0))));
  const auto negative_x = x < 0.0;
  a = masked(negative_x, kPi) + from_bits(bits(a) ^ (negative_x & bits(splat<V>(-0.0))));
  return from_bits(bits(a) ^ sign_bits(y));  // as libm: atan2(-0, x < 0) = -pi
}

/// Element-wise atan2(y, x) of six lanes.
inline Array6d atan2(const Array6d& y, const Array6d& x) noexcept {
  Array6d out;
  for (int k = 0; k < kLegs; k += 2) {
    v2d yv, xv;
    std::memcpy(&yv, y.data() + k, sizeof yv);
    std::memcpy(&xv, x.data() + k, sizeof xv);
    const v2d r = atan2(yv, xv);
    std::memcpy(out.data() + k, &r, sizeof r);
  }
  return out;
}

/// sin and cos of each lane for |r| <= pi/4 [rad], no range reduction.
template <class V>
inline void sin_cos_reduced(V r, V& s, V& c) noexcept {
  const V r2 = r * r;
  // Taylor to r^17 (sin) and r^18 (cos): the first omitted terms are < 5e-17 at |r| = pi/4.
  // Estrin's scheme in r^2, r^4, r^8 keeps the chain of dependent multiply-adds short.
  const V r4 = r2 * r2, r8 = r4 * r4;
  const V sin_poly = ((-1.0 / 6 + r2 * (1.0 / 120)) + r4 * (-1.0 / 5040 + r2 * (1.0 / 362880))) +
                     r8 * ((-1.0 / 39916800 + r2 * (1.0 / 6227020800.0)) +
                           r4 * (-1.0 / 1307674368000.0 + r2 * (1.0 / 355687428096000.0)));
  s = r + r * r2 * sin_poly;
  const V cos_poly =
      ((-0.5 + r2 * (1.0 / 24)) + r4 * (-1.0 / 720 + r2 * (1.0 / 40320))) +
      r8 *
          (((-1.0 / 3628800 + r2 * (1.0 / 479001600.0)) + r4 * (-1.0 / 87178291200.0 + r2 * (1.0 / 20922789888000.0))) +
           r8 * (-1.0 / 6402373705728000.0));
  c = 1.0 + r2 * cos_poly;
}

/// sin and cos of each lane [rad]; error below 2 ulp for |x| < 1e5 (the caller falls back to
/// libm beyond).
template <class V>
inline void sin_cos(V x, V& s, V& c) noexcept {
  // k = round(x 2/pi) by the 1.5 * 2^52 trick (round to nearest even, |x 2/pi| < 2^51).
  constexpr double kShift = 6755399441055744.0;
  const V k = (x * 0.63661977236758134308 + kShift) - kShift;
  // Cody-Waite: pi/2 = P1 + P2 + P3, P1 and P2 of 33 significant bits, so k*P1 and k*P2 are
  // exact for |k| < 2^20 and r = x - k pi/2 is correct to a few ulp, |r| <= pi/4.
  const V r = ((x - k * 1.5707963267341256) - k * 6.077100506303966e-11) - k * 2.0222662487959506e-21;
  V sr, cr;
  sin_cos_reduced(r, sr, cr);
  // Quadrant q = k mod 4: q odd swaps sin and cos; sin < 0 for q = 2, 3; cos < 0 for q = 1, 2.
  const V k4 = k * 0.25;
  const V n = (k4 + kShift) - kShift;               // round(k / 4)
  const V q = k - 4.0 * (n - masked(n > k4, 1.0));  // k - 4 floor(k / 4)
  const auto odd = (q == 1.0) | (q == 3.0);
  const V s0 = blend(odd, cr, sr), c0 = blend(odd, sr, cr);
  s = blend(q >= 2.0, -s0, s0);
  c = blend((q == 1.0) | (q == 2.0), -c0, c0);
}

/// sin and cos of three angles (roll, pitch, yaw) [rad].
inline void sin_cos(const Vector3d& a, Vector3d& s, Vector3d& c) noexcept {
  const double largest = a.cwiseAbs().maxCoeff();
  if (!(largest < 1e5)) {
    for (int k = 0; k < 3; ++k) {
      s[k] = std::sin(a[k]);
      c[k] = std::cos(a[k]);
    }
    return;
  }
  // Within +-0.78 rad (most poses) k = 0, r = x exactly and the quadrant is 0: the reduction
  // and the quadrant's blends can be skipped with the same result, and a shorter chain.
#if defined(__AVX__)
  v4d sv, cv;
  if (largest <= 0.78)
    sin_cos_reduced(v4d{a[0], a[1], a[2], 0.0}, sv, cv);
  else
    sin_cos(v4d{a[0], a[1], a[2], 0.0}, sv, cv);
  s = Vector3d(sv[0], sv[1], sv[2]);
  c = Vector3d(cv[0], cv[1], cv[2]);
#else
  v2d s01, c01, s2, c2;
  if (largest <= 0.78) {
    sin_cos_reduced(v2d{a[0], a[1]}, s01, c01);
    sin_cos_reduced(v2d{a[2], 0.0}, s2, c2);
  } else {
    sin_cos(v2d{a[0], a[1]}, s01, c01);
    sin_cos(v2d{a[2], 0.0}, s2, c2);
  }
  s = Vector3d(s01[0], s01[1], s2[0]);
  c = Vector3d(c01[0], c01[1], c2[0]);
#endif
}

/// A rotation matrix per lane (lane p: pose p of a batch), entries m[row][column].
template <class V>
struct LaneRotation {
  V m[3][3];
  const V& operator()(int row, int column) const noexcept { return m[row][column]; }
};

/// Eq. (3): R = Rz(q6) Ry(q5) Rx(q4) from the sines and cosines of roll (4), pitch (5) and yaw (6),
/// written out to avoid three matrix products; T a double or a vector of lanes. One expression
/// for both, so that a batch's lanes round as the single pose does.
template <class T>
inline LaneRotation<T> rotation_rzyx(T s4, T c4, T s5, T c5, T s6, T c6) noexcept {
  return {{{c5 * c6, s4 * s5 * c6 - c4 * s6, c4 * s5 * c6 + s4 * s6},
           {c5 * s6, s4 * s5 * s6 + c4 * c6, c4 * s5 * s6 - s4 * c6},
           {-s5, s4 * c5, c4 * c5}}};
}

/// Eq. (3), inlined into the real-time kernels (hexatwist::rotation_from_rpy calls it).
inline Matrix3d rotation_from_rpy(const Vector3d& rpy) noexcept {
  Vector3d sn, cs;
  sin_cos(rpy, sn, cs);
  const LaneRotation<double> r = rotation_rzyx(sn[0], cs[0], sn[1], cs[1], sn[2], cs[2]);
  Matrix3d R;
  R << r.m[0][0], r.m[0][1], r.m[0][2], r.m[1][0], r.m[1][1], r.m[1][2], r.m[2][0], r.m[2][1], r.m[2][2];
  return R;
}

}  // namespace hexatwist::detail
