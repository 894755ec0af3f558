// SPDX-License-Identifier: BSD-3-Clause
// Shared helpers of the Python bindings: checked views of numpy arrays (no copy of a contiguous
// float64 input), output arrays, the status names, and the std::thread chunking of batch work.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "hexatwist/hexatwist.hpp"

namespace hexatwist::python {

namespace py = pybind11;

/// Copies the bindings made of inputs that were not C-contiguous float64 (a debug counter for the
/// tests: a contiguous float64 input is never copied).
std::atomic<std::uint64_t>& input_copies() noexcept;

/// Poses of a batch per deterministic block: work is split on these boundaries whatever the number
/// of threads, so warm-started forward kinematics gives the same numbers on 1 or 64 threads.
inline constexpr std::size_t kBlock = 4096;

/// A checked read-only view of an (N, 6) float64 array (or (6,) seen as N = 1). Throws
/// ValueError / TypeError with one line naming the argument. Holds the array (or its copy).
struct Rows6 {
  py::array array;  ///< the array read (the input itself when it was C-contiguous float64)
  const double* data = nullptr;
  std::size_t rows = 0;
  bool single = false;  ///< the input was one row of shape (6,)
};
Rows6 rows6(const py::handle& obj, const char* name, bool allow_single = true);

/// A new C-contiguous float64 array of shape (n, cols), or (cols,) when `single` (n must be 1).
py::array_t<double> new_rows(std::size_t n, std::size_t cols, bool single);
/// A new 1-D array of n elements, or a 0-d array when `single` (one pose given as (6,)).
template <class T>
py::array_t<T> new_column(std::size_t n, bool single) {
  if (single) return py::array_t<T>(std::vector<py::ssize_t>{});
  return py::array_t<T>(static_cast<py::ssize_t>(n));
}

/// Status from its snake_case name; throws ValueError naming the argument.
Strategy strategy_from(const std::string& name);
LengthKind length_kind_from(const std::string& name);

/// Threads a batch call uses (0 = every core).
std::atomic<unsigned>& thread_setting() noexcept;
/// The threads a batch call may use: the setting, or every core.
unsigned thread_count() noexcept;

/// Runs body(begin, end) over [0, n) in blocks of `block` items (kBlock poses by default) spread
/// over the cores, with the GIL released. Small batches run on the calling thread.
template <class F>
void parallel_blocks(std::size_t n, F&& body, std::size_t block = kBlock) {
  py::gil_scoped_release release;
  const std::size_t blocks = (n + block - 1) / block;
  const std::size_t workers = blocks > 1 ? std::min<std::size_t>(thread_count(), blocks) : 1;
  if (workers <= 1) {
    for (std::size_t b = 0; b < blocks; ++b) body(b * block, std::min(n, (b + 1) * block));
    return;
  }
  std::atomic<std::size_t> next{0};
  auto run = [&] {
    for (std::size_t b = next++; b < blocks; b = next++) body(b * block, std::min(n, (b + 1) * block));
  };
  std::vector<std::thread> threads;
  threads.reserve(workers - 1);
  for (std::size_t w = 1; w < workers; ++w) threads.emplace_back(run);
  run();
  for (auto& t : threads) t.join();
}

/// Poses [m, rad] as a new (N, 6) array.
py::array_t<double> pose_rows(const std::vector<Pose>& poses);
/// A trajectory's sample times (T,) [s] and poses (T, 6) [m, rad]: a dict {"t", "poses"}.
py::dict trajectory_arrays(const Trajectory& trajectory);
/// Poses (T, 6) at times (T,) [s], as a file gives them; InputError naming `times_name` unless there is
/// one time per pose.
TimedPoses timed_poses_of(const py::object& times, const char* times_name, const py::object& poses);

/// The pose of row `i` of an (N, 6) row-major array.
inline Pose pose_row(const double* data, std::size_t i) noexcept {
  const double* q = data + 6 * i;
  Pose p;
  p.position = Vector3d(q[0], q[1], q[2]);
  p.rpy = Vector3d(q[3], q[4], q[5]);
  return p;
}

/// Throws InputError naming the first row whose status is NonFiniteInput ("holds NaN or inf", or
/// "too large to compute with" when `rows`, the (n, 6) input, shows it finite) or InvalidArgument (a length <= 0).
void raise_non_finite(const std::int8_t* status, std::size_t n, const char* name, const double* rows = nullptr);

/// hexatwist.Rig: a validated configuration and the YAML text it came from (for pickling).
struct PyRig {
  std::shared_ptr<const Config> config;
  std::string yaml;
  std::string source;
};
/// The Rig of a `config` argument: a Rig itself, or one built from YAML text, a path or None (seed).
std::shared_ptr<const PyRig> rig_of(const py::handle& src);

/// A platform argument of the design functions: a Model, or a config (Rig, YAML text, path, None
/// for the seed) with its study section and its text (empty for a Model).
struct PlatformSource {
  std::shared_ptr<const Model> model;
  StudySpec study;
  std::string yaml, source;
};
PlatformSource platform_of(const py::handle& src);

/// A (3,) float64 vector argument (lists accepted); InputError naming it otherwise, or for NaN/inf.
Vector3d vector3(const py::handle& obj, const char* name);

/// The workspace searches' settings from Python arguments (InputError for an unknown strategy).
WorkspaceOptions search_options(double step, double tolerance, const std::string& strategy);
/// The slice `plane` ("xy", "xz", "yz") at `offset` [m] of `model` at `orientation` [rad], searched
/// `spacing` [m] apart; InputError / StatusError beginning with `what` when it cannot be searched.
WorkspaceSlice slice_of(const Model& model, const py::object& orientation, const std::string& plane, double offset,
                        double spacing, double step, double tolerance, const std::string& strategy, const char* what);

/// The leg number the package reports for a library leg index: 1 to 6, and 0 for none (the
/// library's -1: no limit, or the platform Jacobian's condition). Every `leg` field and array of
/// the Python package is numbered so, as the command line's messages and JSON are.
constexpr int leg_number(int index) noexcept { return index + 1; }

/// A limit report as a dict: status (name), leg (1 to 6; 0 for none), value, bound.
py::dict limit_dict(const LimitReport& r);

/// A (6,) float64 vector argument (lists accepted); InputError naming it otherwise, or for NaN/inf.
Vector6d vector6(const py::handle& obj, const char* name);

/// The Python exception types (hexatwist.Error and its subclasses), set by expose_errors.
struct Errors {
  py::object error, config_error, input_error, dtype_error, status_error;
};
Errors& errors();
/// Raises hexatwist.StatusError for a status where a value was needed.
[[noreturn]] void raise_status(Status s, const std::string& what);
/// Raises hexatwist.InputError (a ValueError) with a one-line message.
[[noreturn]] void raise_input(const std::string& what);

// One function per binding file.
void expose_errors(py::module_& m);
void expose_model(py::module_& m);
void expose_kinematics(py::module_& m);
void expose_commands(py::module_& m);
void expose_forward(py::module_& m);
void expose_simulation(py::module_& m);
void expose_measurement(py::module_& m);
void expose_identification(py::module_& m);
void expose_station_plan(py::module_& m);
void expose_validation(py::module_& m);
void expose_stream(py::module_& m);
void expose_trajectory(py::module_& m);
void expose_rig(py::module_& m);
void expose_mechanism(py::module_& m);
void expose_motor_sizing(py::module_& m);
void expose_registration(py::module_& m);
void expose_workspace(py::module_& m);
void expose_mjcf(py::module_& m);
void expose_workspace_volume(py::module_& m);
void expose_workspace_boundary(py::module_& m);
void expose_workspace_map(py::module_& m);
void expose_axis_design(py::module_& m);
void expose_tolerance(py::module_& m);

}  // namespace hexatwist::python
