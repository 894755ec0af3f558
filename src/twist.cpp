#include "hexatwist/twist.hpp"

#include <cmath>

#include "fast_math.hpp"
#include "geometry.hpp"
#include "twist_internal.hpp"

namespace hexatwist {
namespace {

using detail::Array6d;

// Squared |s x ja| |s x jd| below which the U-joint's cross axis (Eq. 8) is undefined.
constexpr double kSingularSin2 = 1e-24;

// Called when the fast test of a packet failed: the singular joint of the leg nearest to a
// singularity (legs without axes never are), by the scalar formula of geometry.hpp. Always
// returns SingularBase or SingularPlatform, so no caller can mistake it for success.
Status singular_joint(const Model& model, const LegState& st) noexcept {
  int worst = -1;
  double worst_n2 = INFINITY;
  for (int i = 0; i < kLegs; ++i) {
    if (model.geometry().has_axes[i] == 0.0) continue;
    const auto xy = detail::twist_xy(st.s_B.row(i).transpose(), model.leg(i).axis_base_B,
                                     st.axis_platform_B.row(i).transpose());
    const double n2 = xy.x * xy.x + xy.y * xy.y;
    if (!(n2 >= worst_n2)) {  // also picks a NaN leg
      worst = i;
      worst_n2 = n2;
    }
  }
  if (worst < 0) return Status::SingularBase;  // unreachable: the fast test passes without axes
  const Vector3d s = st.s_B.row(worst).transpose();
  return s.cross(model.leg(worst).axis_base_B).squaredNorm() <=
                 s.cross(st.axis_platform_B.row(worst).transpose()).squaredNorm()
             ? Status::SingularBase
             : Status::SingularPlatform;
}

// Wraps an angle to (-pi, pi].
double wrap(double a) noexcept { return a - 2.0 * kPi * std::ceil((a - kPi) / (2.0 * kPi)); }

// The twist terms of legs i and i+1 (one packet): the coordinates of docs/theory.md §3,
// theta = atan2(y, x), and the products the Jacobian reuses, kept in registers.
struct PacketTerms {
  detail::v3d s, ja, jd;
  detail::v2d ja_s, jd_s;
  detail::v3d ja_x_jd;
  detail::v2d x, y;
};

PacketTerms packet_terms(const Model& model, const LegState& st, int i) noexcept {
  using namespace detail;
  PacketTerms t;
  t.s = load_rows(st.s_B, i);
  t.ja = load_rows(model.geometry().axis_base_B, i);
  t.jd = load_rows(st.axis_platform_B, i);
  t.ja_s = dot(t.ja, t.s);
  t.jd_s = dot(t.jd, t.s);
  t.ja_x_jd = cross(t.ja, t.jd);
  t.x = dot(t.ja, t.jd) - t.ja_s * t.jd_s;
  t.y = dot(t.s, t.ja_x_jd);
  return t;
}

// Lanes set where the leg is away from a U-joint singularity or has no axes (the fast path of
// singular_joint; NaN fails it, and the slow path then names the joint). Callers AND the masks
// of all packets and test once: extracting lanes costs more than the test itself.
detail::v2m packet_regular(const PacketTerms& t, detail::v2d no_axes) noexcept {
  return (t.x * t.x + t.y * t.y) + no_axes >= kSingularSin2;
}

bool all_lanes(detail::v2m m) noexcept { return (m[0] & m[1]) != 0; }

}  // namespace

namespace {

// Absolute (relative = false) or home-relative twist of all legs, two legs per register.
Status twist_angles(const Model& model, const LegState& state, bool relative, Vector6d& out) noexcept {
  using namespace detail;
  const LegGeometry& g = model.geometry();
  v2d y_rot[3], x_rot[3];
  v2m regular = bits(splat(-0.0)) | ~bits(splat(-0.0));  // all ones
  for (int i = 0; i < kLegs; i += 2) {
    const PacketTerms t = packet_terms(model, state, i);
    regular &= packet_regular(t, 1.0 - load2(g.has_axes.data() + i));
    // theta - theta_home in one atan2: rotate (x, y) by -theta_home.
    const v2d c0 = relative ? load2(g.cos_theta_home.data() + i) : splat(1.0);
    const v2d s0 = relative ? load2(g.sin_theta_home.data() + i) : splat(0.0);
    y_rot[i / 2] = t.y * c0 - t.x * s0;
    x_rot[i / 2] = t.x * c0 + t.y * s0;
  }
  if (!all_lanes(regular)) return singular_joint(model, state);
  for (int i = 0; i < kLegs; i += 2)
    store2(out.data() + i, atan2(y_rot[i / 2], x_rot[i / 2]) * load2(g.has_axes.data() + i));
  return Status::Ok;
}

}  // namespace

Status twist_absolute(const Model& model, const LegState& state, Vector6d& theta) noexcept {
  return twist_angles(model, state, false, theta);
}

Status twist(const Model& model, const LegState& state, Vector6d& dtheta) noexcept {
  return twist_angles(model, state, true, dtheta);
}

Status twist_continued(const Model& model, const LegState& state, const Vector6d& reference,
                       Vector6d& dtheta) noexcept {
  const Status status = twist(model, state, dtheta);
  if (status != Status::Ok) return status;
  for (int i = 0; i < kLegs; ++i) dtheta[i] = reference[i] + wrap(dtheta[i] - reference[i]);
  return Status::Ok;
}

namespace {

// Rows i, i+1 of the twist Jacobian (twist_jacobian), or, with kMotor, of the motor-side length
// Jacobian [s^T, (arm x s)^T] - twist_gain * (twist Jacobian). Returns packet_regular's lane
// mask; where a lane is clear the leg is near a U-joint singularity and J's rows are unspecified.
template <bool kMotor>
detail::v2m jacobian_rows(const Model& model, const LegState& state, int i, Matrix6d& J) noexcept {
  using namespace detail;
  const LegGeometry& g = model.geometry();
  const PacketTerms t = packet_terms(model, state, i);
  const v2d mask = load2(g.has_axes.data() + i);
  const v2m regular = packet_regular(t, 1.0 - mask);
  // d atan2(y, x) = (x dy - y dx) / (x^2 + y^2), with the partials of y and x in s and jd:
  // dy/ds = ja x jd, dx/ds = -(jd.s) ja - (ja.s) jd, dy/djd = s x ja, dx/djd = ja - (ja.s) s.
  // Legs without axes have x = y = 0: give them n2 = 1 and mask their rows to zero.
  const v2d n2 = t.x * t.x + t.y * t.y + (1.0 - mask);
  const v2d fx = mask * t.x / n2, fy = mask * t.y / n2;
  const v3d dx_ds = (-t.jd_s) * t.ja - t.ja_s * t.jd;
  const v3d g_s = fx * t.ja_x_jd - fy * dx_ds;
  const v3d g_jd = fx * cross(t.s, t.ja) - fy * (t.ja - t.ja_s * t.s);
  // s = L/|L|: ds = (I - s s^T) dL / |L|; dL = dt + dw x arm; djd = dw x jd.
  const v2d inv_length = 1.0 / load2(state.length.data() + i);
  const v3d a = inv_length * (g_s - dot(g_s, t.s) * t.s);
  const v3d arm = load_rows(state.arm_B, i);
  const v3d b = cross(arm, a) + cross(t.jd, g_jd);
  const v2d col[6] = {a.x, a.y, a.z, b.x, b.y, b.z};
  if constexpr (kMotor) {
    // J = length Jacobian - twist_gain * twist Jacobian (docs/theory.md §5).
    const v2d gain = load2(g.twist_gain.data() + i);
    const v3d arm_x_s = cross(arm, t.s);
    const v2d length_col[6] = {t.s.x, t.s.y, t.s.z, arm_x_s.x, arm_x_s.y, arm_x_s.z};
    for (int k = 0; k < 6; ++k) store2(J.data() + kLegs * k + i, length_col[k] - gain * col[k]);
  } else {
    for (int k = 0; k < 6; ++k) store2(J.data() + kLegs * k + i, col[k]);
  }
  return regular;
}

template <bool kMotor>
Status jacobian(const Model& model, const LegState& state, Matrix6d& J) noexcept {
  const detail::v2m regular = jacobian_rows<kMotor>(model, state, 0, J) & jacobian_rows<kMotor>(model, state, 2, J) &
                              jacobian_rows<kMotor>(model, state, 4, J);
  return all_lanes(regular) ? Status::Ok : singular_joint(model, state);
}

}  // namespace

Status twist_jacobian(const Model& model, const LegState& state, Matrix6d& J) noexcept {
  // Computed into a temporary so that J is left untouched at a singular joint, as before.
  Matrix6d J_twist;
  if (const Status s = jacobian<false>(model, state, J_twist); s != Status::Ok) return s;
  J = J_twist;
  return Status::Ok;
}

namespace detail {

Status motor_length_jacobian(const Model& model, const LegState& state, Matrix6d& J) noexcept {
  return jacobian<true>(model, state, J);
}

}  // namespace detail

}  // namespace hexatwist
