// SPDX-License-Identifier: BSD-3-Clause
// Closed-loop simulation and the paper's study: time series as (T,) and (T, 6) arrays, the
// summary as a dict. Configurations as YAML text or a path (None: the embedded seed); they travel
// to worker processes as text.
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {

std::pair<std::string, std::string> read_yaml_source(const py::object& path_or_text);

namespace {

py::dict samples_dict(const std::vector<SimulationSample>& s) {
  const std::size_t n = s.size();
  py::array_t<double> time(static_cast<py::ssize_t>(n)), error(static_cast<py::ssize_t>(n)),
      error_twist(static_cast<py::ssize_t>(n));
  auto mk = [&] { return py::array_t<double>({static_cast<py::ssize_t>(n), py::ssize_t{6}}); };
  py::array_t<double> desired = mk(), actual = mk(), command = mk(), encoder = mk(), motor = mk(), length = mk(),
                      tw = mk(), torque = mk();
  for (std::size_t k = 0; k < n; ++k) {
    time.mutable_data()[k] = s[k].time;
    error.mutable_data()[k] = s[k].error;
    error_twist.mutable_data()[k] = s[k].error_twist_only;
    auto put = [&](py::array_t<double>& a, const Vector6d& v) {
      std::copy(v.data(), v.data() + 6, a.mutable_data() + 6 * k);
    };
    put(desired, s[k].desired);
    put(actual, s[k].actual);
    put(command, s[k].command);
    put(encoder, s[k].encoder);
    put(motor, s[k].motor);
    put(length, s[k].length);
    put(tw, s[k].twist);
    put(torque, s[k].torque);
  }
  py::dict d;
  d["time"] = time;
  d["desired"] = desired;
  d["actual"] = actual;
  d["command"] = command;
  d["encoder"] = encoder;
  d["motor"] = motor;
  d["length"] = length;
  d["twist"] = tw;
  d["torque"] = torque;
  d["error"] = error;
  d["error_twist_only"] = error_twist;
  return d;
}

py::dict issue_dict(Status s, const SimulationIssue& issue) {
  py::dict d;
  d["status"] = std::string(to_string(s));
  d["index"] = issue.index;
  d["time"] = issue.time;
  d["leg"] = leg_number(issue.limit.leg);
  d["value"] = issue.limit.value;
  d["bound"] = issue.limit.bound;
  return d;
}

// The trajectory of one of the paper's tests (`test`, default Rz) or of `poses`, not both.
Trajectory trajectory_of(const Config& config, const py::object& test, const py::object& poses_in) {
  const double dt = config.rig.control_period();
  if (!poses_in.is_none()) {
    if (!test.is_none()) raise_input("give test or poses, not both");
    const Rows6 rows = rows6(poses_in, "poses", false);
    if (rows.rows == 0) raise_input("poses: expected at least one pose");
    if (const std::string_view why = check_trajectory_samples(0.0, dt, std::max<std::size_t>(rows.rows, 2));
        !why.empty())
      raise_input(std::string(why));
    Trajectory tr;
    tr.dt = dt;
    tr.poses.resize(rows.rows);
    for (std::size_t i = 0; i < rows.rows; ++i) tr.poses[i] = pose_row(rows.data, i);
    return tr;
  }
  const std::string name = test.is_none() ? std::string("Rz") : test.cast<std::string>();
  try {
    return test_trajectory(config.study, study_test(config.study, name), dt);
  } catch (const Error& e) {
    raise_input(std::string("test: ") + e.what());
  }
}

py::dict simulate_py(const py::object& config_src, const py::object& test, const py::object& poses,
                     const std::string& strategy, bool twist_in_plant) {
  const auto rig = rig_of(config_src);  // built once: a Rig argument is not parsed again
  const Config& config = *rig->config;
  const Trajectory tr = trajectory_of(config, test, poses);
  SimulationOptions options;
  options.strategy = strategy_from(strategy);
  options.twist_in_plant = twist_in_plant;
  std::vector<SimulationSample> samples;
  SimulationIssue issue;
  Status s;
  {
    py::gil_scoped_release release;
    s = simulate(config.rig, tr, options, samples, issue);
  }
  py::dict d = samples_dict(samples);
  std::vector<double> err(samples.size());
  for (std::size_t k = 0; k < samples.size(); ++k) err[k] = samples[k].error;
  const ErrorStats st = error_stats(err);
  py::dict summary = issue_dict(s, issue);
  // A run stopped by a limit has no error to report: None, not the zeros of no ticks.
  summary["error_max"] = s == Status::Ok ? py::object(py::float_(st.max)) : py::none();
  summary["error_rms"] = s == Status::Ok ? py::object(py::float_(st.rms)) : py::none();
  summary["ticks"] = samples.size();
  d["summary"] = summary;
  return d;
}

py::dict stats(const ErrorStats& e) {
  py::dict d;
  d["max"] = e.max;
  d["rms"] = e.rms;
  return d;
}

// A strategy's errors and what else the run did (study.hpp's run_metrics, as summary.json has them).
py::dict strategy_summary(const Rig& rig, const StrategyRun& r) {
  py::dict d;
  d["total"] = stats(r.total);
  d["twist_only"] = stats(r.twist_only);
  d["tracking_only"] = stats(r.tracking_only);
  const RunMetrics m = run_metrics(rig, r.samples);
  d["max_torque"] = m.max_torque;
  d["saturated_ticks"] = m.saturated_ticks;
  d["max_following_error"] = m.max_following_error;
  d["max_orientation_error"] = m.max_orientation_error;
  return d;
}

// An effect's costs as summary.json has them.
py::dict effect_dict(const EffectCost& e) {
  py::dict d;
  d["effect"] = e.effect;
  d["conventional"] = stats(e.conventional);
  d["twist_compensated"] = stats(e.twist_compensated);
  d["compensated"] = stats(e.compensated);
  d["static_load_compensated"] = stats(e.static_load_compensated);
  return d;
}

py::dict study_py(const py::object& config_src, const py::object& test, const py::object& poses,
                  const py::object& temperature_rise) {
  const auto rig = rig_of(config_src);  // built once: a Rig argument is not parsed again
  const Config& config = *rig->config;
  const Trajectory tr = trajectory_of(config, test, poses);
  const Vector6d rise = py::isinstance<py::float_>(temperature_rise) || py::isinstance<py::int_>(temperature_rise)
                            ? Vector6d::Constant(temperature_rise.cast<double>())
                            : vector6(temperature_rise, "temperature_rise");
  if (const std::string_view why = check_temperature_rise(config.rig.model(), rise); !why.empty())
    raise_input("temperature_rise: " + std::string(why));
  TestRun run;
  std::vector<EffectCost> effects;
  SimulationIssue issue;
  Status s;
  {
    py::gil_scoped_release release;
    s = run_test(config.rig, tr, run, issue);
    if (s == Status::Ok) s = effect_costs(config.rig, tr, rise, effects, issue);
  }
  py::dict d;
  py::dict summary = issue_dict(s, issue);
  summary["test"] = poses.is_none() ? (test.is_none() ? std::string("Rz") : test.cast<std::string>()) : "poses";
  for (auto [name, r] : {std::pair<const char*, const StrategyRun*>{"conventional", &run.conventional},
                         std::pair<const char*, const StrategyRun*>{"compensated", &run.compensated}}) {
    d[name] = samples_dict(r->samples);
    // A run stopped by a limit has no errors to report: None, not the zeros of no ticks.
    summary[name] = s == Status::Ok ? py::object(strategy_summary(config.rig, *r)) : py::none();
  }
  py::list leg_effects;
  for (const EffectCost& e : effects) leg_effects.append(effect_dict(e));
  summary["leg_effects"] = leg_effects;
  d["tracking_only"] =
      py::array_t<double>(static_cast<py::ssize_t>(run.tracking_only.size()), run.tracking_only.data());
  d["summary"] = summary;
  return d;
}

}  // namespace

void expose_simulation(py::module_& m) {
  m.attr("MAX_TRAJECTORY_SAMPLES") = kMaxTrajectorySamples;
  m.def("_simulate", &simulate_py, py::arg("rig") = py::none(), py::arg("test") = py::none(),
        py::arg("poses") = py::none(), py::arg("strategy") = "compensated", py::arg("twist_in_plant") = true);
  m.def("_study", &study_py, py::arg("rig") = py::none(), py::arg("test") = py::none(), py::arg("poses") = py::none(),
        py::arg("temperature_rise") = 0.0);
  m.def(
      "control_period", [](const py::object& c) { return rig_of(c)->config->rig.control_period(); },
      py::arg("rig") = py::none(), "The configuration's control period [s] (poses of simulate are this far apart).");
  m.def(
      "study_trajectory",
      [](const py::object& c, const std::string& test) {
        const auto rig = rig_of(c);
        const Config& config = *rig->config;
        const Trajectory tr = trajectory_of(config, py::str(test), py::none());
        return pose_rows(tr.poses);
      },
      py::arg("rig") = py::none(), py::arg("test") = "Rz",
      "Poses (T, 6) [m, rad] of one of the paper's tests (Lz, Lx, Rz, Ry), one per control period.");
}

}  // namespace hexatwist::python
