// hexatwist synth / measure / identify: a tracker-like point log made from the simulation of a
// platform with known parameter errors; a point log (real or synthetic) registered, evaluated and
// reported beside the simulation of the same run, as the paper's experiment (§5, Table 1); and the
// lead, twist sign, leg offsets and observation point identified from it, written as a corrected
// configuration (docs/theory.md §12-13).
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
#include "study_report.hpp"

namespace hexatwist::cli {
namespace {

// What both commands run: a study test after the calibration moves, or a trajectory file.
struct RunOptions {
  ModelOptions model;
  std::string test;
  std::string trajectory;
  int stations = 0;
  std::uint64_t station_seed = 1;
  std::string strategy = "compensated";
};

Strategy strategy_of(const RunOptions& o) {
  return o.strategy == "conventional" ? Strategy::Conventional : Strategy::Compensated;
}

// The run to report, the commanded poses as given, and where the calibration moves end (NaN for a
// trajectory file: its calibration is the user's).
struct Run {
  ReportedTest test;
  TimedPoses commanded;
  double calibration_end = std::numeric_limits<double>::quiet_NaN();
};

Run build_run(const Config& config, const RunOptions& o) {
  if (int{!o.test.empty()} + int{!o.trajectory.empty()} + int{o.stations > 0} != 1)
    throw ExitError(kExitBadInput, "give one of --test NAME (Lz, Lx, Rz or Ry), --trajectory FILE.csv or --stations N");
  Run run;
  const double dt = config.rig.control_period();
  if (!o.trajectory.empty()) {
    run.test = reported_trajectory_file(o.trajectory, dt, &run.commanded);
    return run;
  }
  if (o.stations > 0) {
    StationsSpec spec;
    spec.count = o.stations;
    spec.seed = o.station_seed;
    try {
      run.test.trajectory = stations_trajectory(config.rig.model(), strategy_of(o), spec, dt);
    } catch (const Error& e) {
      throw ExitError(kExitOutOfLimit, fmt::format("--stations: {}", e.what()));
    }
    run.test.name = fmt::format("stations{}", o.stations);
    run.test.label = fmt::format("{} stations", o.stations);
    run.test.description =
        fmt::format("{} random stations (seed {}), {:g} s at each", o.stations, o.station_seed, spec.dwell);
    run.commanded = timed_poses(run.test.trajectory);
    return run;
  }
  for (const StudyTest& t : seed_tests(config.study)) {
    if (t.name != o.test) continue;
    run.test = reported_test(t);
    run.test.description += ", after the calibration moves";
    run.test.trajectory = measured_test_trajectory(config.study, t, CalibrationSpec{}, dt, run.calibration_end);
    run.commanded = timed_poses(run.test.trajectory);
    return run;
  }
  throw ExitError(kExitBadInput,
                  fmt::format("--test: unknown test '{}'; expected Lz, Lx, Rz or Ry", printable(o.test)));
}

void add_run_options(CLI::App& app, RunOptions& o) {
  add_model_options(app, o.model);
  auto* test = app.add_option("--test", o.test,
                              "One of the paper's tests, Lz, Lx, Rz or Ry (the study's motion), after calibration "
                              "moves: home, +0.2 m along x, y and z, home, 1 s at each station");
  auto* trajectory =
      app.add_option("--trajectory", o.trajectory, "Or a trajectory CSV file, as for simulate: t,x,y,z,roll,pitch,yaw");
  auto* stations = app.add_option(
      "--stations", o.stations,
      "Or a calibration run for identify: home, N random stations (+-0.25 m, +-15 deg in every coordinate at once, "
      "each reachable inside the limits), home; 1 s at each, straight jerk-limited moves");
  app.add_option("--station-seed", o.station_seed, "Seed of the stations (the same seed gives the same run)")
      ->capture_default_str();
  test->excludes(trajectory);
  test->excludes(stations);
  trajectory->excludes(stations);
  stations->check(CLI::Range(1, 10000));
  app.add_option("--strategy", o.strategy, "The commands the platform runs: conventional or compensated")
      ->check(CLI::IsMember({"conventional", "compensated"}))
      ->capture_default_str();
}

// ---- synth ----------------------------------------------------------------------------------------

struct SynthOptions {
  RunOptions run;
  double noise_um = 10.0;
  double rate = 100.0;
  std::uint64_t seed = 1;
  double lead_error_pct = 0.0;
  bool flip_sign = false;
  std::string offsets_mm = "0";
  std::string point_offset_mm = "0,0,0";
  std::string out;
  std::string run_out;
};

// The commanded run as a trajectory CSV that parse_trajectory_csv reads back (SI suffixes), one
// row every `every` ticks and the last tick: a real platform can be driven through it, and
// measure and identify take it as --trajectory. Rests stay exact (the interpolation is flat
// between equal samples), so the same points count as at rest.
std::string trajectory_csv(const Trajectory& trajectory, std::size_t every) {
  fmt::memory_buffer b;
  fmt::format_to(std::back_inserter(b), "t_s,x_m,y_m,z_m,roll_rad,pitch_rad,yaw_rad\n");
  const std::size_t last = trajectory.poses.size() - 1;
  for (std::size_t k = 0;; k = std::min(k + every, last)) {
    const Vector6d q = trajectory.poses[k].to_vector();
    fmt::format_to(std::back_inserter(b), "{},{},{},{},{},{},{}\n", trajectory.time(k), q[0], q[1], q[2], q[3], q[4],
                   q[5]);
    if (k == last) break;
  }
  return fmt::to_string(b);
}

std::string truth_json(const Config& config, const SynthOptions& o, const Run& run, const SynthesisOptions& so,
                       const SyntheticLog& log) {
  const Model& model = config.rig.model();
  JsonWriter j;
  j.begin_object()
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
  j.field("lead_error", so.errors.lead_error)
      .field("lead_nominal", model.leg(0).lead)
      .field("lead_real", model.leg(0).lead * (1.0 + so.errors.lead_error))
      .field("flip_twist_sign", so.errors.flip_twist_sign)
      .field("twist_sign_nominal", model.leg(0).twist_sign)
      .field("twist_sign_real", so.errors.flip_twist_sign ? -model.leg(0).twist_sign : model.leg(0).twist_sign);
  j.key("zero_offset").vector(so.errors.zero_offset);
  j.key("observation_offset_P").vector(so.errors.observation_offset_P);
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

int run_synth(const SynthOptions& o) {
  const Config config = load_config_from(o.run.model);
  const Rig& rig = config.rig;
  const Run run = build_run(config, o.run);
  const std::string out = o.out.empty() ? fmt::format("tracker_{}.csv", run.test.name) : o.out;
  const std::filesystem::path csv(out);
  const std::string truth = (csv.parent_path() / (csv.stem().string() + ".truth.json")).string();
  check_distinct_outputs({{"--out", out}, {"the truth beside --out", truth}, {"--run-out", o.run_out}});
  // Finite but absurd values are refused too: a noise, an offset or a point error as large as the
  // whole stroke leaves nothing in the log to measure or identify.
  const double stroke_um = 1e6 * (rig.model().spec().limits.length_max - rig.model().spec().limits.length_min);
  check_option(o.noise_um >= 0.0, "--noise-um", o.noise_um, "a standard deviation >= 0 [um]");
  check_option(o.noise_um < stroke_um, "--noise-um", o.noise_um,
               fmt::format("a standard deviation below the stroke ({:g} um, limits.length_max - limits.length_min): "
                           "this one would drown every motion",
                           stroke_um));
  check_option(o.rate > 0.0, "--rate", o.rate, "a sample rate > 0 [Hz]");
  check_option(o.lead_error_pct > -100.0 && o.lead_error_pct < 1e4, "--lead-error-pct", o.lead_error_pct,
               "a lead error above -100 % (-100 % is a zero lead) and below 1e4 %");
  SynthesisOptions so;
  so.strategy = strategy_of(o.run);
  so.noise = o.noise_um / 1e6;
  so.rate = o.rate;
  so.seed = o.seed;
  so.errors.lead_error = o.lead_error_pct / 100.0;
  so.errors.flip_twist_sign = o.flip_sign;
  if (o.offsets_mm.find(',') == std::string::npos) {
    const double bound = parse_numbers(o.offsets_mm, 1, "--offsets-mm", "a bound [mm], or six offsets [mm]")[0];
    check_option(bound >= 0.0, "--offsets-mm", bound, "a bound >= 0 [mm], or six offsets [mm]");
    check_option(bound < 1e-3 * stroke_um, "--offsets-mm", bound,
                 fmt::format("a bound below the stroke ({:g} mm) [mm]", 1e-3 * stroke_um));
    so.errors.zero_offset = random_zero_offsets(bound / 1e3, o.seed);
  } else
    for (int i = 0;
         const double v : parse_numbers(o.offsets_mm, 6, "--offsets-mm", "a bound [mm], or six offsets [mm]")) {
      check_option(std::abs(v) < 1e-3 * stroke_um, "--offsets-mm", v,
                   fmt::format("offsets below the stroke ({:g} mm) in magnitude [mm]", 1e-3 * stroke_um));
      so.errors.zero_offset[i++] = v / 1e3;
    }
  const std::vector<double> point = parse_numbers(o.point_offset_mm, 3, "--point-offset-mm", "x,y,z [mm]");
  for (const double v : point)
    check_option(std::abs(v) < 1e-3 * stroke_um, "--point-offset-mm", v,
                 fmt::format("offsets below the stroke ({:g} mm) in magnitude [mm]", 1e-3 * stroke_um));
  so.errors.observation_offset_P = Vector3d(point[0], point[1], point[2]) / 1e3;

  SimulationIssue issue;
  if (const Status s = check_trajectory(rig, run.test.trajectory, issue); s != Status::Ok)
    throw ExitError(kExitOutOfLimit,
                    fmt::format("{}: t = {:.3f} s: {}; nothing was written", run.test.label, issue.time,
                                is_limit(s) ? describe_limit(issue.limit) : std::string(describe(s))));
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
                                is_limit(s) ? describe_limit(issue.limit) : std::string(describe(s))));

  // Like a tracker's export: millimetres with a unit suffix, 1 nm resolution (noise-free logs stay exact enough).
  fmt::memory_buffer b;
  fmt::format_to(std::back_inserter(b), "t_s,x_mm,y_mm,z_mm\n");
  for (std::size_t k = 0; k < log.log.points_T.size(); ++k) {
    const Vector3d p = 1e3 * log.log.points_T[k];
    fmt::format_to(std::back_inserter(b), "{:.6f},{:.6f},{:.6f},{:.6f}\n", log.log.stamps[k], p.x(), p.y(), p.z());
  }
  OutputSet files;
  files.add(out, fmt::to_string(b));
  files.add(truth, truth_json(config, o, run, so, log));
  if (!o.run_out.empty())
    files.add(o.run_out,
              trajectory_csv(run.test.trajectory,
                             static_cast<std::size_t>(std::llround(rig.simulation().control_rate / so.rate))));
  files.commit();

  const Vector3d& origin = log.X_BT.t;
  std::string text = fmt::format("hexatwist synth on {}: {}\n", model_source(o.run.model), rig.model().spec().name);
  text += fmt::format("run: {}, {} commands, {:.2f} s: {} points at {:g} Hz\n", run.test.description, o.run.strategy,
                      run.test.trajectory.duration(), log.log.points_T.size(), so.rate);
  text +=
      fmt::format("real platform: lead {:+g}% ({:g} mm), twist sign {}, zero offsets [{}] mm, point offset [{}] mm\n",
                  o.lead_error_pct, 1e3 * rig.model().leg(0).lead * (1.0 + so.errors.lead_error),
                  so.errors.flip_twist_sign ? "flipped" : "as modelled", mm_list(so.errors.zero_offset),
                  mm_list(so.errors.observation_offset_P));
  text += fmt::format("tracker: origin ({:.3f}, {:.3f}, {:.3f}) m in the base frame, noise {:g} um per axis, seed {}\n",
                      origin.x(), origin.y(), origin.z(), o.noise_um, o.seed);
  text += o.run_out.empty() ? fmt::format("wrote {} and {}", out, truth)
                            : fmt::format("wrote {}, {} and the run {}", out, truth, o.run_out);
  if (std::isfinite(run.calibration_end))
    text += fmt::format("; measure registers on the calibration moves, t <= {:.3f} s", run.calibration_end);
  write_stdout_or_withdraw(text + "\n", files.paths());
  return kExitOk;
}

// ---- measure --------------------------------------------------------------------------------------

// How to read a point log and place it in the run's time (measure and identify).
struct LogOptions {
  std::string points;
  std::string columns = "t,x,y,z";
  std::string units;
  bool index = false;
  double rate = 0.0;
  double time_offset = 0.0;
};

void add_log_options(CLI::App& app, LogOptions& o) {
  app.add_option("--points", o.points, "The point log (CSV with a header row)")->required();
  app.add_option("--columns", o.columns,
                 "Header names of the time (or index), x, y and z columns; case ignored, a unit suffix allowed "
                 "(_s, _ms; _m, _mm)")
      ->capture_default_str();
  app.add_option("--units", o.units, "Length unit of x, y, z when their names carry no suffix: mm or m")
      ->check(CLI::IsMember({"mm", "m"}));
  app.add_flag("--index", o.index, "The time column is a sample index; give --rate");
  app.add_option("--rate", o.rate, "Samples per second of an indexed log [Hz]");
  app.add_option("--time-offset", o.time_offset, "The log's time (or index/rate) when the trajectory's time is 0 [s]")
      ->capture_default_str();
}

struct MeasureOptions {
  RunOptions run;
  LogOptions log;
  std::string out = "measure-out";
  double register_until = std::numeric_limits<double>::quiet_NaN();
  std::size_t register_first = 0;
  double settle = 0.25;
  bool no_figures = false;
  bool no_csv = false;
};

// The log's format, its time alignment and the log itself; bad options or a bad file become
// ExitError(2) with one line.
PointLogFormat log_format(const LogOptions& o) {
  check_option(true, "--time-offset", o.time_offset, "a time [s]");
  PointLogFormat f;
  std::vector<std::string> names;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t comma = o.columns.find(',', begin);
    names.push_back(o.columns.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin));
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  if (names.size() != 4 || std::find(names.begin(), names.end(), std::string()) != names.end())
    throw ExitError(
        kExitBadInput,
        fmt::format("--columns: expected four column names (time or index, x, y, z), got '{}'", printable(o.columns)));
  // Two names for one column would read it twice (x as y): every column once. Case and unit
  // suffix are ignored when matching, so compare the bare names.
  const auto bare = [](std::string n) {
    std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    for (const char* suffix : {"_ms", "_mm", "_s", "_m"})
      if (n.size() > std::string_view(suffix).size() && n.ends_with(suffix)) {
        n.resize(n.size() - std::string_view(suffix).size());
        break;
      }
    return n;
  };
  for (std::size_t a = 0; a < names.size(); ++a)
    for (std::size_t b = a + 1; b < names.size(); ++b)
      if (bare(names[a]) == bare(names[b]))
        throw ExitError(kExitBadInput, fmt::format("--columns: '{}' and '{}' name the same column; expected four "
                                                   "different columns (time or index, x, y, z)",
                                                   printable(names[a]), printable(names[b])));
  f.time_column = names[0];
  f.x_column = names[1];
  f.y_column = names[2];
  f.z_column = names[3];
  if (!o.units.empty()) f.length_unit = o.units == "mm" ? 1e-3 : 1.0;
  f.indexed = o.index;
  if (o.index && !(o.rate > 0.0 && std::isfinite(o.rate)))
    throw ExitError(kExitBadInput, "--index: give the tracker's sample rate with --rate HZ");
  if (!o.index && o.rate != 0.0) throw ExitError(kExitBadInput, "--rate: only with --index (a log of sample indices)");
  return f;
}

PointLog read_point_log(const LogOptions& o, const PointLogFormat& format) {
  const std::string text = read_text_file(o.points, "--points", "point log");
  try {
    return parse_point_log(text, o.points, format);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
}

int run_measure(const MeasureOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = load_config_from(o.run.model);
  const Rig& rig = config.rig;
  const PointLogFormat format = log_format(o.log);
  Run run = build_run(config, o.run);

  check_option(o.settle >= 0.0, "--settle", o.settle, "a time >= 0 [s]");
  check_option(o.settle < run.test.trajectory.duration(), "--settle", o.settle,
               fmt::format("a time shorter than the run ({:g} s): no point can be still for longer [s]",
                           run.test.trajectory.duration()));
  if (!std::isnan(o.register_until)) check_option(true, "--register-until", o.register_until, "a time [s]");
  MeasurementOptions mo;
  mo.strategy = strategy_of(o.run);
  mo.time = {o.log.time_offset, o.log.rate};
  mo.window.settle = o.settle;
  std::string window;
  if (o.register_first > 0) {
    mo.window.first = o.register_first;
    window = fmt::format("the first {} points", o.register_first);
  } else if (std::isfinite(o.register_until)) {
    mo.window.until = o.register_until;
    window = fmt::format("t <= {:g} s", o.register_until);
  } else if (std::isfinite(run.calibration_end)) {
    mo.window.until = run.calibration_end;
    window = "the calibration moves";
  } else {
    throw ExitError(kExitBadInput,
                    "--register-until SECONDS or --register-first N: which points register the tracker frame? (with "
                    "--test, the calibration moves do)");
  }
  const PointLog log = read_point_log(o.log, format);
  ReportedMeasurement measured;
  try {
    measured.measurement = measure_points(rig.model(), run.commanded, log, mo);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
  // A point farther from the commanded position than a whole leg is long is not a point of this
  // run (a typing or export error): its error would be meaningless and swamp the statistics.
  {
    const Measurement& mm = measured.measurement;
    const double absurd = rig.model().spec().limits.length_max;
    for (std::size_t k = mm.window; k < mm.points.size(); ++k) {
      const double e = mm.points[k].error_B.norm();
      if (!(e <= absurd))
        throw ExitError(kExitBadInput,
                        fmt::format("--points: {}: line {}: the point is {:.4g} m from where the run puts it, more "
                                    "than a leg's maximum length ({} m): not a point of this run",
                                    printable(o.log.points), mm.points[k].line, e, absurd));
    }
  }
  measured.source = o.log.points;
  measured.strategy = mo.strategy;
  measured.window = window;

  std::vector<ReportedTest> tests{std::move(run.test)};
  const ReportOptions ro{o.out, "measure", model_source(o.run.model), !o.no_figures, !o.no_csv};
  // After the simulation: the part after the registration window, as the measurement is evaluated.
  const auto compare = [&](std::vector<ReportedTest>& ts) {
    ReportedTest& t = ts[0];
    const Measurement& m = measured.measurement;
    keep_after(t.run, m.window_end);
    std::size_t drop = 0;
    while (drop < t.trajectory.poses.size() && t.trajectory.time(drop) <= m.window_end) ++drop;
    t.trajectory.t0 = t.trajectory.time(drop);
    t.trajectory.poses.erase(t.trajectory.poses.begin(),
                             t.trajectory.poses.begin() + static_cast<std::ptrdiff_t>(drop));
    const StrategyRun& sim = mo.strategy == Strategy::Compensated ? t.run.compensated : t.run.conventional;
    measured.simulated = simulated_errors(sim.samples, m);
    measured.simulated_stats = error_stats(measured.simulated);
    const Registration& reg = m.registration;
    const MeasuredPoint& worst = m.points[m.registered[static_cast<std::size_t>(reg.max_residual_index)]];
    std::string s = fmt::format("points: {}: {} points, t = {:.3f} to {:.3f} s; {} commands\n", printable(o.log.points),
                                m.points.size(), m.points.front().time, m.points.back().time, o.run.strategy);
    s += fmt::format(
        "registration: on the {} points at rest among the {} of {} (t <= {:.3f} s): rms residual {:.4f} mm, largest "
        "{:.4f} mm (line {}), noise {:.4f} mm per axis, condition {:.3g}\n",
        reg.count, m.window, window, m.window_end, 1e3 * reg.rms_residual, 1e3 * reg.max_residual, worst.line,
        1e3 * reg.sigma, reg.condition);
    s += fmt::format("evaluated: the {} points after the window, against the simulation of the same run\n",
                     m.points.size() - m.window);
    t.measured = std::move(measured);
    return s;
  };
  simulate_and_report(rig, ro, tests, start, compare);
  return kExitOk;
}

// ---- identify -------------------------------------------------------------------------------------

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
                                      : read_text_file(o.run.model.config, "--config", "config file");
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
    write_output_file(o.out, yaml);
  } catch (const ExitError& e) {
    fail(e, status);
  }
  if (o.json) {
    write_stdout_or_withdraw(identify_json(model, o, set, log, id, status, true, std::string()) + "\n", {o.out});
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
  write_stdout_or_withdraw(text + "\n", {o.out});
  return kExitOk;
}

}  // namespace

Command make_synth_command(CLI::App& root) {
  auto o = std::make_shared<SynthOptions>();
  CLI::App* app = root.add_subcommand(
      "synth",
      "A tracker-like point log made from the closed-loop simulation: the real platform differs from the model by "
      "known errors (lead, twist sign, zero offsets, observation point), the points are in a random tracker frame "
      "with Gaussian noise. Writes FILE.csv (t_s,x_mm,y_mm,z_mm) and FILE.truth.json (SI: the tracker frame X_BT, the "
      "errors, the noise) beside it, all files or none; outputs naming the same file are refused (exit 2). Input for "
      "measure.");
  add_run_options(*app, o->run);
  app->add_option("--noise-um", o->noise_um, "Tracker noise, standard deviation per axis [um], >= 0")
      ->capture_default_str();
  app->add_option("--rate", o->rate, "Tracker samples per second [Hz], > 0; must divide the control rate")
      ->capture_default_str();
  app->add_option("--seed", o->seed, "Seed of the tracker's placement, the noise and random offsets")
      ->capture_default_str();
  app->add_option("--lead-error-pct", o->lead_error_pct,
                  "Real lead minus nominal, in % of the nominal; above -100 (a zero lead)")
      ->capture_default_str();
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
  return {app, [o] { return run_synth(*o); }};
}

Command make_measure_command(CLI::App& root) {
  auto o = std::make_shared<MeasureOptions>();
  CLI::App* app = root.add_subcommand(
      "measure",
      "A laser tracker's point log of the observation point, processed as the paper's experiment: aligned in time "
      "with the commanded trajectory, the tracker frame registered (Kabsch/Umeyama) on the points at rest in a window "
      "(the calibration moves with --test), the observation-point errors of the points after it, beside the "
      "simulation of the same run: the study's table, summary.json/.md, CSVs and figures, written as a set (all or "
      "none, "
      "exit 4). Two --columns names for one column, or a point farther from the run than a leg is long, is exit 2.");
  add_log_options(*app, o->log);
  add_run_options(*app, o->run);
  app->add_option("--out", o->out, "Output folder (created if missing)")->capture_default_str();
  auto* until =
      app->add_option("--register-until", o->register_until,
                      "Register on the points with t <= SECONDS (default with --test: the calibration moves)");
  auto* first = app->add_option("--register-first", o->register_first, "Or on the first N points of the log");
  until->excludes(first);
  app->add_option("--settle", o->settle,
                  "Of those, only points whose commanded pose has been still for this long [s]; 0 = all")
      ->capture_default_str();
  app->add_flag("--no-figures", o->no_figures, "Skip the PNG/SVG figures (gnuplot)");
  app->add_flag("--no-csv", o->no_csv, "Skip the per-tick CSVs of the simulation (the measured points' CSV is kept)");
  return {app, [o] { return run_measure(*o); }};
}

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
