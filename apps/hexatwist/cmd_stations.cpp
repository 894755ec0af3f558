// SPDX-License-Identifier: BSD-3-Clause
// hexatwist stations: where to measure. The library plans the stations of a calibration run
// (station_plan.hpp: the Ds-optimal choice among candidates inside every limit, ordered into a run
// of reachable moves) and compares them with random stations; this command prints the plan and
// writes the run in the --run-out format (docs/theory/calibration.md §13).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "cli_common.hpp"
#include "hexatwist/io/gcode.hpp"
#include "json.hpp"
#include "output_files.hpp"
#include "schemas.hpp"

namespace hexatwist::cli {
namespace {

struct StationsOptions {
  ModelOptions model;
  int count = 0;
  std::string range = "0.25,15";
  int candidates = 3000;
  std::uint64_t seed = 1;
  std::string strategy = "compensated";
  double noise_um = 10.0;
  int points_per_station = 75;
  double rate = 100.0;
  std::string out;
  std::string gcode;       // the run as a LinuxCNC program
  std::string stream_out;  // the run as `hexatwist stream` input
  double both_sides_mm = 0.0;
  int reference_every = 0;
  bool json = false;
};

// The run as `hexatwist stream` input: one pose per control period, x,y,z [m], roll,pitch,yaw [deg].
std::string stream_input(const Trajectory& run) {
  std::string s;
  s.reserve(run.poses.size() * 64);
  for (const Pose& p : run.poses)
    s += fmt::format("{},{},{},{},{},{}\n", p.position.x(), p.position.y(), p.position.z(), rad2deg(p.rpy[0]),
                     rad2deg(p.rpy[1]), rad2deg(p.rpy[2]));
  return s;
}

// The library's spec from the options, each checked with its own name (exit 2).
StationPlanSpec plan_spec(const Model& model, const StationsOptions& o) {
  StationPlanSpec spec;
  range_option(o.range, spec.run);
  spec.run.seed = o.seed;
  // How the run visits the planned stations (run_options' --both-sides-mm and --reference-every).
  spec.run.approach = o.both_sides_mm * 1e-3;
  spec.run.reference_every = o.reference_every;
  spec.run.count = o.count;
  spec.candidates = o.candidates;
  spec.noise = o.noise_um / 1e6;  // correctly rounded: 10 um is 1e-5 m exactly as Python gives it
  spec.points_per_station = o.points_per_station;
  check_station_plan_spec(model, spec);  // the library's ranges: exit 2 naming the option (main.cpp)
  return spec;
}

// Samples of the run between rows at `rate`: the control rate over it, a whole number (exit 2).
std::size_t rows_every(const Rig& rig, double rate) {
  const double control_rate = rig.simulation().control_rate;
  const double ratio = control_rate / rate;
  check_option(
      rate > 0.0 && std::isfinite(ratio) && ratio >= 1.0 - 1e-9 && std::abs(ratio - std::round(ratio)) <= 1e-9 * ratio,
      "--rate", rate,
      fmt::format("a rate that divides the control rate {:g} Hz ({:g} Hz, {:g} Hz, ...) [Hz]", control_rate,
                  control_rate, control_rate / 2.0));
  return static_cast<std::size_t>(std::llround(ratio));
}

std::string quality_row(const std::string& label, const StationsQuality& q) {
  if (q.status != Status::Ok) return fmt::format("{:<16} do not determine the model: {}\n", label, q.reason);
  const AccuracyPrediction& a = q.accuracy;
  return fmt::format("{:<16} {:>9.2f} {:>7.2f} {:>9.3g} {:>11.1f} {:>10.1f} {:>14.2f} {:>13.2f} {:>14.2f}\n", label,
                     q.criterion, 1e6 * q.sd_geometric, q.condition, 1e6 * a.median, 1e6 * a.max,
                     1e6 * a.aligned_median, 1e6 * a.aligned_max, q.path);
}

std::string text_report(const StationsOptions& o, const Model& model, const StationPlanSpec& spec,
                        const StationPlan& plan, const Trajectory& run, const std::string& defaults) {
  std::string t = fmt::format("hexatwist stations on {}: {}{}\n", model_source(o.model), model.spec().name, defaults);
  t += fmt::format(
      "plan: {} stations within ±{:g} m and ±{:g} deg, {} commands, for the {} model ({} parameters; the tracker "
      "frame a nuisance): the Ds criterion over {} candidates inside the limits ({} drawn, seed {}), {} exchanges in "
      "{} sweeps{}\n",
      spec.run.count, spec.run.translation, rad2deg(spec.run.rotation), o.strategy,
      spec.model == CalibrationModel::Basic ? "basic" : "geometry", plan.parameters.platform_size(), plan.candidates,
      plan.draws, o.seed, plan.exchanges, plan.sweeps,
      plan.replaced > 0 ? fmt::format(", {} replaced to keep every move inside the limits", plan.replaced) : "");
  t += fmt::format("{:>7} {:>9} {:>9} {:>9} {:>11} {:>11} {:>11}\n", "station", "x [mm]", "y [mm]", "z [mm]",
                   "roll [deg]", "pitch [deg]", "yaw [deg]");
  for (std::size_t i = 0; i < plan.planned.stations.size(); ++i) {
    const Vector6d& q = plan.planned.stations[i];
    t += fmt::format("{:>7} {:>9.1f} {:>9.1f} {:>9.1f} {:>11.2f} {:>11.2f} {:>11.2f}\n", i + 1, 1e3 * tidy(q[0]),
                     1e3 * tidy(q[1]), 1e3 * tidy(q[2]), rad2deg(tidy(q[3])), rad2deg(tidy(q[4])), rad2deg(tidy(q[5])));
  }
  t += fmt::format(
      "criterion: log det of the parameters' information ({:g} um noise, {} points per station, home's two rests "
      "included); sd: their geometric-mean standard deviation; median, worst: the predicted error of point A over the "
      "range ({} poses) in the gauge frames, aligned: after a rigid re-alignment; moves: the run's path\n",
      o.noise_um, o.points_per_station, plan.planned.accuracy.poses);
  t += fmt::format("{:<16} {:>9} {:>7} {:>9} {:>11} {:>10} {:>14} {:>13} {:>14}\n", "stations", "criterion", "sd [um]",
                   "condition", "median [um]", "worst [um]", "aligned median", "aligned worst", "moves [m, rad]");
  t += quality_row("planned", plan.planned);
  t += quality_row(fmt::format("random (seed {})", o.seed), plan.random);
  t += fmt::format(
      "wrote {}: home, the {} stations{}{}, home; {:g} s at each, straight jerk-limited moves, {:.2f} s at {:g} Hz "
      "(read by synth and identify with --trajectory)\n",
      o.out, plan.planned.stations.size(),
      spec.run.approach > 0.0 ? fmt::format(" each from {:g} mm above and below", 1e3 * spec.run.approach) : "",
      spec.run.reference_every > 0 ? fmt::format(", home after every {}", spec.run.reference_every) : "",
      spec.run.dwell, run.duration(), o.rate);
  if (!o.gcode.empty())
    t += fmt::format(
        "wrote {}: the same run as a LinuxCNC program (mm, deg; each move timed as planned, G93) for hexatwistkins\n",
        o.gcode);
  if (!o.stream_out.empty())
    t += fmt::format("wrote {}: the same run as stream input, one pose per {:g} ms (hexatwist stream --rate {:g})\n",
                     o.stream_out, 1e3 * run.dt, 1.0 / run.dt);
  return t;
}

void quality_json(JsonWriter& j, const StationsQuality& q) {
  j.begin_object().field("status", q.status == Status::Ok ? "ok" : "failed");
  if (q.status != Status::Ok) {
    j.field("reason", q.reason).end_object();
    return;
  }
  j.field("criterion", q.criterion).field("sd_geometric", q.sd_geometric).field("condition", q.condition);
  j.field("path", q.path);
  const AccuracyPrediction& a = q.accuracy;
  j.key("accuracy").begin_object().field("poses", a.poses).field("median", a.median).field("max", a.max);
  j.field("aligned_median", a.aligned_median).field("aligned_max", a.aligned_max).end_object();
  j.key("sd").vector(Eigen::VectorXd(q.covariance.diagonal().cwiseSqrt()));
  j.key("stations").begin_array(true);
  for (const Vector6d& s : q.stations) j.vector(s);
  j.end_array().end_object();
}

std::string json_report(const StationsOptions& o, const Model& model, const StationPlanSpec& spec,
                        const StationPlan& plan, const Trajectory& run) {
  JsonWriter j;
  j.begin_document(schema::kStations)
      .field("command", "stations")
      .field("model", model.spec().name)
      .field("config", model_source(o.model));
  j.field("strategy", o.strategy).field("count", spec.run.count);
  j.key("range").begin_array().value(spec.run.translation).value(spec.run.rotation).end_array();
  j.field("seed", o.seed).field("candidates", plan.candidates).field("draws", plan.draws);
  j.field("noise", spec.noise).field("points_per_station", spec.points_per_station);
  j.field("sweeps", plan.sweeps).field("exchanges", plan.exchanges).field("converged", plan.converged);
  j.field("replaced", plan.replaced);
  j.key("parameters").begin_array();
  for (int k = 0; k < plan.parameters.platform_size(); ++k) j.value(plan.parameters.name(k));
  j.end_array();
  j.key("planned");
  quality_json(j, plan.planned);
  j.key("random");
  quality_json(j, plan.random);
  j.key("run").begin_object().field("out", o.out).field("rate", o.rate).field("duration", run.duration());
  j.field("dwell", spec.run.dwell).field("approach", spec.run.approach);
  j.field("reference_every", spec.run.reference_every);
  j.field("gcode", o.gcode).field("stream_out", o.stream_out).end_object();
  return j.end_object().str();
}

int run_stations(const StationsOptions& o) {
  OutputFiles files("stations");
  files.input("--config", o.model.config);
  files.output("--out", o.out);
  files.output("--gcode", o.gcode);
  files.output("--stream-out", o.stream_out);
  const Config config = load_config_from(o.model);
  const Model& model = config.rig.model();
  const Strategy strategy = strategy_option(o.strategy);
  const StationPlanSpec spec = plan_spec(model, o);
  const std::size_t every = rows_every(config.rig, o.rate);
  StationPlan plan;
  if (plan_stations(model, strategy, spec, plan) != Status::Ok)
    throw ExitError(kExitOutOfLimit, fmt::format("{}; nothing was written", plan.reason));
  Trajectory run;
  try {
    run = station_run(model, strategy, plan.planned.stations, spec.run, config.rig.control_period());
  } catch (const Error& e) {
    throw ExitError(kExitOutOfLimit, fmt::format("the planned run: {}; nothing was written", e.what()));
  }
  files.add(o.out, format_trajectory_csv(run, every));
  if (!o.gcode.empty()) {
    std::vector<Vector6d> waypoints{Vector6d::Zero()};
    waypoints.insert(waypoints.end(), plan.planned.stations.begin(), plan.planned.stations.end());
    waypoints.push_back(Vector6d::Zero());
    files.add(o.gcode, waypoint_program(model, waypoints, spec.run.limits, spec.run.dwell,
                                        fmt::format("stations --count {} --seed {} on {}: the run of {}", o.count,
                                                    o.seed, model_source(o.model), o.out)));
  }
  if (!o.stream_out.empty()) files.add(o.stream_out, stream_input(run));
  files.commit();
  files.finish(o.json ? json_report(o, model, spec, plan, run)
                      : text_report(o, model, spec, plan, run, defaults_note(config)));
  return kExitOk;
}

}  // namespace

Command make_stations_command(CLI::App& root) {
  auto o = std::make_shared<StationsOptions>();
  CLI::App* app = root.add_subcommand(
      "stations",
      "Where to measure: plans the stations of a calibration run so that identify determines the platform best. "
      "From seeded candidate poses inside every limit it chooses --count stations that maximise the Ds criterion "
      "(the log determinant of the geometric model's information, the tracker frame a nuisance) by an exchange "
      "algorithm, orders them into a run of short straight moves that stay inside the limits, prints them with the "
      "criterion and the predicted accuracy beside random stations of the same count (synth --stations), and writes "
      "the run as a trajectory CSV (the --run-out format: drive the platform through it, or give it to synth and "
      "identify as --trajectory). Exit 3 when the ranges leave too few poses inside the limits.");
  add_model_options(*app, o->model);
  app->add_option("--count", o->count, "Stations, not counting home at the start and the end")->required();
  app->add_option("--range", o->range,
                  "X_M,ROT_DEG: candidates within ±X_M of home in x, y, z [m] and ±ROT_DEG in roll, pitch, yaw [deg]")
      ->capture_default_str();
  app->add_option("--candidates", o->candidates, "Candidate poses to choose from (at least --count)")
      ->capture_default_str();
  app->add_option("--seed", o->seed,
                  "Seed of the candidates and of the random stations compared (synth --station-seed)")
      ->capture_default_str();
  app->add_option("--strategy", o->strategy, "The commands the platform runs: conventional or compensated")
      ->check(CLI::IsMember({"conventional", "compensated"}))
      ->capture_default_str();
  app->add_option("--noise-um", o->noise_um,
                  "The tracker's noise per axis [um], for the predicted accuracy (the choice does not depend on it)")
      ->capture_default_str();
  app->add_option(
         "--points-per-station", o->points_per_station,
         "Points at rest per station (1 s at 100 Hz less identify's 0.25 s settle), for the predicted accuracy")
      ->capture_default_str();
  app->add_option("--rate", o->rate, "Rows of the run per second [Hz]; must divide the control rate")
      ->capture_default_str();
  app->add_option("--both-sides-mm", o->both_sides_mm,
                  "The run approaches each station from both sides, from this far above it along z (every leg "
                  "shortening) and then below (lengthening), for identify's play [mm], 0 to 50; a side outside the "
                  "limits is left out")
      ->check(CLI::Range(0.0, kMaxApproach * 1e3));
  app->add_option("--reference-every", o->reference_every,
                  "The run visits home again after every N stations, a reference repeated for identify's heat")
      ->check(CLI::Range(1, 10000));
  app->add_option("--out", o->out, "The run to write (t_s,x_m,y_m,z_m,roll_rad,pitch_rad,yaw_rad)")->required();
  app->add_option("--gcode", o->gcode,
                  "Also write the run as a LinuxCNC G-code program for hexatwistkins (X Y Z mm, Z absolute; A B C "
                  "deg): the same stations and times, each move timed with G93, a dwell at each station");
  app->add_option("--stream-out", o->stream_out,
                  "Also write the run as hexatwist stream input: one pose per control period, x,y,z [m], "
                  "roll,pitch,yaw [deg]");
  app->add_flag("--json", o->json, "Print the plan as JSON (SI units)");
  return {app, [o] { return run_stations(*o); }};
}

}  // namespace hexatwist::cli
