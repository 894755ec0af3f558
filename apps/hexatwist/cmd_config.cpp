// hexatwist config: the resolved platform model, every leg's vectors.
#include <fmt/format.h>

#include <cstdio>
#include <memory>

#include "cli_common.hpp"
#include "json.hpp"

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

int run_config(const ConfigOptions& o) {
  if (o.yaml) {
    if (!o.model.config.empty())
      throw ExitError(kExitBadInput, "--yaml prints the embedded seed config; drop --config");
    std::fputs(std::string(seed_config_yaml()).c_str(), stdout);
    return kExitOk;
  }
  const Model model = load_model_from(o.model);
  const ModelSpec& spec = model.spec();
  const LimitSpec& lim = spec.limits;
  if (o.json) {
    JsonWriter j;
    j.begin_object().field("status", "ok").field("name", spec.name).field("source", model_source(o.model));
    j.field("home_height", spec.home_height);
    j.key("pivot").vector(spec.pivot_P);
    j.key("observation_point").vector(spec.observation_P);
    j.key("limits").begin_object().field("length_min", lim.length_min).field("length_max", lim.length_max);
    j.field("bend_max", lim.bend_max).field("singularity_margin", lim.singularity_margin).end_object();
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
      j.field("length_home", l.length_home);
      j.key("direction_home").vector(l.s_home_B);
      j.key("twist_home_absolute");
      axes ? j.value(l.theta_home) : j.null();
      j.end_object();
    }
    j.end_array().end_object();
    std::fputs(j.str().c_str(), stdout);
    return kExitOk;
  }
  std::string out = fmt::format("platform: {}\nsource: {}\n", spec.name, model_source(o.model));
  out += fmt::format("home height: {:.6f} m; pivot {} m [P]; observation point {} m [P]\n", spec.home_height,
                     v3(spec.pivot_P), v3(spec.observation_P));
  out += fmt::format("limits: length {:.4f} .. {:.4f} m, U-joint bend <= {:.2f} deg, singularity margin {:.2f} deg\n",
                     lim.length_min, lim.length_max, rad2deg(lim.bend_max), rad2deg(lim.singularity_margin));
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
    out += fmt::format("  home length {:.6f} m, direction {} [B]", l.length_home, v3(l.s_home_B));
    if (!std::isnan(l.theta_home)) out += fmt::format(", absolute twist at home {:.4f} deg", rad2deg(l.theta_home));
    out += "\n";
  }
  std::fputs(out.c_str(), stdout);
  return kExitOk;
}

}  // namespace

Command make_config_command(CLI::App& root) {
  auto opts = std::make_shared<ConfigOptions>();
  CLI::App* app = root.add_subcommand("config", "Show the resolved platform model (every leg's vectors, SI units)");
  add_model_options(*app, opts->model);
  app->add_flag("--json", opts->json, "Machine-readable output (SI units: m, rad)");
  app->add_flag("--yaml", opts->yaml, "Print the embedded seed configuration as YAML (a starting point for your own)");
  return {app, [opts] { return run_config(*opts); }};
}

}  // namespace hexatwist::cli
