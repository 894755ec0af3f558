// SPDX-License-Identifier: BSD-3-Clause
// Errors: hexatwist.Error and its subclasses, the translation of the library's hexatwist::Error,
// the status names, and the checked array views shared by the batch functions.
#include <cmath>
#include <string>

#include "common.hpp"

namespace hexatwist::python {

std::atomic<std::uint64_t>& input_copies() noexcept {
  static std::atomic<std::uint64_t> count{0};
  return count;
}

std::atomic<unsigned>& thread_setting() noexcept {
  static std::atomic<unsigned> n{0};
  return n;
}

unsigned thread_count() noexcept {
  // glibc reads /sys for hardware_concurrency on every call (about 7 us): once per process.
  static const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  const unsigned s = thread_setting().load();
  return s ? s : cores;
}

Errors& errors() {
  static Errors e;
  return e;
}

void raise_status(Status s, const std::string& what) {
  py::object err =
      errors().status_error(what + ": " + std::string(to_string(s)) + " (" + std::string(describe(s)) + ")");
  err.attr("status") = py::str(std::string(to_string(s)));
  PyErr_SetObject(errors().status_error.ptr(), err.ptr());
  throw py::error_already_set();
}

void raise_input(const std::string& what) {
  PyErr_SetString(errors().input_error.ptr(), what.c_str());
  throw py::error_already_set();
}

namespace {
[[noreturn]] void raise_dtype(const std::string& what) {
  PyErr_SetString(errors().dtype_error.ptr(), what.c_str());
  throw py::error_already_set();
}
std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}
}  // namespace

Rows6 rows6(const py::handle& obj, const char* name, bool allow_single) {
  Rows6 r;
  if (!py::isinstance<py::array>(obj)) {
    // Lists and tuples: converted (a new array, not a copy of a numpy input).
    try {
      r.array = py::array(py::module_::import("numpy").attr("asarray")(obj, py::arg("dtype") = "float64"));
    } catch (py::error_already_set&) {
      raise_dtype(std::string(name) + ": expected an array of float64, got " +
                  std::string(py::str(py::type::of(obj).attr("__name__"))));
    }
  } else {
    r.array = py::reinterpret_borrow<py::array>(obj);
  }
  if (!py::isinstance<py::array_t<double>>(r.array))
    raise_dtype(std::string(name) + ": expected dtype float64, got " + std::string(py::str(r.array.dtype())));
  const bool one = r.array.ndim() == 1 && r.array.shape(0) == 6;
  if (!(r.array.ndim() == 2 && r.array.shape(1) == 6) && !(allow_single && one))
    raise_input(std::string(name) + ": expected shape (N, 6)" + (allow_single ? " or (6,)" : "") + ", got " +
                shape_of(r.array));
  if (!(r.array.flags() & py::array::c_style)) {
    ++input_copies();
    r.array = py::array(py::module_::import("numpy").attr("ascontiguousarray")(r.array));
  }
  r.single = one;
  r.rows = one ? 1 : static_cast<std::size_t>(r.array.shape(0));
  r.data = static_cast<const double*>(r.array.data());
  return r;
}

py::array_t<double> new_rows(std::size_t n, std::size_t cols, bool single) {
  if (single) return py::array_t<double>(static_cast<py::ssize_t>(cols));
  return py::array_t<double>({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(cols)});
}

Strategy strategy_from(const std::string& name) {
  if (Strategy s; parse_strategy(name, s)) return s;
  raise_input("strategy: expected 'compensated' or 'conventional', got '" + name + "'");
}

LengthKind length_kind_from(const std::string& name) {
  if (name == "motor") return LengthKind::Motor;
  if (name == "geometric") return LengthKind::Geometric;
  raise_input("kind: expected 'motor' or 'geometric', got '" + name + "'");
}

void raise_non_finite(const std::int8_t* status, std::size_t n, const char* name, const double* rows) {
  for (std::size_t i = 0; i < n; ++i) {
    if (status[i] == static_cast<std::int8_t>(Status::InvalidArgument))
      raise_input(std::string(name) + ": row " + std::to_string(i) + " holds a length <= 0 m");
    if (status[i] != static_cast<std::int8_t>(Status::NonFiniteInput)) continue;
    // Finite numbers whose computation overflows (1e300 m) are too large, not NaN or inf.
    bool finite = rows != nullptr;
    for (int k = 0; finite && k < 6; ++k) finite = std::isfinite(rows[6 * i + static_cast<std::size_t>(k)]);
    raise_input(std::string(name) + ": row " + std::to_string(i) +
                (finite ? " is too large to compute with (a length or pose beyond the platform's reach overflows)"
                        : " holds NaN or inf"));
  }
}

void expose_errors(py::module_& m) {
  Errors& e = errors();
  py::object builtins = py::module_::import("builtins");
  e.error = py::reinterpret_steal<py::object>(
      PyErr_NewExceptionWithDoc("hexatwist.Error", "Base of every hexatwist exception.", PyExc_Exception, nullptr));
  auto sub = [&](const char* qual, const char* doc, py::tuple bases) {
    return py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(qual, doc, bases.ptr(), nullptr));
  };
  e.config_error =
      sub("hexatwist.ConfigError", "An invalid model, configuration or input text (the library's one-line message).",
          py::make_tuple(e.error, builtins.attr("ValueError")));
  e.input_error = sub("hexatwist.InputError", "A bad argument: shape, NaN or inf, an unknown name.",
                      py::make_tuple(e.error, builtins.attr("ValueError")));
  e.dtype_error = sub("hexatwist.DTypeError", "An array argument of the wrong dtype (float64 expected).",
                      py::make_tuple(e.input_error, builtins.attr("TypeError")));
  e.status_error = sub("hexatwist.StatusError",
                       "A numerical status (outside a limit, no convergence ...) where a value was needed; "
                       "`.status` holds its snake_case name.",
                       py::make_tuple(e.error, builtins.attr("RuntimeError")));
  m.attr("Error") = e.error;
  m.attr("ConfigError") = e.config_error;
  m.attr("InputError") = e.input_error;
  m.attr("DTypeError") = e.dtype_error;
  m.attr("StatusError") = e.status_error;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const hexatwist::ParameterError& ex) {
      // The library names the parameter at fault: the keyword argument of the same name.
      PyErr_SetString(errors().input_error.ptr(), (std::string(ex.what()) + " [" + ex.parameter() + "]").c_str());
    } catch (const hexatwist::Error& ex) {
      PyErr_SetString(errors().config_error.ptr(), ex.what());
    }
  });

  // Status codes as stored in the batch results' int8 `status` arrays.
  py::list names;
  for (int s = 0; s <= static_cast<int>(kLastStatus); ++s)
    names.append(py::str(std::string(to_string(static_cast<Status>(s)))));
  m.attr("STATUS_NAMES") = py::tuple(names);
  m.def(
      "describe_status",
      [](int s) {
        if (s < 0 || s > static_cast<int>(kLastStatus)) raise_input("status: no status " + std::to_string(s));
        return std::string(describe(static_cast<Status>(s)));
      },
      py::arg("status"), "One-sentence description of a status code.");
  m.def(
      "set_num_threads",
      [](int n) {
        if (n < 0) raise_input("set_num_threads: expected a count >= 0 (0 = every core)");
        thread_setting() = static_cast<unsigned>(n);
      },
      py::arg("n"), "Threads of the batch functions (0, the default: every core). Results do not depend on it.");
  m.def(
      "get_num_threads", [] { return thread_count(); }, "Threads the batch functions use.");
  m.def(
      "_input_copies", [] { return input_copies().load(); },
      "Debug counter: inputs the bindings had to copy (never a C-contiguous float64 array).");
}

}  // namespace hexatwist::python
