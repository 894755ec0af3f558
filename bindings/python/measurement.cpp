// Measurement and identification: a tracker point log, the commanded run of a measured test, the
// observations at rest, and the identification of lead, offsets, observation point and X_BT.
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {

std::pair<std::string, std::string> read_yaml_source(const py::object& path_or_text);
Config python_config(const py::object& src);

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

py::dict point_log(const py::object& src, const std::string& time_column, double length_unit, bool indexed) {
  auto [text, source] = read_yaml_source(src);
  PointLogFormat f;
  f.time_column = time_column;
  f.length_unit = length_unit;
  f.indexed = indexed;
  const PointLog log = parse_point_log(text, source, f);
  py::dict d;
  d["stamps"] = vec(log.stamps.data(), log.stamps.size());
  d["points"] = points3(log.points_T);
  d["lines"] = py::array_t<int>(static_cast<py::ssize_t>(log.lines.size()), log.lines.data());
  d["source"] = log.source;
  return d;
}

TimedPoses timed(const py::array& t, const py::array& poses) {
  std::size_t nt = 0, np = 0;
  if (!py::isinstance<py::array_t<double>>(t) || t.ndim() != 1) raise_input("t: expected a 1-D float64 array [s]");
  const Rows6 q = rows6(poses, "poses", false);
  nt = static_cast<std::size_t>(t.shape(0));
  np = q.rows;
  if (nt != np) raise_input("t and poses: expected as many times as poses");
  py::array tc = py::module_::import("numpy").attr("ascontiguousarray")(t);
  TimedPoses tp;
  tp.t.assign(static_cast<const double*>(tc.data()), static_cast<const double*>(tc.data()) + nt);
  tp.poses.resize(np);
  for (std::size_t i = 0; i < np; ++i) tp.poses[i] = pose_row(q.data, i);
  return tp;
}

py::dict measured_test(const py::object& config_src, const std::string& test) {
  const Config config = python_config(config_src);
  for (const StudyTest& st : seed_tests(config.study)) {
    if (st.name != test) continue;
    double end = 0.0;
    const Trajectory tr =
        measured_test_trajectory(config.study, st, CalibrationSpec{}, config.rig.control_period(), end);
    py::array_t<double> t(static_cast<py::ssize_t>(tr.poses.size()));
    py::array_t<double> q({static_cast<py::ssize_t>(tr.poses.size()), py::ssize_t{6}});
    for (std::size_t k = 0; k < tr.poses.size(); ++k) {
      t.mutable_data()[k] = tr.time(k);
      const Vector6d v = tr.poses[k].to_vector();
      std::copy(v.data(), v.data() + 6, q.mutable_data() + 6 * k);
    }
    py::dict d;
    d["t"] = t;
    d["poses"] = q;
    d["calibration_end"] = end;
    return d;
  }
  raise_input("test: unknown test '" + test + "'; expected Lz, Lx, Rz or Ry");
}

py::dict observations(const Model& model, const py::array& t, const py::array& poses, const py::array& stamps,
                      const py::array& points, double time_offset, const std::string& strategy, double settle) {
  const TimedPoses tp = timed(t, poses);
  PointLog log;
  std::size_t ns = 0, np = 0;
  if (!py::isinstance<py::array_t<double>>(stamps) || stamps.ndim() != 1)
    raise_input("stamps: expected a 1-D float64 array [s]");
  const double* p = rows_of(points, 3, "points", np);
  ns = static_cast<std::size_t>(stamps.shape(0));
  if (ns != np) raise_input("stamps and points: expected as many stamps as points");
  py::array sc = py::module_::import("numpy").attr("ascontiguousarray")(stamps);
  log.stamps.assign(static_cast<const double*>(sc.data()), static_cast<const double*>(sc.data()) + ns);
  for (std::size_t k = 0; k < np; ++k) {
    log.points_T.emplace_back(p[3 * k], p[3 * k + 1], p[3 * k + 2]);
    log.lines.push_back(static_cast<int>(k) + 2);
    log.stamp_columns.push_back(1);
  }
  log.source = "point log";
  const ObservationSet set =
      observations_at_rest(model, tp, log, TimeAlignment{time_offset, 0.0}, strategy_from(strategy), settle);
  const std::size_t k = set.observations.size();
  py::array_t<double> motor({static_cast<py::ssize_t>(k), py::ssize_t{6}}),
      pts({static_cast<py::ssize_t>(k), py::ssize_t{3}});
  for (std::size_t i = 0; i < k; ++i) {
    std::copy(set.observations[i].motor.data(), set.observations[i].motor.data() + 6, motor.mutable_data() + 6 * i);
    std::copy(set.observations[i].p_T.data(), set.observations[i].p_T.data() + 3, pts.mutable_data() + 3 * i);
  }
  py::dict d;
  d["motor"] = motor;
  d["points"] = pts;
  d["index"] = py::cast(set.points);
  d["poses"] = set.poses;
  return d;
}

py::dict params(const PlatformParameters& p) {
  py::dict d;
  d["lead"] = p.lead;
  d["twist_sign"] = p.twist_sign;
  d["length_offsets"] = vec(p.length_offset.data(), 6);
  d["observation_point"] = vec(p.observation_P.data(), 3);
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> R = p.X_BT.R;
  py::array_t<double> r({3, 3});
  std::copy(R.data(), R.data() + 9, r.mutable_data());
  d["R_BT"] = r;
  d["t_BT"] = vec(p.X_BT.t.data(), 3);
  return d;
}

py::dict identify_py(const Model& model, const py::array& motor, const py::array& points,
                     const std::string& lead_effect) {
  std::size_t nm = 0, np = 0;
  const double* m = rows_of(motor, 6, "motor", nm);
  const double* p = rows_of(points, 3, "points", np);
  if (nm != np) raise_input("motor and points: expected as many rows");
  IdentificationOptions o;
  if (lead_effect == "twist")
    o.lead_effect = LeadEffect::TwistOnly;
  else if (lead_effect == "travel")
    o.lead_effect = LeadEffect::TwistAndTravel;
  else
    raise_input("lead_effect: expected 'twist' or 'travel', got '" + lead_effect + "'");
  std::vector<Observation> obs(nm);
  for (std::size_t k = 0; k < nm; ++k) {
    obs[k].motor = Eigen::Map<const Vector6d>(m + 6 * k);
    obs[k].p_T = Eigen::Map<const Vector3d>(p + 3 * k);
  }
  Identification id;
  Status s;
  {
    py::gil_scoped_release release;
    s = identify(model, obs, id, o);
  }
  py::dict d;
  d["status"] = std::string(to_string(s));
  d["reason"] = id.reason;
  d["estimate"] = params(id.estimate);
  d["sd"] = vec(id.sd.data(), kIdentifiedParameters);
  py::list names;
  for (int i = 0; i < kIdentifiedParameters; ++i) names.append(std::string(parameter_name(i)));
  d["parameter_names"] = names;
  Eigen::Matrix<double, kIdentifiedParameters, kIdentifiedParameters, Eigen::RowMajor> C = id.covariance;
  py::array_t<double> cov({kIdentifiedParameters, kIdentifiedParameters});
  std::copy(C.data(), C.data() + C.size(), cov.mutable_data());
  d["covariance"] = cov;
  d["sigma"] = id.sigma;
  d["count"] = id.count;
  d["rms_before"] = id.rms_before;
  d["rms_after"] = id.rms_after;
  d["max_after"] = id.max_after;
  d["cost_ratio"] = id.cost_ratio;
  d["condition"] = id.condition;
  d["residuals"] = points3(id.residual_B);
  if (s == Status::Ok) {
    const ModelSpec spec = corrected_spec(model.spec(), id.estimate);
    d["corrected_model"] = std::make_shared<Model>(spec);
  }
  return d;
}

}  // namespace

void expose_measurement(py::module_& m) {
  m.def("_read_point_log", &point_log, py::arg("path_or_text"), py::arg("time_column") = "t",
        py::arg("length_unit") = 0.0, py::arg("indexed") = false);
  m.def("_measured_test", &measured_test, py::arg("config") = py::none(), py::arg("test") = "Rz");
  m.def("_observations_at_rest", &observations, py::arg("model"), py::arg("t"), py::arg("poses"), py::arg("stamps"),
        py::arg("points"), py::arg("time_offset") = 0.0, py::arg("strategy") = "compensated", py::arg("settle") = 0.25);
  m.def("_identify", &identify_py, py::arg("model"), py::arg("motor"), py::arg("points"),
        py::arg("lead_effect") = "twist");
}

}  // namespace hexatwist::python
