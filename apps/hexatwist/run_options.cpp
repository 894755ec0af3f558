// SPDX-License-Identifier: BSD-3-Clause
#include "run_options.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

namespace hexatwist::cli {

Strategy strategy_of(const RunOptions& o) { return strategy_option(o.strategy); }

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
    spec.approach = o.both_sides_mm * 1e-3;
    spec.reference_every = o.reference_every;
    try {
      run.test.trajectory = stations_trajectory(config.rig.model(), strategy_of(o), spec, dt);
    } catch (const ParameterError& e) {
      // The library's check (check_stations_spec) names the field: here, the run option that set it.
      const std::string& f = e.parameter();
      const char* option = f == "count"             ? "--stations"
                           : f == "approach"        ? "--both-sides-mm"
                           : f == "reference_every" ? "--reference-every"
                                                    : "--stations";
      throw ExitError(kExitBadInput, fmt::format("{}: {}", option, e.what()));
    } catch (const Error& e) {
      throw ExitError(kExitOutOfLimit, fmt::format("--stations: {}", e.what()));
    }
    run.test.name = fmt::format("stations{}", o.stations);
    run.test.label = fmt::format("{} stations", o.stations);
    run.test.description = fmt::format(
        "{} random stations (seed {}){}{}, {:g} s at each", o.stations, o.station_seed,
        spec.approach > 0.0 ? fmt::format(", each from {:g} mm above and below", o.both_sides_mm) : "",
        spec.reference_every > 0 ? fmt::format(", home after every {}", spec.reference_every) : "", spec.dwell);
    run.commanded = timed_poses(run.test.trajectory);
    return run;
  }
  StudyTest t;
  try {
    t = study_test(config.study, o.test);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, fmt::format("--test: {}", e.what()));
  }
  run.test = reported_test(t);
  run.test.description += ", after the calibration moves";
  run.test.trajectory = measured_test_trajectory(config.study, t, CalibrationSpec{}, dt, run.calibration_end);
  run.commanded = timed_poses(run.test.trajectory);
  return run;
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
  app.add_option("--station-seed", o.station_seed,
                 "With --stations: the seed of the stations (the same seed gives the same run)")
      ->capture_default_str()
      ->needs(stations);
  auto* both = app.add_option("--both-sides-mm", o.both_sides_mm,
                              "With --stations: each station approached from both sides, from this far above it along "
                              "z (every leg shortening) and then below (lengthening), for identify's play [mm], "
                              "0 to 50; a side outside the limits is left out");
  auto* every = app.add_option("--reference-every", o.reference_every,
                               "With --stations: home again after every N stations, a reference repeated through the "
                               "run for identify's heat (where the moves stay inside the limits)");
  both->needs(stations);
  every->needs(stations);
  both->check(CLI::Range(0.0, kMaxApproach * 1e3));
  every->check(CLI::Range(1, 10000));
  test->excludes(trajectory);
  test->excludes(stations);
  trajectory->excludes(stations);
  stations->check(CLI::Range(1, 10000));
  app.add_option("--strategy", o.strategy, "The commands the platform runs: conventional or compensated")
      ->check(CLI::IsMember({"conventional", "compensated"}))
      ->capture_default_str();
}

void add_log_options(CLI::App& app, LogOptions& o) {
  app.add_option("--points", o.points, "The point log (CSV with a header row)")->required();
  app.add_option("--columns", o.columns,
                 "Header names of the time (or index), x, y and z columns; case ignored, a unit suffix allowed "
                 "(_s, _ms; _m, _mm)")
      ->capture_default_str();
  app.add_option("--units", o.units, "Length unit of x, y, z when their names carry no suffix: mm or m")
      ->check(CLI::IsMember({"mm", "m"}));
  app.add_flag("--index", o.index, "The time column is a sample index; give --rate");
  app.add_option("--rate", o.rate, "Samples per second of an indexed log [Hz]")->each([&o](const std::string&) {
    o.rate_given = true;
  });
  app.add_option("--temperature-column", o.temperature_column,
                 "Header name of the machine's temperature column [degC] (a _c suffix allowed); default: a column "
                 "named temperature or temperature_c, if any. With it, identify's heat fits each leg's expansion per "
                 "kelvin and the lead's, and the corrected configuration keeps them");
  app.add_option("--time-offset", o.time_offset,
                 "The log's time (or index/rate) when the trajectory's time is 0 [s], or auto: found with the log's "
                 "clock rate from the rests of the run and of the log (a log that starts whenever the tracker was "
                 "started)")
      ->capture_default_str();
}

namespace {

// --time-offset as a number, or NaN for auto; ExitError(2) for anything else.
double offset_of(const LogOptions& o) {
  if (o.time_offset == "auto") return std::numeric_limits<double>::quiet_NaN();
  double v = 0.0;
  const char* b = o.time_offset.data();
  const char* e = b + o.time_offset.size();
  const auto [ptr, ec] = std::from_chars(b, e, v);
  if (ec != std::errc() || ptr != e || !std::isfinite(v))
    throw ExitError(kExitBadInput,
                    fmt::format("--time-offset '{}': expected a time [s] or auto", printable(o.time_offset)));
  return v;
}

}  // namespace

TimeAlignment log_alignment(const LogOptions& o, const Run& run, PointLog& log, ClockFit& fit, std::size_t& dropped) {
  fit = ClockFit{};
  dropped = 0;
  const double offset = offset_of(o);
  if (!std::isnan(offset)) {
    fit.offset = offset;
    return {offset, o.rate, 1.0};
  }
  try {
    if (fit_log_clock(run.commanded, log, {0.0, o.rate, 1.0}, ClockFitOptions{}, fit) != Status::Ok)
      throw ExitError(kExitBadInput, fmt::format("--time-offset auto: {}", fit.reason));
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, fmt::format("--time-offset auto: {}", e.what()));
  }
  const TimeAlignment alignment = fit.alignment(o.rate);
  // The points outside the run: recorded before it started or after it ended.
  const std::vector<double> t = trajectory_times(log, alignment);
  const double front = run.commanded.t.front(), back = run.commanded.t.back();
  PointLog kept = log;
  kept.stamps.clear(), kept.points_T.clear(), kept.targets.clear(), kept.lines.clear(), kept.stamp_columns.clear();
  kept.temperatures.clear();
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (!(t[k] >= front && t[k] <= back)) {
      ++dropped;
      continue;
    }
    kept.stamps.push_back(log.stamps[k]);
    kept.points_T.push_back(log.points_T[k]);
    if (k < log.targets.size()) kept.targets.push_back(log.targets[k]);
    kept.lines.push_back(log.lines[k]);
    if (k < log.stamp_columns.size()) kept.stamp_columns.push_back(log.stamp_columns[k]);
    if (k < log.temperatures.size()) kept.temperatures.push_back(log.temperatures[k]);
  }
  log = std::move(kept);
  return alignment;
}

std::string clock_line(const ClockFit& fit, const LogOptions& o, std::size_t dropped) {
  if (fit.matched == 0) return {};
  return fmt::format(
      "the log's clock (--time-offset {}): t_log = {:.4f} s ± {:.4f} + {:.7f} ± {:.7f} x t_run, from {} of its {} "
      "rests matched to the run's {} (from the run's rest {} on), worst misfit {:.4f} s; {} points outside the run "
      "left out\n",
      o.time_offset, fit.offset, fit.offset_sd, fit.scale, fit.scale_sd, fit.matched, fit.log_rests, fit.run_rests,
      fit.first + 1, fit.worst, dropped);
}

PointLogFormat log_format(const LogOptions& o) {
  (void)offset_of(o);
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
  f.temperature_column = o.temperature_column;
  if (!o.units.empty()) f.length_unit = o.units == "mm" ? 1e-3 : 1.0;
  f.indexed = o.index;
  if (o.index && !o.rate_given)
    throw ExitError(kExitBadInput, "--index: give the tracker's sample rate with --rate HZ");
  if (o.index && !(o.rate > 0.0 && std::isfinite(o.rate)))
    throw ExitError(kExitBadInput,
                    fmt::format("--rate {:g}: expected the tracker's sample rate, a finite number > 0 [Hz]", o.rate));
  if (!o.index && o.rate_given) throw ExitError(kExitBadInput, "--rate: only with --index (a log of sample indices)");
  return f;
}

PointLog read_point_log(const LogOptions& o, const PointLogFormat& format) {
  const std::string text = read_text_file(o.points, "--points", "point log");
  try {
    return parse_point_log(text, o.points, format);
  } catch (const Error& e) {
    // A column the options name, not found or with a bad cell: the message names the option too.
    const std::string what = e.what();
    const auto names = [&](const std::string& column) {
      return !column.empty() && what.find(fmt::format("column '{}'", column)) != std::string::npos;
    };
    if (names(format.temperature_column)) throw ExitError(kExitBadInput, fmt::format("--temperature-column: {}", what));
    throw ExitError(kExitBadInput, what);
  }
}

}  // namespace hexatwist::cli
