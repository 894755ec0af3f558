// SPDX-License-Identifier: BSD-3-Clause
// Pose trajectories (motion/trajectory.hpp): the paper's sweep along one coordinate, straight moves
// through waypoints, CSV trajectories read and resampled onto a fixed period. Times (T,) [s] and
// poses (T, 6) [m, rad] as arrays; the library's hexatwist::Error becomes ConfigError (a bad file)
// or InputError (a bad argument), one line either way.
#include "common.hpp"

namespace hexatwist::python {

std::pair<std::string, std::string> read_yaml_source(const py::object& path_or_text);

py::array_t<double> pose_rows(const std::vector<Pose>& poses) {
  py::array_t<double> a({poses.size(), std::size_t{6}});
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Vector6d q = poses[k].to_vector();
    std::copy(q.data(), q.data() + 6, a.mutable_data() + 6 * k);
  }
  return a;
}

py::dict trajectory_arrays(const Trajectory& trajectory) {
  py::array_t<double> t(static_cast<py::ssize_t>(trajectory.poses.size()));
  for (std::size_t k = 0; k < trajectory.poses.size(); ++k) t.mutable_data()[k] = trajectory.time(k);
  py::dict d;
  d["t"] = t;
  d["poses"] = pose_rows(trajectory.poses);
  return d;
}

TimedPoses timed_poses_of(const py::object& times, const char* times_name, const py::object& poses) {
  const Rows6 q = rows6(poses, "poses", false);
  py::array_t<double> t;
  try {
    t = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(times);
  } catch (...) {
  }
  if (!t || t.ndim() != 1 || static_cast<std::size_t>(t.shape(0)) != q.rows)
    raise_input(std::string(times_name) + ": expected a 1-D array of as many times as poses [s]");
  TimedPoses tp;
  tp.t.assign(t.data(), t.data() + q.rows);
  tp.poses.resize(q.rows);
  for (std::size_t i = 0; i < q.rows; ++i) tp.poses[i] = pose_row(q.data, i);
  return tp;
}

namespace {

py::dict trajectory_dict(const Trajectory& tr) {
  py::dict d = trajectory_arrays(tr);
  d["dt"] = tr.dt;
  return d;
}

MotionLimits limits_of(double velocity, double acceleration, double jerk) {
  return MotionLimits{velocity, acceleration, jerk};
}

// The library's Error of a bad argument as InputError, after the function's name (its message names
// the field or the sample).
template <class F>
Trajectory checked(const char* function, F&& make) {
  try {
    return make();
  } catch (const Error& e) {
    raise_input(std::string(function) + ": " + e.what());
  }
}

py::dict sweep_py(int coordinate, double amplitude, double velocity, double acceleration, double jerk, double dwell,
                  double dt) {
  return trajectory_dict(checked("sweep_trajectory", [&] {
    return sweep_trajectory(coordinate, amplitude, limits_of(velocity, acceleration, jerk), dwell, dt);
  }));
}

py::dict waypoints_py(const py::object& waypoints_in, double velocity, double acceleration, double jerk, double dwell,
                      double dt) {
  const Rows6 rows = rows6(waypoints_in, "waypoints", false);
  std::vector<Vector6d> waypoints(rows.rows);
  for (std::size_t i = 0; i < rows.rows; ++i) waypoints[i] = Eigen::Map<const Vector6d>(rows.data + 6 * i);
  return trajectory_dict(checked("waypoint_trajectory", [&] {
    return waypoint_trajectory(waypoints, limits_of(velocity, acceleration, jerk), dwell, dt);
  }));
}

py::dict timed_dict(const TimedPoses& tp) {
  py::dict d;
  d["t"] = py::array_t<double>(static_cast<py::ssize_t>(tp.t.size()), tp.t.data());
  d["poses"] = pose_rows(tp.poses);
  d["lines"] = py::array_t<int>(static_cast<py::ssize_t>(tp.lines.size()), tp.lines.data());
  return d;
}

// A CSV file or its text: parse errors are the file's (ConfigError, "source:line:column: ...").
py::dict read_py(const py::object& path_or_text) {
  auto [text, source] = read_yaml_source(path_or_text);
  return timed_dict(parse_trajectory_csv(text, source));
}

py::dict resample_py(const py::object& times, const py::object& poses, double dt) {
  const TimedPoses tp = timed_poses_of(times, "t", poses);
  return trajectory_dict(checked("resample", [&] { return resample(tp, dt); }));
}

}  // namespace

void expose_trajectory(py::module_& m) {
  m.def("_sweep_trajectory", &sweep_py, py::arg("coordinate"), py::arg("amplitude"), py::arg("velocity"),
        py::arg("acceleration"), py::arg("jerk"), py::arg("dwell"), py::arg("dt"));
  m.def("_waypoint_trajectory", &waypoints_py, py::arg("waypoints"), py::arg("velocity"), py::arg("acceleration"),
        py::arg("jerk"), py::arg("dwell"), py::arg("dt"));
  m.def("_read_trajectory", &read_py, py::arg("path_or_text"));
  m.def("_resample", &resample_py, py::arg("t"), py::arg("poses"), py::arg("dt"));
}

}  // namespace hexatwist::python
