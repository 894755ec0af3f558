#include "hexatwist/twist.hpp"

#include <cmath>

#include "fast_math.hpp"
#include "geometry.hpp"

namespace hexatwist {
namespace {

using detail::Array6d;

// Squared |s x ja| |s x jd| below which the U-joint's cross axis (Eq. 8) is undefined.
constexpr double kSingularSin2 = 1e-24;

// The twist coordinates (docs/theory.md §3) of all legs: theta = atan2(y, x).
struct Coordinates {
  Array6d x;
  Array6d y;
};

Coordinates coordinates(const Model& model, const LegState& st) noexcept {
  const LegVectors& ja = model.geometry().axis_base_B;
  const LegVectors& jd = st.axis_platform_B;
  return {detail::dot(ja, jd) - detail::dot(ja, st.s_B) * detail::dot(jd, st.s_B),
          detail::dot(st.s_B, detail::cross(ja, jd))};
}

// Ok, or which joint of the first singular leg is singular (legs without axes never are).
Status singular_joint(const Model& model, const LegState& st, const Coordinates& c) noexcept {
  const Array6d n2 = c.x.square() + c.y.square();
  const Array6d has_axes = model.geometry().has_axes.array();
  // Legs without axes (x = y = 0) are lifted out of the test by 1 - has_axes.
  if ((n2 + (1.0 - has_axes)).minCoeff() >= kSingularSin2) return Status::Ok;
  for (int i = 0; i < kLegs; ++i) {
    if (has_axes[i] == 0.0 || n2[i] >= kSingularSin2) continue;
    const Vector3d s = st.s_B.row(i).transpose();
    return s.cross(model.leg(i).axis_base_B).squaredNorm() <= s.cross(st.axis_platform_B.row(i).transpose()).squaredNorm()
               ? Status::SingularBase
               : Status::SingularPlatform;
  }
  return Status::Ok;
}

// Wraps an angle to (-pi, pi].
double wrap(double a) noexcept { return a - 2.0 * kPi * std::ceil((a - kPi) / (2.0 * kPi)); }

}  // namespace

Status twist_absolute(const Model& model, const LegState& state, Vector6d& theta) noexcept {
  const Coordinates c = coordinates(model, state);
  if (const Status s = singular_joint(model, state, c); s != Status::Ok) return s;
  theta = (detail::atan2(c.y, c.x) * model.geometry().has_axes.array()).matrix();
  return Status::Ok;
}

Status twist(const Model& model, const LegState& state, Vector6d& dtheta) noexcept {
  const Coordinates c = coordinates(model, state);
  if (const Status s = singular_joint(model, state, c); s != Status::Ok) return s;
  // theta - theta_home in one atan2: rotate (x, y) by -theta_home.
  const LegGeometry& g = model.geometry();
  const Array6d c0 = g.cos_theta_home.array(), s0 = g.sin_theta_home.array();
  dtheta = (detail::atan2(c.y * c0 - c.x * s0, c.x * c0 + c.y * s0) * g.has_axes.array()).matrix();
  return Status::Ok;
}

Status twist_continued(const Model& model, const LegState& state, const Vector6d& reference,
                       Vector6d& dtheta) noexcept {
  const Status status = twist(model, state, dtheta);
  if (status != Status::Ok) return status;
  for (int i = 0; i < kLegs; ++i) dtheta[i] = reference[i] + wrap(dtheta[i] - reference[i]);
  return Status::Ok;
}

Status twist_jacobian(const Model& model, const LegState& state, Matrix6d& J) noexcept {
  using detail::cross;
  using detail::dot;
  using detail::scale_rows;
  const Coordinates c = coordinates(model, state);
  if (const Status s = singular_joint(model, state, c); s != Status::Ok) return s;
  const LegGeometry& g = model.geometry();
  const LegVectors& s = state.s_B;
  const LegVectors& ja = g.axis_base_B;
  const LegVectors& jd = state.axis_platform_B;
  // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2), with the partials of y and x in s and jd.
  // Legs without axes have x = y = 0: give them n2 = 1 and mask their rows to zero.
  const Array6d mask = g.has_axes.array();
  const Array6d n2 = c.x.square() + c.y.square() + (1.0 - mask);
  const Array6d fx = mask * c.x / n2, fy = mask * c.y / n2;
  const Array6d ja_s = dot(ja, s), jd_s = dot(jd, s);
  const LegVectors dy_ds = cross(ja, jd);
  const LegVectors dx_ds = -scale_rows(jd_s, ja) - scale_rows(ja_s, jd);
  const LegVectors dy_djd = cross(s, ja);
  const LegVectors dx_djd = ja - scale_rows(ja_s, s);
  const LegVectors g_s = scale_rows(fx, dy_ds) - scale_rows(fy, dx_ds);
  const LegVectors g_jd = scale_rows(fx, dy_djd) - scale_rows(fy, dx_djd);
  // s = L/|L|: ds = (I - s s^T) dL / |L|; dL = dt + dw x arm; djd = dw x jd.
  const LegVectors a = scale_rows(state.length.array().inverse(), g_s - scale_rows(dot(g_s, s), s));
  J.leftCols<3>() = a;
  J.rightCols<3>() = cross(state.arm_B, a) + cross(jd, g_jd);
  return Status::Ok;
}

}  // namespace hexatwist
