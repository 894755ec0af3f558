// Internal: sin/cos and atan2 accurate to a few ulp, vectorised over the six legs.
// libm's scalar calls (~25 ns each on the 2.1 GHz test machine) would dominate the real-time
// budget, and Eigen 3.4's select() compiles to scalar branches, so these kernels use GCC/Clang
// vector extensions (two doubles per vector: SSE2, NEON) with bitwise blends. Both use exact
// range reduction followed by a Taylor series (sin, cos) or its Pade approximant (atan),
// truncated where the error is below 1e-17; tests/test_kernels.cpp checks them against libm.
#pragma once

#include <cmath>
#include <cstring>

#include "geometry.hpp"

namespace hexatwist::detail {

using v2d = double __attribute__((vector_size(16)));
using v2m = decltype(v2d{} < v2d{});  // lane mask: all ones or all zeros

inline v2d blend(v2m mask, v2d if_true, v2d if_false) noexcept {
  return reinterpret_cast<v2d>((reinterpret_cast<v2m>(if_true) & mask) | (reinterpret_cast<v2m>(if_false) & ~mask));
}
inline v2d splat(double a) noexcept { return v2d{a, a}; }
inline v2m bits(v2d a) noexcept { return reinterpret_cast<v2m>(a); }
inline v2d from_bits(v2m m) noexcept { return reinterpret_cast<v2d>(m); }
/// The sign bit of each lane, alone.
inline v2m sign_bits(v2d a) noexcept { return bits(a) & bits(splat(-0.0)); }
inline v2d vabs(v2d a) noexcept { return from_bits(bits(a) & ~bits(splat(-0.0))); }
/// c where the mask is set, else 0.
inline v2d masked(v2m mask, double c) noexcept { return from_bits(mask & bits(splat(c))); }

/// Two legs' worth of a leg-vector set: lanes are legs i and i+1 (rows i, i+1 of a LegVectors).
/// Per-leg code written on these packets keeps every intermediate in registers; the equivalent
/// expressions on whole LegVectors went through memory temporaries and out-of-line helpers.
struct v3d {
  v2d x, y, z;
};
inline v2d load2(const double* p) noexcept {
  v2d v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void store2(double* p, v2d v) noexcept { std::memcpy(p, &v, sizeof v); }
/// Rows i and i+1 of a column-major 6-row matrix or vector, column by column.
template <class M>
inline v3d load_rows(const M& m, int i) noexcept {
  return {load2(m.data() + i), load2(m.data() + kLegs + i), load2(m.data() + 2 * kLegs + i)};
}
inline v2d dot(const v3d& a, const v3d& b) noexcept { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline v3d cross(const v3d& a, const v3d& b) noexcept {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline v3d operator*(v2d f, const v3d& a) noexcept { return {f * a.x, f * a.y, f * a.z}; }
inline v3d operator+(const v3d& a, const v3d& b) noexcept { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline v3d operator-(const v3d& a, const v3d& b) noexcept { return {a.x - b.x, a.y - b.y, a.z - b.z}; }

/// atan2 of two lanes, in [-pi, pi] (-pi only for y = -0), atan2(+-0, +0) = +-0. Error below 2 ulp of pi.
inline v2d atan2(v2d y, v2d x) noexcept {
  const v2d ax = vabs(x), ay = vabs(y);
  const v2m swap = ay > ax;
  const v2d hi = blend(swap, ay, ax), lo = blend(swap, ax, ay);
  // First octant: a = atan(lo/hi) in [0, pi/4]. Above pi/8 use atan(t) = pi/4 + atan((t-1)/(t+1))
  // so that |z| <= tan(pi/8) below.
  const v2m upper = lo > 0.41421356237309503 * hi;
  const v2d num = lo - from_bits(upper & bits(hi));
  const v2d den = blend(hi > 0.0, hi, splat(1.0)) + from_bits(upper & bits(lo));
  const v2d z = num / den;
  const v2d w = z * z;
  // atan(z)/z as the [6/6] Pade approximant in w = z^2 of its Taylor series sum (-w)^n/(2n+1);
  // its error is below 1e-18 for w <= tan(pi/8)^2 (checked in 50-digit arithmetic).
  // Estrin's scheme (w^2, w^4) instead of Horner: half the dependent multiply-adds.
  const v2d w2 = w * w, w4 = w2 * w2;
  const v2d P = (1.0 + 2.7866666666666666 * w) + w2 * (2.8904347826086956 + 1.3693416149068323 * w) +
                w4 * ((0.28994079401402056 + 0.02213105421074192 * w) + w2 * 0.0002685815488923002);
  const v2d Q = (1.0 + 3.12 * w) + w2 * (3.7304347826086954 + 2.1316770186335403 * w) +
                w4 * ((0.5890160183066362 + 0.0692960021537219 * w) + w2 * 0.0023098667384573966);
  v2d a = z * P / Q + masked(upper, kPi / 4);
  // Unfold: swapped octant a -> pi/2 - a; x < 0: a -> pi - a; y < 0 (sign bit): a -> -a.
  a = masked(swap, kPi / 2) + from_bits(bits(a) ^ (swap & bits(splat(-0.0))));
  const v2m negative_x = x < 0.0;
  a = masked(negative_x, kPi) + from_bits(bits(a) ^ (negative_x & bits(splat(-0.0))));
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

/// sin and cos of two angles [rad]; error below 2 ulp for |x| < 1e5 (the caller falls back to
/// libm beyond).
inline void sin_cos(v2d x, v2d& s, v2d& c) noexcept {
  // k = round(x 2/pi) by the 1.5 * 2^52 trick (round to nearest even, |x 2/pi| < 2^51).
  constexpr double kShift = 6755399441055744.0;
  const v2d k = (x * 0.63661977236758134308 + kShift) - kShift;
  // Cody-Waite: pi/2 = P1 + P2 + P3, P1 and P2 of 33 significant bits, so k*P1 and k*P2 are
  // exact for |k| < 2^20 and r = x - k pi/2 is correct to a few ulp, |r| <= pi/4.
  const v2d r = ((x - k * 1.5707963267341256) - k * 6.077100506303966e-11) - k * 2.0222662487959506e-21;
  const v2d r2 = r * r;
  // Taylor to r^17 (sin) and r^18 (cos): the first omitted terms are < 5e-17 at |r| = pi/4.
  // Estrin's scheme in r^2, r^4, r^8 keeps the chain of dependent multiply-adds short.
  const v2d r4 = r2 * r2, r8 = r4 * r4;
  const v2d sin_poly = ((-1.0 / 6 + r2 * (1.0 / 120)) + r4 * (-1.0 / 5040 + r2 * (1.0 / 362880))) +
                       r8 * ((-1.0 / 39916800 + r2 * (1.0 / 6227020800.0)) +
                             r4 * (-1.0 / 1307674368000.0 + r2 * (1.0 / 355687428096000.0)));
  const v2d sr = r + r * r2 * sin_poly;
  const v2d cos_poly = ((-0.5 + r2 * (1.0 / 24)) + r4 * (-1.0 / 720 + r2 * (1.0 / 40320))) +
                       r8 * (((-1.0 / 3628800 + r2 * (1.0 / 479001600.0)) +
                              r4 * (-1.0 / 87178291200.0 + r2 * (1.0 / 20922789888000.0))) +
                             r8 * (-1.0 / 6402373705728000.0));
  const v2d cr = 1.0 + r2 * cos_poly;
  // Quadrant q = k mod 4: q odd swaps sin and cos; sin < 0 for q = 2, 3; cos < 0 for q = 1, 2.
  const v2d k4 = k * 0.25;
  const v2d n = (k4 + kShift) - kShift;                           // round(k / 4)
  const v2d q = k - 4.0 * (n - masked(n > k4, 1.0));           // k - 4 floor(k / 4)
  const v2m odd = (q == 1.0) | (q == 3.0);
  const v2d s0 = blend(odd, cr, sr), c0 = blend(odd, sr, cr);
  s = blend(q >= 2.0, -s0, s0);
  c = blend((q == 1.0) | (q == 2.0), -c0, c0);
}

/// sin and cos of three angles (roll, pitch, yaw) [rad].
inline void sin_cos(const Vector3d& a, Vector3d& s, Vector3d& c) noexcept {
  if (!(a.cwiseAbs().maxCoeff() < 1e5)) {
    for (int k = 0; k < 3; ++k) {
      s[k] = std::sin(a[k]);
      c[k] = std::cos(a[k]);
    }
    return;
  }
  v2d s01, c01, s2, c2;
  sin_cos(v2d{a[0], a[1]}, s01, c01);
  sin_cos(v2d{a[2], 0.0}, s2, c2);
  s = Vector3d(s01[0], s01[1], s2[0]);
  c = Vector3d(c01[0], c01[1], c2[0]);
}

}  // namespace hexatwist::detail
