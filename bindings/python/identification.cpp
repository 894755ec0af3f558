// SPDX-License-Identifier: BSD-3-Clause
// Identification (identification.hpp): the twist-aware calibration from observations at rest, with
// the library's decisions (the same status and estimate as `hexatwist identify`), and the corrected
// configuration written into the user's YAML.
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {

// Per-observation target indices (None: every observation is target 0).
std::vector<int> targets_of(const py::object& targets, std::size_t n) {
  std::vector<int> out(n, 0);
  if (targets.is_none()) return out;
  py::array_t<int, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<int, py::array::c_style | py::array::forcecast>::ensure(targets);
  } catch (...) {
  }
  if (!a || a.ndim() != 1 || static_cast<std::size_t>(a.shape(0)) != n)
    raise_input("targets: expected one integer per observation (0 = the observation point)");
  for (std::size_t k = 0; k < n; ++k) {
    const int t = a.data()[k];
    if (t < 0 || t >= static_cast<int>(kMaxTargets))
      raise_input("targets: row " + std::to_string(k) + ": expected 0 to " + std::to_string(kMaxTargets - 1) +
                  ", got " + std::to_string(t));
    out[k] = t;
  }
  return out;
}

namespace {

// A copy of a vector, fixed-size or dynamic (no conversion to a dynamic one: GCC 12 then flags
// Eigen's AVX-512 loads).
template <class V>
py::array_t<double> array(const V& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

py::array_t<double> matrix(const Eigen::MatrixXd& m) {
  py::array_t<double> a({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto v = a.mutable_unchecked<2>();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) v(r, c) = m(r, c);
  return a;
}

py::array_t<double> legs3(const LegVectors& m) { return matrix(Eigen::MatrixXd(m)); }

// Rows of (K, C) float64 observations (a copy for other layouts: identification is not a hot path).
std::vector<double> rows(const py::handle& obj, std::size_t cols, const char* name, std::size_t& n) {
  py::array_t<double> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (...) {
  }
  if (!a || a.ndim() != 2 || a.shape(1) != static_cast<py::ssize_t>(cols))
    raise_input(std::string(name) + ": expected a (K, " + std::to_string(cols) + ") float64 array");
  n = static_cast<std::size_t>(a.shape(0));
  const double* d = a.data();
  for (std::size_t k = 0; k < n * cols; ++k)
    if (!std::isfinite(d[k]))
      raise_input(std::string(name) + ": row " + std::to_string(k / cols) + " holds NaN or inf");
  return std::vector<double>(d, d + n * cols);
}

IdentificationOptions options_of(const std::string& calibration, const std::string& lead_effect,
                                 const std::string& axes, const py::object& tracker_noise, int folds,
                                 int accuracy_poses) {
  IdentificationOptions o;
  if (calibration == "geometry")
    o.model = CalibrationModel::Geometry;
  else if (calibration == "basic")
    o.model = CalibrationModel::Basic;
  else
    raise_input("calibration: expected 'geometry' or 'basic', got '" + calibration + "'");
  if (lead_effect == "travel")
    o.lead_effect = LeadEffect::TwistAndTravel;
  else if (lead_effect == "twist")
    o.lead_effect = LeadEffect::TwistOnly;
  else
    raise_input("lead_effect: expected 'travel' or 'twist', got '" + lead_effect + "'");
  if (axes == "auto")
    o.axes = AxisFit::Auto;
  else if (axes == "none")
    o.axes = AxisFit::None;
  else if (axes == "all")
    o.axes = AxisFit::All;
  else
    raise_input("axes: expected 'auto', 'none' or 'all', got '" + axes + "'");
  if (!tracker_noise.is_none()) o.tracker_noise = tracker_noise.cast<double>();
  o.folds = folds;
  o.accuracy_poses = accuracy_poses;
  check_identification_options(o);  // the library's ranges: InputError naming the keyword
  return o;
}

py::dict corrected_dict(const ModelSpec& c) {
  py::dict d;
  LegVectors base, platform, base_axes, platform_axes;
  Vector6d leads, offsets, homes, drives;
  py::list hands;
  for (int i = 0; i < kLegs; ++i) {
    const LegSpec& leg = c.legs[static_cast<std::size_t>(i)];
    base.row(i) = leg.base_B.transpose();
    platform.row(i) = leg.platform_P.transpose();
    base_axes.row(i) = leg.axis_base_B.transpose();
    platform_axes.row(i) = leg.axis_platform_P.transpose();
    leads[i] = leg.lead;
    offsets[i] = leg.length_offset;
    homes[i] = leg.home_command;
    drives[i] = leg.drive_lead;
    hands.append(leg.thread == ThreadSense::Right ? "right" : "left");
  }
  d["base_joints"] = legs3(base);
  d["platform_joints"] = legs3(platform);
  d["base_axes"] = legs3(base_axes);
  d["platform_axes"] = legs3(platform_axes);
  d["leads"] = array(leads);
  d["thread_hands"] = py::tuple(hands);
  d["length_offsets"] = array(offsets);
  d["home_commands"] = array(homes);
  d["drive_leads"] = array(drives);
  d["observation_point"] = array(c.observation_P);
  return d;
}

py::dict result(const Identification& id, Status s) {
  py::dict d;
  d["status"] = std::string(to_string(s));
  d["reason"] = id.reason;
  d["hint"] = id.hint;
  d["fitted"] = id.fitted;
  d["effects"] = id.parameters.effects().names();
  d["effects_choice"] = id.effects_choice;
  const ParameterSet& ps = id.parameters;
  py::list names;
  for (int k = 0; k < ps.size(); ++k) names.append(ps.name(k));
  d["parameter_names"] = py::tuple(names);
  d["calibration"] = ps.model() == CalibrationModel::Geometry ? "geometry" : "basic";
  d["nominal"] = array(id.nominal);
  d["estimate"] = array(id.estimate);
  d["sd"] = array(id.sd);
  d["covariance"] = matrix(id.covariance);
  d["twist_sign"] = id.twist_sign;
  d["R_BT"] = matrix(Eigen::MatrixXd(id.X_BT.R));
  d["t_BT"] = array(id.X_BT.t);
  d["corrected"] = id.fitted ? py::object(corrected_dict(id.corrected)) : py::object(py::none());
  d["corrected_model"] = s == Status::Ok ? py::cast(std::make_shared<Model>(id.corrected)) : py::object(py::none());
  d["base_shift"] = legs3(id.base_shift);
  d["base_shift_sd"] = legs3(id.base_shift_sd);
  d["platform_shift"] = legs3(id.platform_shift);
  d["platform_shift_sd"] = legs3(id.platform_shift_sd);
  d["axis_sd"] = py::array_t<double>(static_cast<py::ssize_t>(id.axis_sd.size()), id.axis_sd.data());
  py::list fitted_axes;
  for (const bool a : ps.axes()) fitted_axes.append(a);
  d["axes_fitted"] = py::tuple(fitted_axes);
  py::list targets;
  for (int t = 0; t < ps.targets() && id.estimate.size() == ps.size(); ++t)
    targets.append(array(Vector3d(ps.target(id.estimate, t))));
  d["targets"] = targets;
  d["observations"] = id.observations;
  d["stations"] = id.stations;
  d["groups"] = id.groups;
  for (const auto& [key, v] : {std::pair{"sigma", id.sigma},
                               {"tracker_noise", id.tracker_noise},
                               {"scatter", id.scatter},
                               {"fit_statistic", id.fit_statistic},
                               {"fit_z", id.fit_z},
                               {"unexplained", id.unexplained},
                               {"rms_before", id.rms_before},
                               {"rms_after", id.rms_after},
                               {"max_after", id.max_after},
                               {"cost_ratio", id.cost_ratio},
                               {"sign_separation", id.sign_separation},
                               {"condition", id.condition}})
    d[key] = v;
  d["fit_dof"] = id.fit_dof;
  py::dict diagnosis;  // effect -> drop of the fit statistic [sigma], on a refusal
  for (const Identification::EffectDiagnosis& e : id.diagnosis) diagnosis[py::str(e.effect)] = e.z;
  d["diagnosis"] = diagnosis;
  d["max_after_index"] = id.max_after_index;
  d["undetermined"] = id.undetermined;
  py::list worst;
  for (const StationResidual& w : id.worst) {
    py::dict r;
    r["station"] = w.station + 1;  // 1-based, as the command line reports it
    r["target"] = w.target;
    r["first"] = w.first;
    r["count"] = w.count;
    r["mean_error"] = w.mean_error;
    r["statistic"] = w.statistic;
    worst.append(r);
  }
  d["worst"] = worst;
  py::array_t<double> residuals({static_cast<py::ssize_t>(id.residual_B.size()), py::ssize_t{3}});
  for (std::size_t k = 0; k < id.residual_B.size(); ++k)
    std::copy(id.residual_B[k].data(), id.residual_B[k].data() + 3, residuals.mutable_data() + 3 * k);
  d["residuals"] = residuals;
  py::list fits;
  for (const SignFit& f : id.fits) {
    py::dict r;
    r["twist_sign"] = f.twist_sign;
    r["status"] = std::string(to_string(f.status));
    r["cost"] = f.cost;
    r["iterations"] = f.iterations;
    r["lead_at_bound"] = f.lead_at_bound;
    fits.append(r);
  }
  d["fits"] = fits;
  const CrossValidation& cv = id.cross_validation;
  py::dict c;
  c["folds"] = cv.folds;
  c["predicted"] = cv.predicted;
  c["rms"] = cv.rms;
  c["expected"] = cv.expected;
  c["max"] = cv.max;
  d["cross_validation"] = c;
  const AccuracyPrediction& acc = id.accuracy;
  py::dict a;
  a["poses"] = acc.poses;
  a["median"] = acc.median;
  a["max"] = acc.max;
  a["aligned_median"] = acc.aligned_median;
  a["aligned_max"] = acc.aligned_max;
  a["range_low"] = array(acc.range_low);
  a["range_high"] = array(acc.range_high);
  d["accuracy"] = a;
  return d;
}

py::dict identify_py(const Model& model, const py::object& motor, const py::object& points, const py::object& targets,
                     const std::string& calibration, const std::string& lead_effect, const std::string& axes,
                     const py::object& tracker_noise, int folds, int accuracy_poses, const std::string& effects,
                     const py::object& times, const py::object& approach, const py::object& temperatures) {
  std::size_t nm = 0, np = 0;
  const std::vector<double> m = rows(motor, 6, "motor", nm);
  const std::vector<double> p = rows(points, 3, "points", np);
  if (nm != np) raise_input("motor and points: expected as many rows");
  const std::vector<int> target = targets_of(targets, nm);
  IdentificationOptions o = options_of(calibration, lead_effect, axes, tracker_noise, folds, accuracy_poses);
  o.auto_effects = effects == "auto";
  try {
    if (!o.auto_effects) o.effects = effect_fit(effects);
  } catch (const Error& e) {
    raise_input(e.what());
  }
  std::vector<Observation> obs(nm);
  std::vector<double> t, d, c;
  if (!times.is_none()) {
    std::size_t nt = 0;
    t = rows(times, 1, "times", nt);
    if (nt != nm) raise_input("times: expected one per observation");
  }
  if (!temperatures.is_none()) {
    std::size_t nc = 0;
    c = rows(temperatures, 1, "temperatures", nc);
    if (nc != nm) raise_input("temperatures: expected one per observation");
  }
  if (!approach.is_none()) {
    std::size_t nd = 0;
    d = rows(approach, 6, "approach", nd);
    if (nd != nm) raise_input("approach: expected one row per observation");
  }
  for (std::size_t k = 0; k < nm; ++k) {
    obs[k].motor = Eigen::Map<const Vector6d>(m.data() + 6 * k);
    obs[k].p_T = Eigen::Map<const Vector3d>(p.data() + 3 * k);
    obs[k].target = target[k];
    if (!t.empty()) obs[k].time = t[k];
    if (!c.empty()) obs[k].temperature = c[k];
    if (!d.empty()) obs[k].approach = Eigen::Map<const Vector6d>(d.data() + 6 * k);
  }
  Identification id;
  Status s;
  {
    py::gil_scoped_release release;
    s = identify(model, obs, id, o);
  }
  return result(id, s);
}

// The configuration of a Rig (its text), YAML text, a path or None (the seed) with its platform replaced.
std::string corrected_config_py(const py::object& config, const Model& corrected, const std::string& header) {
  const auto rig = rig_of(config);
  return platform_config_yaml(rig->yaml, rig->source, corrected.spec(), header, true);
}

}  // namespace

void expose_identification(py::module_& m) {
  m.def("_identify", &identify_py, py::arg("model"), py::arg("motor"), py::arg("points"),
        py::arg("targets") = py::none(), py::arg("calibration") = "geometry", py::arg("lead_effect") = "travel",
        py::arg("axes") = "auto", py::arg("tracker_noise") = py::none(), py::arg("folds") = 5,
        py::arg("accuracy_poses") = 1000, py::arg("effects") = "auto", py::arg("times") = py::none(),
        py::arg("approach") = py::none(), py::arg("temperatures") = py::none());
  m.def("_corrected_config", &corrected_config_py, py::arg("rig"), py::arg("corrected"), py::arg("header") = "");
}

}  // namespace hexatwist::python
