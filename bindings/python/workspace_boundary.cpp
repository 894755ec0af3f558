// SPDX-License-Identifier: BSD-3-Clause
// Slices of the constant-orientation workspace with the limit of each boundary point, and the
// orientation workspace at a position (design/workspace_boundary.hpp).
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {

SlicePlane plane_from(const std::string& name) {
  if (name == "xy") return SlicePlane::XY;
  if (name == "xz") return SlicePlane::XZ;
  if (name == "yz") return SlicePlane::YZ;
  raise_input("plane: expected 'xy', 'xz' or 'yz', got '" + name + "'");
}

WorkspaceOptions search_options(double step, double tolerance, const std::string& strategy) {
  WorkspaceOptions o;
  o.step = step;
  o.tolerance = tolerance;
  o.strategy = strategy_from(strategy);
  return o;
}

WorkspaceSlice slice_of(const Model& model, const py::object& orientation, const std::string& plane, double offset,
                        double spacing, double step, double tolerance, const std::string& strategy, const char* what) {
  SliceSpec spec;
  spec.plane = plane_from(plane);
  spec.offset = offset;
  spec.spacing = spacing;
  const WorkspaceOptions o = search_options(step, tolerance, strategy);
  const Vector3d rpy = vector3(orientation, "orientation");
  WorkspaceSlice s;
  Status st;
  {
    py::gil_scoped_release release;
    st = workspace_slice(model, rpy, spec, o, s);
  }
  if (st == Status::NonFiniteInput)
    raise_input(std::string(what) + ": offset, spacing, step and tolerance must be finite, > 0");
  if (st != Status::Ok) raise_status(st, std::string(what) + ": the legs' bounds do not meet");
  return s;
}

namespace {

py::dict slice_py(const Model& model, const py::object& orientation, const std::string& plane, double offset,
                  double spacing, double step, double tolerance, const std::string& strategy) {
  const WorkspaceSlice s =
      slice_of(model, orientation, plane, offset, spacing, step, tolerance, strategy, "workspace_slice");
  const std::size_t n = s.boundary.size();
  py::array_t<double> u(n), v(n), value(n), bound(n);
  py::array_t<double> inside({n, std::size_t{3}}), outside({n, std::size_t{3}});
  py::array_t<std::int8_t> status(n), leg(n), along(n);
  for (std::size_t k = 0; k < n; ++k) {
    const BoundaryPoint& p = s.boundary[k];
    u.mutable_data()[k] = p.u;
    v.mutable_data()[k] = p.v;
    for (int c = 0; c < 3; ++c) {
      inside.mutable_data()[3 * k + c] = p.inside[c];
      outside.mutable_data()[3 * k + c] = p.outside[c];
    }
    status.mutable_data()[k] = static_cast<std::int8_t>(p.limit.status);
    leg.mutable_data()[k] = static_cast<std::int8_t>(leg_number(p.limit.leg));
    value.mutable_data()[k] = p.limit.value;
    bound.mutable_data()[k] = p.limit.bound;
    along.mutable_data()[k] = static_cast<std::int8_t>(p.along);
  }
  py::dict d;
  d["u"] = u, d["v"] = v, d["inside"] = inside, d["outside"] = outside, d["status"] = status, d["leg"] = leg;
  d["value"] = value, d["bound"] = bound, d["along"] = along;
  d["area"] = s.area;
  d["extent"] = py::make_tuple(s.u0, s.u1, s.v0, s.v1);
  return d;
}

py::dict orientation_py(const Model& model, const py::object& position, const std::vector<double>& torsions,
                        int directions, double step, double max_tilt, double tolerance, const std::string& strategy) {
  OrientationSpec spec;
  spec.position = vector3(position, "position");
  spec.torsions = torsions;
  spec.directions = directions;
  spec.step = step;
  spec.max_tilt = max_tilt;
  spec.tolerance = tolerance;
  const Strategy st = strategy_from(strategy);
  OrientationWorkspace ow;
  Status s;
  {
    py::gil_scoped_release release;
    s = orientation_workspace(model, spec, st, ow);
  }
  if (s != Status::Ok) raise_input("orientation_workspace: directions >= 1; step, max_tilt, tolerance finite and > 0");
  const std::size_t nt = torsions.size(), nd = static_cast<std::size_t>(directions);
  py::array_t<double> azimuth(nd), tilt({nt, nd}), value({nt, nd}), bound({nt, nd});
  py::array_t<std::int8_t> status({nt, nd}), leg({nt, nd});
  for (std::size_t t = 0; t < nt; ++t)
    for (std::size_t j = 0; j < nd; ++j) {
      const TiltReach& r = ow.reach[t][j];
      if (t == 0) azimuth.mutable_data()[j] = r.azimuth;
      tilt.mutable_data()[t * nd + j] = r.tilt;
      status.mutable_data()[t * nd + j] = static_cast<std::int8_t>(r.limit.status);
      leg.mutable_data()[t * nd + j] = static_cast<std::int8_t>(leg_number(r.limit.leg));
      value.mutable_data()[t * nd + j] = r.limit.value;
      bound.mutable_data()[t * nd + j] = r.limit.bound;
    }
  py::dict d;
  d["azimuth"] = azimuth, d["torsion"] = py::array_t<double>(nt, torsions.data()), d["tilt"] = tilt;
  d["status"] = status, d["leg"] = leg, d["value"] = value, d["bound"] = bound;
  return d;
}

// One torsion's extremes (tilt_extremes) from a row of hexatwist.design.orientation_workspace's
// arrays (legs numbered 1 to 6, 0 none).
py::dict tilt_extremes_py(const std::vector<double>& azimuth, const std::vector<double>& tilt,
                          const std::vector<int>& status, const std::vector<int>& leg, const std::vector<double>& value,
                          const std::vector<double>& bound) {
  const std::size_t n = azimuth.size();
  if (tilt.size() != n || status.size() != n || leg.size() != n || value.size() != n || bound.size() != n)
    raise_input("tilt_extremes: azimuth, tilt, status, leg, value and bound of one length");
  std::vector<TiltReach> row(n);
  for (std::size_t j = 0; j < n; ++j)
    row[j] =
        TiltReach{azimuth[j], tilt[j], LimitReport{static_cast<Status>(status[j]), leg[j] - 1, value[j], bound[j]}};
  const TiltExtremes e = tilt_extremes(row);
  py::dict d;
  d["reached"] = e.reached, d["smallest"] = e.smallest, d["smallest_azimuth"] = e.smallest_azimuth;
  d["smallest_limit"] = limit_dict(e.smallest_limit);
  d["largest"] = e.largest, d["largest_azimuth"] = e.largest_azimuth;
  return d;
}

}  // namespace

void expose_workspace_boundary(py::module_& m) {
  const WorkspaceOptions w;
  const OrientationSpec o;
  m.def("_workspace_slice", &slice_py, py::arg("model"), py::arg("orientation"), py::arg("plane") = "xy",
        py::arg("offset") = 0.0, py::arg("spacing") = SliceSpec{}.spacing, py::arg("step") = w.step,
        py::arg("tolerance") = w.tolerance, py::arg("strategy") = "compensated");
  m.def("_orientation_workspace", &orientation_py, py::arg("model"), py::arg("position"), py::arg("torsions"),
        py::arg("directions") = o.directions, py::arg("step") = o.step, py::arg("max_tilt") = o.max_tilt,
        py::arg("tolerance") = o.tolerance, py::arg("strategy") = "compensated");
  m.def("_tilt_extremes", &tilt_extremes_py, py::arg("azimuth"), py::arg("tilt"), py::arg("status"), py::arg("leg"),
        py::arg("value"), py::arg("bound"));
  m.def(
      "tilt_torsion_rotation",
      [](double azimuth, double tilt, double torsion) {
        const Matrix3d R = tilt_torsion_rotation(azimuth, tilt, torsion);
        py::array_t<double> a({3, 3});
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) a.mutable_data()[3 * i + j] = R(i, j);
        return a;
      },
      py::arg("azimuth"), py::arg("tilt"), py::arg("torsion") = 0.0,
      "Rotation of tilt-and-torsion angles [rad] (Bonev and Ryu): the platform's z axis tilted by `tilt` towards "
      "`azimuth`, the torsion about it; R = Rz(azimuth) Ry(tilt) Rz(torsion - azimuth), (3, 3).");
}

}  // namespace hexatwist::python
