// SPDX-License-Identifier: BSD-3-Clause
// Maps over a slice of the constant-orientation workspace (design/workspace_map.hpp): the grid
// around a slice, and rows of the map (the whole map here, or its rows on Dask workers).
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

}  // namespace

void expose_workspace_map(py::module_& m) {
  const WorkspaceOptions w;
  m.def("_map_grid", &map_grid_py, py::arg("model"), py::arg("orientation"), py::arg("plane") = "xy",
        py::arg("offset") = 0.0, py::arg("spacing") = 0.02, py::arg("step") = w.step,
        py::arg("tolerance") = w.tolerance, py::arg("strategy") = "compensated");
  m.def("_workspace_map_rows", &map_rows_py, py::arg("model"), py::arg("orientation"), py::arg("grid"),
        py::arg("strategy"), py::arg("first"), py::arg("count"));
}

}  // namespace hexatwist::python
