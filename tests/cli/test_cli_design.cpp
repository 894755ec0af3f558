// SPDX-License-Identifier: BSD-3-Clause
// The design commands end to end (hexatwist workspace, design, tolerance): the real binary, its
// JSON, its files; boundary points checked with `hexatwist ik` as a user would; bad inputs one line
// with their exit codes.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

namespace fs = std::filesystem;

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream s(line);
  for (std::string x; std::getline(s, x, ',');) f.push_back(x);
  return f;
}

std::string pose_text(double x, double y, double z, double roll, double pitch, double yaw) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "--pose=%.17g,%.17g,%.17g,%.17g,%.17g,%.17g", x, y, z, roll, pitch, yaw);
  return buf;
}

TEST(CliWorkspace, WritesItsVolumeSlicesMapsAndFiguresAndEveryBoundaryPointPassesIkInsideAndFailsOutside) {
  const fs::path out = temp_dir() / "ws";
  const Outcome r = run({"workspace", "--orientation", "2,-4,6", "--heights", "-0.2,0.1", "--spacing", "0.03",
                         "--map-spacing", "0.05", "--yaws", "0,15", "--out", out.string(), "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const YAML::Node j = YAML::Load(r.out);
  const double volume = j["volume"].as<double>(), error = j["volume_error"].as<double>();
  EXPECT_GT(volume, 0.5);
  EXPECT_LT(volume, 1.3);
  EXPECT_LT(error, 0.01 * volume);
  EXPECT_EQ(j["slices"].size(), 4u);  // two x-y, x-z, y-z
  EXPECT_EQ(j["orientation_workspace"]["torsions"].size(), 2u);
  EXPECT_GT(j["map"]["inside"].as<int>(), 50);
  EXPECT_EQ(read_file(out / "summary.json"), r.out);
  for (const char* f : {"slices.csv", "orientation.csv", "map.csv", "slices_xy.png", "slices_vertical.svg",
                        "orientation.png", "map_twist.png", "map_dexterity.svg"})
    EXPECT_TRUE(fs::exists(out / f)) << f;

  // The check: points just inside a slice's boundary pass ik, just outside fail it for the
  // limit named (every 97th boundary point of the file).
  std::istringstream csv(read_file(out / "slices.csv"));
  std::string line;
  std::getline(csv, line);
  int checked = 0;
  for (int k = 0; std::getline(csv, line); ++k) {
    if (k % 97 != 0) continue;
    const std::vector<std::string> f = split(line);
    ASSERT_EQ(f.size(), 14u) << line;
    const auto pose = [&](int first) {
      return pose_text(std::stod(f[static_cast<std::size_t>(first)]), std::stod(f[static_cast<std::size_t>(first) + 1]),
                       std::stod(f[static_cast<std::size_t>(first) + 2]), 2, -4, 6);
    };
    const Outcome in = run({"ik", pose(4), "--json"});
    EXPECT_EQ(in.code, 0) << line << in.err;
    const Outcome outside = run({"ik", pose(7), "--json"});
    EXPECT_EQ(outside.code, 3) << line;
    const YAML::Node o = YAML::Load(outside.out);
    EXPECT_EQ(o["status"].as<std::string>(), f[10]) << line;
    EXPECT_EQ(o["limit"]["leg"].as<int>(), std::stoi(f[11])) << line;
    ++checked;
  }
  EXPECT_GE(checked, 4);
}

TEST(CliDesign, WritesAConfigurationWhoseLargestTwistIsHalvedWithEveryLimitKept) {
  const fs::path designed = temp_dir() / "designed.yaml";
  const Outcome r = run({"design", "--workspace", "random=400,samples=21", "--out", designed.string(), "--json"});
  ASSERT_EQ(r.code, 0) << r.err;
  const YAML::Node j = YAML::Load(r.out);
  const double before = j["before"]["max_twist"].as<double>(), after = j["after"]["max_twist"].as<double>();
  EXPECT_LT(after, 0.5 * before);
  EXPECT_EQ(j["after"]["reached"].as<int>(), j["after"]["poses"].as<int>());
  EXPECT_GE(j["after"]["volume"].as<double>(), 0.95 * j["before"]["volume"].as<double>());
  // The designed file is a whole configuration: the study's sections kept, its axes the report's.
  const YAML::Node y = YAML::LoadFile(designed.string());
  EXPECT_TRUE(y["servo"]) << read_file(designed);
  EXPECT_TRUE(y["study"]);
  EXPECT_EQ(y["legs"].size(), 6u);
  EXPECT_EQ(y["legs"][2]["base_axis"][0].as<double>(), j["axes"][2]["base_axis"][0].as<double>());
  // It loads, and its twist at the pose the report names is the largest it reports.
  const Outcome ik = run({"ik", "--config", designed.string(), "--pose=0,0,0,0,0,30", "--json"});
  ASSERT_EQ(ik.code, 0) << ik.err;
  double largest = 0.0;
  for (const YAML::Node& leg : YAML::Load(ik.out)["legs"])
    largest = std::max(largest, std::abs(leg["twist"].as<double>()));
  EXPECT_LE(largest, after + 1e-12);
  EXPECT_GT(largest, 0.5 * after);  // yaw 30 deg is one of the tests' poses, among the largest
  // The text report says the same.
  const Outcome text =
      run({"design", "--workspace", "random=50,samples=5", "--out", (temp_dir() / "d2.yaml").string()});
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("largest |twist|"), std::string::npos);
  EXPECT_NE(text.out.find("U-joint singularity"), std::string::npos);
  // --cell: a coarser volume grid (as workspace's and Python's), the same volume within the errors
  // each run states, the coarser one's error larger.
  const Outcome coarse = run({"design", "--workspace", "random=50,samples=5", "--cell", "0.1", "--json", "--out",
                              (temp_dir() / "d3.yaml").string()});
  ASSERT_EQ(coarse.code, 0) << coarse.err;
  const YAML::Node c = YAML::Load(coarse.out);
  EXPECT_EQ(c["cell"].as<double>(), 0.1);
  const double fine_error = j["before"]["volume_error"].as<double>(),
               coarse_error = c["before"]["volume_error"].as<double>();
  EXPECT_GT(coarse_error, 2.0 * fine_error);
  EXPECT_NEAR(c["before"]["volume"].as<double>(), j["before"]["volume"].as<double>(), coarse_error + fine_error);
}

TEST(CliTolerance, ReportsTheMonteCarloBesideTheLinearisedAnswer) {
  const fs::path out = temp_dir() / "tol";
  const Outcome r = run({"tolerance", "--platforms", "200", "--workspace", "random=100,samples=11", "--out",
                         out.string(), "--json", "--sigma-joint-um", "30", "--sigma-lead-ppm", "100"});
  ASSERT_EQ(r.code, 0) << r.err;
  const YAML::Node j = YAML::Load(r.out);
  EXPECT_EQ(j["platforms"].as<int>(), 200);
  EXPECT_EQ(j["failures"].as<int>(), 0);
  EXPECT_DOUBLE_EQ(j["sigmas"]["base_joint"].as<double>(), 30e-6);
  for (const char* what : {"point", "position", "orientation"}) {
    const double mc = j["monte_carlo"][what]["p95"].as<double>(), lin = j["linearised"][what]["p95"].as<double>();
    EXPECT_NEAR(mc / lin, 1.0, 0.15) << what;
  }
  EXPECT_EQ(std::count(std::istreambuf_iterator<char>(std::ifstream(out / "platforms.csv").rdbuf()), {}, '\n'), 201);
  EXPECT_TRUE(fs::exists(out / "tolerance.png"));
  // The same seed, the same platforms: the CSV again bit for bit.
  const Outcome again =
      run({"tolerance", "--platforms", "200", "--workspace", "random=100,samples=11", "--out",
           (temp_dir() / "tol2").string(), "--sigma-joint-um", "30", "--sigma-lead-ppm", "100", "--no-figures"});
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(read_file(temp_dir() / "tol2" / "platforms.csv"), read_file(out / "platforms.csv"));
  // A perfect calibration: nothing left.
  const Outcome perfect = run({"tolerance", "--platforms", "5", "--workspace", "random=20,samples=3", "--calibration",
                               "perfect", "--json", "--no-figures", "--out", (temp_dir() / "tol3").string()});
  ASSERT_EQ(perfect.code, 0) << perfect.err;
  EXPECT_LT(YAML::Load(perfect.out)["monte_carlo"]["point"]["max"].as<double>(), 1e-11);
}

TEST(CliTolerance, AfterATrackerCalibrationFromAStationPlanMicrometresRemain) {
  // 40 random stations, and the same plan as synth --run-out writes it: the same study.
  const std::vector<std::string> common = {"tolerance",    "--platforms",         "4",
                                           "--workspace",  "random=40,samples=5", "--json",
                                           "--no-figures", "--tracker-noise-um",  "10"};
  auto args = common;
  args.insert(args.end(), {"--calibration", "stations:40", "--out", (temp_dir() / "cal").string()});
  const Outcome r = run(args);
  ASSERT_EQ(r.code, 0) << r.err;
  const YAML::Node j = YAML::Load(r.out);
  EXPECT_EQ(j["calibration"].as<std::string>(), "stations:40");
  EXPECT_DOUBLE_EQ(j["tracker"]["noise"].as<double>(), 10e-6);
  EXPECT_EQ(j["failures"].as<int>(), 0);
  // Measured 1.8 um median (0.22 mm with the nominal controller), MC / linear 0.99.
  const double mc = j["monte_carlo"]["point"]["median"].as<double>(),
               lin = j["linearised"]["point"]["median"].as<double>();
  EXPECT_LT(mc, 10e-6);
  EXPECT_NEAR(mc / lin, 1.0, 0.3);
  const fs::path run_csv = temp_dir() / "run.csv";
  const Outcome synth =
      run({"synth", "--stations", "40", "--run-out", run_csv.string(), "--out", (temp_dir() / "log.csv").string()});
  ASSERT_EQ(synth.code, 0) << synth.err;
  args = common;
  args.insert(args.end(), {"--station-plan", run_csv.string(), "--out", (temp_dir() / "plan").string()});
  const Outcome p = run(args);
  ASSERT_EQ(p.code, 0) << p.err;
  const YAML::Node k = YAML::Load(p.out);
  EXPECT_EQ(k["calibration"].as<std::string>(), "plan");
  EXPECT_EQ(k["tracker"]["stations"].size(), 42u);
  // The run's rests are the stations to the last bits of its trajectory: the same platforms' errors
  // to 1e-4 (measured 7e-6: the identification amplifies them).
  const auto max_points = [](const std::string& csv) {
    std::vector<double> v;
    std::istringstream in(csv);
    std::string line;
    std::getline(in, line);  // the header
    while (std::getline(in, line)) v.push_back(std::stod(line.substr(line.find(',') + 1)));
    return v;
  };
  const std::vector<double> a = max_points(read_file(temp_dir() / "plan" / "platforms.csv"));
  const std::vector<double> b = max_points(read_file(temp_dir() / "cal" / "platforms.csv"));
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(b.size(), 4u);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i] / b[i], 1.0, 1e-4) << "platform " << i;
}

TEST(CliTolerance, TargetsAroundThePlatformCalibrateThePivotAndTheLayoutsSayWhereToPutThem) {
  const std::vector<std::string> common = {
      "tolerance", "--platforms",  "3",        "--workspace",   "random=40,samples=5",
      "--json",    "--no-figures", "--no-csv", "--calibration", "stations:20"};
  auto args = common;
  args.insert(args.end(), {"--target-layouts", "2", "--out", (temp_dir() / "layouts").string()});
  const Outcome r = run(args);
  ASSERT_EQ(r.code, 0) << r.err;
  const YAML::Node j = YAML::Load(r.out);
  const YAML::Node layouts = j["target_layouts"];
  ASSERT_EQ(layouts.size(), 3u);
  // Layout 1 is this study's own calibration: its linear answer is the summary's.
  EXPECT_EQ(layouts[0]["extra_targets"].size(), 0u);
  EXPECT_EQ(layouts[0]["position"]["p95"].as<double>(), j["linearised"]["position"]["p95"].as<double>());
  EXPECT_EQ(layouts[2]["extra_targets"].size(), 2u);
  // The layout of two more targets, given as --targets-mm: its Monte Carlo and its linear answer are
  // the layout's, and the pivot far better than with point A alone (measured 24x at the p95).
  std::string targets;
  for (const YAML::Node& t : layouts[2]["extra_targets"])
    targets += fmt::format("{}{:.17g},{:.17g},{:.17g}", targets.empty() ? "" : ";", 1e3 * t[0].as<double>(),
                           1e3 * t[1].as<double>(), 1e3 * t[2].as<double>());
  args = common;
  args.insert(args.end(), {"--targets-mm", targets, "--out", (temp_dir() / "targets").string()});
  const Outcome t = run(args);
  ASSERT_EQ(t.code, 0) << t.err;
  const YAML::Node k = YAML::Load(t.out);
  EXPECT_EQ(k["tracker"]["targets"].size(), 2u);
  EXPECT_NEAR(k["linearised"]["position"]["p95"].as<double>() / layouts[2]["position"]["p95"].as<double>(), 1.0, 1e-9);
  EXPECT_GT(j["monte_carlo"]["position"]["p95"].as<double>(), 5 * k["monte_carlo"]["position"]["p95"].as<double>());
  EXPECT_GT(j["monte_carlo"]["orientation"]["p95"].as<double>(),
            5 * k["monte_carlo"]["orientation"]["p95"].as<double>());
  // The text report's table, and the options refused where they mean nothing.
  args = common;
  args.erase(args.begin() + 5);  // --json
  args.insert(args.end(), {"--target-layouts", "1", "--out", (temp_dir() / "layouts-text").string()});
  const Outcome text = run(args);
  ASSERT_EQ(text.code, 0) << text.err;
  EXPECT_NE(text.out.find("where to put the targets"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("(point A alone)"), std::string::npos);
  expect_error(run({"tolerance", "--targets-mm", "100,0,0"}), 2, {"--targets-mm", "tracker calibration"});
  expect_error(run({"tolerance", "--target-layouts", "2"}), 2, {"--target-layouts", "tracker calibration"});
  expect_error(run({"tolerance", "--calibration", "stations:20", "--targets-mm", "100,0"}), 2, {"--targets-mm"});
  // The library's parameter (targets) named as the option that sets it, its unit suffix included.
  expect_error(run({"tolerance", "--calibration", "stations:20", "--targets-mm", "1200,0,0.5"}), 2,
               {"within 1 mm", "[--targets-mm]"});

  expect_error(run({"tolerance", "--calibration", "stations:20", "--target-layouts", "9"}), 2, {"--target-layouts"});
}

TEST(CliDesignCommands, BadInputsAreOneLineWithTheirExitCodes) {
  const std::string out = (temp_dir() / "bad").string();
  expect_error(run({"design", "--workspace", "random=many", "--out", out}), 2, {"--workspace 'random=many'"});
  expect_error(run({"design", "--workspace", "colour=red", "--out", out}), 2, {"unknown key"});
  expect_error(run({"tolerance", "--sigma-joint-um", "-1", "--out", out}), 2, {"--sigma-joint-um"});
  expect_error(run({"tolerance", "--calibration", "stations:0", "--out", out}), 2, {"--calibration"});
  expect_error(run({"tolerance", "--calibration", "plan", "--out", out}), 2, {"--station-plan"});
  expect_error(run({"tolerance", "--tracker-noise-um", "0", "--out", out}), 2, {"--tracker-noise-um"});
  expect_error(run({"tolerance", "--points-per-station", "0", "--out", out}), 2, {"--points-per-station"});
  expect_error(run({"tolerance", "--tracker-noise-um", "5", "--out", out}), 2, {"--tracker-noise-um", "only with"});
  expect_error(run({"tolerance", "--calibration", "stations:5", "--platforms", "2", "--out", out}), 2,
               {"--calibration stations:5", "does not determine"});
  expect_error(run({"tolerance", "--station-plan", "/nonexistent/run.csv", "--out", out}), 2, {"--station-plan"});
  expect_error(run({"workspace", "--orientation", "0,0", "--out", out}), 2, {"--orientation"});
  expect_error(run({"workspace", "--spacing", "0", "--out", out}), 2, {"--spacing"});
  // An orientation the platform reaches nowhere: refused, nothing written.
  expect_error(run({"workspace", "--orientation", "0,95,0", "--out", out}), 3, {"--orientation 0,95,0"});
  EXPECT_FALSE(fs::exists(out));
  expect_error(
      run({"design", "--volume-orientation", "0,95,0", "--workspace", "random=10,samples=3", "--out", out + ".yaml"}),
      3, {"--volume-orientation 0,95,0", "volume 0"});
  EXPECT_FALSE(fs::exists(out + ".yaml"));
  // Only a unit is taken from an option's help: "stations:N[,SEED]" is none.
  const Outcome calibration = run({"tolerance", "--calibration", "foo", "--out", out});
  EXPECT_EQ(calibration.code, 2);
  EXPECT_EQ(calibration.err.find("typed"), std::string::npos) << calibration.err;
  // The library states a value in SI; an option typed in another unit shows what was typed beside it.
  expect_error(run({"design", "--clearance", "-1", "--out", out}), 2, {"got -0.0174533; typed -1 deg [--clearance]"});
  expect_error(run({"design", "--max-volume-loss", "200", "--out", out}), 2,
               {"got 2; typed 200 % [--max-volume-loss]"});
  expect_error(run({"tolerance", "--calibration", "stations:20", "--tracker-noise-um", "1e5", "--out", out}), 2,
               {"; typed 1e5 um [--tracker-noise-um]"});
  const Outcome s = run({"tolerance", "--scheduler", "localhost:8786", "--out", out});
  EXPECT_EQ(s.code, 2) << s.err;
  EXPECT_NE(s.err.find("tcp://HOST:PORT"), std::string::npos) << s.err;
  // A required trajectory outside the limits: file, line and limit.
  const fs::path csv = temp_dir() / "high.csv";
  std::ofstream(csv) << "t,x,y,z,roll,pitch,yaw\n0,0,0,0,0,0,0\n1,0,0,0.9,0,0,0\n";
  expect_error(run({"design", "--trajectory", csv.string(), "--out", out}), 3, {"high.csv:3"});
  // The designed file cannot be written: exit 4, nothing left.
  expect_error(run({"design", "--workspace", "random=10,samples=3", "--out", "/nonexistent/d.yaml"}), 4,
               {"/nonexistent/d.yaml"});
  // Standard output that cannot be written: exit 4, and no report left behind.
  const Outcome full = run_to_full_disk(
      {"tolerance", "--platforms", "2", "--workspace", "random=5,samples=3", "--no-figures", "--out", out});
  EXPECT_EQ(full.code, 4) << full.err;
  EXPECT_FALSE(fs::exists(fs::path(out) / "summary.json"));
}

}  // namespace
