// SPDX-License-Identifier: BSD-3-Clause
// The workspace's boundary: slices of the constant-orientation workspace with the limit that
// bounds each boundary point, and the orientation workspace at a position, the largest tilt in
// every direction at several torsions (docs/theory/design.md §16).
#pragma once

#include <vector>

#include "hexatwist/design/workspace_volume.hpp"

namespace hexatwist {

/// A plane of positions: the two coordinates that vary (u, v) and the one held at `offset`.
enum class SlicePlane {
  XY,  ///< u = x, v = y at z = offset
  XZ,  ///< u = x, v = z at y = offset
  YZ,  ///< u = y, v = z at x = offset
};

/// A slice of the constant-orientation workspace.
struct SliceSpec {
  SlicePlane plane = SlicePlane::XY;
  double offset = 0.0;    ///< the fixed coordinate [m] (pivot displacement from home)
  double spacing = 0.01;  ///< between the search lines, each way [m]
};

/// Position [m, B] of the in-plane point (u, v) of a slice.
Vector3d slice_point(const SliceSpec& spec, double u, double v) noexcept;

/// One point of a slice's boundary, found on a search line.
struct BoundaryPoint {
  double u = 0.0, v = 0.0;              ///< the inside point in the plane's coordinates [m]
  Vector3d inside = Vector3d::Zero();   ///< last accepted position [m, B], within tolerance of ...
  Vector3d outside = Vector3d::Zero();  ///< ... the first refused one [m, B]
  LimitReport limit;                    ///< the limit the outside point breaks
  int along = 0;                        ///< 0: on a line along u, 1: along v
};

/// A slice: its boundary points and the area inside.
struct WorkspaceSlice {
  SliceSpec spec;
  Vector3d rpy = Vector3d::Zero();        ///< the orientation [rad]
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;  ///< the searched rectangle (workspace_bounds) [m]
  std::vector<BoundaryPoint> boundary;
  double area = 0.0;  ///< inside length of the lines along u times their spacing [m^2]
};

/// The slice `spec` of the constant-orientation workspace at `rpy` [rad]: lines along u and along
/// v, `spec.spacing` apart across workspace_bounds, each searched by line_intervals; every
/// crossing is a boundary point. Returns as line_intervals, or workspace_bounds' status.
[[nodiscard]] Status workspace_slice(const Model& model, const Vector3d& rpy, const SliceSpec& spec,
                                     const WorkspaceOptions& options, WorkspaceSlice& out);

/// The rotation of tilt-and-torsion angles (Bonev and Ryu 2001): the platform's z axis tilted by
/// `tilt` towards `azimuth` (about z from x), with the torsion `torsion` about it:
/// R = Rz(azimuth) Ry(tilt) Rz(torsion - azimuth). At tilt 0 it is a yaw of `torsion` [rad].
Matrix3d tilt_torsion_rotation(double azimuth, double tilt, double torsion) noexcept;

/// Settings of the orientation workspace.
struct OrientationSpec {
  Vector3d position = Vector3d::Zero();  ///< pivot displacement from home [m, B]
  std::vector<double> torsions{0.0};     ///< torsions (yaw at zero tilt) [rad]
  int directions = 72;                   ///< azimuths, evenly over a turn
  double step = deg2rad(0.5);            ///< tilt march step [rad]
  double max_tilt = deg2rad(90.0);       ///< search no further [rad]
  double tolerance = 1e-9;               ///< bisection bracket [rad]
};

/// Largest tilt towards one azimuth.
struct TiltReach {
  double azimuth = 0.0;  ///< [rad]
  double tilt = 0.0;     ///< largest tilt such that every smaller one is accepted [rad]; NaN when
                         ///< tilt 0 (the torsion alone) is refused
  LimitReport limit;     ///< what the first refused tilt breaks (status Ok: max_tilt reached)
};

/// The orientation workspace at a position.
struct OrientationWorkspace {
  OrientationSpec spec;
  std::vector<std::vector<TiltReach>> reach;  ///< per torsion, per azimuth
};

/// The extremes of one torsion's row of an orientation workspace: the azimuths where the torsion
/// alone is refused (tilt NaN) do not count.
struct TiltExtremes {
  std::size_t reached = 0;        ///< azimuths where the torsion alone is accepted
  double smallest = NAN;          ///< smallest of their largest tilts [rad] (NaN: none reached)
  double smallest_azimuth = NAN;  ///< its azimuth [rad] (the first of equal ones)
  LimitReport smallest_limit;     ///< what bounds it; when none is reached, what refuses the torsion alone
  double largest = NAN;           ///< largest tilt reached [rad]
  double largest_azimuth = NAN;   ///< its azimuth [rad]
};

/// The extremes of `row` (one torsion of OrientationWorkspace::reach).
TiltExtremes tilt_extremes(const std::vector<TiltReach>& row) noexcept;

/// For every torsion and azimuth, the largest tilt (tilt_torsion_rotation) with every smaller tilt
/// accepted by motor_commands for `strategy`, marched and bisected as line_intervals. Returns
/// NonFiniteInput for a bad spec (directions < 1, step or tolerance not > 0, non-finite values).
[[nodiscard]] Status orientation_workspace(const Model& model, const OrientationSpec& spec, Strategy strategy,
                                           OrientationWorkspace& out);

}  // namespace hexatwist
