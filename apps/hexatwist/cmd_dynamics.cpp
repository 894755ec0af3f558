// SPDX-License-Identifier: BSD-3-Clause
// hexatwist dynamics: motor sizing along a trajectory from a CSV file (motor_sizing.hpp): the
// per-sample CSV, summary.json, the torque-speed figure, and a table on the terminal.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <numeric>

#include "cli_common.hpp"
#include "figures.hpp"
#include "json.hpp"
#include "output_files.hpp"
#include "schemas.hpp"
#include "study_report.hpp"

namespace hexatwist::cli {
namespace {

namespace fs = std::filesystem;

constexpr double kRpmPerRadPerSecond = 60.0 / (2.0 * kPi);

struct DynamicsOptions {
  ModelOptions model;
  std::string trajectory;
  std::string out = "dynamics-out";
  bool no_figures = false;
  bool no_csv = false;
};

double rpm(double rad_per_s) { return rad_per_s * kRpmPerRadPerSecond; }

constexpr std::array<TorqueTerm, kTorqueTerms> kTerms{TorqueTerm::Gravity,         TorqueTerm::PlatformInertia,
                                                      TorqueTerm::VelocityProduct, TorqueTerm::Legs,
                                                      TorqueTerm::Drives,          TorqueTerm::Friction};

// "leg 2 at t = 1.234 s: peak torque 31.20 N m is above the envelope's 28.00 N m at 2150 rpm".
std::string describe_violation(const EnvelopeViolation& v) {
  const std::string where = fmt::format("leg {} at t = {:.3f} s", v.leg + 1, v.time);
  switch (v.check) {
    case EnvelopeCheck::Speed:
      return fmt::format(
          "{}: motor speed {:.0f} rpm ({:.2f} rad/s) is above the maximum {:.0f} rpm (servo.max_speed_rpm)", where,
          rpm(v.value), v.value, rpm(v.bound));
    case EnvelopeCheck::PeakTorque:
      return fmt::format(
          "{}: torque {:.2f} N m is above the peak envelope's {:.2f} N m at that speed "
          "(servo.torque_limit, peak_corner_rpm, peak_torque_at_max_speed)",
          where, v.value, v.bound);
    case EnvelopeCheck::ContinuousTorque:
      return fmt::format(
          "leg {}: RMS torque {:.2f} N m over the trajectory (0 to {:.3f} s) is above the continuous "
          "rating {:.2f} N m (servo.continuous_torque)",
          v.leg + 1, v.value, v.time, v.bound);
    case EnvelopeCheck::None:
      break;
  }
  return "inside the envelope";
}

std::string per_sample_csv(const MotorSizing& s) {
  std::string out = "t_s";
  for (int i = 1; i <= kLegs; ++i) out += fmt::format(",torque_{0}_Nm,speed_{0}_rad_s,power_{0}_W", i);
  for (const TorqueTerm term : kTerms)
    for (int i = 1; i <= kLegs; ++i) out += fmt::format(",{}_{}_Nm", to_string(term), i);
  out += "\n";
  auto it = std::back_inserter(out);
  for (const MotorSample& x : s.samples) {
    fmt::format_to(it, "{:.6f}", x.time);
    for (int i = 0; i < kLegs; ++i) fmt::format_to(it, ",{:.9g},{:.9g},{:.9g}", x.torque[i], x.speed[i], x.power[i]);
    for (int t = 0; t < kTorqueTerms; ++t)
      for (int i = 0; i < kLegs; ++i) fmt::format_to(it, ",{:.9g}", x.terms[t][i]);
    out += "\n";
  }
  return out;
}

void violation_json(JsonWriter& j, const EnvelopeViolation& v) {
  if (v.check == EnvelopeCheck::None) {
    j.null();
    return;
  }
  j.begin_object();
  j.field("check", to_string(v.check));
  j.field("leg", v.leg + 1);
  j.field("time", v.time);
  j.field("value", v.value);
  j.field("bound", v.bound);
  j.field("message", describe_violation(v));
  j.end_object();
}

std::string summary_json(const Rig& rig, const DynamicsOptions& o, const Trajectory& traj, const MotorSizing& s,
                         const std::vector<std::string>& files) {
  const ServoSpec& servo = rig.servo();
  JsonWriter j;
  j.begin_document(schema::kDynamics);
  j.field("command", "dynamics");
  j.field("units", "SI: s, N m, rad/s, W, J; shares and usages are ratios");
  j.field("config", model_source(o.model));
  j.field("model", rig.model().spec().name);
  j.field("trajectory", o.trajectory);
  j.field("duration", traj.duration());
  j.field("sample_period", traj.dt);
  j.field("samples", static_cast<std::uint64_t>(s.samples.size()));
  j.key("motor").begin_object();
  j.field("torque_limit", servo.torque_limit);
  j.field("peak_corner_speed", servo.peak_corner_speed);
  j.field("peak_torque_at_max_speed", servo.peak_torque_at_max_speed);
  j.field("max_speed", servo.max_speed);
  j.field("continuous_torque", servo.continuous_torque);
  j.end_object();
  j.field("envelope", s.violation.check == EnvelopeCheck::None ? "ok" : "exceeded");
  j.key("first_violation");
  violation_json(j, s.violation);
  j.key("legs").begin_array(true);
  for (int i = 0; i < kLegs; ++i) {
    const MotorSummary& m = s.motors[i];
    j.begin_object();
    j.field("leg", i + 1);
    j.field("peak_torque", m.peak_torque);
    j.field("peak_torque_time", m.peak_torque_time);
    j.field("rms_torque", m.rms_torque);
    j.field("peak_speed", m.peak_speed);
    j.field("peak_speed_time", m.peak_speed_time);
    j.field("peak_power", m.peak_power);
    j.field("peak_power_time", m.peak_power_time);
    j.field("energy_driven", m.energy_driven);
    j.field("energy_regenerated", m.energy_regenerated);
    j.key("share").begin_object();
    for (int t = 0; t < kTorqueTerms; ++t) j.field(to_string(kTerms[t]), m.share[t]);
    j.end_object();
    j.field("peak_usage", m.peak_usage);
    j.field("peak_usage_time", m.peak_usage_time);
    j.field("speed_usage", m.speed_usage);
    j.field("rms_usage", m.rms_usage);
    j.field("speed_ok", m.speed_usage <= accepted_max(1.0));  // on the limit is inside it
    j.field("peak_torque_ok", m.peak_usage <= accepted_max(1.0));
    j.field("continuous_torque_ok", m.rms_usage <= accepted_max(1.0));
    j.key("first_violation");
    violation_json(j, m.violation);
    j.end_object();
  }
  j.end_array();
  j.field("share_definition", "RMS of the term over the trajectory divided by the RMS torque");
  j.key("files").begin_array();
  for (const std::string& f : files) j.value(f);
  j.end_array();
  j.end_object();
  return j.str();
}

// One panel per motor: its operating points, the four-quadrant peak envelope, the continuous
// torque and the maximum speed, in rpm and N m.
Figure torque_speed(const Rig& rig, const MotorSizing& s, const std::string& stem, const std::string& label) {
  const TorqueSpeedFigure data = torque_speed_figure(rig, s);
  const double w = rpm(data.max_speed), tc = data.continuous_torque;
  const double nan = std::nan("");
  Figure fig;
  fig.stem = stem;
  fig.title = fmt::format("Torque-speed of each motor: {}", label);
  for (int i = 0; i < kLegs; ++i) {
    Panel p;
    const MotorSummary& m = s.motors[i];
    p.title = fmt::format("motor {}: peak {:.1f} N m, RMS {:.1f} N m, {:.0f} rpm{}", i + 1, m.peak_torque, m.rms_torque,
                          rpm(m.peak_speed), m.violation.check == EnvelopeCheck::None ? "" : " - OUTSIDE THE ENVELOPE");
    p.xlabel = "motor speed [rpm]";
    p.ylabel = "motor torque [N m]";
    Series points{"operating points", {}, {}, Series::Style::Points};
    for (std::size_t k = 0; k < data.operating[i].speed.size(); ++k) {
      points.x.push_back(rpm(data.operating[i].speed[k]));
      points.y.push_back(data.operating[i].torque[k]);
    }
    Series envelope{"peak envelope", {}, {}, Series::Style::Solid};
    for (std::size_t k = 0; k < data.envelope.speed.size(); ++k) {
      envelope.x.push_back(rpm(data.envelope.speed[k]));
      envelope.y.push_back(data.envelope.torque[k]);
    }
    Series continuous{
        fmt::format("continuous +-{:g} N m", tc), {-w, w, nan, -w, w}, {tc, tc, nan, -tc, -tc}, Series::Style::Dashed};
    // The speed limit spans the whole torque range drawn.
    const double t_hi = std::max(rig.servo().torque_limit, m.peak_torque) * 1.05;
    Series max_speed{fmt::format("max speed +-{:g} rpm", w),
                     {w, w, nan, -w, -w},
                     {-t_hi, t_hi, nan, -t_hi, t_hi},
                     Series::Style::Dotted};
    p.series = {std::move(points), std::move(envelope), std::move(continuous), std::move(max_speed)};
    fig.panels.push_back(std::move(p));
  }
  return fig;
}

// The two largest shares, "gravity 71%, platform_inertia 40%".
std::string largest_terms(const MotorSummary& m) {
  std::array<int, kTorqueTerms> order;
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return m.share[a] > m.share[b]; });
  return fmt::format("{} {:.0f}%, {} {:.0f}%", to_string(kTerms[order[0]]), 100.0 * m.share[order[0]],
                     to_string(kTerms[order[1]]), 100.0 * m.share[order[1]]);
}

std::string table(const Config& config, const DynamicsOptions& o, const Trajectory& traj, const MotorSizing& s) {
  const Rig& rig = config.rig;
  const ServoSpec& servo = rig.servo();
  std::string out = fmt::format("hexatwist dynamics on {}: {}{}\n", model_source(o.model), rig.model().spec().name,
                                defaults_note(config));
  out += fmt::format("trajectory: {}: {:.3f} s, {} samples at {:g} Hz\n", printable(o.trajectory), traj.duration(),
                     s.samples.size(), 1.0 / traj.dt);
  out += fmt::format("motor: peak {:g} N m up to {:.0f} rpm, {:g} N m at {:.0f} rpm; continuous {:g} N m\n\n",
                     servo.torque_limit, rpm(servo.peak_corner_speed), servo.peak_torque_at_max_speed,
                     rpm(servo.max_speed), servo.continuous_torque);
  out += fmt::format("{:>3} {:>11} {:>8} {:>10} {:>15} {:>11} {:>11} {:>9}   {:<34} {:>24}\n", "leg", "peak[N m]",
                     "at[s]", "rms[N m]", "speed[rpm]", "speed[rad/s]", "power[W]", "regen[J]",
                     "largest shares (rms/rms)", "envelope use peak/speed/rms");
  for (int i = 0; i < kLegs; ++i) {
    const MotorSummary& m = s.motors[i];
    out += fmt::format(
        "{:>3} {:>11.2f} {:>8.3f} {:>10.2f} {:>15.0f} {:>11.1f} {:>11.0f} {:>9.1f}   {:<34} "
        "{:>9.0f}%/{:>3.0f}%/{:>3.0f}%\n",
        i + 1, m.peak_torque, m.peak_torque_time, m.rms_torque, rpm(m.peak_speed), m.peak_speed, m.peak_power,
        m.energy_regenerated, largest_terms(m), 100.0 * m.peak_usage, 100.0 * m.speed_usage, 100.0 * m.rms_usage);
  }
  out += s.violation.check == EnvelopeCheck::None
             ? "envelope: ok, every motor inside it\n"
             : fmt::format("envelope: EXCEEDED: {}\n", describe_violation(s.violation));
  return out;
}

int run_dynamics(const DynamicsOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = load_config_from(o.model);
  const Rig& rig = config.rig;
  OutputFiles files("dynamics");
  files.input("--config", o.model.config);
  files.input("--trajectory", o.trajectory);
  files.folder("--out", o.out);
  // Read and resampled at the control rate as simulate does (ExitError(2) on a bad file).
  const ReportedTest input = reported_trajectory_file(o.trajectory, rig.control_period());
  const Trajectory& traj = input.trajectory;

  MotorSizing sizing;
  if (const Status status = size_motors(rig, traj, sizing); status != Status::Ok) {
    const std::string where = fmt::format("{}: t = {:.3f} s", printable(o.trajectory), sizing.failed_time);
    if (is_limit(status))
      throw ExitError(kExitOutOfLimit, fmt::format("{}: {}; nothing was written", where, describe(sizing.limit)));
    throw ExitError(kExitOutOfLimit,
                    fmt::format("{} (sample {}): inverse dynamics failed: {} ({}); nothing was written", where,
                                sizing.failed_index, describe(status), to_string(status)));
  }

  // Every file is written as one set: all of them or none (exit 4).
  const fs::path dir(o.out);
  std::vector<std::string> names;
  const std::string csv_name = input.name + "_dynamics.csv";
  if (!o.no_csv) names.push_back(csv_name);
  std::vector<Figure> figures;
  if (!o.no_figures) {
    figures.push_back(torque_speed(rig, sizing, (dir / (input.name + "_torque_speed")).string(), input.label));
    names.push_back(input.name + "_torque_speed.png");
    names.push_back(input.name + "_torque_speed.svg");
  }
  names.push_back("summary.json");
  if (!o.no_csv) files.add((dir / csv_name).string(), per_sample_csv(sizing));
  files.add((dir / "summary.json").string(), summary_json(rig, o, traj, sizing, names));
  files.stage();
  for (Figure& f : figures) f.stem = files.external(f.stem, {".png", ".svg"});
  if (!figures.empty()) write_figures(figures);
  files.commit();

  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string text = table(config, o, traj, sizing);
  text += fmt::format("\n{} written to {} in {:.1f} s\n", counted(files.paths().size(), "file"), o.out, wall);
  files.finish(text);
  // A motor outside its envelope is the run's finding: the report is complete and kept.
  if (sizing.violation.check != EnvelopeCheck::None)
    throw ExitError(kExitOutOfLimit,
                    fmt::format("{}: motor envelope exceeded: {} (the report was written to {})",
                                printable(o.trajectory), describe_violation(sizing.violation), printable(o.out)));
  return kExitOk;
}

}  // namespace

Command make_dynamics_command(CLI::App& root) {
  auto o = std::make_shared<DynamicsOptions>();
  CLI::App* app = root.add_subcommand(
      "dynamics",
      "Motor sizing along a trajectory: the inverse dynamics of the whole mechanism (platform and payload, leg bodies, "
      "rotors and screws, friction and screw efficiency) at every control tick, each motor's torque [N m], speed "
      "[rad/s and rpm] and power [W], what the torque is made of, and the check against the motor's envelope: "
      "|torque| <= the peak torque at that speed, |speed| <= max speed, RMS torque <= continuous torque (servo "
      "section of the config).\nThe CSV is simulate's: header t,x,y,z,roll,pitch,yaw (s, m, deg; or suffixed names "
      "such as z_mm, yaw_rad), resampled at the control rate; rates and accelerations are central differences.\n"
      "Writes to --out: <name>_dynamics.csv (per tick, SI), summary.json (SI), <name>_torque_speed.png/.svg (rpm, "
      "N m). Exit 3 when a motor leaves its envelope (the report is written, the first violation is named), or when a "
      "pose is outside a limit or the dynamics fail (nothing is written).");
  app->add_option("--trajectory", o->trajectory, "CSV file: t,x,y,z,roll,pitch,yaw (s, m, deg)")->required();
  add_model_options(*app, o->model);
  app->add_option("--out", o->out,
                  "Output folder (created if missing) for the CSV, summary.json and the figure, written as a set: all "
                  "or none (exit 4)")
      ->capture_default_str();
  app->add_flag("--no-figures", o->no_figures, "Skip the torque-speed figure (gnuplot)");
  app->add_flag("--no-csv", o->no_csv, "Skip the per-tick CSV");
  return {app, [o] { return run_dynamics(*o); }};
}

}  // namespace hexatwist::cli
