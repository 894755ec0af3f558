// SPDX-License-Identifier: BSD-3-Clause
// Measurement: a tracker point log (one or more targets), the commanded runs (a measured test, a
// stations run), and the observations at rest an identification uses (identification.cpp).
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {

std::pair<std::string, std::string> read_yaml_source(const py::object& path_or_text);

std::vector<int> targets_of(const py::object& targets, std::size_t n);

namespace {

py::array_t<double> points3(const std::vector<Vector3d>& p) {
  py::array_t<double> a({static_cast<py::ssize_t>(p.size()), py::ssize_t{3}});
  for (std::size_t k = 0; k < p.size(); ++k) std::copy(p[k].data(), p[k].data() + 3, a.mutable_data() + 3 * k);
  return a;
}
py::array_t<double> vec(const double* x, std::size_t n) { return py::array_t<double>(static_cast<py::ssize_t>(n), x); }

// (K, C) float64 array, C-contiguous (a copy otherwise, counted).
const double* rows_of(const py::array& a, std::size_t cols, const char* name, std::size_t& n) {
  if (!py::isinstance<py::array_t<double>>(a)) raise_input(std::string(name) + ": expected dtype float64");
  if (a.ndim() != 2 || a.shape(1) != static_cast<py::ssize_t>(cols))
    raise_input(std::string(name) + ": expected shape (K, " + std::to_string(cols) + ")");
  if (!(a.flags() & py::array::c_style)) raise_input(std::string(name) + ": expected a C-contiguous array");
  n = static_cast<std::size_t>(a.shape(0));
  return static_cast<const double*>(a.data());
}

py::dict point_log(const py::object& src, const std::string& time_column, double length_unit, bool indexed,
                   const std::string& target_column, const std::string& temperature_column) {
  auto [text, source] = read_yaml_source(src);
  PointLogFormat f;
  f.time_column = time_column;
  f.length_unit = length_unit;
  f.indexed = indexed;
  f.target_column = target_column;
  f.temperature_column = temperature_column;
  const PointLog log = parse_point_log(text, source, f);
  py::dict d;
  d["stamps"] = vec(log.stamps.data(), log.stamps.size());
  d["points"] = points3(log.points_T);
  d["targets"] = py::array_t<int>(static_cast<py::ssize_t>(log.targets.size()), log.targets.data());
  d["target_names"] = py::cast(log.target_names);
  d["lines"] = py::array_t<int>(static_cast<py::ssize_t>(log.lines.size()), log.lines.data());
  d["temperatures"] = vec(log.temperatures.data(), log.temperatures.size());
  d["source"] = log.source;
  return d;
}

py::dict stations_run(const py::object& config_src, int count, std::uint64_t seed, const std::string& strategy,
                      double translation, double rotation, const py::object& stations, double approach,
                      int reference_every) {
  const auto rig = rig_of(config_src);
  const Config& config = *rig->config;
  StationsSpec spec;
  spec.count = count;
  spec.seed = seed;
  spec.translation = translation;
  spec.rotation = rotation;
  spec.approach = approach;
  spec.reference_every = reference_every;
  std::vector<Vector6d> poses;
  if (stations.is_none()) {
    poses = random_stations(config.rig.model(), strategy_from(strategy), spec);
  } else {
    const Rows6 q = rows6(stations, "stations", false);
    for (std::size_t i = 0; i < q.rows; ++i) poses.push_back(pose_row(q.data, i).to_vector());
  }
  const Trajectory tr =
      station_run(config.rig.model(), strategy_from(strategy), poses, spec, config.rig.control_period());
  py::dict d = trajectory_arrays(tr);
  py::array_t<double> st({static_cast<py::ssize_t>(poses.size()), py::ssize_t{6}});
  for (std::size_t i = 0; i < poses.size(); ++i)
    std::copy(poses[i].data(), poses[i].data() + 6, st.mutable_data() + 6 * i);
  d["stations"] = st;
  return d;
}

py::dict measured_test(const py::object& config_src, const std::string& test) {
  const auto rig = rig_of(config_src);
  const Config& config = *rig->config;
  for (const StudyTest& st : seed_tests(config.study)) {
    if (st.name != test) continue;
    double end = 0.0;
    const Trajectory tr =
        measured_test_trajectory(config.study, st, CalibrationSpec{}, config.rig.control_period(), end);
    py::dict d = trajectory_arrays(tr);
    d["calibration_end"] = end;
    return d;
  }
  raise_input("test: unknown test '" + test + "'; expected Lz, Lx, Rz or Ry");
}

py::dict observations(const Model& model, const py::array& t, const py::array& poses, const py::array& stamps,
                      const py::array& points, const py::object& targets, double time_offset,
                      const std::string& strategy, double settle, const py::object& temperatures) {
  const TimedPoses tp = timed_poses_of(t, "t", poses);
  PointLog log;
  std::size_t ns = 0, np = 0;
  if (!py::isinstance<py::array_t<double>>(stamps) || stamps.ndim() != 1)
    raise_input("stamps: expected a 1-D float64 array [s]");
  const double* p = rows_of(points, 3, "points", np);
  ns = static_cast<std::size_t>(stamps.shape(0));
  if (ns != np) raise_input("stamps and points: expected as many stamps as points");
  py::array sc = py::module_::import("numpy").attr("ascontiguousarray")(stamps);
  log.stamps.assign(static_cast<const double*>(sc.data()), static_cast<const double*>(sc.data()) + ns);
  const std::vector<int> target = targets_of(targets, np);
  for (std::size_t k = 0; k < np; ++k) {
    log.points_T.emplace_back(p[3 * k], p[3 * k + 1], p[3 * k + 2]);
    log.targets.push_back(target[k]);
    log.lines.push_back(static_cast<int>(k) + 2);
    log.stamp_columns.push_back(1);
  }
  if (!temperatures.is_none()) {
    const py::array_t<double, py::array::c_style | py::array::forcecast> tc(temperatures);
    if (tc.ndim() != 1 || static_cast<std::size_t>(tc.shape(0)) != np)
      raise_input("temperatures: expected one per point [degC]");
    log.temperatures.assign(tc.data(), tc.data() + np);
  }
  log.source = "point log";
  const ObservationSet set =
      observations_at_rest(model, tp, log, TimeAlignment{time_offset, 0.0}, strategy_from(strategy), settle);
  const std::size_t k = set.observations.size();
  py::array_t<double> motor({static_cast<py::ssize_t>(k), py::ssize_t{6}}),
      pts({static_cast<py::ssize_t>(k), py::ssize_t{3}});
  py::array_t<int> tg(static_cast<py::ssize_t>(k));
  py::array_t<double> time(static_cast<py::ssize_t>(k)), temperature(static_cast<py::ssize_t>(k)),
      approach({static_cast<py::ssize_t>(k), py::ssize_t{6}});
  for (std::size_t i = 0; i < k; ++i) {
    std::copy(set.observations[i].motor.data(), set.observations[i].motor.data() + 6, motor.mutable_data() + 6 * i);
    std::copy(set.observations[i].approach.data(), set.observations[i].approach.data() + 6,
              approach.mutable_data() + 6 * i);
    time.mutable_data()[i] = set.observations[i].time;
    temperature.mutable_data()[i] = set.observations[i].temperature;
    std::copy(set.observations[i].p_T.data(), set.observations[i].p_T.data() + 3, pts.mutable_data() + 3 * i);
    tg.mutable_data()[i] = set.observations[i].target;
  }
  py::dict d;
  d["motor"] = motor;
  d["points"] = pts;
  d["targets"] = tg;
  d["time"] = time;
  d["temperature"] = temperature;
  d["approach"] = approach;
  d["index"] = py::cast(set.points);
  d["stations"] = set.poses;
  return d;
}

}  // namespace

void expose_measurement(py::module_& m) {
  m.def("_read_point_log", &point_log, py::arg("path_or_text"), py::arg("time_column") = "t",
        py::arg("length_unit") = 0.0, py::arg("indexed") = false, py::arg("target_column") = "",
        py::arg("temperature_column") = "");
  m.def("_stations_run", &stations_run, py::arg("rig") = py::none(), py::arg("count") = 40, py::arg("seed") = 1,
        py::arg("strategy") = "compensated", py::arg("translation") = 0.25, py::arg("rotation") = deg2rad(15.0),
        py::arg("stations") = py::none(), py::arg("approach") = 0.0, py::arg("reference_every") = 0);
  m.def("_measured_test", &measured_test, py::arg("rig") = py::none(), py::arg("test") = "Rz");
  m.def("_observations_at_rest", &observations, py::arg("model"), py::arg("t"), py::arg("poses"), py::arg("stamps"),
        py::arg("points"), py::arg("targets") = py::none(), py::arg("time_offset") = 0.0,
        py::arg("strategy") = "compensated", py::arg("settle") = 0.25, py::arg("temperatures") = py::none());
}

}  // namespace hexatwist::python
