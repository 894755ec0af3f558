#include "study_report.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "cli_common.hpp"
#include "figures.hpp"
#include "json.hpp"

namespace hexatwist::cli {
namespace {

namespace fs = std::filesystem;

constexpr const char* kCoordinateNames[6] = {"x", "y", "z", "roll", "pitch", "yaw"};

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

// The swept coordinate of a sample as plotted: m for translations, deg for rotations, or time.
double displacement(const ReportedTest& t, double time, const Vector6d& desired) {
  if (t.coordinate < 0) return time;
  const double v = desired[t.coordinate];
  return t.coordinate < 3 ? v : rad2deg(v);
}
double displacement(const ReportedTest& t, const SimulationSample& s) { return displacement(t, s.time, s.desired); }

const char* strategy_name(Strategy s) { return s == Strategy::Compensated ? "compensated" : "conventional"; }

std::string displacement_label(const ReportedTest& t) {
  if (t.coordinate < 0) return "time [s]";
  if (t.coordinate < 3) return fmt::format("commanded {} displacement [m]", kCoordinateNames[t.coordinate]);
  return fmt::format("commanded {} angle [deg]", kCoordinateNames[t.coordinate]);
}

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

// What a run did besides the three errors.
struct RunFigures {
  double max_torque = 0.0;             // [N m]
  std::size_t saturated = 0;           // ticks with some torque at the limit
  double max_following_error = 0.0;    // largest |target - true motor-side length| [m]
  double max_orientation_error = 0.0;  // largest angle between real and commanded orientation [rad]
};

RunFigures run_figures(const Rig& rig, const StrategyRun& r) {
  RunFigures f;
  for (const SimulationSample& s : r.samples) {
    const double m = s.torque.cwiseAbs().maxCoeff();
    f.max_torque = std::max(f.max_torque, m);
    f.saturated += m >= rig.servo().torque_limit ? 1 : 0;
    f.max_following_error = std::max(f.max_following_error, (s.command - s.motor).cwiseAbs().maxCoeff());
    const Matrix3d dR = rotation_from_rpy(s.actual.tail<3>()) * rotation_from_rpy(s.desired.tail<3>()).transpose();
    f.max_orientation_error = std::max(f.max_orientation_error, Eigen::AngleAxisd(dR).angle());
  }
  return f;
}

void stats_json(JsonWriter& j, const StrategyRun& r, const Rig& rig) {
  const RunFigures f = run_figures(rig, r);
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
      .field("saturated_ticks", static_cast<int>(f.saturated))
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
      .field("strategy", strategy_name(r.strategy))
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

std::string summary_json(const Rig& rig, const ReportOptions& o, const std::vector<ReportedTest>& tests,
                         const std::vector<std::string>& files) {
  JsonWriter j;
  j.begin_object()
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
          t.name, r.source, strategy_name(r.strategy), reg.count, m.window, r.window, m.window_end,
          mm(reg.rms_residual), mm(reg.max_residual), worst_line(m), mm(reg.sigma), reg.condition,
          m.points.size() - m.window, t.name);
    }
  }
  if (const std::string notes = report_notes(rig, tests); !notes.empty()) s += "\n" + notes;
  s += "\nTests:\n\n";
  for (const ReportedTest& t : tests)
    s += fmt::format("- **{}**: {}, {:.2f} s\n", t.name, t.description, t.trajectory.duration());
  s += "\nFiles written by this run (beside this summary and summary.json):\n\n";
  for (const std::string& f : files) s += fmt::format("- `{}`\n", f);
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

// The experiment beside the simulation: the error against the swept coordinate (or time), and its
// components in the base frame against time.
Figure measured_figure(const fs::path& dir, const ReportedTest& t) {
  const ReportedMeasurement& r = *t.measured;
  const Measurement& m = r.measurement;
  const char* strategy = strategy_name(r.strategy);
  Series measured{fmt::format("measured ({})", strategy), {}, {}, Series::Style::Solid};
  Series simulated{fmt::format("simulated ({}, closed loop)", strategy), {}, {}, Series::Style::Dashed};
  std::array<Series, 3> axes;
  for (int a = 0; a < 3; ++a)
    axes[static_cast<std::size_t>(a)].label = fmt::format("{} (base frame)", kCoordinateNames[a]);
  for (std::size_t k = m.window; k < m.points.size(); ++k) {
    const MeasuredPoint& p = m.points[k];
    const double x = displacement(t, p.time, p.desired);
    measured.x.push_back(x);
    measured.y.push_back(1e3 * p.error_B.norm());
    simulated.x.push_back(x);
    simulated.y.push_back(1e3 * r.simulated[k - m.window]);
    for (int a = 0; a < 3; ++a) {
      axes[static_cast<std::size_t>(a)].x.push_back(p.time);
      axes[static_cast<std::size_t>(a)].y.push_back(1e3 * p.error_B[a]);
    }
  }
  Figure f{(dir / (t.name + "_measured")).string(), "", {}};
  f.panels.push_back({fmt::format("{} ({}): measured and simulated error of point A", t.name, t.description),
                      displacement_label(t),
                      "position error [mm]",
                      {std::move(measured), std::move(simulated)}});
  f.panels.push_back({fmt::format("Measured error by axis, registered on {} points (rms residual {:.4f} mm)",
                                  m.registration.count, 1e3 * m.registration.rms_residual),
                      "time [s]",
                      "error [mm]",
                      {axes.begin(), axes.end()}});
  return f;
}

std::vector<Figure> figures_of(const fs::path& dir, const ReportedTest& t, const Model& model) {
  // x: the swept coordinate (or time) by default; time for the transients of the servo.
  const auto series = [&](const std::string& label, const std::vector<SimulationSample>& samples, auto value,
                          Series::Style style = Series::Style::Solid, bool against_time = false) {
    Series s{label, {}, {}, style};
    s.x.reserve(samples.size());
    s.y.reserve(samples.size());
    for (std::size_t k = 0; k < samples.size(); ++k) {
      s.x.push_back(against_time ? samples[k].time : displacement(t, samples[k]));
      s.y.push_back(value(k, samples[k]));
    }
    return s;
  };
  const auto tracking = [&](double scale) {
    return [&t, scale](std::size_t k, const SimulationSample&) {
      return k < t.run.tracking_only.size() ? scale * t.run.tracking_only[k] : NAN;
    };
  };
  const auto& conv = t.run.conventional.samples;
  const auto& comp = t.run.compensated.samples;
  Figure error{(dir / (t.name + "_error")).string(), "", {}};
  Panel p{fmt::format("{} ({}): observation-point error", t.name, t.description),
          displacement_label(t),
          "position error [mm]",
          {}};
  p.series.push_back(
      series("conventional, closed loop", conv, [](std::size_t, const SimulationSample& s) { return 1e3 * s.error; }));
  p.series.push_back(series(
      "conventional, perfect servo", conv,
      [](std::size_t, const SimulationSample& s) { return 1e3 * s.error_twist_only; }, Series::Style::Dashed));
  p.series.push_back(
      series("compensated, closed loop", comp, [](std::size_t, const SimulationSample& s) { return 1e3 * s.error; }));
  error.panels.push_back(std::move(p));
  // On the scale of the twist error the compensated strategy is a flat line: zoom in on it,
  // against time, where the servo's transients (starts, stops, reversals) are apart.
  Panel zoom{fmt::format("Compensated, zoomed: the servo's own error (with perfect servos it is {:.1e} µm)",
                         1e6 * t.run.compensated.twist_only.max),
             "time [s]",
             "position error [µm]",
             {}};
  zoom.series.push_back(series(
      "compensated, closed loop", comp, [](std::size_t, const SimulationSample& s) { return 1e6 * s.error; },
      Series::Style::Solid, true));
  zoom.series.push_back(series("servo alone (no twist)", comp, tracking(1e6), Series::Style::Dashed, true));
  error.panels.push_back(std::move(zoom));

  // Legs that move alike (symmetry) would hide each other: say so in the legend.
  std::array<int, kLegs> same{};
  for (int i = 0; i < kLegs; ++i) {
    same[static_cast<std::size_t>(i)] = -1;
    for (int j = 0; j < i && same[static_cast<std::size_t>(i)] < 0; ++j) {
      double d = 0.0;
      for (const SimulationSample& s : conv) d = std::max(d, std::abs(s.twist[i] - s.twist[j]));
      if (d < 1e-6) same[static_cast<std::size_t>(i)] = j;
    }
  }
  const auto leg_label = [&](int i) {
    const int j = same[static_cast<std::size_t>(i)];
    return j < 0 ? fmt::format("leg {}", i + 1) : fmt::format("leg {} (= leg {})", i + 1, j + 1);
  };
  Figure legs{(dir / (t.name + "_legs")).string(), "", {}};
  Panel twist{fmt::format("{} ({}): twist of each leg (conventional run)", t.name, t.description),
              displacement_label(t),
              "twist [deg]",
              {}};
  Panel length{
      "Length error of each leg, real minus motor-side (Eq. 10)", displacement_label(t), "length error [mm]", {}};
  for (int i = 0; i < kLegs; ++i) {
    twist.series.push_back(
        series(leg_label(i), conv, [i](std::size_t, const SimulationSample& s) { return rad2deg(s.twist[i]); }));
    const double g = model.geometry().twist_gain[i];
    length.series.push_back(
        series(leg_label(i), conv, [i, g](std::size_t, const SimulationSample& s) { return 1e3 * g * s.twist[i]; }));
  }
  legs.panels.push_back(std::move(twist));
  legs.panels.push_back(std::move(length));
  std::vector<Figure> out{std::move(error), std::move(legs)};
  if (t.measured) out.push_back(measured_figure(dir, t));
  return out;
}

// A progress bar on stderr, drawn only on a terminal.
class Progress {
 public:
  explicit Progress(std::size_t total) : total_(total), tty_(isatty(fileno(stderr)) != 0) {}
  void update(std::size_t done, const std::string& what) {
    if (!tty_ || total_ == 0) return;
    const int percent = static_cast<int>(100.0 * static_cast<double>(done) / static_cast<double>(total_));
    if (percent == last_) return;
    last_ = percent;
    const int filled = percent * 30 / 100;
    std::fprintf(stderr, "\r[%s%s] %3d%%  %-24s", std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(30 - filled), '.').c_str(), percent, what.c_str());
    std::fflush(stderr);
  }
  void finish() {
    if (tty_ && last_ >= 0) std::fprintf(stderr, "\r%*s\r", 60, "");
  }

 private:
  std::size_t total_;
  bool tty_;
  int last_ = -1;
};

std::string where(const ReportedTest& t, const SimulationIssue& issue) {
  return fmt::format("{}: t = {:.3f} s", t.label, issue.time);
}

}  // namespace

void simulate_tests(const Rig& rig, std::vector<ReportedTest>& tests, const std::string& out_dir) {
  for (const ReportedTest& t : tests) {
    SimulationIssue issue;
    if (const Status s = check_trajectory(rig, t.trajectory, issue); s != Status::Ok)
      throw ExitError(kExitOutOfLimit,
                      fmt::format("{}: {}; nothing was simulated", where(t, issue),
                                  is_limit(s) ? describe_limit(issue.limit) : std::string(describe(s))));
  }
  prepare_output_folder(out_dir);
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
      throw ExitError(kExitOutOfLimit,
                      fmt::format("{}: simulation stopped: {}; no report was written", where(t, issue),
                                  is_limit(s) ? describe_limit(issue.limit) : std::string(describe(s))));
    }
    before += 3 * t.trajectory.poses.size();
  }
  bar.finish();
}

void simulate_and_report(const Rig& rig, const ReportOptions& o, std::vector<ReportedTest>& tests,
                         std::chrono::steady_clock::time_point start,
                         const std::function<std::string(std::vector<ReportedTest>&)>& after_simulation) {
  simulate_tests(rig, tests, o.out_dir);
  const double simulated = [&] {
    double d = 0.0;
    for (const ReportedTest& t : tests) d += 3.0 * t.trajectory.duration();
    return d;
  }();
  const double sim_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string preamble = after_simulation ? after_simulation(tests) : std::string();
  const std::vector<std::string> files = write_report(rig, o, tests);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string out = fmt::format("hexatwist {} on {}: {}\n", o.command, o.config_source, rig.model().spec().name);
  out += preamble + "\n";
  out += summary_table(tests);
  out += report_notes(rig, tests);
  out += fmt::format("\n{:.1f} s simulated ({} runs) in {:.1f} s; {} files written to {} in {:.1f} s in all\n",
                     simulated, 3 * tests.size(), sim_wall, files.size(), o.out_dir, wall);
  write_stdout_or_withdraw(out, files);
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
    s += fmt::format("{:<13} {:<14}", "experiment", strategy_name(strategy));
    for (const ReportedTest& t : tests)
      s += fmt::format(" {:>10}", measured(t) ? mm(t.measured->measurement.error.max) : std::string());
    s += "\n";
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

void prepare_output_folder(const std::string& out_dir) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec || !fs::is_directory(out_dir))
    throw ExitError(kExitOutputFailed, fmt::format("--out: cannot create the output folder '{}'{}", printable(out_dir),
                                                   ec ? ": " + ec.message() : std::string()));
}

std::string report_notes(const Rig& rig, const std::vector<ReportedTest>& tests) {
  std::string s;
  for (const ReportedTest& t : tests)
    for (const bool comp : {false, true}) {
      const RunFigures f = run_figures(rig, comp ? t.run.compensated : t.run.conventional);
      if (f.saturated > 0)
        s += fmt::format("note: {} {}: the torque limit {:g} N m was reached on {} of {} ticks\n", t.label,
                         comp ? "compensated" : "conventional", rig.servo().torque_limit, f.saturated,
                         (comp ? t.run.compensated : t.run.conventional).samples.size());
    }
  return s;
}

namespace {

// The files an earlier run left in the folder: every entry, and those its summary.json lists
// as written by it (file names).
struct EarlierRun {
  std::vector<std::string> entries;
  std::vector<std::string> listed;
};

EarlierRun earlier_run(const fs::path& dir) {
  EarlierRun e;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    e.entries.push_back(it->path().filename().string());
  std::sort(e.entries.begin(), e.entries.end());
  const fs::path summary = dir / "summary.json";
  if (!fs::is_regular_file(summary, ec)) return e;
  // The list is one JSON array of plain file names (our own writer): read it without a parser.
  std::ifstream in(summary, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const std::string t = text.str();
  const std::size_t key = t.rfind("\"files\": [");
  if (key == std::string::npos) return e;
  const std::size_t close = t.find(']', key);
  for (std::size_t q = t.find('"', key + 9); q < close; q = t.find('"', q + 1)) {
    const std::size_t r = t.find('"', q + 1);
    if (r == std::string::npos || r > close) break;
    const std::string name = t.substr(q + 1, r - q - 1);
    if (!name.empty() && name.find('/') == std::string::npos && name.find('\\') == std::string::npos)
      e.listed.push_back(name);
    q = r;
  }
  return e;
}

}  // namespace

std::vector<std::string> write_report(const Rig& rig, const ReportOptions& o, const std::vector<ReportedTest>& tests) {
  const fs::path dir(o.out_dir);
  prepare_output_folder(o.out_dir);
  const EarlierRun earlier = earlier_run(dir);
  OutputSet set;
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
  std::vector<std::string> all = names;
  all.push_back("summary.md");
  all.push_back("summary.json");
  set.add((dir / "summary.md").string(), summary_md(rig, o, tests, names));
  set.add((dir / "summary.json").string(), summary_json(rig, o, tests, names));
  // Everything is written before anything is put in place: a failure leaves the folder as it was.
  set.stage();
  if (!figures.empty()) {
    write_figures(figures);
    for (const Figure& f : figures)
      for (const char* ext : {".png", ".svg"}) set.adopt(f.stem + ext);
  }
  set.commit();

  // A reused folder: the earlier run's files (as its summary listed them) that this run did not
  // write are removed, so the summary never sits beside results it does not describe; other files
  // are left and named.
  if (!earlier.entries.empty()) {
    const auto ours = [&](const std::string& n) { return std::find(all.begin(), all.end(), n) != all.end(); };
    std::size_t replaced = 0, removed = 0;
    std::vector<std::string> others;
    for (const std::string& n : earlier.entries) {
      if (ours(n)) {
        ++replaced;
      } else if (std::find(earlier.listed.begin(), earlier.listed.end(), n) != earlier.listed.end()) {
        std::error_code ec;
        if (fs::remove(dir / n, ec)) ++removed;
      } else {
        others.push_back(n);
      }
    }
    std::string note = fmt::format(
        "hexatwist {}: note: --out '{}' was not empty: {} files replaced, {} of an earlier "
        "run removed",
        o.command, printable(o.out_dir), replaced, removed);
    if (!others.empty()) {
      note += fmt::format("; {} other files left, not described by the summary:", others.size());
      for (std::size_t k = 0; k < others.size() && k < 5; ++k) note += " " + printable(others[k]);
      if (others.size() > 5) note += " ...";
    }
    std::fprintf(stderr, "%s\n", note.c_str());
  }
  return set.paths();
}

}  // namespace hexatwist::cli
