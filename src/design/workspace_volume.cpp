// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/design/workspace_volume.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "design/parallel.hpp"
#include "design/search.hpp"

namespace hexatwist {

Status workspace_bounds(const Model& model, const Vector3d& rpy, Box& box) noexcept {
  box = Box{};
  if (!std::isfinite(rpy.x()) || !std::isfinite(rpy.y()) || !std::isfinite(rpy.z())) return Status::NonFiniteInput;
  // Platform joint i lies at b_i + l s_i with l in the stroke and s_i within bend_max of its home
  // direction (the base bend, check_limits): a sector of a spherical shell, whose box holds it. The
  // pivot's displacement t is that joint minus pivot_home + R arm_i. The bounds are widened by a
  // part in 1e9 so that a point on a limit stays inside after rounding.
  const Matrix3d R = rotation_from_rpy(rpy);
  const LimitSpec& lim = model.spec().limits;
  const double lmin = lim.length_min, lmax = lim.length_max * (1.0 + 1e-9);
  const double bend = lim.bend_max * (1.0 + 1e-9) + 1e-9;
  Vector3d lower = Vector3d::Constant(-INFINITY), upper = Vector3d::Constant(INFINITY);
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = model.leg(i);
    const Vector3d c = leg.base_B - model.pivot_home_B() - R * leg.arm_P;
    for (int k = 0; k < 3; ++k) {
      // The extremes of s_k over the cone of half-angle `bend` about s_home: at the angles from
      // e_k nearest and farthest from the cone's axis.
      const double gamma = std::acos(std::clamp(leg.s_home_B[k], -1.0, 1.0));
      const double s_max = std::cos(std::max(0.0, gamma - bend));
      const double s_min = std::cos(std::min(kPi, gamma + bend));
      lower[k] = std::max(lower[k], c[k] + std::min(lmin * s_min, lmax * s_min) - 1e-9);
      upper[k] = std::min(upper[k], c[k] + std::max(lmin * s_max, lmax * s_max) + 1e-9);
    }
  }
  if (!(lower.array() <= upper.array()).all()) return Status::StrokeAboveMax;
  box.lower = lower;
  box.upper = upper;
  return Status::Ok;
}

Status line_intervals(const Model& model, const Vector3d& rpy, const Vector3d& origin_B, const Vector3d& direction_B,
                      double t0, double t1, const WorkspaceOptions& options, std::vector<LineInterval>& out) {
  out.clear();
  if (!detail::search_options_valid(options) || !(t1 >= t0) || !std::isfinite(t0) || !std::isfinite(t1) ||
      !origin_B.allFinite() || !direction_B.allFinite() || !rpy.allFinite())
    return Status::NonFiniteInput;
  const detail::PositionProbe probe{model, rpy, origin_B, direction_B, options.strategy};
  detail::march(probe, t0, t1, options, out);
  return Status::Ok;
}

Status volume_grid(const Model& model, const Vector3d& rpy_in, const VolumeOptions& options, VolumeGrid& grid) {
  const Vector3d rpy = rpy_in;  // a copy: the caller may pass grid.rpy
  grid = VolumeGrid{};
  if (!detail::search_options_valid(options.search) || !(options.cell >= 0.0) || !std::isfinite(options.cell) ||
      options.refine < 0 || options.refine > 8)
    return Status::NonFiniteInput;
  if (const Status s = workspace_bounds(model, rpy, grid.box); s != Status::Ok) return s;
  grid.rpy = rpy;
  grid.refine = options.refine;
  const Vector3d span = grid.box.upper - grid.box.lower;
  grid.cell = options.cell > 0.0 ? options.cell : std::max(span.x(), span.y()) / 64.0;
  if (!(grid.cell > 0.0)) grid.cell = 1e-3;  // a degenerate box: one cell around it
  // Coarse cells of side 2 * cell cover the box, centred on it.
  const double coarse = 2.0 * grid.cell;
  grid.nx = std::max(1, static_cast<int>(std::ceil(span.x() / coarse)));
  grid.ny = std::max(1, static_cast<int>(std::ceil(span.y() / coarse)));
  grid.x0 = 0.5 * (grid.box.lower.x() + grid.box.upper.x()) - 0.5 * coarse * grid.nx;
  grid.y0 = 0.5 * (grid.box.lower.y() + grid.box.upper.y()) - 0.5 * coarse * grid.ny;
  return Status::Ok;
}

namespace {

// The columns of one block of cells, by node of the finest lattice (side cell / 2^refine); a node
// shared by two blocks is searched in both, with the same result.
class Columns {
 public:
  Columns(const Model& model, const VolumeGrid& grid, const WorkspaceOptions& search)
      : model_(model), grid_(grid), search_(search), unit_(grid.cell / static_cast<double>(1 << grid.refine)) {}

  // Inside length of the z column at lattice node (a, b) [m].
  double length(std::int64_t a, std::int64_t b) {
    const std::uint64_t key = (static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b);
    if (const auto it = cache_.find(key); it != cache_.end()) return it->second;
    const Vector3d origin(grid_.x0 + static_cast<double>(a) * unit_, grid_.y0 + static_cast<double>(b) * unit_, 0.0);
    const detail::PositionProbe probe{model_, grid_.rpy, origin, Vector3d::UnitZ(), search_.strategy};
    detail::march(probe, grid_.box.lower.z(), grid_.box.upper.z(), search_, intervals_);
    double sum = 0.0;
    for (const LineInterval& iv : intervals_) sum += iv.upper.inside - iv.lower.inside;
    ++searches_;
    cache_.emplace(key, sum);
    return sum;
  }

  // The trapezoidal rule on the square cell of `size` lattice units at (a, b), split in four while
  // its corners disagree on being inside the shadow and `depth` allows [m^3].
  double cell(std::int64_t a, std::int64_t b, std::int64_t size, int depth) {
    const double l00 = length(a, b), l10 = length(a + size, b);
    const double l01 = length(a, b + size), l11 = length(a + size, b + size);
    const int inside = (l00 > 0.0) + (l10 > 0.0) + (l01 > 0.0) + (l11 > 0.0);
    if (inside == 0) return 0.0;
    if (inside == 4 || depth == 0) {
      const double side = static_cast<double>(size) * unit_;
      return side * side * 0.25 * (l00 + l10 + l01 + l11);
    }
    const std::int64_t h = size / 2;
    return cell(a, b, h, depth - 1) + cell(a + h, b, h, depth - 1) + cell(a, b + h, h, depth - 1) +
           cell(a + h, b + h, h, depth - 1);
  }

  std::uint64_t searches() const noexcept { return searches_; }

 private:
  const Model& model_;
  const VolumeGrid& grid_;
  const WorkspaceOptions& search_;
  double unit_;
  std::unordered_map<std::uint64_t, double> cache_;
  std::vector<LineInterval> intervals_;
  std::uint64_t searches_ = 0;
};

}  // namespace

std::uint64_t volume_cells(const Model& model, const VolumeGrid& grid, const WorkspaceOptions& search,
                           std::size_t first, std::size_t count, double* fine, double* coarse) {
  Columns columns(model, grid, search);
  const std::int64_t fine_size = std::int64_t{1} << grid.refine;  // a fine cell in lattice units
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t c = first + k;
    const auto I = static_cast<std::int64_t>(c % static_cast<std::size_t>(grid.nx));
    const auto J = static_cast<std::int64_t>(c / static_cast<std::size_t>(grid.nx));
    const std::int64_t a = 2 * fine_size * I, b = 2 * fine_size * J;
    fine[k] = columns.cell(a, b, fine_size, grid.refine) + columns.cell(a + fine_size, b, fine_size, grid.refine) +
              columns.cell(a, b + fine_size, fine_size, grid.refine) +
              columns.cell(a + fine_size, b + fine_size, fine_size, grid.refine);
    coarse[k] = columns.cell(a, b, 2 * fine_size, grid.refine);
  }
  return columns.searches();
}

WorkspaceVolume volume_from_cells(const VolumeGrid& grid, const std::vector<double>& fine,
                                  const std::vector<double>& coarse, std::uint64_t columns) {
  WorkspaceVolume v;
  v.grid = grid;
  for (const double f : fine) v.volume += f;
  for (const double c : coarse) v.coarse_volume += c;
  v.error = std::abs(v.volume - v.coarse_volume);
  v.columns = columns;
  return v;
}

Status workspace_volume(const Model& model, const Vector3d& rpy_in, const VolumeOptions& options,
                        WorkspaceVolume& out) {
  const Vector3d rpy = rpy_in;  // a copy: the caller may pass out.grid.rpy
  out = WorkspaceVolume{};
  VolumeGrid grid;
  if (const Status s = volume_grid(model, rpy, options, grid); s != Status::Ok) return s;
  const std::size_t n = grid.cells();
  std::vector<double> fine(n), coarse(n);
  std::atomic<std::uint64_t> columns{0};
  detail::BlockProgress progress(options.progress, n);
  // Blocks of one row of coarse cells: neighbours share their columns within a block.
  detail::for_blocks(n, static_cast<std::size_t>(grid.nx), options.threads, [&](std::size_t begin, std::size_t end) {
    columns +=
        volume_cells(model, grid, options.search, begin, end - begin, fine.data() + begin, coarse.data() + begin);
    progress.add(end - begin);
  });
  out = volume_from_cells(grid, fine, coarse, columns);
  return Status::Ok;
}

}  // namespace hexatwist
