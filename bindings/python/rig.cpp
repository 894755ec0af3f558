// SPDX-License-Identifier: BSD-3-Clause
// hexatwist.Rig: a whole validated configuration (platform, servo, load, mechanism, simulation
// rates, study) built once from YAML, for the functions that need more than the Model: dynamics,
// motor sizing, simulation. Every `config` argument takes a Rig, YAML text, a path or None (seed).
#include <pybind11/stl.h>

#include <memory>

#include "common.hpp"

namespace hexatwist::python {

std::pair<std::string, std::string> read_config_source(const py::object& path_or_text);

Vector6d vector6(const py::handle& obj, const char* name) {
  const Rows6 r = rows6(obj, name);
  if (!r.single) raise_input(std::string(name) + ": expected 6 numbers");
  const Vector6d v = Eigen::Map<const Vector6d>(r.data);
  if (!v.allFinite()) raise_input(std::string(name) + ": holds NaN or inf");
  return v;
}

namespace {

py::array_t<double> vec6(const Vector6d& x) { return py::array_t<double>(6, x.data()); }
py::array_t<double> vec3(const Vector3d& x) { return py::array_t<double>(3, x.data()); }

std::shared_ptr<const PyRig> rig_from_source(const py::object& src) {
  auto r = std::make_shared<PyRig>();
  if (src.is_none()) {
    r->yaml = std::string(seed_config_yaml());
    r->config = std::make_shared<const Config>(default_config());
    r->source = "seed";
    return r;
  }
  auto [text, source] = read_config_source(src);
  r->config = std::make_shared<const Config>(load_config(text, source));
  r->yaml = std::move(text);
  r->source = std::move(source);
  return r;
}

py::dict leg_body(const LegBodySpec& b) {
  py::dict d;
  d["mass"] = b.mass;
  d["center"] = b.center;
  d["axial_inertia"] = b.axial_inertia;
  d["transverse_inertia"] = b.transverse_inertia;
  return d;
}

}  // namespace

// Refuses what is neither a Rig nor what builds one (a Model has no drives, no load, no rates).
void check_source(const py::handle& src, const char* expected) {
  if (src.is_none() || py::isinstance<py::str>(src) || py::isinstance(src, py::module_::import("os").attr("PathLike")))
    return;
  raise_input(std::string(expected) + ", got " + std::string(py::str(py::type::of(src).attr("__name__"))));
}

std::shared_ptr<const PyRig> rig_of(const py::handle& src) {
  if (py::isinstance<PyRig>(src)) return src.cast<std::shared_ptr<PyRig>>();
  check_source(src, "rig: expected a Rig, YAML text, a path or None (the seed)");
  return rig_from_source(py::reinterpret_borrow<py::object>(src));
}

PlatformSource platform_of(const py::handle& src) {
  PlatformSource p;
  if (py::isinstance<Model>(src)) {
    p.model = src.cast<std::shared_ptr<Model>>();
    p.source = "model";
    return p;
  }
  if (!py::isinstance<PyRig>(src))
    check_source(src, "platform: expected a Model, a Rig, YAML text, a path or None (the seed)");
  const std::shared_ptr<const PyRig> rig = rig_of(src);
  p.model = std::shared_ptr<const Model>(rig, &rig->config->rig.model());
  p.study = rig->config->study;
  p.yaml = rig->yaml;
  p.source = rig->source;
  return p;
}

Vector3d vector3(const py::handle& obj, const char* name) {
  py::array_t<double> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (...) {
  }
  if (!a || a.ndim() != 1 || a.shape(0) != 3) raise_input(std::string(name) + ": expected 3 numbers");
  const Vector3d v(a.data()[0], a.data()[1], a.data()[2]);
  if (!v.allFinite()) raise_input(std::string(name) + ": holds NaN or inf");
  return v;
}

py::dict limit_dict(const LimitReport& r) {
  py::dict d;
  d["status"] = std::string(to_string(r.status));
  d["leg"] = leg_number(r.leg);
  d["value"] = r.value;
  d["bound"] = r.bound;
  return d;
}

void expose_rig(py::module_& m) {
  py::class_<PyRig, std::shared_ptr<PyRig>> c(
      m, "Rig",
      "A validated configuration: the platform (Model) with its drives (servo), load (platform + payload), "
      "leg bodies and screw efficiency (mechanism), simulation rates and study (rig.hpp, config.hpp). Built once "
      "from YAML text, a path or None (the embedded seed); pass it wherever a `config` is taken. Pickles as its "
      "YAML text.");
  c.def(py::init([](const py::object& src) { return std::const_pointer_cast<PyRig>(rig_from_source(src)); }),
        py::arg("config") = py::none(),
        "Rig from YAML text, a path (str without ':' or newline, or os.PathLike) or None (the seed). Raises "
        "ConfigError with the library's one-line 'source:line:column: field ...' message.");
  c.def_property_readonly(
      "model", [](const PyRig& r) { return std::make_shared<Model>(r.config->rig.model()); }, "The platform model.");
  c.def_property_readonly(
      "yaml", [](const PyRig& r) { return r.yaml; }, "The YAML text it was built from.");
  c.def_property_readonly(
      "source", [](const PyRig& r) { return r.source; }, "Where the text came from.");
  c.def_property_readonly(
      "control_period", [](const PyRig& r) { return r.config->rig.control_period(); },
      "Servo control period [s]: the sample period of simulate and size_motors.");
  c.def_property_readonly(
      "motor_gain", [](const PyRig& r) { return vec6(r.config->rig.motor_gain()); },
      "Motor-side length per motor radian, lead / (2 pi gear_ratio) (6,) [m/rad].");
  c.def_property_readonly(
      "drive_inertia", [](const PyRig& r) { return r.config->rig.drive_inertia(); },
      "Rotor + screw inertia at the motor shaft [kg m^2].");
  c.def_property_readonly(
      "nominal_inertia", [](const PyRig& r) { return vec6(r.config->rig.nominal_inertia()); },
      "Inertia each motor sees at home, drive + reflected load (6,) [kg m^2].");
  c.def_property_readonly(
      "servo",
      [](const PyRig& r) {
        const ServoSpec& s = r.config->rig.servo();
        py::dict d;
        d["motor_inertia"] = s.motor_inertia;
        d["screw_inertia"] = s.screw_inertia;
        d["viscous_friction"] = s.viscous_friction;
        d["coulomb_friction"] = s.coulomb_friction;
        d["friction_speed"] = s.friction_speed;
        d["torque_limit"] = s.torque_limit;
        d["max_speed"] = s.max_speed;
        d["peak_corner_speed"] = s.peak_corner_speed;
        d["peak_torque_at_max_speed"] = s.peak_torque_at_max_speed;
        d["continuous_torque"] = s.continuous_torque;
        d["gear_ratio"] = s.gear_ratio;
        return d;
      },
      "The drive (ServoSpec), SI: inertias [kg m^2], viscous_friction [N m s/rad], coulomb_friction, torque_limit, "
      "peak_torque_at_max_speed, continuous_torque [N m], friction_speed, max_speed, peak_corner_speed [rad/s], "
      "gear_ratio [-].");
  c.def_property_readonly(
      "load",
      [](const PyRig& r) {
        const LoadSpec& l = r.config->rig.load();
        py::dict d;
        d["mass"] = l.mass;
        d["center_of_mass"] = vec3(l.center_of_mass_P);
        const Matrix3d I = l.inertia_tensor();
        py::array_t<double> t({3, 3});
        for (int i = 0; i < 3; ++i)
          for (int k = 0; k < 3; ++k) t.mutable_data()[3 * i + k] = I(i, k);
        d["inertia"] = t;
        d["gravity"] = l.gravity;
        return d;
      },
      "Platform + payload: mass [kg], center_of_mass [m, P], inertia (3, 3) about the centre of mass along P's "
      "axes [kg m^2], gravity [m/s^2] along -z of B.");
  c.def_property_readonly(
      "mechanism",
      [](const PyRig& r) {
        const MechanismSpec& s = r.config->rig.mechanism();
        py::dict d;
        d["housing"] = leg_body(s.housing);
        d["rod"] = leg_body(s.rod);
        d["efficiency"] = s.efficiency;
        d["back_efficiency"] = s.back_efficiency;
        return d;
      },
      "Leg bodies (housing on the base U-joint, rod on the platform U-joint: mass [kg], center [m from its "
      "U-joint along the leg], axial_inertia, transverse_inertia [kg m^2]) and screw efficiencies [-].");
  c.def("__repr__", [](const PyRig& r) { return "<hexatwist.Rig '" + r.config->rig.model().spec().name + "'>"; });
  c.def(py::pickle([](const PyRig& r) { return py::make_tuple(1, r.yaml, r.source); },
                   [](const py::tuple& t) {
                     if (t.size() != 3 || t[0].cast<int>() != 1) raise_input("Rig pickle: unknown state");
                     auto r = std::make_shared<PyRig>();
                     r->yaml = t[1].cast<std::string>();
                     r->source = t[2].cast<std::string>();
                     r->config = std::make_shared<const Config>(load_config(r->yaml, r->source));
                     return r;
                   }));
}

}  // namespace hexatwist::python
