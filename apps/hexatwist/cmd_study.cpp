// hexatwist study / simulate: the closed-loop servo simulation of the paper's four tests, or of a
// trajectory from a CSV file, with both strategies; writes the report (study_report.hpp).
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli_common.hpp"
#include "study_report.hpp"

namespace hexatwist::cli {
namespace {

struct StudyOptions {
  ModelOptions model;
  std::string out = "study-out";
  std::string tests = "Lz,Lx,Rz,Ry";
  std::string trajectory;  // simulate only
  bool no_figures = false;
  bool no_csv = false;
};

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

// Checks every trajectory against the limits first (nothing runs if one fails), then simulates.
void run_all(const Rig& rig, std::vector<ReportedTest>& tests, const std::string& out_dir) {
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

int finish(const Rig& rig, const StudyOptions& o, const std::string& command, std::vector<ReportedTest>& tests,
           std::chrono::steady_clock::time_point start) {
  run_all(rig, tests, o.out);
  const double simulated = [&] {
    double d = 0.0;
    for (const ReportedTest& t : tests) d += 3.0 * t.trajectory.duration();
    return d;
  }();
  const double sim_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ReportOptions ro{o.out, command, model_source(o.model), !o.no_figures, !o.no_csv};
  const std::vector<std::string> files = write_report(rig, ro, tests);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::string out = fmt::format("hexatwist {} on {}: {}\n\n", command, model_source(o.model), rig.model().spec().name);
  out += summary_table(tests);
  out += report_notes(rig, tests);
  out += fmt::format("\n{:.1f} s simulated ({} runs) in {:.1f} s; {} files written to {} in {:.1f} s in all\n",
                     simulated, 3 * tests.size(), sim_wall, files.size(), o.out, wall);
  std::fputs(out.c_str(), stdout);
  return kExitOk;
}

int run_study(const StudyOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = load_config_from(o.model);
  const std::vector<StudyTest> all = seed_tests(config.study);
  std::vector<ReportedTest> tests;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t comma = o.tests.find(',', begin);
    const std::string name = o.tests.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    const StudyTest* found = nullptr;
    for (const StudyTest& t : all) found = t.name == name ? &t : found;
    if (found == nullptr)
      throw ExitError(kExitBadInput, fmt::format("--tests: unknown test '{}'; expected some of Lz,Lx,Rz,Ry", name));
    for (const ReportedTest& t : tests)
      if (t.name == name) throw ExitError(kExitBadInput, fmt::format("--tests: '{}' given twice", name));
    ReportedTest& t = tests.emplace_back();
    t.name = found->name;
    t.label = found->name;
    t.description = fmt::format("{}, +-{:g} {}", found->description,
                                found->coordinate < 3 ? found->amplitude : rad2deg(found->amplitude),
                                found->coordinate < 3 ? "m" : "deg");
    t.coordinate = found->coordinate;
    t.trajectory = test_trajectory(config.study, *found, config.rig.control_period());
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  return finish(config.rig, o, "study", tests, start);
}

int run_simulate(const StudyOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = load_config_from(o.model);
  const std::string text = read_text_file(o.trajectory, "--trajectory", "trajectory CSV file");
  std::vector<ReportedTest> tests(1);
  ReportedTest& t = tests[0];
  try {
    t.trajectory = resample(parse_trajectory_csv(text, o.trajectory), config.rig.control_period());
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
  // File-name-safe name from the file's stem.
  for (const char c : std::filesystem::path(o.trajectory).stem().string())
    t.name += (std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '-' || c == '_') ? c : '_';
  if (t.name.empty()) t.name = "trajectory";
  t.description = fmt::format("trajectory {}", std::filesystem::path(o.trajectory).filename().string());
  t.label = printable(o.trajectory);
  return finish(config.rig, o, "simulate", tests, start);
}

void add_common(CLI::App& app, StudyOptions& o) {
  add_model_options(app, o.model);
  app.add_option("--out", o.out, "Output folder for summary.json, summary.md, CSVs and figures (created if missing)")
      ->capture_default_str();
  app.add_flag("--no-figures", o.no_figures, "Skip the PNG/SVG figures (gnuplot)");
  app.add_flag("--no-csv", o.no_csv, "Skip the per-tick CSVs (about 9 MB per test and strategy at 1 kHz)");
}

}  // namespace

Command make_study_command(CLI::App& root) {
  auto o = std::make_shared<StudyOptions>();
  CLI::App* app = root.add_subcommand(
      "study",
      "The paper's four tests (translation along z and x, rotation about z and y, +-0.5 m / +-30 deg by default) in a "
      "closed-loop servo simulation, conventional vs compensated: Table 1 and Figs. 6-9. Servo, load and test motion "
      "come from the config's servo/load/simulation/study sections (SI; see configs/seed.yaml).");
  add_common(*app, *o);
  app->add_option("--tests", o->tests, "Comma-separated subset of Lz,Lx,Rz,Ry")->capture_default_str();
  return {app, [o] { return run_study(*o); }};
}

Command make_simulate_command(CLI::App& root) {
  auto o = std::make_shared<StudyOptions>();
  o->out = "simulate-out";
  CLI::App* app = root.add_subcommand(
      "simulate",
      "Closed-loop servo simulation of a trajectory from a CSV file, conventional vs compensated, with the same report "
      "as study.\nCSV: a header row t,x,y,z,roll,pitch,yaw, then one row per sample, time strictly increasing. Units: "
      "t in s, x/y/z in m, roll/pitch/yaw in degrees; a header name may carry a unit suffix instead: _s, _m, _mm, "
      "_deg, "
      "_rad (e.g. x_mm, yaw_rad). Poses are relative to home (R = Rz*Ry*Rx). The trajectory is resampled at the "
      "control rate (monotone cubic: no overshoot between samples) and checked against every limit before anything "
      "runs; the simulation starts settled at the first sample.");
  app->add_option("--trajectory", o->trajectory, "CSV file: t,x,y,z,roll,pitch,yaw (s, m, deg)")->required();
  add_common(*app, *o);
  return {app, [o] { return run_simulate(*o); }};
}

}  // namespace hexatwist::cli
