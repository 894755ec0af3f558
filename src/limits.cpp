#include "hexatwist/limits.hpp"

#include <cmath>

#include "geometry.hpp"

namespace hexatwist {
namespace {

using detail::angle_between;
using detail::Array6d;
using detail::line_axis_angle;

Status report_violation(LimitReport& r, Status s, int leg, double value, double bound) noexcept {
  r.status = s;
  r.leg = leg;
  r.value = value;
  r.bound = bound;
  return s;
}

}  // namespace

void bend_angles(const Model& model, const LegState& state, Vector6d& bend_base, Vector6d& bend_platform) noexcept {
  for (int i = 0; i < kLegs; ++i) {
    const Vector3d s = state.s_B.row(i).transpose();
    const Vector3d& s0 = model.leg(i).s_home_B;
    bend_base[i] = angle_between(s, s0);
    bend_platform[i] = angle_between(state.R_BP.transpose() * s, s0);
  }
}

Status check_limits(const Model& model, const LegState& state, LimitReport& r) noexcept {
  r = LimitReport{};
  const LimitSpec& lim = model.spec().limits;
  const LegGeometry& g = model.geometry();
  const double cos_bend = model.cos_bend_max();
  const double cos2_margin = model.cos2_singularity_margin();
  const LegVectors& s = state.s_B;
  // All legs at once, without trigonometry: bend as cosines to the home direction seen from
  // each end; singularity as (s . axis)^2 > cos^2(margin) for unit vectors.
  const Array6d len = state.length.array();
  const Array6d cos_base = detail::dot(s, g.s_home_B);
  const Array6d cos_platform = detail::dot(s, detail::rotate_rows(state.R_BP, g.s_home_B));
  const Array6d dot_a = detail::dot(s, g.axis_base_B);
  const Array6d dot_d = detail::dot(s, state.axis_platform_B);
  // Every slack below must be >= 0. Legs without axes have zero axis rows, so dot_a = dot_d = 0
  // passes. NaN lanes could vanish in min(), so finiteness is tested on the sums.
  const Array6d slack = (len - lim.length_min)
                            .min(lim.length_max - len)
                            .min(cos_base - cos_bend)
                            .min(cos_platform - cos_bend)
                            .min(cos2_margin - dot_a.square())
                            .min(cos2_margin - dot_d.square());
  if (slack.minCoeff() >= 0.0 && (len.sum() + cos_platform.sum() + dot_d.sum()) * 0.0 == 0.0) return Status::Ok;

  // Some leg is out: name the first, with the first limit it breaks (stroke, bend, singularity).
  for (int i = 0; i < kLegs; ++i) {
    const Vector3d si = s.row(i).transpose();
    if (!std::isfinite(len[i])) return report_violation(r, Status::NonFiniteInput, i, len[i], 0.0);
    if (len[i] < lim.length_min) return report_violation(r, Status::StrokeBelowMin, i, len[i], lim.length_min);
    if (len[i] > lim.length_max) return report_violation(r, Status::StrokeAboveMax, i, len[i], lim.length_max);
    if (!(cos_base[i] >= cos_bend))
      return report_violation(r, Status::BendBase, i, angle_between(si, model.leg(i).s_home_B), lim.bend_max);
    if (!(cos_platform[i] >= cos_bend))
      return report_violation(r, Status::BendPlatform, i, angle_between(state.R_BP.transpose() * si, model.leg(i).s_home_B),
                              lim.bend_max);
    if (g.has_axes[i] == 0.0) continue;
    if (dot_a[i] * dot_a[i] > cos2_margin)
      return report_violation(r, Status::SingularBase, i, line_axis_angle(si, model.leg(i).axis_base_B), lim.singularity_margin);
    if (dot_d[i] * dot_d[i] > cos2_margin)
      return report_violation(r, Status::SingularPlatform, i, line_axis_angle(si, state.axis_platform_B.row(i).transpose()),
                              lim.singularity_margin);
  }
  return report_violation(r, Status::NonFiniteInput, -1, 0.0, 0.0);  // NaN in the leg axes
}

Status check_stroke(const Model& model, const Vector6d& command, LimitReport& r) noexcept {
  r = LimitReport{};
  const LimitSpec& lim = model.spec().limits;
  const Array6d c = command.array();
  if ((c - lim.length_min).min(lim.length_max - c).minCoeff() >= 0.0 && c.sum() * 0.0 == 0.0) return Status::Ok;
  for (int i = 0; i < kLegs; ++i) {
    if (!std::isfinite(command[i])) return report_violation(r, Status::NonFiniteInput, i, command[i], 0.0);
    if (command[i] < lim.length_min) return report_violation(r, Status::StrokeBelowMin, i, command[i], lim.length_min);
    if (command[i] > lim.length_max) return report_violation(r, Status::StrokeAboveMax, i, command[i], lim.length_max);
  }
  return Status::Ok;
}

}  // namespace hexatwist
