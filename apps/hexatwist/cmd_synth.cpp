// SPDX-License-Identifier: BSD-3-Clause
// hexatwist synth: a tracker-like point log made from the simulation of a platform with known parameter
// errors, with the truth beside it (docs/theory.md §12).
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
#include "schemas.hpp"
#include "study_report.hpp"

namespace hexatwist::cli {
namespace {

struct SynthOptions {
  RunOptions run;
  double noise_um = 10.0;
  double rate = 100.0;
  std::uint64_t seed = 1;
  std::string lead_error_pct = "0";
  bool flip_sign = false;
  std::string offsets_mm = "0";
  std::string point_offset_mm = "0,0,0";
  double joint_errors_mm = 0.0;
  double axis_errors_deg = 0.0;
  std::string targets_mm;
  std::string stiffness_n_per_um;
  std::string play_um;
  std::string temperature_rise_k;
  std::string expansion_ppm_per_k = "11.5,11.5";
  bool temperature_column = false;
  std::string out;
  std::string run_out;
  std::string real;
};

std::string truth_json(const Config& config, const SynthOptions& o, const Run& run, const SynthesisOptions& so,
                       const SyntheticLog& log) {
  const Model& model = config.rig.model();
  const Model real = real_platform(model, so);
  JsonWriter j;
  j.begin_document(schema::kTruth)
      .field("command", "synth")
      .field("model", model.spec().name)
      .field("config", model_source(o.run.model))
      .field("run", run.test.description)
      .field("strategy", o.run.strategy)
      .field("points", static_cast<int>(log.log.points_T.size()))
      .field("rate", so.rate)
      .field("seed", so.seed);
  j.key("calibration_end");
  std::isfinite(run.calibration_end) ? j.value(run.calibration_end) : j.null();
  j.key("X_BT").begin_object();
  j.key("R").begin_array();
  for (int i = 0; i < 3; ++i) j.vector(log.X_BT.R.row(i));
  j.end_array();
  j.key("t").vector(log.X_BT.t);
  j.end_object();
  j.field("noise", so.noise);
  j.key("errors").begin_object();
  j.key("lead_error").vector(so.errors.lead_error);
  j.field("flip_twist_sign", so.errors.flip_twist_sign);
  j.key("zero_offset").vector(so.errors.zero_offset);
  j.key("observation_offset_P").vector(so.errors.observation_offset_P);
  j.key("base_offset_B").begin_array();
  for (int i = 0; i < kLegs; ++i) j.vector(Vector3d(so.errors.base_offset_B.row(i).transpose()));
  j.end_array();
  j.key("platform_offset_P").begin_array();
  for (int i = 0; i < kLegs; ++i) j.vector(Vector3d(so.errors.platform_offset_P.row(i).transpose()));
  j.end_array();
  j.key("base_axis_rotation").begin_array();
  for (int i = 0; i < kLegs; ++i) j.vector(Vector3d(so.errors.base_axis_rotation.row(i).transpose()));
  j.end_array();
  j.key("platform_axis_rotation").begin_array();
  for (int i = 0; i < kLegs; ++i) j.vector(Vector3d(so.errors.platform_axis_rotation.row(i).transpose()));
  j.end_array();
  j.end_object();
  // The real platform itself, in the gauge frames (the joints' errors have no rigid part).
  j.key("real").begin_object();
  const auto legs = [&](const char* key, const auto& get) {
    j.key(key).begin_array();
    for (const LegSpec& leg : real.spec().legs) j.vector(get(leg));
    j.end_array();
  };
  legs("base_joints", [](const LegSpec& l) { return l.base_B; });
  legs("platform_joints", [](const LegSpec& l) { return l.platform_P; });
  legs("base_axes", [](const LegSpec& l) { return l.axis_base_B; });
  legs("platform_axes", [](const LegSpec& l) { return l.axis_platform_P; });
  j.key("leads").begin_array();
  for (int i = 0; i < kLegs; ++i) j.value(real.leg(i).lead);
  j.end_array();
  j.key("drive_leads").begin_array();
  for (int i = 0; i < kLegs; ++i) j.value(real.leg(i).lead / real.leg(i).drive_scale);
  j.end_array();
  j.key("threads").begin_array();
  for (int i = 0; i < kLegs; ++i) j.value(real.leg(i).thread == ThreadSense::Right ? "right" : "left");
  j.end_array();
  j.key("length_offsets").vector(real.geometry().length_offset);
  j.key("stiffness").begin_array();
  for (const LegSpec& leg : real.spec().legs) j.value(leg.stiffness);  // null: rigid
  j.end_array();
  j.key("play").begin_array();
  for (const LegSpec& leg : real.spec().legs) j.value(leg.play);
  j.end_array();
  j.key("temperature_rise").vector(so.temperature_rise);
  j.key("home_commands").vector(real.home_command());
  j.key("targets").begin_array();
  j.vector(real.spec().observation_P);
  for (const Vector3d& t : so.extra_targets_P) j.vector(t);
  j.end_array();
  j.end_object().end_object();
  return j.str();
}

// "0.1234, -0.5000, ..." in mm from metres.
template <class Vec>
std::string mm_list(const Vec& v) {
  std::string s;
  for (Eigen::Index i = 0; i < v.size(); ++i) s += fmt::format("{}{:.4f}", i == 0 ? "" : ", ", 1e3 * v[i]);
  return s;
}

// The real platform as a configuration: --config's text (or the seed's) with the real platform in
// the legs form, its legs' effects included: for synth --real (a validation run) and compare.
std::string real_platform_yaml(const SynthOptions& o, const Model& model, const SynthesisOptions& so,
                               const std::string& out) {
  const std::string source_text = o.run.model.config.empty()
                                      ? std::string(seed_config_yaml())
                                      : read_text_file(o.run.model.config, "--config", "config file");
  ModelSpec real = real_platform(model, so).spec();
  real.name = fmt::format("the real platform of {} (hexatwist synth --seed {})", out, o.seed);
  const std::string header = fmt::format(
      "The real platform hexatwist synth measured for {}: give it to synth --real to drive the same platform with\n"
      "another configuration's commands (a validation run), or to compare.",
      out);
  return platform_config_yaml(source_text, model_source(o.run.model), real, header, true);
}

// The synthesis options from the command's, their units converted; the library checks them
// (check_synthesis_options, random_geometry_errors), the error naming the option.
SynthesisOptions synthesis_options(const SynthOptions& o, const Rig& rig) {
  SynthesisOptions so;
  so.strategy = strategy_of(o.run);
  so.noise = o.noise_um / 1e6;
  so.rate = o.rate;
  so.seed = o.seed;
  {
    const bool six = o.lead_error_pct.find(',') != std::string::npos;
    const std::vector<double> pct =
        parse_numbers(o.lead_error_pct, six ? 6 : 1, "--lead-error-pct", "a lead error [%], or six (one per leg)");
    for (int i = 0; i < kLegs; ++i) so.errors.lead_error[i] = pct[six ? static_cast<std::size_t>(i) : 0] / 100.0;
  }
  so.errors.flip_twist_sign = o.flip_sign;
  if (o.offsets_mm.find(',') == std::string::npos)
    so.errors.zero_offset = random_zero_offsets(
        parse_numbers(o.offsets_mm, 1, "--offsets-mm", "a bound [mm], or six offsets [mm]")[0] / 1e3, o.seed);
  else
    for (int i = 0;
         const double v : parse_numbers(o.offsets_mm, 6, "--offsets-mm", "a bound [mm], or six offsets [mm]"))
      so.errors.zero_offset[i++] = v / 1e3;
  const std::vector<double> point = parse_numbers(o.point_offset_mm, 3, "--point-offset-mm", "x,y,z [mm]");
  so.errors.observation_offset_P = Vector3d(point[0], point[1], point[2]) / 1e3;
  // Joint-centre and axis errors (theory §13): a bound each, drawn per coordinate, no rigid part.
  random_geometry_errors(rig.model(), o.joint_errors_mm / 1e3, deg2rad(o.axis_errors_deg), o.seed, so.errors);
  so.extra_targets_P = targets_option(o.targets_mm);

  // The real legs' effects (theory §4b): stiffness, play, warming and expansion.
  if (!o.stiffness_n_per_um.empty())
    so.errors.stiffness = per_leg_option(
        o.stiffness_n_per_um, "--stiffness-n-per-um",
        fmt::format("an axial stiffness from {:g} to {:g} N/um, or six", kMinStiffness / 1e6, kMaxStiffness / 1e6),
        kMinStiffness / 1e6, kMaxStiffness / 1e6, 1e6);
  if (!o.play_um.empty())
    so.errors.play =
        per_leg_option(o.play_um, "--play-um", fmt::format("a play from 0 to {:g} um, or six", kMaxPlay * 1e6), 0.0,
                       kMaxPlay * 1e6, 1e-6);
  // The expansions are checked whether or not the legs warm: a bad value is never ignored.
  const std::vector<double> expansion = parse_numbers(o.expansion_ppm_per_k, 2, "--expansion-ppm-per-k",
                                                      "the length's and the lead's expansion [ppm/K], two numbers");
  for (const double v : expansion)
    check_option(v >= kMinExpansion * 1e6 && v <= kMaxExpansion * 1e6, "--expansion-ppm-per-k", v,
                 fmt::format("expansions from {:g} to {:g} ppm/K", kMinExpansion * 1e6, kMaxExpansion * 1e6));
  if (!o.temperature_rise_k.empty()) {
    so.temperature_rise = temperature_rise_option(o.temperature_rise_k, nullptr);
    so.errors.length_expansion = expansion[0] * 1e-6;
    so.errors.lead_expansion = expansion[1] * 1e-6;
  }
  so.log_temperature = o.temperature_column;
  if (!o.real.empty()) so.real = load_model_from(ModelOptions{o.real, "--real"}).spec();
  check_synthesis_options(rig.model(), so);
  return so;
}

// The log like a tracker's export: millimetres with a unit suffix, 1 nm resolution (noise-free
// logs stay exact enough), a target column when there are several targets.
// With the machine's temperature, a temperature_c column (0.001 K resolution).
std::string log_csv(const SyntheticLog& log, bool targets) {
  fmt::memory_buffer b;
  const bool temperature = !log.log.temperatures.empty();
  fmt::format_to(std::back_inserter(b), "{}{}\n", targets ? "t_s,target,x_mm,y_mm,z_mm" : "t_s,x_mm,y_mm,z_mm",
                 temperature ? ",temperature_c" : "");
  for (std::size_t k = 0; k < log.log.points_T.size(); ++k) {
    const Vector3d p = 1e3 * log.log.points_T[k];
    fmt::format_to(std::back_inserter(b), "{:.6f},", log.log.stamps[k]);
    if (targets)
      fmt::format_to(std::back_inserter(b), "{},", log.log.target_names[static_cast<std::size_t>(log.log.targets[k])]);
    fmt::format_to(std::back_inserter(b), "{:.6f},{:.6f},{:.6f}", p.x(), p.y(), p.z());
    if (temperature) fmt::format_to(std::back_inserter(b), ",{:.3f}", log.log.temperatures[k]);
    fmt::format_to(std::back_inserter(b), "\n");
  }
  return fmt::to_string(b);
}

// What synth tells the user: the run, the real platform's errors, the tracker, the files.
std::string summary_text(const SynthOptions& o, const Rig& rig, const Run& run, const SynthesisOptions& so,
                         const SyntheticLog& log, const std::string& out, const std::string& truth,
                         const std::string& real_yaml, const std::string& defaults) {
  const bool targets = !so.extra_targets_P.empty();
  const Vector3d& origin = log.X_BT.t;
  std::string text =
      fmt::format("hexatwist synth on {}: {}{}\n", model_source(o.run.model), rig.model().spec().name, defaults);
  text += fmt::format("run: {}, {} commands, {:.2f} s: {} points at {:g} Hz\n", run.test.description, o.run.strategy,
                      run.test.trajectory.duration(), log.log.points_T.size(), so.rate);
  const bool one_lead = (so.errors.lead_error.array() == so.errors.lead_error[0]).all();
  if (!o.real.empty())
    text += fmt::format("real platform: {} (its joints, leads, offsets, point and legs' effects)\n", printable(o.real));
  else
    text += fmt::format(
        "real platform: lead {} ({} mm), twist sign {}, zero offsets [{}] mm, point offset [{}] mm\n",
        one_lead ? fmt::format("{:+g}%", 100.0 * so.errors.lead_error[0]) : "errors [" + o.lead_error_pct + "] %",
        one_lead ? fmt::format("{:g}", 1e3 * rig.model().leg(0).lead * (1.0 + so.errors.lead_error[0]))
                 : mm_list(Vector6d(so.errors.lead_error.array() + 1.0)
                               .cwiseProduct(Vector6d::Constant(rig.model().leg(0).lead))),
        so.errors.flip_twist_sign ? "flipped" : "as modelled", mm_list(so.errors.zero_offset),
        mm_list(so.errors.observation_offset_P));
  if (o.real.empty() && (o.joint_errors_mm > 0.0 || o.axis_errors_deg > 0.0))
    text += fmt::format(
        "joints: centres off by up to {:.4f} mm (within ±{:g} mm per coordinate, no rigid part), axes turned by up to "
        "{:.3f} deg\n",
        1e3 * std::max(so.errors.base_offset_B.rowwise().norm().maxCoeff(),
                       so.errors.platform_offset_P.rowwise().norm().maxCoeff()),
        o.joint_errors_mm,
        rad2deg(std::max(so.errors.base_axis_rotation.rowwise().norm().maxCoeff(),
                         so.errors.platform_axis_rotation.rowwise().norm().maxCoeff())),
        o.axis_errors_deg);
  if (targets) text += fmt::format("targets: A and {} more, measured at every sample\n", so.extra_targets_P.size());
  text += fmt::format("tracker: origin ({:.3f}, {:.3f}, {:.3f}) m in the base frame, noise {:g} um per axis, seed {}\n",
                      origin.x(), origin.y(), origin.z(), o.noise_um, o.seed);
  text += o.run_out.empty() ? fmt::format("wrote {}, {} and {}", out, truth, real_yaml)
                            : fmt::format("wrote {}, {}, {} and the run {}", out, truth, real_yaml, o.run_out);
  if (std::isfinite(run.calibration_end))
    text += fmt::format("; measure registers on the calibration moves, t <= {:.3f} s", run.calibration_end);
  return text + "\n";
}

int run_synth(const SynthOptions& o) {
  const Config config = load_config_from(o.run.model);
  const Rig& rig = config.rig;
  const Run run = build_run(config, o.run);
  const std::string out = o.out.empty() ? fmt::format("tracker_{}.csv", run.test.name) : o.out;
  const std::filesystem::path csv(out);
  const std::string truth = (csv.parent_path() / (csv.stem().string() + ".truth.json")).string();
  const std::string real_yaml = (csv.parent_path() / (csv.stem().string() + ".real.yaml")).string();
  OutputFiles files("synth");
  files.input("--config", o.run.model.config);
  files.input("--trajectory", o.run.trajectory);
  files.input("--real", o.real);
  files.output("--out", out);
  files.output("the truth beside --out", truth);
  files.output("the real platform beside --out", real_yaml);
  files.output("--run-out", o.run_out);
  const SynthesisOptions so = synthesis_options(o, rig);
  SimulationIssue issue;
  if (const Status s = check_trajectory(rig, run.test.trajectory, issue); s != Status::Ok)
    throw ExitError(kExitOutOfLimit,
                    fmt::format("{}: t = {:.3f} s: {}; nothing was written", run.test.label, issue.time,
                                is_limit(s) ? describe(issue.limit) : std::string(describe(s))));
  SyntheticLog log;
  Status synthesized = Status::Ok;
  try {
    synthesized = synthesize(rig, run.test.trajectory, so, log, issue);
  } catch (const Error& e) {
    // The options were checked above but the rate's divisibility: name the option, not the routine.
    std::string what = e.what();
    if (what.starts_with("rate: ")) what = fmt::format("--rate {}: {}", o.rate, what.substr(6));
    throw ExitError(kExitBadInput, what);
  }
  if (const Status s = synthesized; s != Status::Ok)
    throw ExitError(kExitOutOfLimit,
                    fmt::format("{}: t = {:.3f} s: {}; nothing was written", run.test.label, issue.time,
                                is_limit(s) ? describe(issue.limit) : std::string(describe(s))));

  files.add(out, log_csv(log, !so.extra_targets_P.empty()));
  files.add(truth, truth_json(config, o, run, so, log));
  files.add(real_yaml, real_platform_yaml(o, rig.model(), so, out));
  if (!o.run_out.empty())
    files.add(o.run_out,
              format_trajectory_csv(run.test.trajectory,
                                    static_cast<std::size_t>(std::llround(rig.simulation().control_rate / so.rate))));
  files.commit();

  files.finish(summary_text(o, rig, run, so, log, out, truth, real_yaml, defaults_note(config)));
  return kExitOk;
}

}  // namespace

Command make_synth_command(CLI::App& root) {
  auto o = std::make_shared<SynthOptions>();
  CLI::App* app = root.add_subcommand(
      "synth",
      "A tracker-like point log made from the closed-loop simulation: the real platform differs from the model by "
      "known errors (joint centres and axes, leads, twist sign, zero offsets, observation point), the points of one "
      "or more targets are in a random tracker frame with Gaussian noise. Writes FILE.csv (t_s,x_mm,y_mm,z_mm; a "
      "target column with --targets-mm), FILE.truth.json (SI: the tracker frame X_BT, the errors, the real "
      "platform, the noise) and FILE.real.yaml (the real platform as a configuration: for --real and compare) "
      "beside it, all files or none; outputs naming the same file are refused (exit 2). Input for measure and "
      "identify.");
  add_run_options(*app, o->run);
  app->add_option("--noise-um", o->noise_um, "Tracker noise, standard deviation per axis [um], >= 0")
      ->capture_default_str();
  app->add_option("--rate", o->rate, "Tracker samples per second [Hz], > 0; must divide the control rate")
      ->capture_default_str();
  app->add_option("--seed", o->seed, "Seed of the tracker's placement, the noise and random offsets")
      ->capture_default_str();
  app->add_option("--lead-error-pct", o->lead_error_pct,
                  "Real lead minus nominal, in % of the nominal (the drives keep the nominal lead); one for every "
                  "leg, or six comma-separated; each in (-100, 100)")
      ->capture_default_str();
  app->add_option("--joint-errors-mm", o->joint_errors_mm,
                  "U-joint centres off by up to this in every coordinate [mm], drawn uniformly (seeded), the rigid "
                  "part per set removed (the truth is in the gauge frames)")
      ->capture_default_str();
  app->add_option("--axis-errors-deg", o->axis_errors_deg,
                  "U-joint fixed axes turned by up to this about each of the two directions across them [deg]")
      ->capture_default_str();
  app->add_option("--targets-mm", o->targets_mm,
                  "More targets on the platform, measured at every sample after A: \"x,y,z;x,y,z\" [mm, platform]; the "
                  "log gets a target column (A, T2, T3, ...)");
  app->add_option("--stiffness-n-per-um", o->stiffness_n_per_um,
                  "The real legs' axial stiffness [N/um], one or six: they shorten under the configuration's load "
                  "(default: as configured)");
  app->add_option("--play-um", o->play_um,
                  "The real legs' play (lost motion of nut and joints) [um], one or six (default: as configured)");
  auto* rise =
      app->add_option("--temperature-rise-k", o->temperature_rise_k,
                      "The legs warm by this over the run [K], one or six, along 1 - exp(-t/T) (default: no warming)");
  // Without a warming the expansion changes nothing: given alone it is refused, not ignored.
  app->add_option("--expansion-ppm-per-k", o->expansion_ppm_per_k,
                  "With --temperature-rise-k: the real legs' expansion of the length between the joints and of the "
                  "screw's lead [ppm/K] (steel: 11.5)")
      ->capture_default_str()
      ->needs(rise);
  app->add_flag("--temperature-column", o->temperature_column,
                "The log gets the machine's temperature at each point, the legs' mean [degC], as a temperature_c "
                "column: identify then fits the legs' expansion per kelvin from it");
  app->add_flag("--flip-sign", o->flip_sign, "The real twist term has the opposite sign (other thread hand)");
  app->add_option("--offsets-mm", o->offsets_mm,
                  "Zero-length offset of each leg's motor-side length [mm]: one number B draws each uniformly in "
                  "[-B, B] (seeded); six comma-separated numbers give them")
      ->capture_default_str();
  app->add_option("--point-offset-mm", o->point_offset_mm,
                  "Real minus modelled observation point, x,y,z [mm, platform]")
      ->capture_default_str();
  app->add_option("--out", o->out, "The CSV to write (default tracker_<test>.csv); the truth goes beside it");
  app->add_option("--run-out", o->run_out,
                  "Also write the commanded run as a trajectory CSV (t_s,x_m,y_m,z_m,roll_rad,pitch_rad,yaw_rad, at "
                  "the tracker rate): to drive a real platform through it (e.g. a --stations run), or as --trajectory");
  CLI::Option* real = app->add_option(
      "--real", o->real,
      "The real platform itself, a configuration (e.g. the FILE.real.yaml of an earlier synth): the log is measured "
      "on it while --config's commands drive it (a validation run of a corrected configuration); excludes the "
      "options of the real platform's errors");
  for (const char* name : {"--lead-error-pct", "--joint-errors-mm", "--axis-errors-deg", "--stiffness-n-per-um",
                           "--play-um", "--expansion-ppm-per-k", "--flip-sign", "--offsets-mm", "--point-offset-mm"})
    real->excludes(app->get_option(name));
  return {app, [o] { return run_synth(*o); }};
}

}  // namespace hexatwist::cli
