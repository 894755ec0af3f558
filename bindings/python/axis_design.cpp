// SPDX-License-Identifier: BSD-3-Clause
// The required workspace and the design of the fixed U-joint axes (design/required_workspace.hpp,
// design/axis_design.hpp), with the designed configuration's YAML (io/platform_yaml.hpp).
#include <pybind11/stl.h>

#include "common.hpp"

namespace hexatwist::python {
namespace {

RequiredWorkspaceSpec required_spec(bool tests, int test_samples, int random, double linear, double angular,
                                    std::uint64_t seed) {
  RequiredWorkspaceSpec s;
  s.tests = tests;
  s.test_samples = test_samples;
  s.random = random;
  s.linear = linear;
  s.angular = angular;
  s.seed = seed;
  return s;
}

std::vector<Pose> poses_of(const py::handle& obj) {
  const Rows6 r = rows6(obj, "poses", false);
  std::vector<Pose> poses(r.rows);
  for (std::size_t k = 0; k < r.rows; ++k) {
    poses[k] = pose_row(r.data, k);
    if (!poses[k].is_finite()) raise_input("poses: row " + std::to_string(k) + " holds NaN or inf");
  }
  return poses;
}

}  // namespace

// The poses of a design or tolerance study: `poses` (N, 6) when given, else the required workspace
// `required` (tests, test_samples, random, linear, angular, seed) of the platform.
std::vector<Pose> design_poses(const PlatformSource& p, const py::object& poses, const py::dict& required) {
  if (!poses.is_none()) return poses_of(poses);
  RequiredWorkspace w;
  const RequiredWorkspaceSpec spec = required_spec(
      required["tests"].cast<bool>(), required["test_samples"].cast<int>(), required["random"].cast<int>(),
      required["linear"].cast<double>(), required["angular"].cast<double>(), required["seed"].cast<std::uint64_t>());
  // The library checks the spec (ParameterError: InputError naming the keyword).
  if (const Status s = required_workspace(*p.model, p.study, spec, Strategy::Compensated, w); s != Status::Ok)
    raise_status(s, "workspace");
  return std::move(w.poses);
}

namespace {

py::dict required_py(const py::object& config, bool tests, int test_samples, int random, double linear, double angular,
                     std::uint64_t seed, const std::string& strategy) {
  const PlatformSource p = platform_of(config);
  RequiredWorkspace w;
  const Status s = required_workspace(
      *p.model, p.study, required_spec(tests, test_samples, random, linear, angular, seed), strategy_from(strategy), w);
  if (s != Status::Ok) raise_status(s, "required_workspace");
  py::dict d;
  d["poses"] = pose_rows(w.poses);
  d["test_poses"] = w.test_poses;
  d["tests_dropped"] = w.tests_dropped;
  d["random_drawn"] = w.random_drawn;
  d["random_reached"] = w.random_reached;
  return d;
}

DesignObjective objective_from(const std::string& s) {
  if (s == "twist") return DesignObjective::Twist;
  if (s == "length_error") return DesignObjective::LengthError;
  if (s == "lead_sensitivity") return DesignObjective::LeadSensitivity;
  raise_input("objective: expected 'twist', 'length_error' or 'lead_sensitivity', got '" + s + "'");
}

AxisSymmetry symmetry_from(const std::string& s) {
  if (s == "symmetric") return AxisSymmetry::Symmetric;
  if (s == "threefold") return AxisSymmetry::Threefold;
  if (s == "per_leg") return AxisSymmetry::PerLeg;
  raise_input("symmetry: expected 'symmetric', 'threefold' or 'per_leg', got '" + s + "'");
}

const char* kMarginNames[kMarginKinds] = {"stroke", "command", "bend", "singularity", "condition"};

py::dict evaluation_dict(const DesignEvaluation& e) {
  py::dict d;
  d["poses"] = e.poses;
  d["reached"] = e.reached;
  d["max_twist"] = e.max_twist;
  d["twist_leg"] = leg_number(e.twist_leg);
  d["twist_pose"] = e.twist_pose;
  d["max_length_error"] = e.max_length_error;
  d["max_lead_sensitivity"] = e.max_lead_sensitivity;
  d["axis_sensitivity"] = e.axis_sensitivity;
  py::dict margins;
  for (int k = 0; k < kMarginKinds; ++k) {
    const LimitMargin& m = e.margins[static_cast<std::size_t>(k)];
    py::dict x = limit_dict(m.at);
    x["share"] = m.share;
    x["pose"] = m.pose;
    margins[kMarginNames[k]] = x;
  }
  d["margins"] = margins;
  d["volume"] = e.volume;
  d["volume_error"] = e.volume_error;
  return d;
}

py::array_t<double> per_leg(const PerLeg<double>& v) { return py::array_t<double>(kLegs, v.data()); }

py::dict design_py(const py::object& config, const py::object& poses_in, const py::dict& required,
                   const std::string& objective, const std::string& symmetry, bool tilt, double max_tilt,
                   double grid_step, double fine_step, double clearance, double max_volume_loss,
                   const py::object& volume_orientation, double cell, int volume_samples, std::uint64_t seed,
                   int threads) {
  const PlatformSource p = platform_of(config);
  const std::vector<Pose> poses = design_poses(p, poses_in, required);
  DesignOptions o;
  o.objective = objective_from(objective);
  o.symmetry = symmetry_from(symmetry);
  o.tilt = tilt;
  o.max_tilt = max_tilt;
  o.grid_step = grid_step;
  o.fine_step = fine_step;
  o.clearance = clearance;
  o.max_volume_loss = max_volume_loss;
  o.volume_rpy = vector3(volume_orientation, "volume_orientation");
  o.volume.cell = cell;
  o.volume_samples = volume_samples;
  o.seed = seed;
  o.threads = threads;
  check_design_options(o);  // the library's check, before the GIL is released
  AxisDesign d;
  Status s;
  {
    py::gil_scoped_release release;
    s = design_axes(*p.model, poses, o, d);
  }
  if (s != Status::Ok) raise_status(s, "design_axes");
  py::dict r;
  r["turn_base"] = per_leg(d.turns.base);
  r["turn_platform"] = per_leg(d.turns.platform);
  r["tilt_base"] = per_leg(d.turns.base_tilt);
  r["tilt_platform"] = per_leg(d.turns.platform_tilt);
  r["before"] = evaluation_dict(d.before);
  r["after"] = evaluation_dict(d.after);
  r["objective"] = objective;
  r["objective_before"] = d.objective_before;
  r["objective_after"] = d.objective_after;
  r["objective_bound"] = d.objective_bound;
  r["evaluations"] = d.evaluations;
  r["attempts"] = d.attempts;
  r["poses"] = poses.size();
  r["model"] = std::make_shared<Model>(d.designed);
  r["yaml"] = p.yaml.empty() ? py::object(py::none())
                             : py::object(py::str(designed_config_yaml(
                                   p.yaml, p.source, d.designed, "U-joint axes designed by hexatwist.design_axes")));
  return r;
}

}  // namespace

void expose_axis_design(py::module_& m) {
  const RequiredWorkspaceSpec w;
  const DesignOptions o;
  m.def("_required_workspace_defaults", [w] {
    py::dict d;  // the library's RequiredWorkspaceSpec, for the package's keyword defaults
    d["tests"] = w.tests;
    d["test_samples"] = w.test_samples;
    d["random"] = w.random;
    d["linear"] = w.linear;
    d["angular"] = w.angular;
    d["seed"] = w.seed;
    return d;
  });
  m.def("_required_workspace", &required_py, py::arg("platform"), py::arg("tests") = w.tests,
        py::arg("test_samples") = w.test_samples, py::arg("random") = w.random, py::arg("linear") = w.linear,
        py::arg("angular") = w.angular, py::arg("seed") = w.seed, py::arg("strategy") = "compensated");
  m.def("_design_axes", &design_py, py::arg("platform"), py::arg("poses"), py::arg("required"),
        py::arg("objective") = "twist", py::arg("symmetry") = "symmetric", py::arg("tilt") = o.tilt,
        py::arg("max_tilt") = o.max_tilt, py::arg("grid_step") = o.grid_step, py::arg("fine_step") = o.fine_step,
        py::arg("clearance") = o.clearance, py::arg("max_volume_loss") = o.max_volume_loss,
        py::arg("volume_orientation") = py::make_tuple(0.0, 0.0, 0.0), py::arg("cell") = o.volume.cell,
        py::arg("volume_samples") = o.volume_samples, py::arg("seed") = o.seed, py::arg("threads") = 1);
}

}  // namespace hexatwist::python
