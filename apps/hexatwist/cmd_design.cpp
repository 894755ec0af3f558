// SPDX-License-Identifier: BSD-3-Clause
// hexatwist design: the fixed U-joint axes that minimise the twist, the length error or the sensitivity
// to the lead over a required workspace, every limit kept there and the volume kept
// (design/axis_design.hpp); writes the designed configuration (io/platform_yaml.hpp).
#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <memory>

#include "cli_common.hpp"
#include "design_options.hpp"
#include "json.hpp"
#include "output_files.hpp"
#include "progress.hpp"
#include "schemas.hpp"

namespace hexatwist::cli {
namespace {

struct DesignCommandOptions {
  ModelOptions model;
  RequiredOptions required;
  std::string objective = "twist";
  std::string symmetry = "symmetric";
  bool tilt = false;
  double max_volume_loss_pct = 5.0;
  double clearance_deg = 0.0;
  std::string volume_orientation = "0,0,0";
  double cell = 0.0;  // the volume's grid cell [m]; 0: automatic
  std::string out;
  bool json = false;
};

DesignObjective objective_of(const std::string& s) {
  if (s == "twist") return DesignObjective::Twist;
  if (s == "length_error") return DesignObjective::LengthError;
  return DesignObjective::LeadSensitivity;
}
AxisSymmetry symmetry_of(const std::string& s) {
  if (s == "symmetric") return AxisSymmetry::Symmetric;
  if (s == "threefold") return AxisSymmetry::Threefold;
  return AxisSymmetry::PerLeg;
}

constexpr const char* kMarginNames[kMarginKinds] = {"stroke", "command", "bend", "singularity", "condition"};
constexpr const char* kMarginLabels[kMarginKinds] = {"stroke (legs)", "stroke (commands)", "U-joint bend",
                                                     "U-joint singularity", "platform condition"};

// "0.463 (leg 5: 44.34 deg, limit 5 deg)": a margin with the value that sets it, in the limit's unit.
std::string margin_text(const LimitMargin& m) {
  if (std::isinf(m.share)) return "-";
  const Status s = m.at.status;
  const bool angle =
      s == Status::BendBase || s == Status::BendPlatform || s == Status::SingularBase || s == Status::SingularPlatform;
  const std::string leg = m.at.leg >= 0 ? fmt::format("leg {}: ", m.at.leg + 1) : "";
  if (angle)
    return fmt::format("{:.3f} ({}{:.2f} deg, limit {:g} deg)", m.share, leg, rad2deg(m.at.value), rad2deg(m.at.bound));
  if (s == Status::PlatformSingularity)
    return fmt::format("{:.3f} (condition {:.2f}, limit {:g})", m.share, m.at.value, m.at.bound);
  return fmt::format("{:.3f} ({}{:.4f} m, limit {:g} m)", m.share, leg, m.at.value, m.at.bound);
}

void evaluation_json(JsonWriter& j, const DesignEvaluation& e) {
  j.begin_object();
  j.field("poses", static_cast<std::uint64_t>(e.poses));
  j.field("reached", static_cast<std::uint64_t>(e.reached));
  j.field("max_twist", e.max_twist);
  j.field("twist_leg", e.twist_leg + 1);
  j.field("max_length_error", e.max_length_error);
  j.field("max_lead_sensitivity", e.max_lead_sensitivity);
  j.field("axis_sensitivity", e.axis_sensitivity);
  j.key("margins").begin_object();
  for (int k = 0; k < kMarginKinds; ++k) {
    const LimitMargin& m = e.margins[static_cast<std::size_t>(k)];
    j.key(kMarginNames[k]).begin_object();
    j.field("share", m.share);
    j.field("limit", to_string(m.at.status));
    j.field("leg", m.at.leg + 1);
    j.field("value", m.at.value);
    j.field("bound", m.at.bound);
    j.end_object();
  }
  j.end_object();
  j.field("volume", e.volume);
  j.field("volume_error", e.volume_error);
  j.end_object();
}

std::string report_json(const Model& model, const DesignCommandOptions& o, const RequiredPoses& req,
                        const DesignOptions& d, const AxisDesign& r) {
  JsonWriter j;
  j.begin_document(schema::kDesign);
  j.field("command", "design");
  j.field("units", "SI: m, rad, m^3; lead_sensitivity in m per unit relative lead error; margins are shares");
  j.field("config", model_source(o.model));
  j.field("model", model.spec().name);
  j.key("required_workspace");
  write_required_json(j, req);
  j.field("objective", o.objective);
  j.field("symmetry", o.symmetry);
  j.field("tilt", o.tilt);
  j.field("max_volume_loss", d.max_volume_loss);
  j.key("volume_orientation").vector(d.volume_rpy);
  j.field("cell", o.cell);
  j.field("objective_before", r.objective_before);
  j.field("objective_after", r.objective_after);
  j.field("objective_bound", r.objective_bound);
  j.key("before");
  evaluation_json(j, r.before);
  j.key("after");
  evaluation_json(j, r.after);
  const auto legs = [&](const char* key, const PerLeg<double>& v) {
    j.key(key).begin_array();
    for (const double x : v) j.value(x);
    j.end_array();
  };
  j.key("turns").begin_object();
  legs("base", r.turns.base);
  legs("platform", r.turns.platform);
  legs("base_tilt", r.turns.base_tilt);
  legs("platform_tilt", r.turns.platform_tilt);
  j.end_object();
  j.key("axes").begin_array(true);
  for (int i = 0; i < kLegs; ++i) {
    j.begin_object().field("leg", i + 1);
    j.key("base_axis").vector(r.designed.legs[static_cast<std::size_t>(i)].axis_base_B);
    j.key("platform_axis").vector(r.designed.legs[static_cast<std::size_t>(i)].axis_platform_P);
    j.end_object();
  }
  j.end_array();
  j.field("evaluations", static_cast<std::uint64_t>(r.evaluations));
  j.field("designed_config", o.out);
  j.end_object();
  return j.str();
}

std::string report_text(const Model& model, const DesignCommandOptions& o, const RequiredPoses& req,
                        const DesignOptions& d, const AxisDesign& r, double seconds, const std::string& defaults) {
  const DesignEvaluation &b = r.before, &a = r.after;
  std::string out = fmt::format("hexatwist design on {}: {}{}\n", model_source(o.model), model.spec().name, defaults);
  out += fmt::format("required workspace: {}\n", req.description);
  out += fmt::format("objective: largest {}; symmetry: {}{}; volume kept within {:g} %\n",
                     o.objective == "twist"          ? "|twist|"
                     : o.objective == "length_error" ? "|length error|"
                                                     : "lead sensitivity",
                     o.symmetry == "symmetric" ? "symmetric (odd legs turn +a, even legs -a)" : o.symmetry,
                     o.tilt ? ", tilts searched" : "", o.max_volume_loss_pct);
  out += fmt::format("\n{:<28}{:>40}{:>40}\n", "", "before", "after");
  out += fmt::format("{:<28}{:>40}{:>40}\n", "largest |twist|",
                     fmt::format("{:.2f} deg (leg {})", rad2deg(b.max_twist), b.twist_leg + 1),
                     fmt::format("{:.2f} deg (leg {})", rad2deg(a.max_twist), a.twist_leg + 1));
  out +=
      fmt::format("{:<28}{:>40}{:>40}\n", "largest |length error|", fmt::format("{:.4f} mm", 1e3 * b.max_length_error),
                  fmt::format("{:.4f} mm", 1e3 * a.max_length_error));
  out += fmt::format("{:<28}{:>40}{:>40}\n", "lead sensitivity (point A)",
                     fmt::format("{:.4f} mm per 1 % lead", 10.0 * b.max_lead_sensitivity),
                     fmt::format("{:.4f} mm per 1 % lead", 10.0 * a.max_lead_sensitivity));
  const std::string axis_row = fmt::format("U-joint axis errors {:g} deg", rad2deg(kDesignAxisSigma));
  out +=
      fmt::format("{:<28}{:>40}{:>40}\n", axis_row, fmt::format("{:.4f} mm at point A (p95)", 1e3 * b.axis_sensitivity),
                  fmt::format("{:.4f} mm at point A (p95)", 1e3 * a.axis_sensitivity));
  out += fmt::format("{:<28}{:>40}{:>40}\n", "poses reached (with home)", fmt::format("{} of {}", b.reached, b.poses),
                     fmt::format("{} of {}", a.reached, a.poses));
  out += "margin: share of range left\n";
  for (int k = 0; k < kMarginKinds; ++k)
    out += fmt::format("  {:<26}{:>40}{:>40}\n", kMarginLabels[k], margin_text(b.margins[static_cast<std::size_t>(k)]),
                       margin_text(a.margins[static_cast<std::size_t>(k)]));
  out += fmt::format("{:<28}{:>40}{:>40}\n",
                     fmt::format("volume at {:g},{:g},{:g} deg", rad2deg(d.volume_rpy[0]), rad2deg(d.volume_rpy[1]),
                                 rad2deg(d.volume_rpy[2])),
                     fmt::format("{:.4f} m^3 (+-{:.4f})", b.volume, b.volume_error),
                     fmt::format("{:.4f} m^3 ({:+.2f} %)", a.volume, 100.0 * (a.volume / b.volume - 1.0)));
  out += "\nturns of the fixed axes [deg] (about z of their frame; tilt up out of the joint plane)\n";
  out += "leg    base  platform  base tilt  platform tilt\n";
  for (int i = 0; i < kLegs; ++i)
    out += fmt::format("{:>3}{:>8.2f}{:>10.2f}{:>11.2f}{:>15.2f}\n", i + 1, rad2deg(r.turns.base[i]),
                       rad2deg(r.turns.platform[i]), rad2deg(r.turns.base_tilt[i]), rad2deg(r.turns.platform_tilt[i]));
  if (std::isfinite(r.objective_bound)) {
    // How close to the optimum: each leg's own best bounds every design of the axes searched from below.
    const bool twist = o.objective == "twist";
    // The values as printed, and their difference as printed (the gap of the rounded numbers).
    const auto shown = [&](double x) {
      return twist ? std::round(100.0 * rad2deg(x)) / 100.0 : std::round(1e7 * x) / 1e4;
    };
    const auto value = [&](double x) { return twist ? fmt::format("{:.2f} deg", x) : fmt::format("{:.4f} mm", x); };
    const double bound = shown(r.objective_bound), gap = shown(r.objective_after) - bound;
    out += fmt::format(
        "optimum: no axes {} do better than {} as far as the search finds (the worst leg's own best, each leg's "
        "axes searched alone with the volume free); this design is {}\n",
        o.tilt ? fmt::format("tilted up to {:g} deg", rad2deg(d.max_tilt)) : std::string("in the joint planes"),
        value(bound),
        gap <= 0.0 ? "at that bound"
                   : fmt::format("{} above it ({:.2g} %): what the symmetry and the volume kept cost at most",
                                 value(gap), 100.0 * gap / bound));
  } else if (o.objective == "lead_sensitivity") {
    out += "optimum: no bound for the lead objective, which couples the legs through the platform's Jacobian\n";
  }
  if (r.objective_after >= r.objective_before)
    out += "no design kept every limit and the volume and did better: the configuration's own axes are kept\n";
  out += fmt::format("wrote {}: the configuration with the designed axes ({} candidates in {:.1f} s)\n",
                     printable(o.out), r.evaluations, seconds);
  return out;
}

int run_design(const DesignCommandOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = load_config_from(o.model);
  const Model& model = config.rig.model();
  OutputFiles files("design");
  files.input("--config", o.model.config);
  for (const std::string& t : o.required.trajectories) files.input("--trajectory", t);
  files.output("--out", o.out);
  const std::vector<double> vo = parse_numbers(o.volume_orientation, 3, "--volume-orientation", "roll,pitch,yaw [deg]");
  check_cell_option(o.cell);
  const RequiredPoses req = required_poses(config, o.required);
  // The configuration's own text: every other key of it is kept in the designed one.
  const std::string text = o.model.config.empty()
                               ? std::string(seed_config_yaml())
                               : read_text_file(o.model.config, "--config", "configuration", kMaxConfigBytes);

  DesignOptions d;
  d.objective = objective_of(o.objective);
  d.symmetry = symmetry_of(o.symmetry);
  d.tilt = o.tilt;
  d.max_volume_loss = o.max_volume_loss_pct / 100.0;
  d.clearance = deg2rad(o.clearance_deg);
  d.volume_rpy = Vector3d(deg2rad(vo[0]), deg2rad(vo[1]), deg2rad(vo[2]));
  d.volume.cell = o.cell;
  d.threads = 0;
  AxisDesign r;
  {
    std::unique_ptr<Progress> bar;  // on a terminal; the library's first call (0 done) gives the steps
    d.progress = [&](std::size_t done, std::size_t total) {
      if (!bar) bar = std::make_unique<Progress>(total, !o.json);
      const bool alone = d.objective != DesignObjective::LeadSensitivity && done < kLegs;
      bar->update(done, alone ? fmt::format("each leg alone ({} of 6)", done + 1) : std::string("the design"));
    };
    if (const Status s = design_axes(model, req.poses, d, r); s != Status::Ok)
      throw ExitError(kExitOutOfLimit,
                      fmt::format("design failed: {} ({}); nothing was written", describe(s), to_string(s)));
  }
  if (!(r.before.volume > 0.0))
    throw ExitError(kExitOutOfLimit,
                    fmt::format("--volume-orientation {}: the platform reaches no position at that orientation (volume "
                                "0), so there is no volume to keep; give one it reaches. Nothing was written",
                                printable(o.volume_orientation)));
  const std::string header = fmt::format(
      "{} with its fixed U-joint axes designed by hexatwist design (objective {}, symmetry {}):\n"
      "largest |twist| over the required workspace {:.2f} deg -> {:.2f} deg",
      model_source(o.model), o.objective, o.symmetry, rad2deg(r.before.max_twist), rad2deg(r.after.max_twist));
  std::string yaml;
  try {
    yaml = designed_config_yaml(text, model_source(o.model), r.designed, header);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
  files.add(o.out, yaml);
  files.commit();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  files.finish(o.json ? report_json(model, o, req, d, r)
                      : report_text(model, o, req, d, r, seconds, defaults_note(config)));
  return kExitOk;
}

}  // namespace

Command make_design_command(CLI::App& root) {
  auto o = std::make_shared<DesignCommandOptions>();
  CLI::App* app = root.add_subcommand(
      "design",
      "Design of the fixed U-joint axes (docs/theory/design.md §17): the directions of every leg's base and platform "
      "U-joint axis (turned in their joint planes, and tilted out of them with --tilt) that minimise --objective "
      "over the required workspace (--workspace SPEC, default the study's four tests at their amplitudes and 2000 "
      "random combined poses within +-0.25 m / +-15 deg, those the platform reaches; or --trajectory FILE...), with "
      "every limit holding at each of its poses and the workspace volume at --volume-orientation kept within "
      "--max-volume-loss. Only the axes change; joints, home and limits stay. Writes the designed configuration to "
      "--out (every other key of the configuration kept) and prints before and after: the largest twist, length "
      "error and lead sensitivity, each limit's margin, the volume.");
  add_model_options(*app, o->model);
  add_required_options(*app, o->required);
  app->add_option("--objective", o->objective,
                  "twist (largest |twist| [deg]), length_error (largest |lead * twist / 2 pi| [mm]) or "
                  "lead_sensitivity (point A's error per relative lead error)")
      ->check(CLI::IsMember({"twist", "length_error", "lead_sensitivity"}))
      ->capture_default_str();
  app->add_option("--symmetry", o->symmetry,
                  "symmetric (the seed's: odd legs turn +a, even legs -a), threefold (odd legs one turn, even legs "
                  "another) or per_leg")
      ->check(CLI::IsMember({"symmetric", "threefold", "per_leg"}))
      ->capture_default_str();
  app->add_flag("--tilt", o->tilt, "Also search tilts of the axes out of their joint planes (up to 30 deg)");
  app->add_option("--max-volume-loss", o->max_volume_loss_pct,
                  "Largest share of the workspace volume the design may lose [%]")
      ->capture_default_str();
  app->add_option("--clearance", o->clearance_deg,
                  "Required over the workspace beyond the configured U-joint singularity margin [deg]")
      ->capture_default_str();
  app->add_option("--volume-orientation", o->volume_orientation, "roll,pitch,yaw of the volume kept [deg]")
      ->capture_default_str();
  add_cell_option(*app, o->cell);
  app->add_option("--out", o->out, "The designed configuration (YAML)")->required();
  app->add_flag("--json", o->json, "Print the report as JSON (SI)");
  return {app, [o] { return run_design(*o); }};
}

}  // namespace hexatwist::cli
