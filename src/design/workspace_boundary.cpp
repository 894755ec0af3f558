// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/design/workspace_boundary.hpp"

#include <algorithm>
#include <cmath>

#include "design/search.hpp"

namespace hexatwist {

Vector3d slice_point(const SliceSpec& spec, double u, double v) noexcept {
  switch (spec.plane) {
    case SlicePlane::XZ:
      return {u, spec.offset, v};
    case SlicePlane::YZ:
      return {spec.offset, u, v};
    case SlicePlane::XY:
      break;
  }
  return {u, v, spec.offset};
}

namespace {

// The coordinate indices (u, v, fixed) of a plane.
struct Axes {
  int u, v, fixed;
};
Axes axes_of(SlicePlane p) noexcept {
  switch (p) {
    case SlicePlane::XZ:
      return {0, 2, 1};
    case SlicePlane::YZ:
      return {1, 2, 0};
    case SlicePlane::XY:
      break;
  }
  return {0, 1, 2};
}

// Line k of n across [lo, hi], at the middle of its strip.
double strip_centre(double lo, double hi, long k, long n) {
  return lo + (hi - lo) * (static_cast<double>(k) + 0.5) / static_cast<double>(n);
}

}  // namespace

Status workspace_slice(const Model& model, const Vector3d& rpy_in, const SliceSpec& spec_in,
                       const WorkspaceOptions& options, WorkspaceSlice& out) {
  const Vector3d rpy = rpy_in;  // copies: the caller may pass out.rpy and out.spec
  const SliceSpec spec = spec_in;
  out = WorkspaceSlice{};
  out.spec = spec;
  out.rpy = rpy;
  if (!detail::search_options_valid(options) || !(spec.spacing > 0.0) || !std::isfinite(spec.spacing) ||
      !std::isfinite(spec.offset) || !rpy.allFinite())
    return Status::NonFiniteInput;
  Box box;
  if (const Status s = workspace_bounds(model, rpy, box); s != Status::Ok) return s;
  const Axes ax = axes_of(spec.plane);
  out.u0 = box.lower[ax.u];
  out.u1 = box.upper[ax.u];
  out.v0 = box.lower[ax.v];
  out.v1 = box.upper[ax.v];
  if (spec.offset < box.lower[ax.fixed] || spec.offset > box.upper[ax.fixed]) return Status::Ok;  // nothing there

  std::vector<LineInterval> intervals;
  for (int along = 0; along < 2; ++along) {
    // Lines along u (along = 0) are stacked in v, and the other way round.
    const double lo = along == 0 ? out.v0 : out.u0, hi = along == 0 ? out.v1 : out.u1;
    const double t0 = along == 0 ? out.u0 : out.v0, t1 = along == 0 ? out.u1 : out.v1;
    const long n = std::max(1L, static_cast<long>(std::ceil((hi - lo) / spec.spacing)));
    Vector3d direction = Vector3d::Zero();
    direction[along == 0 ? ax.u : ax.v] = 1.0;
    for (long k = 0; k < n; ++k) {
      const double c = strip_centre(lo, hi, k, n);
      const Vector3d origin = along == 0 ? slice_point(spec, 0.0, c) : slice_point(spec, c, 0.0);
      const detail::PositionProbe probe{model, rpy, origin, direction, options.strategy};
      detail::march(probe, t0, t1, options, intervals);
      for (const LineInterval& iv : intervals) {
        if (along == 0) out.area += (iv.upper.inside - iv.lower.inside) * (hi - lo) / static_cast<double>(n);
        for (const Crossing* end : {&iv.lower, &iv.upper}) {
          if (end->limit.status == Status::Ok) continue;  // the search range's end, not the workspace's
          BoundaryPoint p;
          p.inside = origin + end->inside * direction;
          p.outside = origin + end->outside * direction;
          p.u = p.inside[ax.u];
          p.v = p.inside[ax.v];
          p.limit = end->limit;
          p.along = along;
          out.boundary.push_back(p);
        }
      }
    }
  }
  return Status::Ok;
}

Matrix3d tilt_torsion_rotation(double azimuth, double tilt, double torsion) noexcept {
  return (Eigen::AngleAxisd(azimuth, Vector3d::UnitZ()) * Eigen::AngleAxisd(tilt, Vector3d::UnitY()) *
          Eigen::AngleAxisd(torsion - azimuth, Vector3d::UnitZ()))
      .toRotationMatrix();
}

Status orientation_workspace(const Model& model, const OrientationSpec& spec_in, Strategy strategy,
                             OrientationWorkspace& out) {
  const OrientationSpec spec = spec_in;  // a copy: the caller may pass out.spec
  out = OrientationWorkspace{};
  out.spec = spec;
  if (spec.directions < 1 || !(spec.step > 0.0) || !std::isfinite(spec.step) || !(spec.tolerance > 0.0) ||
      !std::isfinite(spec.tolerance) || !(spec.max_tilt > 0.0) || !std::isfinite(spec.max_tilt) ||
      !spec.position.allFinite() ||
      !std::all_of(spec.torsions.begin(), spec.torsions.end(), [](double t) { return std::isfinite(t); }))
    return Status::NonFiniteInput;
  for (const double torsion : spec.torsions) {
    std::vector<TiltReach> row;
    for (int j = 0; j < spec.directions; ++j) {
      TiltReach r;
      r.azimuth = 2.0 * kPi * static_cast<double>(j) / static_cast<double>(spec.directions);
      const auto probe = [&](double tilt, LimitReport& report) {
        Pose pose;
        pose.position = spec.position;
        pose.rpy = rpy_from_rotation(tilt_torsion_rotation(r.azimuth, tilt, torsion));
        return detail::accepts(model, pose, strategy, report);
      };
      if (!probe(0.0, r.limit)) {
        r.tilt = NAN;
      } else {
        const Crossing c = detail::first_exit(probe, 0.0, spec.max_tilt, spec.step, spec.tolerance);
        r.tilt = c.inside;
        r.limit = c.limit;
      }
      row.push_back(r);
    }
    out.reach.push_back(std::move(row));
  }
  return Status::Ok;
}

TiltExtremes tilt_extremes(const std::vector<TiltReach>& row) noexcept {
  TiltExtremes e;
  for (const TiltReach& r : row) {
    if (std::isnan(r.tilt)) continue;
    ++e.reached;
    if (!(r.tilt >= e.smallest)) e.smallest = r.tilt, e.smallest_azimuth = r.azimuth, e.smallest_limit = r.limit;
    if (!(r.tilt <= e.largest)) e.largest = r.tilt, e.largest_azimuth = r.azimuth;
  }
  if (e.reached == 0 && !row.empty()) e.smallest_limit = row.front().limit;
  return e;
}

}  // namespace hexatwist
