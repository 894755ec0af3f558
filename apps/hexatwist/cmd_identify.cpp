// hexatwist identify: lead, twist sign, leg offsets and observation point identified from a point log,
// written as a corrected configuration (docs/theory.md §13).
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>

#include "cli_common.hpp"
#include "json.hpp"
#include "output_files.hpp"
#include "run_options.hpp"
#include "study_report.hpp"

namespace hexatwist::cli {
namespace {

struct IdentifyOptions {
  RunOptions run;
  LogOptions log;
  double settle = 0.25;
  std::string lead_effect = "travel";
  std::string out = "identified.yaml";
  bool json = false;
};

// One row of the table: a parameter in display units.
struct ParameterRow {
  std::string name;
  std::string unit;
  double scale = 1.0;  // display units per SI unit
  double nominal = 0.0;
  double estimate = 0.0;
  double sd = 0.0;
  int decimals = 4;
};

std::vector<ParameterRow> parameter_rows(const Model& nominal, const Identification& id) {
  std::vector<ParameterRow> rows;
  const PlatformParameters& e = id.estimate;
  rows.push_back({"lead", "mm", 1e3, nominal.leg(0).lead, e.lead, id.sd[kLeadIndex], 6});
  for (int i = 0; i < kLegs; ++i)
    rows.push_back({fmt::format("offset {}", i + 1), "mm", 1e3, nominal.geometry().length_offset[i], e.length_offset[i],
                    id.sd[kOffsetIndex + i]});
  for (int a = 0; a < 3; ++a)
    rows.push_back({fmt::format("point {}", "xyz"[a]), "mm", 1e3, nominal.spec().observation_P[a], e.observation_P[a],
                    id.sd[kObservationIndex + a]});
  return rows;
}

// The tracker's own noise per coordinate: the scatter of the points at rest about the mean of
// their pose (runs of one commanded pose), pooled over the poses; NaN without repeats [m]. It
// needs no model, so it is what the fit's sigma is compared with.
double scatter_at_rest(const ObservationSet& set) {
  const std::vector<Observation>& obs = set.observations;
  double sum = 0.0;
  std::size_t dof = 0;
  for (std::size_t a = 0; a < obs.size();) {
    std::size_t b = a + 1;
    while (b < obs.size() && (obs[b].motor - obs[a].motor).cwiseAbs().maxCoeff() <= 1e-9) ++b;
    Vector3d mean = Vector3d::Zero();
    for (std::size_t k = a; k < b; ++k) mean += obs[k].p_T;
    mean /= static_cast<double>(b - a);
    for (std::size_t k = a; k < b; ++k) sum += (obs[k].p_T - mean).squaredNorm();
    dof += 3 * (b - a - 1);
    a = b;
  }
  return dof >= 3 ? std::sqrt(sum / static_cast<double>(dof)) : std::numeric_limits<double>::quiet_NaN();
}

// The fit's noise may exceed the tracker's scatter at rest by this factor before the model is
// said not to explain the data (identify exits 5); the scatter counts as at least
// kTrackerNoiseFloor (a log's rounding and the servo's settling are below it).
constexpr double kNoiseRatioMax = 100.0;
constexpr double kTrackerNoiseFloor = 1e-6;  // [m]

// The JSON of identify. `failure` empty: the run succeeded and wrote `o.out`. Otherwise its
// one-line reason; the estimate and what follows from it are null unless the identification
// itself succeeded (`status` Ok, e.g. only the output failed). `fitted`: the solver converged, so
// the fit's numbers (residuals, sigma, the cost ratio) are known even where the estimate is
// refused (thread hands tied, a fit far noisier than the tracker): they say why.
std::string identify_json(const Model& nominal, const IdentifyOptions& o, const ObservationSet& set,
                          const PointLog& log, const Identification& id, Status status, bool fitted,
                          const std::string& failure) {
  const bool solved = status == Status::Ok;
  const auto number = [](JsonWriter& w, std::string_view key, double v, bool known) {
    w.key(key);
    known&& std::isfinite(v) ? w.value(v) : w.null();
  };
  JsonWriter j;
  j.begin_object().field("command", "identify").field("status", failure.empty() ? "ok" : "failed");
  if (!failure.empty()) j.field("reason", failure);
  j.field("model", nominal.spec().name).field("config", model_source(o.run.model)).field("points", o.log.points);
  j.field("log_points", static_cast<int>(log.points_T.size())).field("observations", id.count);
  j.field("poses", static_cast<int>(set.poses))
      .field("settle", set.settle)
      .field("strategy", o.run.strategy)
      .field("lead_effect", o.lead_effect);
  number(j, "rms_before", id.rms_before, true);
  number(j, "rms_after", id.rms_after, fitted);
  number(j, "max_after", id.max_after, fitted);
  j.key("max_after_line");
  fitted&& id.max_after_index >= 0 ? j.value(log.lines[set.points[static_cast<std::size_t>(id.max_after_index)]])
                                   : j.null();
  number(j, "sigma", id.sigma, fitted);
  const double scatter = scatter_at_rest(set);
  number(j, "tracker_noise", scatter, true);
  number(j, "noise_ratio", id.sigma / std::max(scatter, kTrackerNoiseFloor), fitted);
  number(j, "condition", id.condition, true);
  number(j, "cost_ratio", id.cost_ratio, fitted);
  j.key("fits").begin_array(true);
  for (const SignFit& f : id.fits) {
    j.begin_object().field("twist_sign", f.twist_sign).field("status", describe(f.status));
    number(j, "cost", f.cost, f.status == Status::Ok);
    j.field("iterations", f.iterations).field("lead_at_bound", f.lead_at_bound);
    number(j, "lead", f.estimate.lead, f.status == Status::Ok);
    j.end_object();
  }
  j.end_array();
  const PlatformParameters& e = id.estimate;
  j.key("estimate");
  if (!solved) {
    j.null();
  } else {
    j.begin_object();
    j.field("lead", e.lead).field("lead_sd", id.sd[kLeadIndex]).field("lead_nominal", nominal.leg(0).lead);
    j.field("twist_sign", e.twist_sign).field("twist_sign_nominal", nominal.leg(0).twist_sign);
    j.field("thread", e.twist_sign > 0.0 ? "right" : "left");
    j.key("length_offsets").vector(e.length_offset);
    j.key("length_offsets_sd").vector(id.sd.segment<kLegs>(kOffsetIndex));
    j.key("observation_point").vector(e.observation_P);
    j.key("observation_point_sd").vector(id.sd.segment<3>(kObservationIndex));
    j.key("X_BT").begin_object();
    j.key("R").begin_array();
    for (int i = 0; i < 3; ++i) j.vector(e.X_BT.R.row(i));
    j.end_array();
    j.key("t").vector(e.X_BT.t);
    j.key("rotation_sd").vector(id.sd.segment<3>(kRotationIndex));
    j.key("t_sd").vector(id.sd.segment<3>(kTranslationIndex));
    j.end_object().end_object();
  }
  j.key("corrected_config");
  failure.empty() ? j.value(o.out) : j.null();
  j.end_object();
  return j.str();
}

int run_identify(const IdentifyOptions& o) {
  OutputFiles files("identify");
  files.input("--config", o.run.model.config);
  files.input("--trajectory", o.run.trajectory);
  files.input("--points", o.log.points);
  files.output("--out", o.out);
  const Config config = load_config_from(o.run.model);
  const Model& model = config.rig.model();
  const PointLogFormat format = log_format(o.log);
  check_option(o.settle >= 0.0, "--settle", o.settle, "a time >= 0 [s]");
  const Run run = build_run(config, o.run);
  check_option(o.settle < run.test.trajectory.duration(), "--settle", o.settle,
               fmt::format("a time shorter than the run ({:g} s): no point can be still for longer [s]",
                           run.test.trajectory.duration()));
  const PointLog log = read_point_log(o.log, format);
  ObservationSet set;
  try {
    set =
        observations_at_rest(model, run.commanded, log, {o.log.time_offset, o.log.rate}, strategy_of(o.run), o.settle);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
  IdentificationOptions io;
  io.lead_effect = o.lead_effect == "twist" ? LeadEffect::TwistOnly : LeadEffect::TwistAndTravel;
  Identification id;
  const Status status = identify(model, set.observations, id, io);
  // A failure still prints the JSON (with the reason, and null where there is no value) when asked.
  const auto fail = [&](const ExitError& e, Status solved) {
    if (o.json) write_stdout(identify_json(model, o, set, log, id, solved, status == Status::Ok, e.what()) + "\n");
    throw e;
  };
  if (status != Status::Ok) {
    const char* what = status == Status::NotIdentifiable       ? "not identifiable"
                       : status == Status::SolverNoConvergence ? "no convergence"
                                                               : "failed";
    fail(ExitError(kExitNotIdentified, fmt::format("{}: {} points at rest at {} pose{}: {}: {}; nothing was written",
                                                   printable(o.log.points), set.observations.size(), set.poses,
                                                   set.poses == 1 ? "" : "s", what, id.reason)),
         status);
  }

  // The fit must explain the data about as well as the tracker measures: a residual noise far
  // above the scatter of the points at rest means a model that does not describe the machine
  // (another configuration, log or run), whose lead and thread would mean nothing.
  if (const double scatter = scatter_at_rest(set), floor = std::max(scatter, kTrackerNoiseFloor);
      !(id.sigma <= kNoiseRatioMax * floor))
    fail(
        ExitError(kExitNotIdentified,
                  fmt::format("{}: the fit leaves a noise of {:.4g} mm per axis, {:.3g} times the tracker's scatter at "
                              "rest ({:.4g} mm, at least {:g} mm counted; {:g} times allowed): the model does not "
                              "explain the data (another configuration, log or run?); nothing was written",
                              printable(o.log.points), 1e3 * id.sigma, id.sigma / floor, 1e3 * scatter,
                              1e3 * kTrackerNoiseFloor, kNoiseRatioMax)),
        Status::NotIdentifiable);

  // The thread hand is decided only if the other sign fits worse by more than the noise explains:
  // twice the cost difference over sigma^2 is a chi-square of one degree of freedom; ask 25 (5 sd).
  {
    const bool plus = id.estimate.twist_sign > 0.0;
    const SignFit& rejected = id.fits[plus ? 1 : 0];
    const SignFit& chosen = id.fits[plus ? 0 : 1];
    const double separation = 2.0 * (rejected.cost - chosen.cost) / (id.sigma * id.sigma);
    if (rejected.status == Status::Ok && !rejected.lead_at_bound && !(separation >= 25.0))
      fail(ExitError(kExitNotIdentified,
                     fmt::format("{}: the two thread hands fit the data equally well (cost ratio {:.4g}, difference "
                                 "{:.3g} noise variances, 25 needed): the twist sign and lead are not decided; record "
                                 "a run with rotations (--stations); nothing was written",
                                 printable(o.log.points), id.cost_ratio, separation)),
           Status::NotIdentifiable);
  }
  const std::string source_text = o.run.model.config.empty()
                                      ? std::string(seed_config_yaml())
                                      : read_text_file(o.run.model.config, "--config", "config file", kMaxConfigBytes);
  ModelSpec corrected = corrected_spec(model.spec(), id.estimate);
  corrected.name = fmt::format("{} (identified from {})", model.spec().name, o.log.points);
  const std::string header = fmt::format(
      "corrected by hexatwist identify from {} ({} observations at rest, rms {:.4f} -> {:.4f} mm):\n"
      "name, screw lead and thread, length_offsets and observation_point; everything else as in {}.",
      o.log.points, id.count, 1e3 * id.rms_before, 1e3 * id.rms_after, model_source(o.run.model));
  std::string yaml;
  try {
    yaml = corrected_config_yaml(source_text, model_source(o.run.model), corrected, header);
    (void)load_config(yaml, o.out);  // what is written must load
  } catch (const Error& e) {
    fail(ExitError(kExitNotIdentified, fmt::format("{}: the corrected configuration does not load: {}; nothing was "
                                                   "written",
                                                   printable(o.out), e.what())),
         Status::NotIdentifiable);
  }
  try {
    files.add(o.out, yaml);
    files.commit();
  } catch (const ExitError& e) {
    fail(e, status);
  }
  if (o.json) {
    files.finish(identify_json(model, o, set, log, id, status, true, std::string()) + "\n");
    return kExitOk;
  }

  std::string text = fmt::format("hexatwist identify on {}: {}\n", model_source(o.run.model), model.spec().name);
  text += fmt::format(
      "points: {}: {} points, {} at rest (commanded pose still for {:g} s) at {} poses used; {}; {} commands\n",
      printable(o.log.points), log.points_T.size(), id.count, set.settle, set.poses, run.test.description,
      o.run.strategy);
  text += fmt::format("lead model: {}\n", io.lead_effect == LeadEffect::TwistAndTravel
                                              ? "travel (the drives turn the screws by the nominal lead's angles)"
                                              : "twist only (the drives' travel is right; --lead-effect twist)");
  const SignFit& plus = id.fits[0];
  const SignFit& minus = id.fits[1];
  text += fmt::format(
      "twist sign: +1 cost {:.4g} m^2{}, -1 cost {:.4g} m^2{}: {} ({}-hand thread), cost ratio {:.3g}\n", plus.cost,
      plus.lead_at_bound ? " (lead at 0)" : "", minus.cost, minus.lead_at_bound ? " (lead at 0)" : "",
      id.estimate.twist_sign > 0.0 ? "+1" : "-1", id.estimate.twist_sign > 0.0 ? "right" : "left", id.cost_ratio);
  text += fmt::format(
      "residual: rms {:.4f} mm before (nominal model, tracker frame by Kabsch), {:.4f} mm after, largest {:.4f} mm "
      "(line {}); noise {:.4f} mm per axis (the tracker's scatter at rest {:.4f} mm); condition {:.3g}\n",
      1e3 * id.rms_before, 1e3 * id.rms_after, 1e3 * id.max_after,
      log.lines[set.points[static_cast<std::size_t>(id.max_after_index)]], 1e3 * id.sigma, 1e3 * scatter_at_rest(set),
      id.condition);
  text += fmt::format("{:<12} {:>12} {:>12} {:>10} {:>12}\n", "parameter", "nominal", "estimate", "sd", "change");
  for (const ParameterRow& r : parameter_rows(model, id)) {
    const std::string change = r.name == "lead" ? fmt::format("{:+.4f} %", 100.0 * (r.estimate / r.nominal - 1.0))
                                                : fmt::format("{:+.4f}", r.scale * (r.estimate - r.nominal));
    text += fmt::format("{:<12} {:>12.{}f} {:>12.{}f} {:>10.{}f} {:>12}  [{}]\n", r.name, r.scale * r.nominal,
                        r.decimals, r.scale * r.estimate, r.decimals, r.scale * r.sd, r.decimals, change, r.unit);
  }
  const Eigen::AngleAxisd turn(id.estimate.X_BT.R);
  text += fmt::format(
      "tracker frame in the base frame: origin ({:.4f}, {:.4f}, {:.4f}) m, turned {:.4f} deg about "
      "({:.4f}, {:.4f}, {:.4f})\n",
      id.estimate.X_BT.t.x(), id.estimate.X_BT.t.y(), id.estimate.X_BT.t.z(), rad2deg(turn.angle()), turn.axis().x(),
      turn.axis().y(), turn.axis().z());
  text += fmt::format("wrote {}: the corrected configuration", o.out);
  files.finish(text + "\n");
  return kExitOk;
}

}  // namespace

Command make_identify_command(CLI::App& root) {
  auto o = std::make_shared<IdentifyOptions>();
  CLI::App* app = root.add_subcommand(
      "identify",
      "Estimates, by nonlinear least squares (Ceres), the screw lead, the sign of the twist term (thread hand), each "
      "leg's zero-length offset, the observation point and the tracker frame from a laser tracker's point log of the "
      "observation point, using the points where the platform stood still; reports each with its standard deviation "
      "and the residual before and after, and writes the corrected configuration (YAML). Record a run that stops at "
      "many poses (--stations): the paper's tests alone leave some offsets undetermined. Exit 5 when the data do not "
      "determine the parameters, the thread hand is not decided (both signs fit alike) or the solver does not "
      "converge; exit 4 if the configuration cannot be written. --json is printed on failure too, its status "
      "agreeing with the exit code and null where there is no value.");
  add_log_options(*app, o->log);
  add_run_options(*app, o->run);
  app->add_option("--settle", o->settle,
                  "Use the points whose commanded pose has been still for this long [s]; 0 = every point (the servo "
                  "lags in motion)")
      ->capture_default_str();
  app->add_option("--lead-effect", o->lead_effect,
                  "travel: the drives turn the screws by the nominal lead's angles, so a wrong lead also scales the "
                  "travel; twist: only the twist term sees it (the drives' travel is right)")
      ->check(CLI::IsMember({"travel", "twist"}))
      ->capture_default_str();
  app->add_option("--out", o->out, "The corrected configuration to write (YAML)")->capture_default_str();
  app->add_flag("--json", o->json, "Machine-readable output (SI units: m, rad)");
  return {app, [o] { return run_identify(*o); }};
}

}  // namespace hexatwist::cli
