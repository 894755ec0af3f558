// SPDX-License-Identifier: BSD-3-Clause
// Checking a calibration (validation.hpp, theory §13c): two platforms compared leg by leg and the
// first one's commands on the second, the numbers `hexatwist compare --json` prints.
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {
namespace {

py::array_t<double> vec3(const Vector3d& v) { return py::array_t<double>(3, v.data()); }

py::array_t<double> array_of(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

py::dict compare_py(const Model& a, const Model& b, int stations, std::uint64_t station_seed, double translation,
                    double rotation) {
  if (stations < kMinAccuracyStations || stations > kMaxStations)
    raise_input("stations: expected " + std::to_string(kMinAccuracyStations) + " to " + std::to_string(kMaxStations) +
                ", got " + std::to_string(stations));
  StationsSpec run;
  run.count = stations;
  run.seed = station_seed;
  run.translation = translation;
  run.rotation = rotation;
  PlatformDifference d;
  CommandAccuracy acc;
  Status s;
  {
    py::gil_scoped_release release;
    const std::vector<Vector6d> poses = random_stations(a, Strategy::Compensated, run);  // Error: ParameterError
    d = compare_platforms(a, b);
    s = command_accuracy(a, b, poses, acc);
  }
  if (s != Status::Ok) raise_status(s, "compare: A's commands at its stations give B no pose");
  py::list legs;
  for (const LegDifference& l : d.legs) {
    py::dict x;
    x["base"] = vec3(l.base);
    x["platform"] = vec3(l.platform);
    x["base_axis_angle"] = l.base_axis;
    x["platform_axis_angle"] = l.platform_axis;
    x["lead"] = l.lead;
    x["drive_lead"] = l.drive_lead;
    x["length_offset"] = l.length_offset;
    x["home_command"] = l.home_command;
    x["compliance"] = l.compliance;
    x["play"] = l.play;
    x["thread_differs"] = l.thread_differs;
    legs.append(x);
  }
  py::dict accuracy;
  accuracy["gauge"] = array_of(acc.gauge);
  accuracy["aligned"] = array_of(acc.aligned);
  accuracy["gauge_median"] = acc.gauge_median;
  accuracy["gauge_max"] = acc.gauge_max;
  accuracy["aligned_median"] = acc.aligned_median;
  accuracy["aligned_max"] = acc.aligned_max;
  py::dict out;
  out["legs"] = legs;
  out["observation_point"] = vec3(d.observation);
  out["home_height"] = d.home_height;
  out["largest_joint"] = d.largest_joint;
  out["largest_joint_leg"] = leg_number(d.largest_joint_leg);
  out["largest_joint_side"] = std::string(d.largest_on_platform ? "platform" : "base");
  out["accuracy"] = accuracy;
  return out;
}

}  // namespace

void expose_validation(py::module_& m) {
  m.def("_compare", &compare_py, py::arg("a"), py::arg("b"), py::arg("stations") = 60, py::arg("station_seed") = 1,
        py::arg("translation") = 0.25, py::arg("rotation") = deg2rad(15.0));
}

}  // namespace hexatwist::python
