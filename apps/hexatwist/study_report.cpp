// SPDX-License-Identifier: BSD-3-Clause
#include "study_report.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <iterator>

#include "cli_common.hpp"
#include "json.hpp"
#include "output_files.hpp"
#include "progress.hpp"
#include "schemas.hpp"
#include "study_figures.hpp"

namespace hexatwist::cli {
namespace {

namespace fs = std::filesystem;

// The paper's Table 1 (mm), columns Lz, Lx, Rz, Ry: for comparison in summary.md only.
struct PaperRow {
  const char* label;
  double values[4];
};
constexpr PaperRow kPaperTable1[] = {
    {"paper, simulation, conventional", {0.03006, 0.02431, 0.04637, 0.05836}},
    {"paper, simulation, compensated", {0.002486, 0.003283, 0.01097, 0.02955}},
    {"paper, experiment, conventional", {0.2694, 1.726, 1.292, 1.164}},
    {"paper, experiment, compensated", {0.1431, 0.4954, 0.7534, 0.6362}},
};
constexpr const char* kPaperColumns[4] = {"Lz", "Lx", "Rz", "Ry"};

std::string csv(const ReportedTest& t, const StrategyRun& run, const Model& model) {
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out, "t_s");
  for (const char* what : {"desired", "actual"})
    for (int c = 0; c < 6; ++c) fmt::format_to(out, ",{}_{}_{}", what, kCoordinateNames[c], c < 3 ? "m" : "rad");
  for (const char* what : {"command", "encoder", "motor", "length"})
    for (int i = 1; i <= kLegs; ++i) fmt::format_to(out, ",{}_{}_m", what, i);
  for (int i = 1; i <= kLegs; ++i) fmt::format_to(out, ",twist_{}_rad", i);
  for (int i = 1; i <= kLegs; ++i) fmt::format_to(out, ",length_error_{}_m", i);
  for (int i = 1; i <= kLegs; ++i) fmt::format_to(out, ",torque_{}_Nm", i);
  fmt::format_to(out, ",error_total_m,error_twist_only_m,error_tracking_only_m\n");
  const Vector6d& gain = model.geometry().twist_gain;
  for (std::size_t k = 0; k < run.samples.size(); ++k) {
    const SimulationSample& s = run.samples[k];
    fmt::format_to(out, "{:.6f}", s.time);
    for (const Vector6d* v : {&s.desired, &s.actual, &s.command, &s.encoder, &s.motor, &s.length, &s.twist})
      for (int i = 0; i < 6; ++i) fmt::format_to(out, ",{:.10g}", (*v)[i]);
    for (int i = 0; i < kLegs; ++i) fmt::format_to(out, ",{:.9g}", gain[i] * s.twist[i]);  // Eq. (10)
    for (int i = 0; i < kLegs; ++i) fmt::format_to(out, ",{:.6g}", s.torque[i]);
    const double tracking = k < t.run.tracking_only.size() ? t.run.tracking_only[k] : NAN;
    fmt::format_to(out, ",{:.6g},{:.6g},{:.6g}\n", s.error, s.error_twist_only, tracking);
  }
  return fmt::to_string(b);
}

// The measured points: as measured, registered, commanded, their error and the simulated one.
std::string measured_csv(const ReportedMeasurement& r) {
  fmt::memory_buffer b;
  auto out = std::back_inserter(b);
  fmt::format_to(out,
                 "t_s,line,registration_window,registration_point,x_T_m,y_T_m,z_T_m,x_B_m,y_B_m,z_B_m,desired_x_B_m,"
                 "desired_y_B_m,desired_z_B_m,error_x_m,error_y_m,error_z_m,error_m,simulated_error_m\n");
  const Measurement& m = r.measurement;
  for (std::size_t k = 0; k < m.points.size(); ++k) {
    const MeasuredPoint& p = m.points[k];
    fmt::format_to(out, "{:.6f},{},{},{}", p.time, p.line, p.in_window ? 1 : 0, p.registered ? 1 : 0);
    for (const Vector3d* v : {&p.p_T, &p.p_B, &p.desired_B, &p.error_B})
      for (int a = 0; a < 3; ++a) fmt::format_to(out, ",{:.10g}", (*v)[a]);
    fmt::format_to(out, ",{:.6g},", p.error_B.norm());
    if (k >= m.window) fmt::format_to(out, "{:.6g}", r.simulated[k - m.window]);
    fmt::format_to(out, "\n");
  }
  return fmt::to_string(b);
}

void stats_json(JsonWriter& j, const StrategyRun& r, const Rig& rig) {
  const RunMetrics f = run_metrics(rig, r.samples);
  j.begin_object()
      .field("max_error_total", r.total.max)
      .field("max_error_twist_only", r.twist_only.max)
      .field("max_error_tracking_only", r.tracking_only.max)
      .field("rms_error_total", r.total.rms)
      .field("rms_error_twist_only", r.twist_only.rms)
      .field("rms_error_tracking_only", r.tracking_only.rms)
      .field("max_orientation_error", f.max_orientation_error)
      .field("max_following_error", f.max_following_error)
      .field("max_torque", f.max_torque)
      .field("saturated_ticks", static_cast<int>(f.saturated_ticks))
      .end_object();
}

// The log line of the registration point with the largest residual.
int worst_line(const Measurement& m) {
  return m.points[m.registered[static_cast<std::size_t>(m.registration.max_residual_index)]].line;
}

void measured_json(JsonWriter& j, const ReportedMeasurement& r) {
  const Measurement& m = r.measurement;
  const Registration& reg = m.registration;
  int registered = 0;
  for (const MeasuredPoint& p : m.points) registered += p.registered ? 1 : 0;
  j.begin_object()
      .field("points_file", r.source)
      .field("strategy", to_string(r.strategy).data())
      .field("points", static_cast<int>(m.points.size()))
      .field("evaluated", static_cast<int>(m.points.size() - m.window));
  j.key("registration").begin_object();
  j.field("window", r.window)
      .field("window_points", static_cast<int>(m.window))
      .field("window_end", m.window_end)
      .field("points", registered);
  j.key("R_BT").begin_array();
  for (int i = 0; i < 3; ++i) j.vector(reg.X_BT.R.row(i));
  j.end_array();
  j.key("t_BT").vector(reg.X_BT.t);
  j.field("rms_residual", reg.rms_residual)
      .field("max_residual", reg.max_residual)
      .field("max_residual_line", worst_line(m))
      .field("sigma", reg.sigma)
      .field("condition", reg.condition)
      .field("reflection", reg.reflection)
      .end_object();
  j.field("max_error", m.error.max).field("rms_error", m.error.rms);
  j.key("max_error_axes").vector(Vector3d(m.axes[0].max, m.axes[1].max, m.axes[2].max));
  j.key("rms_error_axes").vector(Vector3d(m.axes[0].rms, m.axes[1].rms, m.axes[2].rms));
  j.field("simulated_max_error", r.simulated_stats.max).field("simulated_rms_error", r.simulated_stats.rms);
  j.end_object();
}

// An effect's costs in the tables' order, with their JSON names.
std::array<std::pair<const char*, const ErrorStats*>, 4> effect_columns(const EffectCost& e) {
  return {{{"conventional", &e.conventional},
           {"twist_compensated", &e.twist_compensated},
           {"compensated", &e.compensated},
           {"static_load_compensated", &e.static_load_compensated}}};
}

// How many of effect_columns a table shows for row `r`: the static load's alone where the legs of
// the row have a stiffness (the load's row, and all of them beside it).
std::size_t effect_columns_shown(const std::vector<EffectCost>& rows, std::size_t r) {
  const bool loaded = rows[r].effect == "load" || (rows[r].effect == "all" && rows.front().effect == "load");
  return loaded ? 4 : 3;
}

// How the tables name an effect's row.
std::string effect_label(const EffectCost& e) { return e.effect == "all" ? std::string("all of them") : e.effect; }

std::string summary_json(const Rig& rig, const ReportOptions& o, const std::vector<ReportedTest>& tests,
                         const std::vector<std::string>& files) {
  JsonWriter j;
  j.begin_document(schema::kReport)
      .field("command", o.command)
      .field("model", rig.model().spec().name)
      .field("config", o.config_source)
      .field("control_rate", rig.simulation().control_rate)
      .field("plant_step", rig.plant_step());
  j.key("observation_point").vector(rig.model().spec().observation_P);
  j.key("tests").begin_array(true);
  for (const ReportedTest& t : tests) {
    j.begin_object().field("name", t.name).field("description", t.description);
    j.key("coordinate");
    t.coordinate >= 0 ? j.value(kCoordinateNames[t.coordinate]) : j.null();
    j.field("duration", t.trajectory.duration()).field("samples", static_cast<int>(t.trajectory.poses.size()));
    j.key("conventional");
    stats_json(j, t.run.conventional, rig);
    j.key("compensated");
    stats_json(j, t.run.compensated, rig);
    if (t.measured) {
      j.key("measured");
      measured_json(j, *t.measured);
    }
    if (!t.effects.empty()) {
      j.key("leg_effects").begin_array(true);
      for (const EffectCost& e : t.effects) {
        j.begin_object().field("effect", e.effect);
        for (const auto& [name, stats] : effect_columns(e)) {
          j.key(name).begin_object().field("max", stats->max).field("rms", stats->rms).end_object();
        }
        j.end_object();
      }
      j.end_array();
    }
    j.end_object();
  }
  j.end_array();
  j.key("files").begin_array();
  for (const std::string& f : files) j.value(f);
  j.end_array().end_object();
  return j.str();
}

// The rows of the error tables: strategy and which of the three errors.
struct ErrorRow {
  bool compensated;
  const char* name;
  ErrorStats StrategyRun::*member;
  const ErrorStats& stats(const ReportedTest& t) const {
    return (compensated ? t.run.compensated : t.run.conventional).*member;
  }
};
constexpr ErrorRow kErrorRows[] = {
    {false, "total", &StrategyRun::total},
    {false, "twist only", &StrategyRun::twist_only},
    {false, "tracking only", &StrategyRun::tracking_only},
    {true, "total", &StrategyRun::total},
    {true, "twist only", &StrategyRun::twist_only},
    {true, "tracking only", &StrategyRun::tracking_only},
};

// Millimetres with four decimals; values too small for that (the exact compensation) keep two
// significant digits, so that 1e-9 mm does not read as 0.
std::string mm(double m) {
  const double v = 1e3 * m;
  return v != 0.0 && std::abs(v) < 5e-5 ? fmt::format("{:.1e}", v) : fmt::format("{:.4f}", v);
}

// summary.md's table of the legs' effects; empty without them.
std::string effects_md(const std::vector<ReportedTest>& tests, const Vector6d& temperature_rise) {
  if (tests.empty() || tests.front().effects.empty()) return {};
  std::string s =
      "\n**The legs' effects** (the configuration's `leg_effects`; theory §4b): the error of point A in mm with "
      "perfect servos (the motors exactly at their targets), each effect alone on otherwise rigid legs. "
      "**conventional**: commands that ignore the twist and the effect; **twist compensated**: Eq. (12) alone, "
      "the effect left; **compensated**: both (the legs' temperatures known to the commands, and their forces: "
      "the static load and the test's accelerations); **static load only**: both, the forces those of the static "
      "load at the pose, as ik, stream and LinuxCNC command them.";
  if (temperature_rise.any())
    s +=
        temperature_rise.minCoeff() == temperature_rise.maxCoeff()
            ? fmt::format(" Heat: the legs warm by {:g} K over each test (along synth's warm-up).", temperature_rise[0])
            : fmt::format(" Heat: the legs warm by {:g} to {:g} K over each test (along synth's warm-up).",
                          temperature_rise.minCoeff(), temperature_rise.maxCoeff());
  s += "\n\n";
  s += "| effect | commands |";
  for (const ReportedTest& t : tests) s += fmt::format(" {} max | {} RMS |", t.name, t.name);
  s += "\n|---|---|";
  for (std::size_t i = 0; i < tests.size(); ++i) s += "---:|---:|";
  s += "\n";
  for (std::size_t r = 0; r < tests.front().effects.size(); ++r)
    for (std::size_t c = 0; c < effect_columns_shown(tests.front().effects, r); ++c) {
      const char* column_names[] = {"conventional", "twist compensated", "compensated", "static load only"};
      s += fmt::format("| {} | {} |", effect_label(tests.front().effects[r]), column_names[c]);
      for (const ReportedTest& t : tests) {
        const ErrorStats& st = *effect_columns(t.effects[r])[c].second;
        s += fmt::format(" {} | {} |", mm(st.max), mm(st.rms));
      }
      s += "\n";
    }
  return s;
}

std::string summary_md(const Rig& rig, const ReportOptions& o, const std::vector<ReportedTest>& tests,
                       const std::vector<std::string>& files) {
  std::string s = fmt::format("# hexatwist {}: observation-point error\n\n", o.command);
  s += fmt::format(
      "Platform: {} (from {}). Control rate {} Hz, plant step {} s. Observation point ({}, {}, {}) m in "
      "the platform frame.\n\n",
      rig.model().spec().name, o.config_source, rig.simulation().control_rate, rig.plant_step(),
      rig.model().spec().observation_P.x(), rig.model().spec().observation_P.y(), rig.model().spec().observation_P.z());
  s += "Errors in mm. **total**: the closed loop as simulated; **twist only**: perfect servos, what the twist alone "
       "does; **tracking only**: the same servos with no twist in the plant (one run, the same for both "
       "strategies).\n\n";
  s += "| strategy | error |";
  for (const ReportedTest& t : tests) s += fmt::format(" {} max | {} RMS |", t.name, t.name);
  s += "\n|---|---|";
  for (std::size_t i = 0; i < tests.size(); ++i) s += "---:|---:|";
  s += "\n";
  for (const ErrorRow& row : kErrorRows) {
    s += fmt::format("| {} | {} |", row.compensated ? "compensated" : "conventional", row.name);
    for (const ReportedTest& t : tests) {
      const ErrorStats& st = row.stats(t);
      s += fmt::format(" {} | {} |", mm(st.max), mm(st.rms));
    }
    s += "\n";
  }
  // The experiment: measured, and the simulation at the same instants.
  if (std::any_of(tests.begin(), tests.end(), [](const ReportedTest& t) { return t.measured.has_value(); })) {
    for (const bool simulated : {false, true}) {
      s += fmt::format("| experiment | {} |", simulated ? "simulated at the measured times" : "measured");
      for (const ReportedTest& t : tests) {
        const ErrorStats* st = !t.measured ? nullptr
                               : simulated ? &t.measured->simulated_stats
                                           : &t.measured->measurement.error;
        s += st != nullptr ? fmt::format(" {} | {} |", mm(st->max), mm(st->rms)) : std::string(" | |");
      }
      s += "\n";
    }
    for (const ReportedTest& t : tests) {
      if (!t.measured) continue;
      const ReportedMeasurement& r = *t.measured;
      const Measurement& m = r.measurement;
      const Registration& reg = m.registration;
      s += fmt::format(
          "\n**{}**: measured points `{}`, {} commands. The tracker frame was registered on the {} points at rest "
          "among "
          "the {} of {} (t <= {:.3f} s): rms residual {} mm, largest {} mm (line {}), noise estimate {} mm per axis, "
          "condition {:.3g}. The {} points after them are evaluated (`{}_measured.csv`).\n",
          t.name, r.source, to_string(r.strategy).data(), reg.count, m.window, r.window, m.window_end,
          mm(reg.rms_residual), mm(reg.max_residual), worst_line(m), mm(reg.sigma), reg.condition,
          m.points.size() - m.window, t.name);
    }
  }
  s += effects_md(tests, o.temperature_rise);
  if (const std::string notes = report_notes(rig, tests); !notes.empty()) s += "\n" + notes;
  s += "\nTests:\n\n";
  for (const ReportedTest& t : tests)
    s += fmt::format("- **{}**: {}, {:.2f} s\n", t.name, t.description, t.trajectory.duration());
  if (files.empty()) {
    s += "\nThis run wrote no other file than this summary and summary.json (--no-csv, --no-figures).\n";
  } else {
    s += "\nFiles written by this run (beside this summary and summary.json):\n\n";
    for (const std::string& f : files) s += fmt::format("- `{}`\n", f);
  }
  if (o.command == "study") {
    s += "\nFor comparison, the paper's Table 1 (maximum error, mm; its lead, servo and trajectories are not "
         "given, so only the orders of magnitude compare):\n\n| | Lz | Lx | Rz | Ry |\n|---|---:|---:|---:|---:|\n";
    for (const PaperRow& row : kPaperTable1)
      s += fmt::format("| {} | {} | {} | {} | {} |\n", row.label, row.values[0], row.values[1], row.values[2],
                       row.values[3]);
    (void)kPaperColumns;
  }
  return s;
}

std::string where(const ReportedTest& t, const SimulationIssue& issue) {
  return fmt::format("{}: t = {:.3f} s", t.label, issue.time);
}

// For one of the paper's tests: which configuration key sets the sweep that left the limits (a small
// machine's stroke is less than the seed's default amplitudes).
std::string amplitude_hint(const ReportedTest& t, Status s) {
  if (t.coordinate < 0 || !is_limit(s) || s == Status::MotorSpeedAboveMax || s == Status::TorqueAboveMax) return {};
  const bool linear = t.coordinate < 3;
  return fmt::format("; the test sweeps +-{:g} {} (the configuration's study.{}): give a smaller amplitude there",
                     linear ? t.amplitude : rad2deg(t.amplitude), linear ? "m" : "deg",
                     linear ? "linear_amplitude" : "angular_amplitude_deg");
}

}  // namespace

void simulate_tests(const Rig& rig, std::vector<ReportedTest>& tests, const Vector6d& temperature_rise) {
  for (const ReportedTest& t : tests) {
    SimulationIssue issue;
    if (const Status s = check_trajectory(rig, t.trajectory, issue); s != Status::Ok)
      throw ExitError(kExitOutOfLimit, fmt::format("{}: {}; nothing was simulated{}", where(t, issue),
                                                   is_limit(s) ? describe(issue.limit) : std::string(describe(s)),
                                                   amplitude_hint(t, s)));
  }
  std::size_t total = 0;
  for (const ReportedTest& t : tests) total += 3 * t.trajectory.poses.size();
  Progress bar(total);
  std::size_t before = 0;
  for (ReportedTest& t : tests) {
    SimulationIssue issue;
    const Status s = run_test(rig, t.trajectory, t.run, issue,
                              [&](std::size_t done, std::size_t) { bar.update(before + done, t.name); });
    if (s != Status::Ok) {
      bar.finish();
      throw ExitError(kExitOutOfLimit, fmt::format("{}: simulation stopped: {}; no report was written", where(t, issue),
                                                   is_limit(s) ? describe(issue.limit) : std::string(describe(s))));
    }
    before += 3 * t.trajectory.poses.size();
  }
  bar.finish();
  for (ReportedTest& t : tests) {
    SimulationIssue issue;
    if (const Status s = effect_costs(rig, t.trajectory, temperature_rise, t.effects, issue); s != Status::Ok)
      throw ExitError(kExitOutOfLimit, fmt::format("{}: the legs' effects: {}; no report was written", where(t, issue),
                                                   is_limit(s) ? describe(issue.limit) : std::string(describe(s))));
  }
}

void simulate_and_report(const Rig& rig, const ReportOptions& o, std::vector<ReportedTest>& tests, OutputFiles& files,
                         std::chrono::steady_clock::time_point start,
                         const std::function<std::string(std::vector<ReportedTest>&)>& after_simulation) {
  simulate_tests(rig, tests, o.temperature_rise);
  const double simulated = [&] {
    double d = 0.0;
    for (const ReportedTest& t : tests) d += 3.0 * t.trajectory.duration();
    return d;
  }();
  const double sim_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string preamble = after_simulation ? after_simulation(tests) : std::string();
  write_report(rig, o, tests, files);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string out =
      fmt::format("hexatwist {} on {}: {}{}\n", o.command, o.config_source, rig.model().spec().name, o.defaults);
  out += preamble + "\n";
  out += summary_table(tests);
  out += report_notes(rig, tests);
  out += fmt::format("\n{:.1f} s simulated ({} runs) in {:.1f} s; {} written to {} in {:.1f} s in all\n", simulated,
                     3 * tests.size(), sim_wall, counted(files.paths().size(), "file"), o.out_dir, wall);
  files.finish(out);
}

std::string summary_table(const std::vector<ReportedTest>& tests) {
  std::string s = fmt::format("{:<28}", "max. error of point A [mm]");
  for (const ReportedTest& t : tests) s += fmt::format(" {:>10}", t.name.substr(0, 10));
  s += "\n";
  for (const ErrorRow& row : kErrorRows) {
    const bool first = row.member == &StrategyRun::total;
    s += fmt::format("{:<13} {:<14}", first ? (row.compensated ? "compensated" : "conventional") : "", row.name);
    for (const ReportedTest& t : tests) s += fmt::format(" {:>10}", mm(row.stats(t).max));
    s += "\n";
  }
  // The experiment: one row per strategy measured.
  for (const Strategy strategy : {Strategy::Conventional, Strategy::Compensated}) {
    const auto measured = [strategy](const ReportedTest& t) { return t.measured && t.measured->strategy == strategy; };
    if (std::none_of(tests.begin(), tests.end(), measured)) continue;
    s += fmt::format("{:<13} {:<14}", "experiment", to_string(strategy));
    for (const ReportedTest& t : tests)
      s += fmt::format(" {:>10}", measured(t) ? mm(t.measured->measurement.error.max) : std::string());
    s += "\n";
  }
  // The legs' effects (the same rows on every test: they depend on the configuration), perfect servos.
  if (tests.empty() || tests.front().effects.empty()) return s;
  s += "legs' effects, perfect servos:\n";
  for (std::size_t r = 0; r < tests.front().effects.size(); ++r) {
    const char* column_names[] = {"conventional", "twist comp.", "compensated", "static load"};
    for (std::size_t c = 0; c < effect_columns_shown(tests.front().effects, r); ++c) {
      s += fmt::format("{:<13} {:<14}", c == 0 ? effect_label(tests.front().effects[r]) : "", column_names[c]);
      for (const ReportedTest& t : tests) s += fmt::format(" {:>10}", mm(effect_columns(t.effects[r])[c].second->max));
      s += "\n";
    }
  }
  return s;
}

ReportedTest reported_test(const StudyTest& test) {
  ReportedTest t;
  t.name = test.name;
  t.label = test.name;
  t.description =
      fmt::format("{}, +-{:g} {}", test.description, test.coordinate < 3 ? test.amplitude : rad2deg(test.amplitude),
                  test.coordinate < 3 ? "m" : "deg");
  t.coordinate = test.coordinate;
  t.amplitude = test.amplitude;
  return t;
}

ReportedTest reported_trajectory_file(const std::string& path, double dt, TimedPoses* commanded) {
  const std::string text = read_text_file(path, "--trajectory", "trajectory CSV file");
  ReportedTest t;
  TimedPoses poses;
  try {
    poses = parse_trajectory_csv(text, path);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
  // Shorter than one control period, there is nothing to simulate: no error would mean anything.
  const double span = poses.t.back() - poses.t.front();
  if (!(span >= dt))
    throw ExitError(kExitBadInput, fmt::format("--trajectory: {} spans {:g} s, less than one control period ({:g} s, "
                                               "simulation.control_rate): nothing to simulate",
                                               printable(path), span, dt));
  try {
    t.trajectory = resample(poses, dt);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, fmt::format("--trajectory: {}: {}", printable(path), e.what()));
  }
  if (commanded != nullptr) *commanded = poses;
  // File-name-safe name from the file's stem.
  for (const char c : fs::path(path).stem().string())
    t.name += (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_') ? c : '_';
  if (t.name.empty()) t.name = "trajectory";
  t.description = fmt::format("trajectory {}", fs::path(path).filename().string());
  t.label = printable(path);
  return t;
}

std::string report_notes(const Rig& rig, const std::vector<ReportedTest>& tests) {
  std::string s;
  for (const ReportedTest& t : tests)
    for (const bool comp : {false, true}) {
      const RunMetrics f = run_metrics(rig, (comp ? t.run.compensated : t.run.conventional).samples);
      if (f.saturated_ticks > 0)
        s += fmt::format("note: {} {}: the torque limit {:g} N m was reached on {} of {} ticks\n", t.label,
                         comp ? "compensated" : "conventional", rig.servo().torque_limit, f.saturated_ticks,
                         (comp ? t.run.compensated : t.run.conventional).samples.size());
    }
  return s;
}

void write_report(const Rig& rig, const ReportOptions& o, const std::vector<ReportedTest>& tests, OutputFiles& set) {
  const fs::path dir(o.out_dir);
  std::vector<std::string> names;  // this run's files other than the summaries, as named in them
  const auto put = [&](const std::string& name, std::string content) {
    set.add((dir / name).string(), std::move(content));
    names.push_back(name);
  };
  std::vector<Figure> figures;
  for (const ReportedTest& t : tests) {
    if (o.csv) {
      put(t.name + "_conventional.csv", csv(t, t.run.conventional, rig.model()));
      put(t.name + "_compensated.csv", csv(t, t.run.compensated, rig.model()));
    }
    if (t.measured) put(t.name + "_measured.csv", measured_csv(*t.measured));
    if (o.figures)
      for (Figure& f : figures_of(dir, t, rig.model())) figures.push_back(std::move(f));
  }
  for (const Figure& f : figures)
    for (const char* ext : {".png", ".svg"}) names.push_back(fs::path(f.stem + ext).filename().string());
  set.add((dir / "summary.md").string(), summary_md(rig, o, tests, names));
  set.add((dir / "summary.json").string(), summary_json(rig, o, tests, names));
  // Everything is written before anything is put in place: a failure leaves the folder as it was.
  set.stage();
  for (Figure& f : figures) f.stem = set.external(f.stem, {".png", ".svg"});
  if (!figures.empty()) write_figures(figures);
  set.commit();
}

}  // namespace hexatwist::cli
