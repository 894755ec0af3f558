// SPDX-License-Identifier: BSD-3-Clause
// Maps over a slice of the constant-orientation workspace (design/workspace_map.hpp): the grid
// around a slice, and rows of the map (the whole map here, or its rows on Dask workers).
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {

SlicePlane plane_from(const std::string& name);

namespace {

const char* plane_name(SlicePlane p) { return p == SlicePlane::XY ? "xy" : p == SlicePlane::XZ ? "xz" : "yz"; }

py::dict grid_dict(const MapGrid& g) {
  py::dict d;
  d["plane"] = plane_name(g.plane);
  d["offset"] = g.offset;
  d["u0"] = g.u0, d["u1"] = g.u1, d["nu"] = g.nu;
  d["v0"] = g.v0, d["v1"] = g.v1, d["nv"] = g.nv;
  return d;
}

MapGrid grid_of(const py::dict& d) {
  MapGrid g;
  g.plane = plane_from(d["plane"].cast<std::string>());
  g.offset = d["offset"].cast<double>();
  g.u0 = d["u0"].cast<double>(), g.u1 = d["u1"].cast<double>(), g.nu = d["nu"].cast<int>();
  g.v0 = d["v0"].cast<double>(), g.v1 = d["v1"].cast<double>(), g.nv = d["nv"].cast<int>();
  return g;
}

py::dict map_grid_py(const Model& model, const py::object& orientation, const std::string& plane, double offset,
                     double spacing, double step, double tolerance, const std::string& strategy) {
  return grid_dict(map_grid_around(
      slice_of(model, orientation, plane, offset, spacing, step, tolerance, strategy, "workspace_map"), spacing));
}

// Rows [first, first + count) of the map as arrays (count, nu), with the library's values: legs as
// 0-based indices, -1 for none. They are what `python3 -m hexatwist.cluster` hands the command line;
// hexatwist.design.workspace_map numbers the legs 1 to 6 (0: none) as every other result does.
py::dict map_rows_py(const Model& model, const py::object& orientation, const py::dict& grid_in,
                     const std::string& strategy, int first, int count) {
  const MapGrid g = grid_of(grid_in);
  const Strategy st = strategy_from(strategy);
  const Vector3d rpy = vector3(orientation, "orientation");
  if (g.nu < 2 || g.nv < 2 || first < 0 || count < 0 || first + count > g.nv)
    raise_input("workspace_map: rows outside the grid (nu, nv >= 2)");
  const std::size_t rows = static_cast<std::size_t>(count), nu = static_cast<std::size_t>(g.nu);
  std::vector<MapPoint> points(rows * nu);
  parallel_blocks(
      rows,
      [&](std::size_t b, std::size_t e) {
        workspace_map_rows(model, rpy, g, st, first + static_cast<int>(b), static_cast<int>(e - b),
                           points.data() + b * nu);
      },
      1);
  const std::vector<std::size_t> shape{rows, nu};
  py::array_t<double> max_twist(shape), max_length_error(shape), condition(shape), margin(shape);
  py::array_t<std::int8_t> status(shape), limit_leg(shape), twist_leg(shape), length_error_leg(shape),
      nearest_status(shape), nearest_leg(shape);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const MapPoint& p = points[k];
    status.mutable_data()[k] = static_cast<std::int8_t>(p.status);
    limit_leg.mutable_data()[k] = static_cast<std::int8_t>(p.limit.leg);
    max_twist.mutable_data()[k] = p.max_twist;
    twist_leg.mutable_data()[k] = static_cast<std::int8_t>(p.twist_leg);
    max_length_error.mutable_data()[k] = p.max_length_error;
    length_error_leg.mutable_data()[k] = static_cast<std::int8_t>(p.length_error_leg);
    condition.mutable_data()[k] = p.condition;
    margin.mutable_data()[k] = p.margin;
    nearest_status.mutable_data()[k] = static_cast<std::int8_t>(p.status == Status::Ok ? p.nearest.status : p.status);
    nearest_leg.mutable_data()[k] = static_cast<std::int8_t>(p.status == Status::Ok ? p.nearest.leg : p.limit.leg);
  }
  py::dict d;
  d["status"] = status, d["limit_leg"] = limit_leg, d["max_twist"] = max_twist, d["twist_leg"] = twist_leg;
  d["max_length_error"] = max_length_error, d["length_error_leg"] = length_error_leg;
  d["condition"] = condition, d["margin"] = margin, d["nearest_status"] = nearest_status;
  d["nearest_leg"] = nearest_leg;
  return d;
}

// The extremes of a map (summarize_map) from hexatwist.design.workspace_map's arrays (flattened, legs
// numbered 1 to 6, 0 none).
py::dict map_summary_py(const py::dict& grid_in, const std::vector<int>& status, const std::vector<double>& max_twist,
                        const std::vector<int>& twist_leg, const std::vector<double>& max_length_error,
                        const std::vector<double>& condition, const std::vector<double>& margin,
                        const std::vector<int>& nearest_status, const std::vector<int>& nearest_leg) {
  WorkspaceMap map;
  map.grid = grid_of(grid_in);
  const std::size_t n = status.size();
  if (n != map.grid.size() || max_twist.size() != n || twist_leg.size() != n || max_length_error.size() != n ||
      condition.size() != n || margin.size() != n || nearest_status.size() != n || nearest_leg.size() != n)
    raise_input("map summary: one value per node of the grid in every array");
  map.points.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    MapPoint& p = map.points[k];
    p.status = static_cast<Status>(status[k]);
    p.max_twist = max_twist[k], p.twist_leg = twist_leg[k] - 1;
    p.max_length_error = max_length_error[k];
    p.condition = condition[k], p.margin = margin[k];
    p.nearest = LimitReport{static_cast<Status>(nearest_status[k]), nearest_leg[k] - 1, 0.0, 0.0};
  }
  const MapSummary s = summarize_map(map);
  const auto at = [&](std::size_t k) {
    const Vector3d x = s.inside > 0 ? map_node_position(map.grid, k) : Vector3d::Constant(NAN);
    return py::array_t<double>(3, x.data());
  };
  py::dict d;
  d["inside"] = s.inside, d["max_twist"] = s.max_twist, d["max_twist_leg"] = leg_number(s.max_twist_leg);
  d["max_twist_at"] = at(s.max_twist_node), d["max_length_error"] = s.max_length_error;
  d["max_length_error_at"] = at(s.max_length_error_node);
  d["condition_min"] = s.condition_min, d["condition_max"] = s.condition_max, d["margin_min"] = s.margin_min;
  d["margin_min_at"] = at(s.margin_min_node);
  d["margin_min_limit"] =
      s.inside > 0 ? py::object(py::str(std::string(to_string(s.margin_min_limit.status)))) : py::object(py::none());
  d["margin_min_leg"] = leg_number(s.margin_min_limit.leg);
  return d;
}

}  // namespace

void expose_workspace_map(py::module_& m) {
  const WorkspaceOptions w;
  m.def("_map_grid", &map_grid_py, py::arg("model"), py::arg("orientation"), py::arg("plane") = "xy",
        py::arg("offset") = 0.0, py::arg("spacing") = 0.02, py::arg("step") = w.step,
        py::arg("tolerance") = w.tolerance, py::arg("strategy") = "compensated");
  m.def("_map_summary", &map_summary_py, py::arg("grid"), py::arg("status"), py::arg("max_twist"), py::arg("twist_leg"),
        py::arg("max_length_error"), py::arg("condition"), py::arg("margin"), py::arg("nearest_status"),
        py::arg("nearest_leg"));
  m.def("_workspace_map_rows", &map_rows_py, py::arg("model"), py::arg("orientation"), py::arg("grid"),
        py::arg("strategy"), py::arg("first"), py::arg("count"));
}

}  // namespace hexatwist::python
