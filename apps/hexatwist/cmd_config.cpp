// SPDX-License-Identifier: BSD-3-Clause
// hexatwist config: the resolved platform model, every leg's vectors.
#include <fmt/format.h>

#include <cstdio>
#include <memory>
#include <optional>

#include "cli_common.hpp"
#include "json.hpp"
#include "schemas.hpp"

namespace hexatwist::cli {
namespace {

struct ConfigOptions {
  ModelOptions model;
  bool json = false;
  bool yaml = false;
};

std::string v3(const Vector3d& v) {
  return fmt::format("[{:.6f}, {:.6f}, {:.6f}]", tidy(v.x()), tidy(v.y()), tidy(v.z()));
}

// The servo numbers derived from the config (study, simulate), or why there are none.
struct ServoView {
  std::optional<Config> config;
  std::string why_not;
  Vector6d holding = Vector6d::Zero();  // torque holding the mechanism at rest at home [N m]
};

// The drives of a configuration whose platform loaded: a platform without a screw on some leg
// (lead 0, plain Stewart) has none, and says why; any other error of the other sections is the
// configuration's, exit 2 as for every command.
ServoView servo_view(const ModelOptions& opts, const Model& model) {
  ServoView v;
  try {
    v.config.emplace(load_config_from(opts));
  } catch (const ExitError& e) {
    bool screwless = false;
    for (const Leg& leg : model.legs()) screwless = screwless || !(leg.lead > 0.0);
    if (!screwless) throw;
    v.why_not = e.what();
    return v;
  }
  // What the simulation checks against servo.torque_limit: the whole mechanism at rest.
  if (holding_torque(v.config->rig, Pose{}, v.holding) != Status::Ok) v.holding.setConstant(std::nan(""));
  return v;
}

// `config --json`: the model, its legs and the drives derived from the configuration (SI).
std::string config_json(const Model& model, const ModelOptions& source) {
  const ModelSpec& spec = model.spec();
  const LimitSpec& lim = spec.limits;
  JsonWriter j;
  j.begin_document(schema::kConfig)
      .field("status", "ok")
      .field("name", spec.name)
      .field("source", model_source(source));
  j.field("home_height", spec.home_height);
  j.key("pivot").vector(spec.pivot_P);
  j.key("observation_point").vector(spec.observation_P);
  j.key("limits").begin_object().field("length_min", lim.length_min).field("length_max", lim.length_max);
  j.field("bend_max", lim.bend_max).field("singularity_margin", lim.singularity_margin);
  j.field("jacobian_condition_max", lim.jacobian_condition_max).end_object();
  j.key("legs").begin_array(true);
  for (int i = 0; i < kLegs; ++i) {
    const Leg& l = model.leg(i);
    const bool axes = !std::isnan(l.theta_home);
    j.begin_object().field("leg", i + 1);
    j.key("base").vector(l.base_B);
    j.key("platform").vector(l.platform_P);
    j.key("base_axis");
    axes ? j.vector(l.axis_base_B) : j.null();
    j.key("platform_axis");
    axes ? j.vector(l.axis_platform_P) : j.null();
    j.field("lead", l.lead).field("thread", l.thread == ThreadSense::Right ? "right" : "left");
    j.field("driven_side", l.driven == DrivenSide::Base ? "base" : "platform").field("twist_gain", l.twist_gain);
    j.field("length_offset", l.length_offset).field("length_home", l.length_home);
    j.key("direction_home").vector(l.s_home_B);
    j.key("twist_home_absolute");
    axes ? j.value(l.theta_home) : j.null();
    j.end_object();
  }
  j.end_array();
  const ServoView sv = servo_view(source, model);
  j.key("servo");
  if (sv.config) {
    const Rig& rig = sv.config->rig;
    j.begin_object();
    j.key("motor_gain").vector(rig.motor_gain());
    j.field("drive_inertia", rig.drive_inertia());
    j.key("nominal_inertia").vector(rig.nominal_inertia());
    j.key("kp").vector(rig.kp());
    j.key("ki").vector(rig.ki());
    j.key("kd").vector(rig.kd());
    j.key("holding_torque_home").vector(sv.holding);
    j.field("torque_limit", rig.servo().torque_limit).field("control_period", rig.control_period());
    j.field("plant_step", rig.plant_step()).end_object();
  } else {
    j.null();
  }
  j.end_object();
  return j.str();
}

// `config`: the same for a person (mm where a person reads it).
std::string config_text(const Model& model, const ModelOptions& source) {
  const ModelSpec& spec = model.spec();
  const LimitSpec& lim = spec.limits;
  std::string out = fmt::format("platform: {}\nsource: {}\n", spec.name, model_source(source));
  out += fmt::format("home height: {:.6f} m; pivot {} m [P]; observation point {} m [P]\n", spec.home_height,
                     v3(spec.pivot_P), v3(spec.observation_P));
  out += fmt::format(
      "limits: length {:.4f} .. {:.4f} m, U-joint bend <= {:.2f} deg, singularity margin {:.2f} deg, "
      "Jacobian condition <= {:.4g}\n",
      lim.length_min, lim.length_max, rad2deg(lim.bend_max), rad2deg(lim.singularity_margin),
      lim.jacobian_condition_max);
  for (int i = 0; i < kLegs; ++i) {
    const Leg& l = model.leg(i);
    out += fmt::format("leg {}:\n  base joint      {} m [B]\n  platform joint  {} m [P]\n", i + 1, v3(l.base_B),
                       v3(l.platform_P));
    if (!std::isnan(l.theta_home))
      out += fmt::format("  base axis ja    {} [B]\n  platform axis jd {} [P]\n", v3(l.axis_base_B),
                         v3(l.axis_platform_P));
    out += fmt::format("  lead {:.4g} mm, {}-hand thread, driven at the {}; twist gain {:+.6g} mm/rad\n", 1e3 * l.lead,
                       l.thread == ThreadSense::Right ? "right" : "left",
                       l.driven == DrivenSide::Base ? "base" : "platform", 1e3 * l.twist_gain);
    if (l.length_offset != 0.0)
      out += fmt::format("  length offset {:+.4f} mm (real minus motor-side)\n", 1e3 * l.length_offset);
    out += fmt::format("  home length {:.6f} m, direction {} [B]", l.length_home, v3(l.s_home_B));
    if (!std::isnan(l.theta_home)) out += fmt::format(", absolute twist at home {:.4f} deg", rad2deg(l.theta_home));
    out += "\n";
  }
  const ServoView sv = servo_view(source, model);
  if (sv.config) {
    const Rig& rig = sv.config->rig;
    const ServoSpec& ss = rig.servo();
    out += fmt::format(
        "servo (study, simulate), leg 1: {:.5g} mm of leg per motor rad, {:.3g} nm per encoder count; inertia "
        "{:.3g} kg m^2 (drive) + load = {:.3g} kg m^2\n",
        1e3 * rig.motor_gain()[0], 1e9 * rig.motor_gain()[0] * rig.encoder_step(), rig.drive_inertia(),
        rig.nominal_inertia()[0]);
    out += fmt::format(
        "  PID kp {:.4g} N m/rad, ki {:.4g} N m/(rad s), kd {:.4g} N m s/rad{}; torque limit {:g} N m, "
        "holding the load at home {:.3g} N m\n",
        rig.kp()[0], rig.ki()[0], rig.kd()[0],
        ss.kp == 0.0 ? fmt::format(" (poles at {:g} Hz)", ss.pole_frequency) : std::string(), ss.torque_limit,
        sv.holding[0]);
    out += fmt::format("  load {:g} kg; control {:g} Hz, plant step {:g} ms\n", rig.load().mass,
                       rig.simulation().control_rate, 1e3 * rig.plant_step());
  } else {
    out += fmt::format("servo (study, simulate): not usable: {}\n", sv.why_not);
  }
  return out;
}

int run_config(const ConfigOptions& o) {
  if (o.yaml) {
    if (!o.model.config.empty())
      throw ExitError(kExitBadInput, "--yaml prints the embedded seed config; drop --config");
    if (o.json) throw ExitError(kExitBadInput, "--json: not with --yaml (which prints the seed configuration as YAML)");
    write_stdout(seed_config_yaml());
    return kExitOk;
  }
  const Model model = load_model_from(o.model);
  write_stdout(o.json ? config_json(model, o.model) : config_text(model, o.model));
  return kExitOk;
}
}  // namespace

Command make_config_command(CLI::App& root) {
  auto opts = std::make_shared<ConfigOptions>();
  CLI::App* app = root.add_subcommand("config", "Show the resolved platform model (every leg's vectors, SI units)");
  add_model_options(*app, opts->model);
  app->add_flag("--json", opts->json, "Machine-readable output (SI units: m, rad)");
  app->add_flag(
      "--yaml", opts->yaml,
      "Print the embedded seed configuration as YAML (a starting point for your own); not with --config or --json");
  return {app, [opts] { return run_config(*opts); }};
}

}  // namespace hexatwist::cli
