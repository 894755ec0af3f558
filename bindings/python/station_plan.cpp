// SPDX-License-Identifier: BSD-3-Clause
// Where to measure (station_plan.hpp, theory §13): the library's plan of a calibration run's
// stations (the same stations, criterion and predicted accuracy as `hexatwist stations --json`)
// beside random stations of the same count, and the planned run.
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {
namespace {

py::array_t<double> station_rows(const std::vector<Vector6d>& q) {
  py::array_t<double> a({static_cast<py::ssize_t>(q.size()), py::ssize_t{6}});
  for (std::size_t i = 0; i < q.size(); ++i) std::copy(q[i].data(), q[i].data() + 6, a.mutable_data() + 6 * i);
  return a;
}

py::dict quality_dict(const StationsQuality& q) {
  py::dict d;
  d["status"] = std::string(to_string(q.status));
  d["reason"] = q.reason;
  d["stations"] = station_rows(q.stations);
  d["criterion"] = q.criterion;
  d["sd_geometric"] = q.sd_geometric;
  d["condition"] = q.condition;
  d["path"] = q.path;
  py::array_t<double> cov(
      {static_cast<py::ssize_t>(q.covariance.rows()), static_cast<py::ssize_t>(q.covariance.cols())});
  auto v = cov.mutable_unchecked<2>();
  for (Eigen::Index r = 0; r < q.covariance.rows(); ++r)
    for (Eigen::Index c = 0; c < q.covariance.cols(); ++c) v(r, c) = q.covariance(r, c);
  d["covariance"] = cov;
  const Eigen::VectorXd sd = q.covariance.diagonal().cwiseSqrt();
  d["sd"] = py::array_t<double>(static_cast<py::ssize_t>(sd.size()), sd.data());
  py::dict a;
  a["poses"] = q.accuracy.poses;
  a["median"] = q.accuracy.median;
  a["max"] = q.accuracy.max;
  a["aligned_median"] = q.accuracy.aligned_median;
  a["aligned_max"] = q.accuracy.aligned_max;
  a["range_low"] = py::array_t<double>(6, q.accuracy.range_low.data());
  a["range_high"] = py::array_t<double>(6, q.accuracy.range_high.data());
  d["accuracy"] = a;
  return d;
}

py::dict plan_stations_py(const py::object& config_src, int count, std::uint64_t seed, const std::string& strategy,
                          double translation, double rotation, int candidates, const std::string& calibration,
                          double noise, int points_per_station, int accuracy_poses) {
  const auto rig = rig_of(config_src);
  const Model& model = rig->config->rig.model();
  const Strategy s = strategy_from(strategy);
  StationPlanSpec spec;
  if (calibration == "basic")
    spec.model = CalibrationModel::Basic;
  else if (calibration != "geometry")
    raise_input("calibration: expected 'basic' or 'geometry', got '" + calibration + "'");
  spec.run.count = count;
  spec.run.seed = seed;
  spec.run.translation = translation;
  spec.run.rotation = rotation;
  spec.candidates = candidates;
  spec.noise = noise;
  spec.points_per_station = points_per_station;
  spec.accuracy_poses = accuracy_poses;
  StationPlan plan;
  Status status;
  {
    py::gil_scoped_release release;
    status = plan_stations(model, s, spec, plan);  // a bad value: ParameterError, InputError naming the keyword
  }
  py::dict d;
  d["status"] = std::string(to_string(status));
  d["reason"] = plan.reason;
  py::list names;
  for (int k = 0; k < plan.parameters.platform_size(); ++k) names.append(plan.parameters.name(k));
  d["parameter_names"] = py::tuple(names);
  d["candidates"] = plan.candidates;
  d["draws"] = plan.draws;
  d["sweeps"] = plan.sweeps;
  d["exchanges"] = plan.exchanges;
  d["converged"] = plan.converged;
  d["replaced"] = plan.replaced;
  d["planned"] = quality_dict(plan.planned);
  d["random"] = quality_dict(plan.random);
  d["stations"] = station_rows(plan.planned.stations);
  return d;
}

}  // namespace

void expose_station_plan(py::module_& m) {
  m.def("_plan_stations", &plan_stations_py, py::arg("rig") = py::none(), py::arg("count") = 20, py::arg("seed") = 1,
        py::arg("strategy") = "compensated", py::arg("translation") = 0.25, py::arg("rotation") = deg2rad(15.0),
        py::arg("candidates") = 3000, py::arg("calibration") = "geometry", py::arg("noise") = 10e-6,
        py::arg("points_per_station") = 75, py::arg("accuracy_poses") = 1000);
}

}  // namespace hexatwist::python
