// SPDX-License-Identifier: BSD-3-Clause
// hexatwist stations end to end: the planned run is read back by synth and identify (which
// determines a platform with joint errors from it, to the standard deviations the plan predicts);
// the run rests at the planned stations; the text and the JSON report one plan, the same for a
// seed; bad options exit 2 naming the option, ranges beyond the limits exit 3, an output that
// cannot be written exits 4, and nothing is written then.
#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

namespace fs = std::filesystem;

// `stations` on a small candidate set; the run goes to `name` in the scratch folder.
Outcome plan(const std::string& name, std::vector<std::string> extra = {}) {
  std::vector<std::string> args{
      "stations", "--count", "16", "--candidates", "600", "--out", (temp_dir() / name).string()};
  args.insert(args.end(), extra.begin(), extra.end());
  return run(args);
}

// The poses of a run file's rows (SI, as written).
std::vector<std::vector<double>> run_rows(const std::string& path) {
  std::vector<std::vector<double>> rows;
  const auto cells = csv_rows(read_file(path));
  for (std::size_t k = 1; k < cells.size(); ++k) {
    rows.emplace_back();
    for (const std::string& c : cells[k]) rows.back().push_back(std::stod(c));
  }
  return rows;
}

TEST(CliStations, ThePlannedRunIsReadBySynthAndIdentifyWhichDeterminesThePlatformAsPredicted) {
  const std::string run_csv = (temp_dir() / "planned.csv").string();
  const Outcome p = plan("planned.csv", {"--json"});
  ASSERT_EQ(p.code, 0) << p.err;
  const YAML::Node j = json(p);
  ASSERT_EQ(j["planned"]["status"].as<std::string>(), "ok");
  // The run rests at home, then at each planned station in order, then at home (to rounding: the
  // run's poses pass through rotation matrices).
  const std::vector<std::vector<double>> rows = run_rows(run_csv);
  std::vector<std::vector<double>> rests;
  for (std::size_t k = 1; k < rows.size(); ++k)
    if (std::equal(rows[k].begin() + 1, rows[k].end(), rows[k - 1].begin() + 1) &&
        (rests.empty() || !std::equal(rows[k].begin() + 1, rows[k].end(), rests.back().begin())))
      rests.emplace_back(rows[k].begin() + 1, rows[k].end());
  ASSERT_EQ(rests.size(), 18u);
  for (std::size_t i = 0; i < 16; ++i)
    for (int c = 0; c < 6; ++c) EXPECT_NEAR(rests[i + 1][c], j["planned"]["stations"][i][c].as<double>(), 1e-15) << i;
  EXPECT_NEAR(rows.back()[0], j["run"]["duration"].as<double>(), 1e-9);

  // A platform with joint, lead and offset errors driven through it, then identified from it.
  const std::string log = (temp_dir() / "planned-log.csv").string();
  const Outcome s = run({"synth", "--trajectory", run_csv, "--joint-errors-mm", "1", "--lead-error-pct", "2",
                         "--offsets-mm", "0.5", "--seed", "4", "--out", log});
  ASSERT_EQ(s.code, 0) << s.err;
  const Outcome id = run({"identify", "--points", log, "--trajectory", run_csv, "--axes", "none", "--folds", "0",
                          "--no-figures", "--json", "--out", (temp_dir() / "planned.yaml").string()});
  ASSERT_EQ(id.code, 0) << id.err;
  const YAML::Node k = json(id);
  EXPECT_EQ(k["stations"].as<int>(), 18);
  // identify's standard deviations are the ones the plan predicted (measured: 0.93-1.02 of them).
  const YAML::Node parameters = k["estimate"]["parameters"];
  const YAML::Node predicted = j["planned"]["sd"];
  ASSERT_EQ(predicted.size(), j["parameters"].size());
  double lo = 1e9, hi = 0.0;
  for (std::size_t i = 0; i < predicted.size(); ++i) {
    ASSERT_EQ(parameters[i]["name"].as<std::string>(), j["parameters"][i].as<std::string>());
    const double ratio = parameters[i]["sd"].as<double>() / predicted[i].as<double>();
    lo = std::min(lo, ratio), hi = std::max(hi, ratio);
  }
  std::printf("  identify's standard deviations over the plan's: %.3f-%.3f\n", lo, hi);
  EXPECT_GT(lo, 0.85);
  EXPECT_LT(hi, 1.15);
}

TEST(CliStations, TheTextAndTheJsonReportOnePlanTheSameForASeed) {
  const Outcome text = plan("text.csv"), again = plan("again.csv", {"--json"}),
                other = plan("other.csv", {"--seed", "2"});
  ASSERT_EQ(text.code, 0) << text.err;
  ASSERT_EQ(again.code, 0) << again.err;
  ASSERT_EQ(other.code, 0) << other.err;
  EXPECT_EQ(read_file(temp_dir() / "text.csv"), read_file(temp_dir() / "again.csv"));
  EXPECT_NE(read_file(temp_dir() / "text.csv"), read_file(temp_dir() / "other.csv"));
  const YAML::Node j = json(again);
  const YAML::Node first = j["planned"]["stations"][0];
  char row[160];
  std::snprintf(row, sizeof row, "\n      1 %9.1f %9.1f %9.1f %11.2f %11.2f %11.2f\n", 1e3 * first[0].as<double>(),
                1e3 * first[1].as<double>(), 1e3 * first[2].as<double>(), first[3].as<double>() * 180 / kPi,
                first[4].as<double>() * 180 / kPi, first[5].as<double>() * 180 / kPi);
  EXPECT_NE(text.out.find(row), std::string::npos) << row << "\n" << text.out;
  for (const char* which : {"planned", "random"}) {
    const YAML::Node q = j[which];
    char line[200];
    std::snprintf(line, sizeof line, "%9.2f %7.2f", q["criterion"].as<double>(), 1e6 * q["sd_geometric"].as<double>());
    EXPECT_NE(text.out.find(line), std::string::npos) << which << ": " << line;
  }
  // The planned stations beat the random ones on the worst predicted error, the JSON says.
  EXPECT_LT(j["planned"]["accuracy"]["max"].as<double>(), j["random"]["accuracy"]["max"].as<double>());
  EXPECT_GT(j["planned"]["criterion"].as<double>(), j["random"]["criterion"].as<double>());
}

TEST(CliStations, BadOptionsExitTwoNamingTheOptionAndWriteNothing) {
  const std::string out = (temp_dir() / "bad.csv").string();
  const auto bad = [&](std::vector<std::string> args, std::initializer_list<std::string_view> parts) {
    args.insert(args.begin(), "stations");
    if (std::find(args.begin(), args.end(), "--out") == args.end()) args.insert(args.end(), {"--out", out});
    expect_error(run(args), 2, parts);
    EXPECT_FALSE(fs::exists(out));
  };
  // The library's checks (check_station_plan_spec, check_stations_spec) name the option.
  bad({"--count", "12"}, {"[--count]", "13 to 10000 stations", "got 12"});
  bad({"--count", "0"}, {"[--count]", "got 0"});
  bad({"--count", "20", "--range", "0.25"}, {"--range"});
  bad({"--count", "20", "--range", "-0.1,15"}, {"--range -0.1", "0 to 10 m"});
  bad({"--count", "20", "--range", "0.25,95"}, {"--range 0.25,95", "0 to 90 deg"});
  bad({"--count", "20", "--range", "0,0"}, {"--range 0,0", "all be at home"});
  bad({"--count", "20", "--candidates", "19"}, {"[--candidates]", "20 (the stations)", "got 19"});
  bad({"--count", "20", "--noise-um", "0"}, {"[--noise-um]", "below 0.01 m", "got 0"});
  bad({"--count", "20", "--noise-um", "1e4"}, {"[--noise-um]", "got 0.01"});
  bad({"--count", "20", "--points-per-station", "0"}, {"[--points-per-station]", "got 0"});
  bad({"--count", "20", "--points-per-station", "100001"}, {"[--points-per-station]", "got 100001"});
  bad({"--count", "20", "--range", "10.5,15"}, {"--range 10.5,15", "0 to 10 m"});
  bad({"--count", "20", "--rate", "300"}, {"--rate 300", "divides the control rate 1000 Hz"});
  bad({"--count", "20", "--strategy", "both"}, {"--strategy"});
  bad({"--count", "20", "--config", (temp_dir() / "missing.yaml").string()}, {"--config", "missing.yaml"});
  expect_error(run({"stations", "--out", out}), 2, {"--count"});
  expect_error(run({"stations", "--count", "20"}), 2, {"--out"});
  // The run may not replace the configuration it was planned for.
  const std::string config = write_file("platform.yaml", kSymmetric);
  expect_error(run({"stations", "--count", "20", "--config", config, "--out", config}), 2, {"--out", "--config"});
  EXPECT_EQ(read_file(config), kSymmetric);
}

TEST(CliStations, RangesBeyondTheLimitsExitThreeAndAnUnwritableRunFourLeavingFilesAsTheyWere) {
  const std::string out = write_file("kept.csv", "an earlier run\n");
  const Outcome r = run({"stations", "--count", "20", "--candidates", "100", "--range", "3,15", "--out", out});
  expect_error(r, 3, {"reachable inside the limits", "give smaller ranges", "nothing was written"});
  EXPECT_EQ(read_file(out), "an earlier run\n");
  const std::string unwritable = (temp_dir() / "no-such-folder" / "run.csv").string();
  expect_error(plan("no-such-folder/run.csv"), 4, {"run.csv"});
  EXPECT_FALSE(fs::exists(unwritable));
  const Outcome full = run_to_full_disk(
      {"stations", "--count", "16", "--candidates", "100", "--out", (temp_dir() / "full.csv").string()});
  EXPECT_EQ(full.code, 4) << full.err;
  EXPECT_FALSE(fs::exists(temp_dir() / "full.csv"));
}

// The same run for the controller: the LinuxCNC program names each station once and moves to it
// once; the stream input is the run at the control rate, and `stream` answers every pose of it
// with a command, at rest on a station the station's command of `ik`. (The program's timing and
// targets: tests/io/test_gcode.cpp; run in LinuxCNC: integrations/linuxcnc/tests.)
TEST(CliStations, TheRunIsAlsoWrittenAsALinuxcncProgramAndAsStreamInput) {
  const std::string ngc = (temp_dir() / "plan.ngc").string(), txt = (temp_dir() / "plan.txt").string();
  const Outcome r = plan("plan-for-controller.csv", {"--gcode", ngc, "--stream-out", txt});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + ngc), std::string::npos) << r.out;
  const std::string program = read_file(ngc);
  for (int k = 1; k <= 16; ++k)
    EXPECT_NE(program.find("(station " + std::to_string(k) + " of 16: arrive at t = "), std::string::npos) << k;
  std::size_t moves = 0;
  for (std::size_t at = program.find("\nG1 "); at != std::string::npos; at = program.find("\nG1 ", at + 1)) ++moves;
  EXPECT_EQ(moves, 17u);  // to each station, and home
  const auto rows = run_rows((temp_dir() / "plan-for-controller.csv").string());
  const std::string poses = read_file(txt);
  const auto lines = static_cast<std::size_t>(std::count(poses.begin(), poses.end(), '\n'));
  // The CSV is at 100 Hz (and its last row, the run's end), the stream input at the control rate
  // (1 kHz): a line per millisecond up to the CSV's last time.
  EXPECT_EQ(lines, static_cast<std::size_t>(std::lround(rows.back()[0] * 1000.0)) + 1);
  const Outcome streamed = run({"stream"}, &poses);
  EXPECT_EQ(streamed.code, 0) << streamed.err;
  const auto answers = csv_rows(streamed.out);
  ASSERT_EQ(answers.size(), lines);
  // Row 150 of the CSV (1.5 s) is at rest on the first station: its line's answer is ik's command.
  std::size_t row = 0;
  for (std::size_t k = 1; k < rows.size(); ++k)
    if (rows[k] != rows[0]) {
      row = k;
      break;
    }
  while (row + 1 < rows.size() && rows[row + 1] != rows[row]) ++row;  // the arrival at station 1
  const std::vector<double>& q = rows[row];
  std::ostringstream pose;
  pose.precision(17);
  pose << "--pose=" << q[1] << "," << q[2] << "," << q[3] << "," << q[4] * 180 / kPi << "," << q[5] * 180 / kPi << ","
       << q[6] * 180 / kPi;
  const Outcome ik = run({"ik", pose.str(), "--json"});
  ASSERT_EQ(ik.code, 0) << ik.err;
  const YAML::Node legs = YAML::Load(ik.out)["legs"];
  const auto line = static_cast<std::size_t>(std::lround(rows[row][0] * 1000.0));  // the row's time, in ms
  ASSERT_LT(line, answers.size());
  const auto& answer = answers[line];
  for (int i = 0; i < 6; ++i)
    EXPECT_NEAR(std::stod(answer[3 + i]), legs[i]["command_compensated"].as<double>(), 1e-9) << answer[0];
  // The controller's files are outputs like the run: one that is an input or the run is refused.
  expect_error(plan("plan-clash.csv", {"--gcode", (temp_dir() / "plan-clash.csv").string()}), 2,
               {"--gcode", "--out", "nothing was written"});
}

}  // namespace
