// SPDX-License-Identifier: BSD-3-Clause
// Batch forward kinematics from (N, 6) leg lengths, motor-side (twist included) or geometric:
// warm-started along the batch (in fixed blocks, so the result does not depend on the threads) or
// from given guesses, with per-pose status, iterations and residual.
#include <memory>

#include "common.hpp"

namespace hexatwist::python {
namespace {

// The library's options from Python's arguments, checked as the library checks them (check_fk_options).
FkOptions fk_options(int max_iterations, double tolerance) {
  FkOptions options;
  options.max_iterations = max_iterations;
  options.tolerance = tolerance;
  if (const std::string_view why = check_fk_options(options); !why.empty()) raise_input(std::string(why));
  return options;
}

py::dict fk_batch(const Model& model, const py::object& lengths_in, const std::string& kind_name,
                  const py::object& guess_in, int max_iterations, double tolerance) {
  const LengthKind kind = length_kind_from(kind_name);
  const Rows6 lengths = rows6(lengths_in, "lengths");
  const std::size_t n = lengths.rows;
  Rows6 guess;
  const bool chain = guess_in.is_none();
  if (!chain) {
    guess = rows6(guess_in, "guess");
    if (!guess.single && guess.rows != n)
      raise_input("guess: expected shape (6,) or (" + std::to_string(n) + ", 6) to match lengths, got (" +
                  std::to_string(guess.rows) + ", 6)");
    for (std::size_t i = 0; i < guess.rows * 6; ++i)
      if (!std::isfinite(guess.data[i])) raise_input("guess: row " + std::to_string(i / 6) + " holds NaN or inf");
  }
  const FkOptions options = fk_options(max_iterations, tolerance);
  auto poses = new_rows(n, 6, lengths.single);
  auto status = new_column<std::int8_t>(n, lengths.single);
  auto iterations = new_column<std::int32_t>(n, lengths.single);
  auto residual = new_column<double>(n, lengths.single);
  double *pq = poses.mutable_data(), *pr = residual.mutable_data();
  std::int8_t* ps = status.mutable_data();
  std::int32_t* pi = iterations.mutable_data();
  const double* l = lengths.data;
  parallel_blocks(n, [&](std::size_t begin, std::size_t end) {
    FkResult r;
    Placement start;  // home; then the last solution of this block
    for (std::size_t i = begin; i < end; ++i) {
      if (!chain) start = placement_from_pose(pose_row(guess.data, guess.single ? 0 : i));
      const Status s = forward_kinematics(model, Eigen::Map<const Vector6d>(l + 6 * i), kind, start, r, options);
      ps[i] = static_cast<std::int8_t>(s);
      pi[i] = r.iterations;
      pr[i] = r.residual;
      const Vector6d q = r.pose.to_vector();
      for (int k = 0; k < 6; ++k) pq[6 * i + k] = s == Status::Ok ? q[k] : NAN;
      if (chain && s == Status::Ok) start = r.placement;
    }
  });
  raise_non_finite(ps, n, "lengths", lengths.data);
  py::dict d;
  d["poses"] = poses;
  d["status"] = status;
  d["iterations"] = iterations;
  d["residual"] = residual;
  return d;
}

// Forward kinematics along a motion (forward_kinematics_tracked): one tracker, rows in order.
struct PyFkTracker {
  std::shared_ptr<Model> model;
  LengthKind kind = LengthKind::Motor;
  FkTracker tracker;
};

void tracker_set(PyFkTracker& t, const py::object& pose_in) {
  const Rows6 r = rows6(pose_in, "pose");
  if (!r.single) raise_input("pose: expected 6 numbers x, y, z [m], roll, pitch, yaw [rad]");
  const Pose pose = pose_row(r.data, 0);
  if (!pose.is_finite()) raise_input("pose: holds NaN or inf");
  const Status s = fk_tracker_set(*t.model, placement_from_pose(pose), t.kind, t.tracker);
  if (s != Status::Ok) raise_status(s, "FkTracker.set: no assembly mode at this pose");
}

py::dict tracker_track(PyFkTracker& t, const py::object& lengths_in, int max_iterations, double tolerance) {
  const FkOptions options = fk_options(max_iterations, tolerance);
  const Rows6 lengths = rows6(lengths_in, "lengths");
  const std::size_t n = lengths.rows;
  auto poses = new_rows(n, 6, lengths.single);
  auto status = new_column<std::int8_t>(n, lengths.single);
  auto iterations = new_column<std::int32_t>(n, lengths.single);
  auto residual = new_column<double>(n, lengths.single), condition = new_column<double>(n, lengths.single),
       det_sign = new_column<double>(n, lengths.single);
  double *pq = poses.mutable_data(), *pr = residual.mutable_data(), *pc = condition.mutable_data(),
         *pd = det_sign.mutable_data();
  std::int8_t* ps = status.mutable_data();
  std::int32_t* pi = iterations.mutable_data();
  {
    // Sequential: each row starts from the tracker's last solution.
    py::gil_scoped_release release;
    FkResult r;
    for (std::size_t i = 0; i < n; ++i) {
      const Status s = forward_kinematics_tracked(*t.model, Eigen::Map<const Vector6d>(lengths.data + 6 * i), t.kind,
                                                  t.tracker, r, options);
      ps[i] = static_cast<std::int8_t>(s);
      pi[i] = r.iterations;
      pr[i] = r.residual;
      pc[i] = r.condition;
      pd[i] = r.det_sign;
      const Vector6d q = r.pose.to_vector();
      for (int k = 0; k < 6; ++k) pq[6 * i + k] = s == Status::Ok ? q[k] : NAN;
    }
  }
  raise_non_finite(ps, n, "lengths", lengths.data);
  py::dict d;
  d["poses"] = poses;
  d["status"] = status;
  d["iterations"] = iterations;
  d["residual"] = residual;
  d["condition"] = condition;
  d["det_sign"] = det_sign;
  return d;
}

}  // namespace

void expose_forward(py::module_& m) {
  py::class_<PyFkTracker>(
      m, "FkTracker",
      "Forward kinematics along a motion (forward.hpp, forward_kinematics_tracked): each solve starts from the "
      "last solution and is ok only on the same assembly mode (the sign of the Jacobian's determinant) and with "
      "the Jacobian's condition inside limits.jacobian_condition_max (else platform_singularity); a failed row "
      "leaves the tracker as it was. Starts at home until set() or the first solution.")
      .def(py::init([](std::shared_ptr<Model> model, const std::string& kind, const py::object& start) {
             auto t = std::make_unique<PyFkTracker>();
             t->model = std::move(model);
             t->kind = length_kind_from(kind);
             if (!start.is_none()) tracker_set(*t, start);
             return t;
           }),
           py::arg("model"), py::arg("kind") = "motor", py::arg("start") = py::none(),
           "kind: 'motor' (motor-side lengths, twist included) or 'geometric'; start: None (home) or a pose "
           "[m, rad] whose assembly mode the tracker keeps.")
      .def("set", &tracker_set, py::arg("pose"),
           "Sets the tracker to a known pose [x, y, z m, roll, pitch, yaw rad] (after homing) and its assembly "
           "mode. Raises StatusError where the pose has no inverse kinematics or a singular Jacobian.")
      .def("_track", &tracker_track, py::arg("lengths"), py::arg("max_iterations") = 30, py::arg("tolerance") = 1e-12,
           "Solves (N, 6) or (6,) leg lengths [m] in order (GIL released); hexatwist.FkTracker.track types the "
           "result. Returns a dict: poses (N, 6) [m, rad] "
           "(NaN unless ok), status (N,) int8 (ok, assembly_mode_changed, platform_singularity, no_convergence, "
           "...), iterations (N,) int32, residual (N,) [m], condition (N,) [-] and det_sign (N,) [-].")
      .def_property_readonly(
          "valid", [](const PyFkTracker& t) { return t.tracker.valid; }, "False until set() or the first solution.")
      .def_property_readonly(
          "det_sign", [](const PyFkTracker& t) { return t.tracker.det_sign; },
          "Assembly mode kept: sign of the Jacobian's determinant (0 before the first).")
      .def_property_readonly(
          "last",
          [](const PyFkTracker& t) -> py::object {
            if (!t.tracker.valid) return py::none();
            const Vector6d q = pose_from_placement(t.tracker.last).to_vector();
            return py::array_t<double>(6, q.data());
          },
          "The last solution [m, rad], the next solve's start (None until valid).");

  m.def("_forward", &fk_batch, py::arg("model"), py::arg("lengths"), py::arg("kind") = "motor",
        py::arg("guess") = py::none(), py::arg("max_iterations") = 30, py::arg("tolerance") = 1e-12);
  m.attr("BLOCK") = kBlock;
}

}  // namespace hexatwist::python
