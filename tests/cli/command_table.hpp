// SPDX-License-Identifier: BSD-3-Clause
// Every command of the tool, run on small inputs: the arguments that make each one run in a moment,
// and the runs in a folder of their own. The tests that walk a class of input or event across the
// commands (the option table, links, signals, locks) share it, so that a new command is walked by
// each of them once it is added here.
#pragma once

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "cli_support.hpp"

namespace hexatwist::cli_test {

namespace fs = std::filesystem;

// A run of the tool in `dir` with standard input from `input` (empty by default).
inline Outcome run_in(const fs::path& dir, const std::vector<std::string>& args, const fs::path& input = "/dev/null") {
  Outcome r;
  const fs::path err_path = dir / "stderr.txt";
  r.command = "cd " + shell_quote(dir.string()) + " && " + shell_quote(HEXATWIST_CLI);
  for (const std::string& a : args) (r.command += ' ') += shell_quote(a);
  FILE* pipe =
      popen((r.command + " <" + shell_quote(input.string()) + " 2>" + shell_quote(err_path.string())).c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buf;
  for (std::size_t n; (n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0;) r.out.append(buf.data(), n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  r.err = read_file(err_path);
  return r;
}

// The inputs the commands run on, small so that each run takes a moment: a short heave, a
// configuration whose study tests last half a second, and a tracker log of the heave.
struct Inputs {
  fs::path dir;
  std::string config, trajectory, log;
};

inline const Inputs& inputs() {
  static const Inputs in = [] {
    Inputs i;
    i.dir = temp_dir() / "command-table";
    fs::create_directories(i.dir);
    i.config = (i.dir / "tiny.yaml").string();
    std::ofstream(i.config) << hexatwist::test::kSymmetricYaml
                            << "study:\n  linear_amplitude: 0.01\n  angular_amplitude_deg: 1\n  dwell: 0.05\n"
                               "  linear: {velocity: 0.5, acceleration: 5, jerk: 50}\n"
                               "  angular_deg: {velocity: 30, acceleration: 300, jerk: 3000}\n";
    // A smooth 5 mm heave with a 5 deg yaw in 1.5 s, then 1.5 s at rest: the log's points span a
    // plane (registration) and the motors stay inside their envelope.
    i.trajectory = (i.dir / "tiny.csv").string();
    std::ofstream traj(i.trajectory);
    traj << "t,x,y,z_mm,roll,pitch,yaw_deg\n";
    for (int k = 0; k <= 300; ++k) {
      const double t = 0.01 * k, s = t < 1.5 ? 0.5 * (1 - std::cos(kPi * t / 1.5)) : 1.0;
      traj << t << ",0,0," << 5.0 * s << ",0,0," << 5.0 * s << "\n";
    }
    traj.close();
    i.log = (i.dir / "log.csv").string();
    const Outcome synth = run_in(i.dir, {"synth", "--trajectory", i.trajectory, "--out", i.log});
    EXPECT_EQ(synth.code, 0) << synth.err;
    return i;
  }();
  return in;
}

// The arguments that make each command run on the small inputs (the option under test replaces
// its own entry).
inline std::map<std::string, std::vector<std::string>> base_arguments(const Inputs& in) {
  const std::string& c = in.config;
  const std::string& t = in.trajectory;
  return {
      {"study", {"--config", c, "--tests", "Rz", "--no-figures", "--no-csv", "--out", "out"}},
      {"simulate", {"--config", c, "--trajectory", t, "--no-figures", "--no-csv", "--out", "out"}},
      {"dynamics", {"--config", c, "--trajectory", t, "--no-figures", "--no-csv", "--out", "out"}},
      {"synth", {"--config", c, "--trajectory", t, "--out", "s.csv"}},
      {"measure",
       {"--config", c, "--points", in.log, "--trajectory", t, "--register-first", "150", "--settle", "0",
        "--no-figures", "--no-csv", "--out", "out"}},
      {"identify", {"--config", c, "--points", in.log, "--trajectory", t, "--settle", "0", "--out", "id.yaml"}},
      {"stations", {"--config", c, "--count", "13", "--candidates", "100", "--out", "run.csv"}},
      {"stream", {"--config", c}},
      {"ik", {"--config", c}},
      {"fk", {"--config", c, "--lengths=1.9,1.9,1.9,1.9,1.9,1.9"}},
      {"compare", {c, c, "--stations", "8"}},
      {"config", {"--config", c}},
      {"linuxcnc", {"--config", c}},
      {"mjcf", {"--config", c}},
      {"workspace",
       {"--config", c, "--heights", "0", "--spacing", "0.1", "--yaws", "0", "--map-spacing", "0.2", "--cell", "0.1",
        "--no-figures", "--no-csv", "--out", "out"}},
      {"design", {"--config", c, "--workspace", "tests=off,random=5", "--cell", "0.1", "--out", "d.yaml"}},
      {"tolerance",
       {"--config", c, "--workspace", "tests=off,random=5", "--platforms", "5", "--no-figures", "--no-csv", "--out",
        "out"}},
  };
}

}  // namespace hexatwist::cli_test
