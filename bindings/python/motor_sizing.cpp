// SPDX-License-Identifier: BSD-3-Clause
// Motor sizing along a trajectory (motor_sizing.hpp): per-sample torque, speed, power and the
// torque's six parts as (T, 6) arrays, the per-motor summary and envelope verdict as dicts, and
// the torque-speed figure's data. The trajectory: a CSV file or text (resampled at the control
// period, as the CLI's `hexatwist dynamics` does), times and poses (resampled alike), or poses
// at a fixed period.
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {

std::pair<std::string, std::string> read_yaml_source(const py::object& path_or_text);

namespace {

constexpr std::array<TorqueTerm, kTorqueTerms> kTerms{TorqueTerm::Gravity,         TorqueTerm::PlatformInertia,
                                                      TorqueTerm::VelocityProduct, TorqueTerm::Legs,
                                                      TorqueTerm::Drives,          TorqueTerm::Friction};

py::object violation_of(const EnvelopeViolation& v) {
  if (v.check == EnvelopeCheck::None) return py::none();
  py::dict d;
  d["check"] = std::string(to_string(v.check));
  d["leg"] = leg_number(v.leg);
  d["index"] = v.index;
  d["time"] = v.time;
  d["value"] = v.value;
  d["bound"] = v.bound;
  return d;
}

py::dict motor_of(const MotorSummary& m) {
  py::dict d;
  d["peak_torque"] = m.peak_torque;
  d["peak_torque_time"] = m.peak_torque_time;
  d["rms_torque"] = m.rms_torque;
  d["peak_speed"] = m.peak_speed;
  d["peak_speed_time"] = m.peak_speed_time;
  d["peak_power"] = m.peak_power;
  d["peak_power_time"] = m.peak_power_time;
  d["energy_driven"] = m.energy_driven;
  d["energy_regenerated"] = m.energy_regenerated;
  py::dict share;
  for (int t = 0; t < kTorqueTerms; ++t) share[py::str(std::string(to_string(kTerms[t])))] = m.share[t];
  d["share"] = share;
  d["peak_usage"] = m.peak_usage;
  d["peak_usage_time"] = m.peak_usage_time;
  d["speed_usage"] = m.speed_usage;
  d["rms_usage"] = m.rms_usage;
  d["violation"] = violation_of(m.violation);
  return d;
}

py::array_t<double> column(const std::vector<double>& v) {
  return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data());
}

Trajectory trajectory_from(const Config& config, const py::object& csv, const py::object& times,
                           const py::object& poses_in, const py::object& dt_in, double t0) {
  const double period = config.rig.control_period();
  if (!csv.is_none()) {
    if (!times.is_none() || !poses_in.is_none())
      raise_input("size_motors: give a trajectory CSV, or poses (with times or dt), not both");
    auto [text, source] = read_yaml_source(csv);
    return resample(parse_trajectory_csv(text, source), period);
  }
  if (poses_in.is_none()) raise_input("size_motors: give a trajectory CSV (path or text) or poses");
  const Rows6 q = rows6(poses_in, "poses", false);
  for (std::size_t i = 0; i < 6 * q.rows; ++i)
    if (!std::isfinite(q.data[i])) raise_input("poses: row " + std::to_string(i / 6) + " holds NaN or inf");
  if (!times.is_none()) {
    if (!dt_in.is_none()) raise_input("size_motors: give times or dt, not both");
    return resample(timed_poses_of(times, "times", poses_in), period);
  }
  Trajectory tr;
  tr.t0 = t0;
  tr.dt = dt_in.is_none() ? period : dt_in.cast<double>();
  // The library's check of a trajectory's samples, before any memory is taken for them.
  if (const std::string_view why = check_trajectory_samples(tr.t0, tr.dt, q.rows); !why.empty())
    raise_input("size_motors: " + std::string(why));
  tr.poses.resize(q.rows);
  for (std::size_t i = 0; i < q.rows; ++i) tr.poses[i] = pose_row(q.data, i);
  return tr;
}

py::dict size_motors_py(const py::object& config_src, const py::object& csv, const py::object& times,
                        const py::object& poses, const py::object& dt, double t0, int envelope_points) {
  const auto rig = rig_of(config_src);
  const Trajectory tr = trajectory_from(*rig->config, csv, times, poses, dt, t0);
  if (envelope_points < 2) raise_input("envelope_points: expected at least 2");
  MotorSizing s;
  Status status;
  TorqueSpeedFigure fig;
  {
    py::gil_scoped_release release;
    status = size_motors(rig->config->rig, tr, s);
    fig = torque_speed_figure(rig->config->rig, s, envelope_points);
  }
  if (status == Status::NonFiniteInput && s.samples.empty() && (tr.poses.size() < 2 || !(tr.dt > 0.0)))
    raise_input("size_motors: expected at least 2 poses and a sample period dt > 0 [s]");
  const std::size_t n = s.samples.size();
  auto mk = [&] { return py::array_t<double>({static_cast<py::ssize_t>(n), py::ssize_t{6}}); };
  py::array_t<double> time(static_cast<py::ssize_t>(n)), torque = mk(), speed = mk(), power = mk();
  std::array<py::array_t<double>, kTorqueTerms> terms;
  for (auto& t : terms) t = mk();
  for (std::size_t k = 0; k < n; ++k) {
    const MotorSample& x = s.samples[k];
    time.mutable_data()[k] = x.time;
    auto put = [&](py::array_t<double>& a, const Vector6d& v) {
      std::copy(v.data(), v.data() + 6, a.mutable_data() + 6 * k);
    };
    put(torque, x.torque);
    put(speed, x.speed);
    put(power, x.power);
    for (int t = 0; t < kTorqueTerms; ++t) put(terms[t], x.terms[t]);
  }
  py::dict d;
  d["time"] = time;
  d["poses"] = pose_rows(tr.poses);
  d["torque"] = torque;
  d["speed"] = speed;
  d["power"] = power;
  for (int t = 0; t < kTorqueTerms; ++t) d[py::str(std::string(to_string(kTerms[t])))] = terms[t];

  py::dict summary;
  summary["status"] = std::string(to_string(status));
  summary["failed_index"] = s.failed_index;
  summary["failed_time"] = s.failed_time;
  summary["limit_leg"] = leg_number(s.limit.leg);
  summary["limit_value"] = s.limit.value;
  summary["limit_bound"] = s.limit.bound;
  summary["samples"] = n;
  summary["sample_period"] = tr.dt;
  if (status == Status::Ok) {
    summary["envelope"] = s.violation.check == EnvelopeCheck::None ? "ok" : "exceeded";
    summary["first_violation"] = violation_of(s.violation);
    py::list motors;
    for (const MotorSummary& m : s.motors) motors.append(motor_of(m));
    summary["motors"] = motors;
  } else {
    summary["envelope"] = py::none();
    summary["first_violation"] = py::none();
    summary["motors"] = py::none();
  }
  d["summary"] = summary;

  py::dict figure;
  py::list operating;
  for (const Curve& c : fig.operating) {
    py::dict cd;
    cd["speed"] = column(c.speed);
    cd["torque"] = column(c.torque);
    operating.append(cd);
  }
  figure["operating"] = operating;
  py::dict env;
  env["speed"] = column(fig.envelope.speed);
  env["torque"] = column(fig.envelope.torque);
  figure["envelope"] = env;
  figure["continuous_torque"] = fig.continuous_torque;
  figure["max_speed"] = fig.max_speed;
  d["figure"] = figure;
  return d;
}

}  // namespace

void expose_motor_sizing(py::module_& m) {
  m.def("_size_motors", &size_motors_py, py::arg("rig") = py::none(), py::arg("trajectory") = py::none(),
        py::arg("times") = py::none(), py::arg("poses") = py::none(), py::arg("dt") = py::none(), py::arg("t0") = 0.0,
        py::arg("envelope_points") = 64);
  py::list names;
  for (TorqueTerm t : kTerms) names.append(py::str(std::string(to_string(t))));
  m.attr("TORQUE_TERMS") = py::tuple(names);
}

}  // namespace hexatwist::python
