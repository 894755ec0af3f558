// SPDX-License-Identifier: BSD-3-Clause
// hexatwist.Model: the immutable platform model, from the embedded seed, YAML text or a file, or
// numpy arrays; its numbers as arrays, its YAML back out, and pickling (exact: the numbers travel).
#include <pybind11/stl.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "common.hpp"

namespace hexatwist::python {
namespace {

using ModelPtr = std::shared_ptr<Model>;

py::array_t<double> rows3(const PerLeg<LegSpec>& legs, Vector3d LegSpec::*field) {
  py::array_t<double> a({kLegs, 3});
  auto v = a.mutable_unchecked<2>();
  for (int i = 0; i < kLegs; ++i)
    for (int k = 0; k < 3; ++k) v(i, k) = (legs[static_cast<std::size_t>(i)].*field)[k];
  return a;
}

// A copy of a fixed-size vector (no conversion to a dynamic one: GCC 12 then flags Eigen's AVX-512 loads).
template <class V>
py::array_t<double> vec(const V& x) {
  return py::array_t<double>(static_cast<py::ssize_t>(x.size()), x.data());
}

// A (6, 3) float64 array argument (copied: a model is built once).
void read_rows3(const py::handle& obj, const char* name, PerLeg<LegSpec>& legs, Vector3d LegSpec::*field) {
  py::array_t<double> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (...) {
  }
  if (!a || a.ndim() != 2 || a.shape(0) != kLegs || a.shape(1) != 3)
    raise_input(std::string(name) + ": expected a (6, 3) array of numbers [one row per leg]");
  auto v = a.unchecked<2>();
  for (int i = 0; i < kLegs; ++i) legs[static_cast<std::size_t>(i)].*field = Vector3d(v(i, 0), v(i, 1), v(i, 2));
}

Vector6d read6(const py::handle& obj, const char* name) {
  py::array_t<double> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (...) {
  }
  if (!a) raise_input(std::string(name) + ": expected a number or 6 numbers");
  if (a.ndim() == 0) return Vector6d::Constant(*a.data());
  if (a.ndim() != 1 || a.shape(0) != kLegs) raise_input(std::string(name) + ": expected a number or 6 numbers");
  return Eigen::Map<const Vector6d>(a.data());
}

Vector3d read3(const py::handle& obj, const char* name) {
  py::array_t<double> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (...) {
  }
  if (!a || a.ndim() != 1 || a.shape(0) != 3) raise_input(std::string(name) + ": expected 3 numbers");
  return Eigen::Map<const Vector3d>(a.data());
}

ThreadSense thread_from(const std::string& s) {
  if (s == "right") return ThreadSense::Right;
  if (s == "left") return ThreadSense::Left;
  raise_input("thread_hand: expected 'right' or 'left', got '" + s + "'");
}

// One hand for every leg ("right" | "left") or six, legs 1 to 6 in order.
PerLeg<ThreadSense> thread_hands_from(const py::object& obj) {
  PerLeg<ThreadSense> hands;
  if (py::isinstance<py::str>(obj)) {
    hands.fill(thread_from(obj.cast<std::string>()));
    return hands;
  }
  std::vector<std::string> names;
  try {
    names = obj.cast<std::vector<std::string>>();
  } catch (const py::cast_error&) {
  }
  if (names.size() != static_cast<std::size_t>(kLegs))
    raise_input("thread_hand: expected 'right' or 'left', or 6 of them (legs 1 to 6)");
  for (std::size_t i = 0; i < hands.size(); ++i) hands[i] = thread_from(names[i]);
  return hands;
}
DrivenSide driven_from(const std::string& s) {
  if (s == "base") return DrivenSide::Base;
  if (s == "platform") return DrivenSide::Platform;
  raise_input("driven_side: expected 'base' or 'platform', got '" + s + "'");
}

ModelPtr from_arrays(const py::object& base, const py::object& platform, const py::object& base_axes,
                     const py::object& platform_axes, double home_height, const py::object& lead,
                     const py::object& thread_hand, const std::string& driven_side, const py::object& length_offsets,
                     double length_min, double length_max, double bend_max, double singularity_margin,
                     double jacobian_condition_max, const py::object& observation_point, const py::object& pivot,
                     const std::string& name) {
  ModelSpec spec;
  spec.name = name;
  read_rows3(base, "base", spec.legs, &LegSpec::base_B);
  read_rows3(platform, "platform", spec.legs, &LegSpec::platform_P);
  read_rows3(base_axes, "base_axes", spec.legs, &LegSpec::axis_base_B);
  read_rows3(platform_axes, "platform_axes", spec.legs, &LegSpec::axis_platform_P);
  const Vector6d leads = read6(lead, "lead");
  const Vector6d offsets = read6(length_offsets, "length_offsets");
  const PerLeg<ThreadSense> hands = thread_hands_from(thread_hand);
  const DrivenSide d = driven_from(driven_side);
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
    leg.lead = leads[i];
    leg.thread = hands[static_cast<std::size_t>(i)];
    leg.driven = d;
    leg.length_offset = offsets[i];
  }
  spec.home_height = home_height;
  spec.limits = LimitSpec{length_min, length_max, bend_max, singularity_margin, jacobian_condition_max};
  spec.observation_P = read3(observation_point, "observation_point");
  spec.pivot_P = read3(pivot, "pivot");
  return std::make_shared<Model>(spec);
}

// The model as a configuration in the legs form (the library's writer: every double exact).
std::string to_yaml(const Model& model) { return model_yaml(model.spec()); }

// Pickle state: every number of the spec, exactly.
py::tuple state_of(const Model& m) {
  const ModelSpec& s = m.spec();
  py::list legs;
  for (const LegSpec& l : s.legs)
    legs.append(py::make_tuple(
        0, l.base_B[0], l.base_B[1], l.base_B[2], l.platform_P[0], l.platform_P[1], l.platform_P[2], l.axis_base_B[0],
        l.axis_base_B[1], l.axis_base_B[2], l.axis_platform_P[0], l.axis_platform_P[1], l.axis_platform_P[2], l.lead,
        static_cast<int>(l.thread), static_cast<int>(l.driven), l.length_offset, l.drive_lead, l.home_command));
  return py::make_tuple(2, s.name, legs, s.home_height,
                        py::make_tuple(s.limits.length_min, s.limits.length_max, s.limits.bend_max,
                                       s.limits.singularity_margin, s.limits.jacobian_condition_max),
                        py::make_tuple(s.observation_P[0], s.observation_P[1], s.observation_P[2]),
                        py::make_tuple(s.pivot_P[0], s.pivot_P[1], s.pivot_P[2]));
}

ModelPtr from_state(const py::tuple& t) {
  if (t.size() != 7 || t[0].cast<int>() != 2) raise_input("Model pickle: unknown state");
  ModelSpec s;
  s.name = t[1].cast<std::string>();
  py::list legs = t[2];
  for (int i = 0; i < kLegs; ++i) {
    py::tuple l = legs[static_cast<std::size_t>(i)];
    LegSpec& g = s.legs[static_cast<std::size_t>(i)];
    auto d = [&](int k) { return l[static_cast<std::size_t>(k)].cast<double>(); };
    g.base_B = Vector3d(d(1), d(2), d(3));
    g.platform_P = Vector3d(d(4), d(5), d(6));
    g.axis_base_B = Vector3d(d(7), d(8), d(9));
    g.axis_platform_P = Vector3d(d(10), d(11), d(12));
    g.lead = d(13);
    g.thread = static_cast<ThreadSense>(l[14].cast<int>());
    g.driven = static_cast<DrivenSide>(l[15].cast<int>());
    g.length_offset = d(16);
    g.drive_lead = d(17);
    g.home_command = d(18);
  }
  s.home_height = t[3].cast<double>();
  py::tuple lim = t[4];
  s.limits = LimitSpec{lim[0].cast<double>(), lim[1].cast<double>(), lim[2].cast<double>(), lim[3].cast<double>(),
                       lim[4].cast<double>()};
  py::tuple o = t[5], p = t[6];
  s.observation_P = Vector3d(o[0].cast<double>(), o[1].cast<double>(), o[2].cast<double>());
  s.pivot_P = Vector3d(p[0].cast<double>(), p[1].cast<double>(), p[2].cast<double>());
  return std::make_shared<Model>(s);
}

// YAML text, or the path of a file holding it.
std::pair<std::string, std::string> read_source(const py::object& path_or_text, std::size_t max_bytes) {
  py::object os = py::module_::import("os");
  std::string text, source;
  bool is_path = py::isinstance(path_or_text, os.attr("PathLike"));
  if (!is_path && py::isinstance<py::str>(path_or_text)) {
    text = path_or_text.cast<std::string>();
    is_path = text.find('\n') == std::string::npos && text.find(':') == std::string::npos;
    if (!is_path) return {text, "<yaml>"};
  } else if (!is_path) {
    raise_input("load: expected YAML text or a path, got " +
                std::string(py::str(py::type::of(path_or_text).attr("__name__"))));
  }
  source = py::str(os.attr("fspath")(path_or_text)).cast<std::string>();
  std::error_code ec;
  if (!std::filesystem::exists(source, ec)) {
    PyErr_SetString(PyExc_FileNotFoundError, (source + ": cannot open the file").c_str());
    throw py::error_already_set();
  }
  // The library's reader: a directory, an unreadable or an overlong file is a ConfigError, as in C.
  return {read_text_file(source, max_bytes == kMaxConfigBytes ? "configuration file" : "file", max_bytes), source};
}

}  // namespace

// A data file (trajectory CSV, point log: up to kMaxDataBytes) or its text.
std::pair<std::string, std::string> read_yaml_source(const py::object& path_or_text) {
  return read_source(path_or_text, kMaxDataBytes);
}

// A configuration file (up to kMaxConfigBytes) or its text.
std::pair<std::string, std::string> read_config_source(const py::object& path_or_text) {
  return read_source(path_or_text, kMaxConfigBytes);
}

void expose_model(py::module_& m) {
  py::class_<Model, std::shared_ptr<Model>> c(
      m, "Model",
      "Immutable, validated six-leg U-P-U lead-screw platform. Frames: B is the base frame, P the platform "
      "frame (B translated by home_height along z at home). Build with default_model(), load_model(), or "
      "Model.from_arrays(); pickles exactly.");
  c.def_static("from_arrays", &from_arrays, py::arg("base"), py::arg("platform"), py::arg("base_axes"),
               py::arg("platform_axes"), py::arg("home_height"), py::arg("lead") = 0.010,
               py::arg("thread_hand") = "right", py::arg("driven_side") = "base", py::arg("length_offsets") = 0.0,
               py::kw_only(), py::arg("length_min"), py::arg("length_max"), py::arg("bend_max"),
               py::arg("singularity_margin"), py::arg("jacobian_condition_max") = kDefaultJacobianConditionMax,
               py::arg("observation_point") = py::make_tuple(0.0, 0.0, 0.0),
               py::arg("pivot") = py::make_tuple(0.0, 0.0, 0.0), py::arg("name") = "",
               "Model from arrays: base (6, 3) base joint centres [m, B]; platform (6, 3) platform joint centres "
               "[m, P]; base_axes, platform_axes (6, 3) fixed U-joint axes ja [B], jd [P]; home_height [m]; lead "
               "[m] (one or 6); thread_hand 'right'|'left' (one or 6); driven_side 'base'|'platform'; "
               "length_offsets [m] (one or 6); keyword-only: the limits length_min, length_max [m], bend_max, "
               "singularity_margin [rad], jacobian_condition_max [-]; observation_point, pivot [m, P]; name. Rows and "
               "entries are legs 1 to 6 in order. Raises ConfigError naming the leg and field at fault.");
  c.def_property_readonly("name", [](const Model& x) { return x.spec().name; });
  c.def_property_readonly(
      "home_height", [](const Model& x) { return x.spec().home_height; }, "[m]");
  c.def_property_readonly(
      "base", [](const Model& x) { return rows3(x.spec().legs, &LegSpec::base_B); },
      "Base joint centres (6, 3) [m, B].");
  c.def_property_readonly(
      "platform", [](const Model& x) { return rows3(x.spec().legs, &LegSpec::platform_P); },
      "Platform joint centres (6, 3) [m, P].");
  c.def_property_readonly(
      "base_axes", [](const Model& x) { return rows3(x.spec().legs, &LegSpec::axis_base_B); },
      "Fixed base U-joint axes ja as given (6, 3) [-, B].");
  c.def_property_readonly(
      "platform_axes", [](const Model& x) { return rows3(x.spec().legs, &LegSpec::axis_platform_P); },
      "Fixed platform U-joint axes jd as given (6, 3) [-, P].");
  c.def_property_readonly(
      "lead",
      [](const Model& x) {
        Vector6d v;
        for (int i = 0; i < kLegs; ++i) v[i] = x.leg(i).lead;
        return vec(v);
      },
      "Screw lead per leg (6,) [m].");
  c.def_property_readonly(
      "thread_hands",
      [](const Model& x) {
        py::list l;
        for (const Leg& g : x.legs()) l.append(g.thread == ThreadSense::Right ? "right" : "left");
        return py::tuple(l);
      },
      "Hand of each leg's screw thread, 'right' or 'left' (legs 1 to 6).");
  c.def_property_readonly(
      "length_offsets",
      [](const Model& x) {
        Vector6d v;
        for (int i = 0; i < kLegs; ++i) v[i] = x.leg(i).length_offset;
        return vec(v);
      },
      "Real minus motor-side length at zero twist (6,) [m].");
  c.def_property_readonly(
      "twist_gain", [](const Model& x) { return vec(x.geometry().twist_gain); },
      "Real minus motor-side length per rad of twist, sign*lead/2pi (6,) [m/rad].");
  c.def_property_readonly(
      "length_home", [](const Model& x) { return vec(x.length_home()); }, "Leg lengths at home (6,) [m].");
  c.def_property_readonly(
      "observation_point", [](const Model& x) { return vec(x.spec().observation_P); }, "Observation point A [m, P].");
  c.def_property_readonly(
      "pivot", [](const Model& x) { return vec(x.spec().pivot_P); }, "Rotation pivot [m, P].");
  c.def_property_readonly("has_twist", &Model::has_twist, "True if any leg has a non-zero lead.");
  c.def_property_readonly(
      "limits",
      [](const Model& x) {
        const LimitSpec& l = x.spec().limits;
        py::dict d;
        d["length_min"] = l.length_min;
        d["length_max"] = l.length_max;
        d["bend_max"] = l.bend_max;
        d["singularity_margin"] = l.singularity_margin;
        d["jacobian_condition_max"] = l.jacobian_condition_max;
        return d;
      },
      "Limits: length_min, length_max [m], bend_max, singularity_margin [rad], jacobian_condition_max [-].");
  c.def("to_yaml", &to_yaml,
        "The model as YAML configuration text (explicit legs; numbers in shortest round-trip form, angles in "
        "degrees) that load_model reads back.");
  c.def("__repr__", [](const Model& x) { return "<hexatwist.Model '" + x.spec().name + "'>"; });
  c.def(py::pickle([](const Model& x) { return state_of(x); }, [](const py::tuple& t) { return from_state(t); }));

  m.def(
      "default_model", [] { return std::make_shared<Model>(default_model()); },
      "The embedded seed platform (configs/seed.yaml): Ra 1.2, Rb 1.5, da 0.2, db 0.3, H 1.511 m, lead 10 mm.");
  m.def(
      "load_model",
      [](const py::object& src) {
        auto [text, source] = read_source(src, kMaxConfigBytes);
        return std::make_shared<Model>(load_model(text, source));
      },
      py::arg("path_or_yaml"),
      "Model from a YAML file (str without ':' or newline, or os.PathLike) or YAML text. Raises ConfigError "
      "with the library's one-line 'source:line:column: field ...' message.");
  m.def(
      "seed_config_yaml", [] { return std::string(seed_config_yaml()); },
      "The embedded seed configuration (platform, servo, load, simulation, study) as YAML text.");
}

}  // namespace hexatwist::python
