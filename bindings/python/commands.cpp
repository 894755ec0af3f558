// SPDX-License-Identifier: BSD-3-Clause
// Motor-side commands (Eq. 11-12) over (N, 6) poses with a per-pose status and limit report, and
// the one-pose real-time call.
#include "common.hpp"

namespace hexatwist::python {
namespace {

py::dict commands_batch(const Model& model, const py::object& poses_in, const std::string& strategy_name) {
  const Strategy strategy = strategy_from(strategy_name);
  const Rows6 poses = rows6(poses_in, "poses");
  const std::size_t n = poses.rows;
  auto commands = new_rows(n, 6, poses.single);
  auto status = new_column<std::int8_t>(n, poses.single);
  auto leg = new_column<std::int8_t>(n, poses.single);
  auto value = new_column<double>(n, poses.single), bound = new_column<double>(n, poses.single);
  double *pc = commands.mutable_data(), *pv = value.mutable_data(), *pb = bound.mutable_data();
  std::int8_t *ps = status.mutable_data(), *pg = leg.mutable_data();
  const double* q = poses.data;
  parallel_blocks(n, [&](std::size_t begin, std::size_t end) {
    // The poses across the lanes (batch.hpp), a few hundred at a time: the reports stay in cache
    // on their way to the four columns.
    constexpr std::size_t kChunk = 256;
    LimitReport reports[kChunk];
    for (std::size_t first = begin; first < end; first += kChunk) {
      const std::size_t m = std::min(kChunk, end - first);
      const Status s =
          motor_commands_batch(model, {q + 6 * first, 6 * m}, strategy, {pc + 6 * first, 6 * m}, {reports, m});
      (void)s;  // the spans are consistent by construction
      for (std::size_t i = 0; i < m; ++i) {
        const LimitReport& r = reports[i];
        ps[first + i] = static_cast<std::int8_t>(r.status);
        pg[first + i] = static_cast<std::int8_t>(leg_number(r.leg));
        pv[first + i] = r.value;
        pb[first + i] = r.bound;
      }
    }
  });
  raise_non_finite(ps, n, "poses", poses.data);
  py::dict d;
  d["commands"] = commands;
  d["status"] = status;
  d["limit_leg"] = leg;
  d["limit_value"] = value;
  d["limit_bound"] = bound;
  return d;
}

// One pose, the real-time function called as directly as Python allows.
py::array_t<double> motor_command(const Model& model, const py::object& pose_in, const std::string& strategy_name) {
  const Strategy strategy = strategy_from(strategy_name);
  Pose pose;
  if (PyList_Check(pose_in.ptr()) || PyTuple_Check(pose_in.ptr())) {
    // Lists and tuples of six numbers read directly: the cheapest path from Python.
    if (PySequence_Fast_GET_SIZE(pose_in.ptr()) != 6)
      raise_input("pose: expected 6 numbers x, y, z [m], roll, pitch, yaw [rad]");
    double q[6];
    for (int k = 0; k < 6; ++k) {
      q[k] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(pose_in.ptr(), k));
      if (q[k] == -1.0 && PyErr_Occurred()) {
        PyErr_Clear();
        raise_input("pose: field " + std::to_string(k) + " is not a number");
      }
    }
    pose = pose_row(q, 0);
  } else {
    const Rows6 r = rows6(pose_in, "pose");
    if (!r.single)
      raise_input("pose: expected 6 numbers x, y, z [m], roll, pitch, yaw [rad]; use commands() for (N, 6)");
    pose = pose_row(r.data, 0);
  }
  Vector6d c;
  LimitReport r;
  const Status s = motor_commands(model, pose, strategy, c, r);
  if (s == Status::NonFiniteInput) raise_input("pose: holds NaN or inf");
  if (s != Status::Ok) raise_status(s, "pose outside a limit: " + describe(r));  // the CLI's words
  py::array_t<double> out(6);
  std::copy(c.data(), c.data() + 6, out.mutable_data());
  return out;
}

}  // namespace

void expose_commands(py::module_& m) {
  m.def("_commands", &commands_batch, py::arg("model"), py::arg("poses"), py::arg("strategy") = "compensated");
  m.def("motor_command", &motor_command, py::arg("model"), py::arg("pose"), py::arg("strategy") = "compensated",
        "Motor-side commands (6,) [m] for one pose [x, y, z m, roll, pitch, yaw rad] relative to home: the "
        "library's real-time motor_commands (Eq. 11-12, limits checked). Raises StatusError outside a limit, "
        "InputError for NaN or a malformed pose.");
}

}  // namespace hexatwist::python
