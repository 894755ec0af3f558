// SPDX-License-Identifier: BSD-3-Clause
// Rigid registration of corresponding point sets (registration.hpp, Kabsch/Umeyama): X_BT from
// points measured in the tracker frame T and the same points in the base frame B.
#include "common.hpp"

namespace hexatwist::python {
namespace {

const double* points_of(const py::handle& obj, const char* name, std::size_t& n, py::array& keep) {
  try {
    keep = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (...) {
  }
  if (!keep || keep.ndim() != 2 || keep.shape(1) != 3)
    raise_input(std::string(name) + ": expected an (N, 3) array [m]");
  n = static_cast<std::size_t>(keep.shape(0));
  return static_cast<const double*>(keep.data());
}

py::dict register_py(const py::object& p_T, const py::object& p_B, double max_condition) {
  std::size_t nt = 0, nb = 0;
  py::array kt, kb;
  const double* t = points_of(p_T, "points_T", nt, kt);
  const double* b = points_of(p_B, "points_B", nb, kb);
  if (nt != nb) raise_input("points_T and points_B: expected as many points in each (one pair per row)");
  if (!(max_condition >= 1.0)) raise_input("max_condition: expected a number >= 1");
  std::vector<PointPair> pairs(nt);
  for (std::size_t i = 0; i < nt; ++i) {
    pairs[i].p_T = Eigen::Map<const Vector3d>(t + 3 * i);
    pairs[i].p_B = Eigen::Map<const Vector3d>(b + 3 * i);
  }
  Registration r;
  RegistrationOptions o;
  o.max_condition = max_condition;
  const Status s = register_points(pairs, r, o);
  if (s == Status::NonFiniteInput) raise_input("points_T, points_B: hold NaN or inf");
  py::array_t<double> R({3, 3});
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) R.mutable_data()[3 * i + k] = r.X_BT.R(i, k);
  py::dict d;
  d["status"] = std::string(to_string(s));
  d["R_BT"] = R;
  d["t_BT"] = py::array_t<double>(3, r.X_BT.t.data());
  d["count"] = r.count;
  d["rms_residual"] = r.rms_residual;
  d["max_residual"] = r.max_residual;
  d["max_residual_index"] = r.max_residual_index;
  d["sigma"] = r.sigma;
  d["singular_values"] = py::array_t<double>(3, r.singular_values.data());
  d["reflection"] = r.reflection;
  d["condition"] = r.condition;
  return d;
}

}  // namespace

void expose_registration(py::module_& m) {
  m.def("_register_points", &register_py, py::arg("points_T"), py::arg("points_B"), py::arg("max_condition") = 1e4);
}

}  // namespace hexatwist::python
