// SPDX-License-Identifier: BSD-3-Clause
// hexatwist study / simulate: the closed-loop servo simulation of the paper's four tests, or of a
// trajectory from a CSV file, with both strategies; writes the report (study_report.hpp).
#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <memory>

#include "cli_common.hpp"
#include "output_files.hpp"
#include "study_report.hpp"

namespace hexatwist::cli {
namespace {

struct StudyOptions {
  ModelOptions model;
  std::string out = "study-out";
  std::string tests = "Lz,Lx,Rz,Ry";
  std::string trajectory;  // simulate only
  std::string temperature_rise_k;
  bool no_figures = false;
  bool no_csv = false;
};

// The run's files: its inputs and the report folder, declared before anything is computed.
struct StudyFiles {
  OutputFiles files;
  explicit StudyFiles(const std::string& command, const StudyOptions& o) : files(command) {
    files.input("--config", o.model.config);
    files.input("--trajectory", o.trajectory);
    files.folder("--out", o.out);
  }
};

int finish(const Config& config, const StudyOptions& o, const std::string& command, std::vector<ReportedTest>& tests,
           OutputFiles& files, std::chrono::steady_clock::time_point start) {
  ReportOptions ro{o.out, command, model_source(o.model), defaults_note(config), !o.no_figures, !o.no_csv};
  ro.temperature_rise = temperature_rise_option(o.temperature_rise_k, &config.rig.model());
  simulate_and_report(config.rig, ro, tests, files, start);
  return kExitOk;
}

int run_study(const StudyOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = load_config_from(o.model);
  std::vector<ReportedTest> tests;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t comma = o.tests.find(',', begin);
    const std::string name = o.tests.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    StudyTest found;
    try {
      found = study_test(config.study, name);
    } catch (const Error& e) {
      throw ExitError(kExitBadInput, fmt::format("--tests: {}", e.what()));
    }
    for (const ReportedTest& t : tests)
      if (t.name == name) throw ExitError(kExitBadInput, fmt::format("--tests: '{}' given twice", name));
    ReportedTest& t = tests.emplace_back(reported_test(found));
    t.trajectory = test_trajectory(config.study, found, config.rig.control_period());
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  StudyFiles out("study", o);
  return finish(config, o, "study", tests, out.files, start);
}

int run_simulate(const StudyOptions& o) {
  const auto start = std::chrono::steady_clock::now();
  const Config config = load_config_from(o.model);
  StudyFiles out("simulate", o);
  std::vector<ReportedTest> tests{reported_trajectory_file(o.trajectory, config.rig.control_period())};
  return finish(config, o, "simulate", tests, out.files, start);
}

void add_common(CLI::App& app, StudyOptions& o) {
  add_model_options(app, o.model);
  app.add_option(
         "--out", o.out,
         "Output folder for summary.json, summary.md, CSVs and figures (created if missing), written as a set: all "
         "or none (exit 4); in a reused folder, an earlier run's files that this run does not write are removed")
      ->capture_default_str();
  app.add_flag("--no-figures", o.no_figures, "Skip the PNG/SVG figures (gnuplot)");
  app.add_flag("--no-csv", o.no_csv, "Skip the per-tick CSVs (about 9 MB per test and strategy at 1 kHz)");
  app.add_option("--temperature-rise-k", o.temperature_rise_k,
                 "For a configuration whose legs expand (leg_effects): the legs warm by this over each test [K], one "
                 "or six, along synth's warm-up, in the table of what each leg effect costs (perfect servos); "
                 "default 0");
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
