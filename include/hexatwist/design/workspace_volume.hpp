// SPDX-License-Identifier: BSD-3-Clause
// The constant-orientation workspace and its volume (docs/theory/design.md §16): the positions the
// platform reaches at one orientation inside every limit, found along lines and integrated by
// columns over a grid refined at the boundary of its shadow.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "hexatwist/kinematics/compensation.hpp"

namespace hexatwist {

/// How the workspaces are searched. A pose is in the workspace when motor_commands accepts it for
/// `strategy`: every pose limit (stroke, U-joint bend, U-joint singularity margin, platform
/// singularity) and the command's stroke, as `hexatwist ik` decides.
struct WorkspaceOptions {
  Strategy strategy = Strategy::Compensated;  ///< the commands whose limits count
  double step = 0.005;                        ///< march step along a search line [m]
  double tolerance = 1e-9;                    ///< a boundary is bisected to this bracket [m]
};

/// An axis-aligned box [m, B].
struct Box {
  Vector3d lower = Vector3d::Zero();
  Vector3d upper = Vector3d::Zero();
};

/// A box holding every position (pivot displacement from home) reachable at orientation `rpy`
/// [rad]: each platform joint within the stroke of its base joint and its leg within bend_max of
/// the leg's home direction (the base U-joint's bend), box by box. Returns NonFiniteInput for a
/// non-finite `rpy`, StrokeAboveMax when the legs' boxes do not meet.
[[nodiscard]] Status workspace_bounds(const Model& model, const Vector3d& rpy, Box& box) noexcept;

/// Where a search line leaves the workspace: the last accepted and the first refused parameter,
/// at most `tolerance` apart, and the limit the refused one breaks.
struct Crossing {
  double inside = 0.0;   ///< line parameter of the last accepted point [m]
  double outside = 0.0;  ///< line parameter of the first refused point [m]
  LimitReport limit;     ///< what the refused point breaks; status Ok where the search range ended inside
};

/// One stretch of a line inside the workspace: [lower.inside, upper.inside].
struct LineInterval {
  Crossing lower;  ///< its end towards smaller parameters
  Crossing upper;  ///< its end towards larger parameters
};

/// The stretches of the line origin + t direction (t in [t0, t1] [m]; direction a unit vector
/// [-, B], origin [m, B], both pivot displacements from home) inside the workspace at orientation
/// `rpy` [rad]: marched at options.step, every change bisected to options.tolerance. A stretch
/// shorter than a step between two refused samples can be missed. Returns NonFiniteInput for
/// non-finite input or options that cannot march (step or tolerance not > 0, t1 < t0).
[[nodiscard]] Status line_intervals(const Model& model, const Vector3d& rpy, const Vector3d& origin_B,
                                    const Vector3d& direction_B, double t0, double t1, const WorkspaceOptions& options,
                                    std::vector<LineInterval>& out);

/// Settings of workspace_volume.
struct VolumeOptions {
  WorkspaceOptions search;  ///< the column searches along z
  /// Side of a grid cell in x and y [m]; 0 = the larger horizontal side of workspace_bounds / 64.
  double cell = 0.0;
  int refine = 3;   ///< how many times a cell across the shadow's edge is split in four (0..8)
  int threads = 1;  ///< threads of the computation (0 = every core); the result does not depend on it
  /// Called (may be empty) with (coarse cells done, coarse cells in all) after each row of cells, one
  /// call at a time from the computing threads; an exception it throws ends the computation and
  /// propagates. Not part of the result: any callback gives the same volume.
  std::function<void(std::size_t, std::size_t)> progress;
};

/// The x-y grid of a volume computation: coarse cells of side 2 * cell, each split into four cells
/// of side `cell` for the volume and taken whole for its coarse twin.
struct VolumeGrid {
  Vector3d rpy = Vector3d::Zero();  ///< the orientation [rad]
  Box box;                          ///< workspace_bounds [m]
  double cell = 0.0;                ///< fine cell side [m]
  int refine = 3;                   ///< edge refinements
  double x0 = 0.0, y0 = 0.0;        ///< lower corner of the grid [m]
  int nx = 0, ny = 0;               ///< coarse cells along x and y
  /// Coarse cells, the unit a computation is split in.
  std::size_t cells() const noexcept { return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny); }
};

/// The constant-orientation workspace's volume.
struct WorkspaceVolume {
  VolumeGrid grid;
  double volume = 0.0;         ///< integral of the columns' inside length over the grid [m^3]
  double coarse_volume = 0.0;  ///< the same rule on the grid twice as coarse [m^3]
  double error = 0.0;          ///< |volume - coarse_volume|: the stated error of `volume` [m^3]
  std::uint64_t columns = 0;   ///< column searches made
};

/// The grid for `options` at orientation `rpy` [rad]. Returns as workspace_bounds, or
/// NonFiniteInput for options out of range (cell < 0, refine outside 0..8, a search that cannot march).
[[nodiscard]] Status volume_grid(const Model& model, const Vector3d& rpy, const VolumeOptions& options,
                                 VolumeGrid& grid);

/// The contributions of coarse cells [first, first + count) (row-major, x fastest): `fine[k]`
/// (the four cells of side grid.cell, each refined where it crosses the shadow's edge) and
/// `coarse[k]` (the coarse cell refined alike) [m^3], and the column searches made. Depends only on
/// the grid and the cell index: any split of the cells gives the same numbers.
std::uint64_t volume_cells(const Model& model, const VolumeGrid& grid, const WorkspaceOptions& search,
                           std::size_t first, std::size_t count, double* fine, double* coarse);

/// The volume from every cell's contributions, summed in cell order.
WorkspaceVolume volume_from_cells(const VolumeGrid& grid, const std::vector<double>& fine,
                                  const std::vector<double>& coarse, std::uint64_t columns);

/// Volume of the constant-orientation workspace at `rpy` [rad] (docs/theory/design.md §16): over
/// the grid, the length of each z column inside the workspace (line_intervals), integrated by the
/// trapezoidal rule, cells across the shadow's edge split `refine` times; `error` is its difference
/// to the same rule on the grid twice as coarse. Returns as volume_grid.
[[nodiscard]] Status workspace_volume(const Model& model, const Vector3d& rpy, const VolumeOptions& options,
                                      WorkspaceVolume& out);

}  // namespace hexatwist
