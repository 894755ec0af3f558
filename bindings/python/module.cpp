// SPDX-License-Identifier: BSD-3-Clause
// The hexatwist Python extension module (_hexatwist): one layer over the library, one file per
// concept. The public API, its typed results and docstrings are in python/hexatwist/ (one module per
// subsystem); python/hexatwist/_hexatwist.pyi types this module.
#include "common.hpp"
#include "hexatwist/version.hpp"

PYBIND11_MODULE(_hexatwist, m) {
  using namespace hexatwist::python;
  m.doc() = "hexatwist: twist-aware kinematics of lead-screw Stewart platforms (compiled core)";
  m.attr("version") = std::string(hexatwist::kVersion);
  expose_errors(m);
  expose_model(m);
  expose_kinematics(m);
  expose_commands(m);
  expose_forward(m);
  expose_simulation(m);
  expose_measurement(m);
  expose_identification(m);
  expose_station_plan(m);
  expose_validation(m);
  expose_stream(m);
  expose_trajectory(m);
  expose_rig(m);
  expose_mechanism(m);
  expose_motor_sizing(m);
  expose_registration(m);
  expose_workspace(m);
  expose_mjcf(m);
  expose_workspace_volume(m);
  expose_workspace_boundary(m);
  expose_workspace_map(m);
  expose_axis_design(m);
  expose_tolerance(m);
}
