// SPDX-License-Identifier: BSD-3-Clause
// Maps over a slice of the constant-orientation workspace (docs/theory/design.md §16): at each grid
// point inside, the largest |twist| and |length error| and the leg that has them, the Jacobian's
// condition number (dexterity) and the share left to the nearest limit.
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "hexatwist/design/workspace_boundary.hpp"

namespace hexatwist {

/// A regular grid over a slice: nu x nv nodes, u from u0 to u1 and v from v0 to v1 inclusive.
struct MapGrid {
  SlicePlane plane = SlicePlane::XY;
  double offset = 0.0;        ///< the fixed coordinate [m]
  double u0 = 0.0, u1 = 0.0;  ///< [m]
  double v0 = 0.0, v1 = 0.0;  ///< [m]
  int nu = 0, nv = 0;         ///< nodes along u and v (>= 2 each)
  /// u of node column i, v of node row j [m].
  double u(int i) const noexcept { return u0 + (u1 - u0) * i / (nu - 1); }
  double v(int j) const noexcept { return v0 + (v1 - v0) * j / (nv - 1); }
  /// Nodes in all.
  std::size_t size() const noexcept { return static_cast<std::size_t>(nu) * static_cast<std::size_t>(nv); }
};

/// What the map holds at one pose.
struct MapPoint {
  Status status = Status::Ok;     ///< motor_commands' verdict
  LimitReport limit;              ///< the limit broken when status is not Ok
  double max_twist = NAN;         ///< largest |twist| over the legs [rad]; NaN outside the workspace
  int twist_leg = -1;             ///< its leg, 0-based (-1 outside)
  double max_length_error = NAN;  ///< largest |length error| (Eq. 10) [m]
  int length_error_leg = -1;      ///< its leg, 0-based
  double condition = NAN;         ///< the motor-side Jacobian's condition number (jacobian_condition) [-]
  double margin = NAN;            ///< share of its range left to the nearest limit (nearest_limit) [-]
  LimitReport nearest;            ///< that limit
};

/// The map's quantities at one pose (compute_commands, jacobian_condition, nearest_limit); the
/// status is motor_commands' for `strategy`. Outside the workspace only status and limit are set.
[[nodiscard]] Status map_point(const Model& model, const Pose& pose, Strategy strategy, MapPoint& out) noexcept;

/// A map: the grid's nodes row by row (v rows of u), at one orientation.
struct WorkspaceMap {
  MapGrid grid;
  Vector3d rpy = Vector3d::Zero();  ///< [rad]
  std::vector<MapPoint> points;     ///< index j * nu + i for node (u(i), v(j))
};

/// The pose position of node k (index j * nu + i) of `grid`: a pivot displacement from home [m, B].
Vector3d map_node_position(const MapGrid& grid, std::size_t k) noexcept;

/// The extremes of a map over its nodes inside the workspace (status Ok), each with the node where
/// it is reached first in node order; every field NaN (and every node 0) when no node is inside.
struct MapSummary {
  std::size_t inside = 0;          ///< nodes inside the workspace
  double max_twist = NAN;          ///< largest |twist| [rad]
  std::size_t max_twist_node = 0;  ///< its node
  int max_twist_leg = -1;          ///< its leg, 0-based
  double max_length_error = NAN;   ///< largest |length error| [m]
  std::size_t max_length_error_node = 0;
  double condition_min = NAN;       ///< the Jacobian's condition number, smallest [-]
  double condition_max = NAN;       ///< and largest [-]
  double margin_min = NAN;          ///< smallest share left to the nearest limit [-]
  std::size_t margin_min_node = 0;  ///< its node
  LimitReport margin_min_limit;     ///< that limit
};

/// The extremes of `map` (the CLI's summary and Python's WorkspaceMap.summary()).
MapSummary summarize_map(const WorkspaceMap& map) noexcept;

/// The grid over a slice's searched rectangle shrunk to its boundary points (plus one grid step
/// each side), with nodes about `spacing` [m] apart (at least 2 each way). Falls back to the whole
/// rectangle for a slice without boundary points.
MapGrid map_grid_around(const WorkspaceSlice& slice, double spacing);

/// Rows [first_row, first_row + rows) of the map into out[0 .. rows * nu) (map_point at each node).
void workspace_map_rows(const Model& model, const Vector3d& rpy, const MapGrid& grid, Strategy strategy, int first_row,
                        int rows, MapPoint* out) noexcept;

/// The whole map, split over `threads` threads (0 = every core) by rows; the result does not depend
/// on it. `progress` (may be empty) is called with (rows done, rows in all) after each row, one call
/// at a time from the computing threads; an exception it throws ends the map and propagates.
/// Returns NonFiniteInput for a grid with fewer than 2 nodes a way or non-finite bounds.
[[nodiscard]] Status workspace_map(const Model& model, const Vector3d& rpy, const MapGrid& grid, Strategy strategy,
                                   WorkspaceMap& out, int threads = 1,
                                   const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace hexatwist
