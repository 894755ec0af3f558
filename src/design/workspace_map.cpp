// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/design/workspace_map.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "design/parallel.hpp"

namespace hexatwist {

Status map_point(const Model& model, const Pose& pose, Strategy strategy, MapPoint& out) noexcept {
  out = MapPoint{};
  Vector6d command;
  out.status = motor_commands(model, pose, strategy, command, out.limit);
  if (out.status != Status::Ok) return out.status;
  CommandReport report;
  if (const Status s = compute_commands(model, pose, report); s != Status::Ok && strategy == Strategy::Compensated) {
    // motor_commands and compute_commands decide alike (compensation.hpp); kept as a guard.
    out.status = s;
    out.limit = report.limit;
    return s;
  }
  Eigen::Index leg = 0;
  out.max_twist = report.twist.cwiseAbs().maxCoeff(&leg);
  out.twist_leg = static_cast<int>(leg);
  out.max_length_error = report.length_error.cwiseAbs().maxCoeff(&leg);
  out.length_error_leg = static_cast<int>(leg);
  // The condition is within its limit here (motor_commands passed): the status is Ok.
  (void)jacobian_condition(model, report.legs, out.condition);
  nearest_limit(model, report.legs, out.condition, out.nearest, out.margin);
  return Status::Ok;
}

MapGrid map_grid_around(const WorkspaceSlice& slice, double spacing) {
  MapGrid g;
  g.plane = slice.spec.plane;
  g.offset = slice.spec.offset;
  double u0 = slice.u0, u1 = slice.u1, v0 = slice.v0, v1 = slice.v1;
  if (!slice.boundary.empty()) {
    u0 = v0 = INFINITY;
    u1 = v1 = -INFINITY;
    for (const BoundaryPoint& p : slice.boundary) {
      u0 = std::min(u0, p.u), u1 = std::max(u1, p.u);
      v0 = std::min(v0, p.v), v1 = std::max(v1, p.v);
    }
    u0 -= spacing, u1 += spacing, v0 -= spacing, v1 += spacing;
  }
  g.u0 = u0, g.u1 = u1, g.v0 = v0, g.v1 = v1;
  g.nu = std::max(2, static_cast<int>(std::lround((u1 - u0) / spacing)) + 1);
  g.nv = std::max(2, static_cast<int>(std::lround((v1 - v0) / spacing)) + 1);
  return g;
}

Vector3d map_node_position(const MapGrid& grid, std::size_t k) noexcept {
  SliceSpec spec;
  spec.plane = grid.plane;
  spec.offset = grid.offset;
  const std::size_t nu = static_cast<std::size_t>(std::max(grid.nu, 1));
  return slice_point(spec, grid.u(static_cast<int>(k % nu)), grid.v(static_cast<int>(k / nu)));
}

MapSummary summarize_map(const WorkspaceMap& map) noexcept {
  MapSummary s;
  // !(x <= best) takes the first value and then each larger one; a NaN best is replaced, a NaN x never wins.
  const auto larger = [](double x, double best) { return !std::isnan(x) && !(x <= best); };
  for (std::size_t k = 0; k < map.points.size(); ++k) {
    const MapPoint& p = map.points[k];
    if (p.status != Status::Ok) continue;
    ++s.inside;
    if (larger(p.max_twist, s.max_twist))
      s.max_twist = p.max_twist, s.max_twist_node = k, s.max_twist_leg = p.twist_leg;
    if (larger(p.max_length_error, s.max_length_error))
      s.max_length_error = p.max_length_error, s.max_length_error_node = k;
    if (larger(-p.condition, -s.condition_min)) s.condition_min = p.condition;
    if (larger(p.condition, s.condition_max)) s.condition_max = p.condition;
    if (larger(-p.margin, -s.margin_min))
      s.margin_min = p.margin, s.margin_min_node = k, s.margin_min_limit = p.nearest;
  }
  return s;
}

void workspace_map_rows(const Model& model, const Vector3d& rpy, const MapGrid& grid, Strategy strategy, int first_row,
                        int rows, MapPoint* out) noexcept {
  SliceSpec spec;
  spec.plane = grid.plane;
  spec.offset = grid.offset;
  for (int r = 0; r < rows; ++r)
    for (int i = 0; i < grid.nu; ++i) {
      Pose pose;
      pose.position = slice_point(spec, grid.u(i), grid.v(first_row + r));
      pose.rpy = rpy;
      (void)map_point(
          model, pose, strategy,
          out[static_cast<std::size_t>(r) * static_cast<std::size_t>(grid.nu) + static_cast<std::size_t>(i)]);
    }
}

Status workspace_map(const Model& model, const Vector3d& rpy_in, const MapGrid& grid_in, Strategy strategy,
                     WorkspaceMap& out, int threads, const std::function<void(std::size_t, std::size_t)>& progress) {
  const MapGrid grid = grid_in;  // copies: the caller may pass out.grid and out.rpy
  const Vector3d rpy = rpy_in;
  out = WorkspaceMap{};
  out.grid = grid;
  out.rpy = rpy;
  if (grid.nu < 2 || grid.nv < 2 || !std::isfinite(grid.u0) || !std::isfinite(grid.u1) || !std::isfinite(grid.v0) ||
      !std::isfinite(grid.v1) || !std::isfinite(grid.offset) || !rpy.allFinite())
    return Status::NonFiniteInput;
  out.points.resize(grid.size());
  detail::BlockProgress done(progress, static_cast<std::size_t>(grid.nv));
  detail::for_blocks(static_cast<std::size_t>(grid.nv), 1, threads, [&](std::size_t begin, std::size_t end) {
    workspace_map_rows(model, rpy, grid, strategy, static_cast<int>(begin), static_cast<int>(end - begin),
                       out.points.data() + begin * static_cast<std::size_t>(grid.nu));
    done.add(end - begin);
  });
  return Status::Ok;
}

}  // namespace hexatwist
