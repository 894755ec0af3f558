// SPDX-License-Identifier: BSD-3-Clause
// The constant-orientation workspace's volume (design/workspace_volume.hpp): the whole computation,
// and its grid and cells apart for Dask (hexatwist.distributed: cells on the workers, the sum here).
#include "common.hpp"

namespace hexatwist::python {
namespace {

VolumeOptions volume_options(double cell, int refine, double step, double tolerance, const std::string& strategy,
                             int threads) {
  VolumeOptions o;
  o.search = search_options(step, tolerance, strategy);
  o.cell = cell;
  o.refine = refine;
  o.threads = threads;
  return o;
}

py::array_t<double> array3(const Vector3d& v) { return py::array_t<double>(3, v.data()); }

py::dict grid_dict(const VolumeGrid& g) {
  py::dict d;
  d["orientation"] = array3(g.rpy);
  d["box_lower"] = array3(g.box.lower);
  d["box_upper"] = array3(g.box.upper);
  d["cell"] = g.cell;
  d["refine"] = g.refine;
  d["x0"] = g.x0;
  d["y0"] = g.y0;
  d["nx"] = g.nx;
  d["ny"] = g.ny;
  d["cells"] = g.cells();
  return d;
}

VolumeGrid grid_of(const py::dict& d) {
  VolumeGrid g;
  g.rpy = vector3(d["orientation"], "grid orientation");
  g.box.lower = vector3(d["box_lower"], "grid box_lower");
  g.box.upper = vector3(d["box_upper"], "grid box_upper");
  g.cell = d["cell"].cast<double>();
  g.refine = d["refine"].cast<int>();
  g.x0 = d["x0"].cast<double>();
  g.y0 = d["y0"].cast<double>();
  g.nx = d["nx"].cast<int>();
  g.ny = d["ny"].cast<int>();
  if (!(g.cell > 0.0) || g.refine < 0 || g.refine > 8 || g.nx < 1 || g.ny < 1) raise_input("grid: not a volume grid");
  return g;
}

void check(Status s, const char* what) {
  if (s == Status::NonFiniteInput)
    raise_input(std::string(what) +
                ": orientation must be finite; cell >= 0, refine 0..8, step and tolerance finite and > 0");
  if (s != Status::Ok) raise_status(s, std::string(what) + ": the legs' bounds do not meet");
}

py::dict volume_dict(const WorkspaceVolume& v) {
  py::dict d;
  d["volume"] = v.volume;
  d["coarse_volume"] = v.coarse_volume;
  d["error"] = v.error;
  d["columns"] = v.columns;
  d["grid"] = grid_dict(v.grid);
  return d;
}

py::dict workspace_volume_py(const Model& model, const py::object& orientation, double cell, int refine, double step,
                             double tolerance, const std::string& strategy, int threads) {
  const VolumeOptions o = volume_options(cell, refine, step, tolerance, strategy, threads);
  const Vector3d rpy = vector3(orientation, "orientation");
  WorkspaceVolume v;
  Status s;
  {
    py::gil_scoped_release release;
    s = workspace_volume(model, rpy, o, v);
  }
  check(s, "workspace_volume");
  return volume_dict(v);
}

py::dict volume_grid_py(const Model& model, const py::object& orientation, double cell, int refine, double step,
                        double tolerance, const std::string& strategy) {
  VolumeGrid g;
  check(volume_grid(model, vector3(orientation, "orientation"),
                    volume_options(cell, refine, step, tolerance, strategy, 1), g),
        "workspace_volume");
  return grid_dict(g);
}

py::tuple volume_cells_py(const Model& model, const py::dict& grid_in, double step, double tolerance,
                          const std::string& strategy, std::size_t first, std::size_t count) {
  const VolumeGrid g = grid_of(grid_in);
  const WorkspaceOptions o = search_options(step, tolerance, strategy);
  if (first > g.cells() || count > g.cells() - first) raise_input("volume cells: range outside the grid");
  py::array_t<double> fine(static_cast<py::ssize_t>(count)), coarse(static_cast<py::ssize_t>(count));
  double *f = fine.mutable_data(), *c = coarse.mutable_data();
  std::atomic<std::uint64_t> columns{0};
  // Blocks of a grid row: neighbouring cells share their columns within a block.
  parallel_blocks(
      count,
      [&](std::size_t b, std::size_t e) { columns += volume_cells(model, g, o, first + b, e - b, f + b, c + b); },
      static_cast<std::size_t>(g.nx));
  return py::make_tuple(fine, coarse, columns.load());
}

py::dict volume_from_cells_py(const py::dict& grid_in, const py::array_t<double>& fine,
                              const py::array_t<double>& coarse, std::uint64_t columns) {
  const VolumeGrid g = grid_of(grid_in);
  if (static_cast<std::size_t>(fine.size()) != g.cells() || static_cast<std::size_t>(coarse.size()) != g.cells())
    raise_input("volume cells: expected one value per cell of the grid");
  const std::vector<double> f(fine.data(), fine.data() + fine.size()), c(coarse.data(), coarse.data() + coarse.size());
  return volume_dict(volume_from_cells(g, f, c, columns));
}

}  // namespace

void expose_workspace_volume(py::module_& m) {
  const WorkspaceOptions w;
  const VolumeOptions v;
  m.def("_workspace_volume", &workspace_volume_py, py::arg("model"), py::arg("orientation"), py::arg("cell") = v.cell,
        py::arg("refine") = v.refine, py::arg("step") = w.step, py::arg("tolerance") = w.tolerance,
        py::arg("strategy") = "compensated", py::arg("threads") = 1);
  m.def("_volume_grid", &volume_grid_py, py::arg("model"), py::arg("orientation"), py::arg("cell") = v.cell,
        py::arg("refine") = v.refine, py::arg("step") = w.step, py::arg("tolerance") = w.tolerance,
        py::arg("strategy") = "compensated");
  m.def("_volume_cells", &volume_cells_py, py::arg("model"), py::arg("grid"), py::arg("step"), py::arg("tolerance"),
        py::arg("strategy"), py::arg("first"), py::arg("count"));
  m.def("_volume_from_cells", &volume_from_cells_py, py::arg("grid"), py::arg("fine"), py::arg("coarse"),
        py::arg("columns"));
}

}  // namespace hexatwist::python
