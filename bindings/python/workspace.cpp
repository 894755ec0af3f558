// SPDX-License-Identifier: BSD-3-Clause
// Reach of the platform along each pose coordinate alone (workspace.hpp, axis_range).
#include "common.hpp"

namespace hexatwist::python {
namespace {

constexpr std::array<const char*, 6> kCoordinates{"x", "y", "z", "roll", "pitch", "yaw"};

int coordinate_of(const py::object& c) {
  if (py::isinstance<py::str>(c)) {
    const std::string s = c.cast<std::string>();
    for (int i = 0; i < 6; ++i)
      if (s == kCoordinates[static_cast<std::size_t>(i)]) return i;
    raise_input("coordinate: expected x, y, z, roll, pitch, yaw or 0..5, got '" + s + "'");
  }
  int i = -1;
  try {
    i = c.cast<int>();
  } catch (const py::cast_error&) {
  }
  if (i < 0 || i > 5) raise_input("coordinate: expected x, y, z, roll, pitch, yaw or 0..5");
  return i;
}

py::dict axis_range_py(const Model& model, const py::object& coordinate, const std::string& strategy,
                       double linear_step, double angular_step, double linear_bound, double angular_bound,
                       double tolerance) {
  const int k = coordinate_of(coordinate);
  const Strategy st = strategy_from(strategy);
  AxisRangeOptions o;
  o.linear_step = linear_step;
  o.angular_step = angular_step;
  o.linear_bound = linear_bound;
  o.angular_bound = angular_bound;
  o.tolerance = tolerance;
  AxisRange r;
  Status s;
  {
    py::gil_scoped_release release;
    s = axis_range(model, k, st, r, o);
  }
  if (s == Status::NonFiniteInput) raise_input("axis_range: steps, bounds and tolerance must be finite and > 0");
  if (s != Status::Ok) raise_status(s, "axis_range: home is outside a limit");
  py::dict d;
  d["coordinate"] = kCoordinates[static_cast<std::size_t>(k)];
  d["lower"] = r.lower;
  d["upper"] = r.upper;
  d["lower_limit"] = limit_dict(r.lower_limit);
  d["upper_limit"] = limit_dict(r.upper_limit);
  return d;
}

}  // namespace

void expose_workspace(py::module_& m) {
  const AxisRangeOptions o;
  m.def("_axis_range", &axis_range_py, py::arg("model"), py::arg("coordinate"), py::arg("strategy") = "compensated",
        py::arg("linear_step") = o.linear_step, py::arg("angular_step") = o.angular_step,
        py::arg("linear_bound") = o.linear_bound, py::arg("angular_bound") = o.angular_bound,
        py::arg("tolerance") = o.tolerance);
}

}  // namespace hexatwist::python
