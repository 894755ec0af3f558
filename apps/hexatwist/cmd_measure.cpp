// SPDX-License-Identifier: BSD-3-Clause
// hexatwist measure: a point log (real or synthetic) registered, evaluated and reported beside the
// simulation of the same run, as the paper's experiment (§5, Table 1; docs/theory.md §12).
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

struct MeasureOptions {
  RunOptions run;
  LogOptions log;
  std::string out = "measure-out";
  double register_until = std::numeric_limits<double>::quiet_NaN();
  std::size_t register_first = 0;
  bool register_first_given = false;
  double settle = 0.25;
  bool no_figures = false;
  bool no_csv = false;
};

// The log's format, its time alignment and the log itself; bad options or a bad file become

int run_measure(const MeasureOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  OutputFiles files("measure");
  files.input("--config", o.run.model.config);
  files.input("--trajectory", o.run.trajectory);
  files.input("--points", o.log.points);
  files.folder("--out", o.out);
  const Config config = load_config_from(o.run.model);
  const Rig& rig = config.rig;
  const PointLogFormat format = log_format(o.log);
  Run run = build_run(config, o.run);

  check_option(o.settle >= 0.0, "--settle", o.settle, "a time >= 0 [s]");
  // 0 points is no window (not "the default one"): refused, never replaced.
  if (o.register_first_given && o.register_first == 0)
    throw ExitError(kExitBadInput,
                    "--register-first 0: expected a number of points >= 1 (the points that register "
                    "the tracker frame)");
  check_option(o.settle < run.test.trajectory.duration(), "--settle", o.settle,
               fmt::format("a time shorter than the run ({:g} s): no point can be still for longer [s]",
                           run.test.trajectory.duration()));
  if (!std::isnan(o.register_until)) check_option(true, "--register-until", o.register_until, "a time [s]");
  MeasurementOptions mo;
  mo.strategy = strategy_of(o.run);
  ClockFit clock;
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
  PointLog log = read_point_log(o.log, format);
  std::size_t outside = 0;
  mo.time = log_alignment(o.log, run, log, clock, outside);
  if (const std::string line = clock_line(clock, o.log, outside); !line.empty())
    std::fprintf(stderr, "hexatwist measure: %s", line.c_str());
  ReportedMeasurement measured;
  measured.measurement = measure_points(rig.model(), run.commanded, log, mo);  // bad input throws: exit 2
  measured.source = o.log.points;
  measured.strategy = mo.strategy;
  measured.window = window;

  std::vector<ReportedTest> tests{std::move(run.test)};
  const ReportOptions ro{o.out, "measure", model_source(o.run.model), defaults_note(config), !o.no_figures, !o.no_csv};
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
  simulate_and_report(rig, ro, tests, files, start, compare);
  return kExitOk;
}

}  // namespace

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
  auto* first = app->add_option("--register-first", o->register_first, "Or on the first N points of the log (N >= 1)")
                    ->each([o](const std::string&) { o->register_first_given = true; });
  until->excludes(first);
  app->add_option("--settle", o->settle,
                  "Of those, only points whose commanded pose has been still for this long [s]; 0 = all")
      ->capture_default_str();
  app->add_flag("--no-figures", o->no_figures, "Skip the PNG/SVG figures (gnuplot)");
  app->add_flag("--no-csv", o->no_csv, "Skip the per-tick CSVs of the simulation (the measured points' CSV is kept)");
  return {app, [o] { return run_measure(*o); }};
}

}  // namespace hexatwist::cli
