// SPDX-License-Identifier: BSD-3-Clause
// hexatwist linuxcnc: the INI file of the platform for LinuxCNC.
#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

// A double as text that parses back to the same value.
std::string fmt_double(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The value of `key` in section `section` of an INI text (empty if absent).
std::string ini_value(const std::string& ini, const std::string& section, const std::string& key) {
  std::istringstream in(ini);
  std::string line, current;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '[') current = line.substr(1, line.find(']') - 1);
    if (current == section && line.rfind(key + " = ", 0) == 0) return line.substr(key.size() + 3);
  }
  return {};
}

TEST(CliLinuxcnc, TheIniCarriesHomeJointsAndAxisReachOfTheKinematics) {
  const Outcome r = run({"linuxcnc"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(ini_value(r.out, "TRAJ", "HOME"), "0 0 1511.000000000 0 0 0");
  EXPECT_EQ(ini_value(r.out, "KINS", "KINEMATICS"), "hexatwistkins");
  // Each joint's home is the compensated command at home (ik), in mm.
  const YAML::Node home = json(run({"ik", "--json", "--pose=0,0,0,0,0,0"}));
  for (int i = 0; i < 6; ++i) {
    const std::string section = "JOINT_" + std::to_string(i);
    const double expected = 1000 * home["legs"][i]["command_compensated"].as<double>();
    EXPECT_NEAR(std::stod(ini_value(r.out, section, "HOME")), expected, 1e-9);
    EXPECT_EQ(ini_value(r.out, section, "HOME_OFFSET"), ini_value(r.out, section, "HOME"));
    EXPECT_EQ(std::stod(ini_value(r.out, section, "MAX_LIMIT")), 2450.0);
  }
  // Each axis' limits are its reach: just inside, ik accepts the pose; just outside, it refuses.
  const char* axes = "XYZABC";
  for (int k = 0; k < 6; ++k) {
    const std::string section = std::string("AXIS_") + axes[k];
    for (const char* end : {"MIN_LIMIT", "MAX_LIMIT"}) {
      const double v = std::stod(ini_value(r.out, section, end));
      const double sign = std::string(end) == "MIN_LIMIT" ? -1.0 : 1.0;
      const double scale = k < 3 ? 1e-3 : 1.0;  // mm to m; degrees stay
      const double offset = k == 2 ? 1.511 : 0.0;
      for (const double step : {-1e-6, 1e-3}) {
        std::vector<double> q(6, 0.0);
        q[static_cast<std::size_t>(k)] = v * scale - offset + sign * step;
        std::string pose;
        for (const double x : q) {
          if (!pose.empty()) pose += ',';
          pose += fmt_double(x);
        }
        const Outcome ik = run({"ik", "--pose=" + pose});
        EXPECT_EQ(ik.code, step < 0 ? 0 : 3) << section << " " << end << " " << pose << "\n" << ik.err;
      }
    }
  }
}

TEST(CliLinuxcnc, UnitsStrategyAndOutputs) {
  const Outcome inch = run({"linuxcnc", "--units=inch", "--strategy=conventional"});
  ASSERT_EQ(inch.code, 0) << inch.err;
  EXPECT_NEAR(std::stod(ini_value(inch.out, "TRAJ", "HOME").substr(4)), 1511.0 / 25.4, 1e-8);
  EXPECT_EQ(ini_value(inch.out, "KINS", "KINEMATICS"), "hexatwistkins strategy=conventional units=inch");
  expect_error(run({"linuxcnc", "--units=furlong"}), 2, {"--units", "furlong"});
  expect_error(run({"linuxcnc", "--out", (temp_dir() / "no/such/dir/x.ini").string()}), 4, {"x.ini"});
  const std::string out = (temp_dir() / "machine.ini").string();
  ASSERT_EQ(run({"linuxcnc", "--out", out}).code, 0);
  EXPECT_EQ(read_file(out), run({"linuxcnc"}).out);
  // Standard output that cannot be written is a failure, not a silent exit 0.
  const std::string err = (temp_dir() / "full.txt").string();
  const int status = std::system((shell_quote(HEXATWIST_CLI) + " linuxcnc >/dev/full 2>" + shell_quote(err)).c_str());
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 4);
  EXPECT_NE(read_file(err).find("cannot write to standard output"), std::string::npos) << read_file(err);
}

TEST(CliLinuxcnc, ValuesThatWouldChangeTheIniOrItsLoadrtLineAreRefused) {
  // A newline in --display would start a second [KINS] section selecting another kinematics.
  expect_error(run({"linuxcnc", "--display", "axis\n[KINS]\nKINEMATICS = trivkins"}), 2, {"--display", "one line"});
  // LinuxCNC's loadrt splits the module's arguments at white space: config=/a b.yaml breaks it.
  const std::filesystem::path dir = temp_dir() / "with space";
  std::filesystem::create_directories(dir);
  const std::string spaced = (dir / "p.yaml").string();
  std::ofstream(spaced) << hexatwist::test::kSymmetricYaml;
  expect_error(run({"linuxcnc", "--config", spaced}), 2, {"--config", "loadrt"});
  const Outcome ok = run({"linuxcnc", "--display", "my-ui"});
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_EQ(ini_value(ok.out, "DISPLAY", "DISPLAY"), "my-ui");
}

TEST(CliLinuxcnc, APlatformWithoutScrewsSaysWhatItLacksNotTheSimulation) {
  const std::string plain = write_file("plain-linuxcnc.yaml", replace_line(kSymmetric, 9, "  lead: 0"));
  for (const char* command : {"linuxcnc", "mjcf"}) {
    const Outcome r = run({command, "--config", plain});
    expect_error(r, 2, {"screw.lead", "needs a lead screw"});
    EXPECT_EQ(r.err.find("simulation"), std::string::npos) << r.err;
  }
}

}  // namespace
