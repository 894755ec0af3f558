// SPDX-License-Identifier: BSD-3-Clause
// What the CLI's end-to-end tests share: a scratch folder, running the real binary (stdout, stderr,
// exit code), the one-line error check, and the inputs several commands' tests use.
#pragma once

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "yaml_text.hpp"

namespace hexatwist::cli_test {

inline constexpr double kPi = 3.14159265358979323846;
inline double deg2rad(double d) { return d * kPi / 180.0; }

// A fresh directory for the files of this run, removed at exit.
inline const std::filesystem::path& temp_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() {
      std::string tmpl = (std::filesystem::temp_directory_path() / "hexatwist_cli_XXXXXX").string();
      if (mkdtemp(tmpl.data()) == nullptr) std::abort();
      path = tmpl;
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

inline std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Writes `text` to a new file in the temp dir; returns its path.
inline std::string write_file(const std::string& name, const std::string& text) {
  const std::filesystem::path path = temp_dir() / name;
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

inline std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

struct Outcome {
  int code = -1;
  std::string out, err;
  std::string command;
};

// Runs the tool with `args`; stdout through a pipe, stderr through a file, stdin from `input`
// (none: the test's own stdin).
inline Outcome run(const std::vector<std::string>& args, const std::string* input = nullptr) {
  Outcome r;
  const std::filesystem::path err_path = temp_dir() / "stderr.txt";
  r.command = shell_quote(HEXATWIST_CLI);
  for (const std::string& a : args) (r.command += ' ') += shell_quote(a);
  if (input != nullptr) r.command += " <" + shell_quote(write_file("stdin.txt", *input));
  FILE* pipe = popen((r.command + " 2>" + shell_quote(err_path.string())).c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buf;
  for (std::size_t n; (n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0;) r.out.append(buf.data(), n);
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = read_file(err_path);
  return r;
}

// The run failed with `code` and exactly one line on stderr that contains every one of `parts`.
inline void expect_error(const Outcome& r, int code, std::initializer_list<std::string_view> parts) {
  SCOPED_TRACE(r.command + "\nstderr: " + r.err);
  EXPECT_EQ(r.code, code);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "not exactly one line";
  EXPECT_TRUE(!r.err.empty() && r.err.back() == '\n');
  EXPECT_EQ(r.err.rfind("hexatwist: ", 0), 0u);
  for (const std::string_view p : parts) EXPECT_NE(r.err.find(p), std::string::npos) << "does not name '" << p << "'";
}

inline YAML::Node json(const Outcome& r) {
  try {
    return YAML::Load(r.out);
  } catch (const YAML::Exception& e) {
    ADD_FAILURE() << "not JSON: " << e.what() << "\n" << r.out;
    return YAML::Node();
  }
}

inline std::string numbers(const std::vector<double>& v) {
  std::ostringstream os;
  os.precision(17);
  for (std::size_t i = 0; i < v.size(); ++i) os << (i ? "," : "") << v[i];
  return os.str();
}

inline std::vector<double> leg_values(const YAML::Node& j, const char* key) {
  std::vector<double> v;
  for (const auto& leg : j["legs"]) v.push_back(leg[key].as<double>());
  return v;
}

inline std::string vec(const YAML::Node& v) {
  std::ostringstream os;
  os.precision(17);
  os << "[" << v[0].as<double>() << ", " << v[1].as<double>() << ", " << v[2].as<double>() << "]";
  return os.str();
}

using hexatwist::test::kSymmetricYaml;
inline const std::string& kSymmetric = kSymmetricYaml;

using hexatwist::test::replace_line;

// The default platform in the `legs` form, built from `config --json`. Lines: 1 home_height,
// 2-5 screw, 6-8 limits, 9 "legs:", then leg i (0-based) from line 10 + 4 i: base, platform,
// base_axis, platform_axis.
constexpr int legs_line(int i, int field) { return 10 + 4 * i + field; }
inline std::string seed_legs_yaml() {
  const YAML::Node c = json(run({"config", "--json"}));
  std::ostringstream os;
  os.precision(17);
  os << "home_height: " << c["home_height"].as<double>() << "\n"
     << "screw:\n  lead: 0.010\n  thread: right\n  driven_side: base\n"
     << "limits:\n  length_min: 1.40\n  length_max: 2.45\n"
     << "legs:\n";
  for (const auto& leg : c["legs"])
    os << "  - base: " << vec(leg["base"]) << "\n"
       << "    platform: " << vec(leg["platform"]) << "\n"
       << "    base_axis: " << vec(leg["base_axis"]) << "\n"
       << "    platform_axis: " << vec(leg["platform_axis"]) << "\n";
  return os.str();
}

// A smooth 1.5 s heave of 50 mm with a 5 deg yaw, sampled at 100 Hz, in mm and degrees.
inline std::string heave_csv(double z_mm = 50.0) {
  std::ostringstream os;
  os << "t,x,y,z_mm,roll,pitch,yaw_deg\n";
  for (int k = 0; k <= 150; ++k) {
    const double t = k / 100.0;
    const double s = 0.5 * (1 - std::cos(kPi * t / 1.5));
    os << t << ",0,0," << z_mm * s << ",0,0," << 5.0 * s << "\n";
  }
  return os.str();
}

// "leg 3 at t = 0.917 s", as dynamics names a violation.
inline std::string fmt_leg_time(int leg, double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "leg %d at t = %.3f s", leg, t);
  return buf;
}

inline bool is_png(const std::filesystem::path& p) {
  const std::string head = read_file(p).substr(0, 8);
  return head == std::string("\x89PNG\r\n\x1a\n", 8);
}

inline std::vector<std::vector<std::string>> csv_rows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream is(text);
  for (std::string line; std::getline(is, line);) {
    rows.emplace_back(1);
    for (const char c : line) {
      if (c == ',')
        rows.back().emplace_back();
      else
        rows.back().back() += c;
    }
  }
  return rows;
}

inline std::vector<double> commands_of(const std::vector<std::string>& row) {
  std::vector<double> m;
  for (int i = 3; i < 9; ++i) m.push_back(std::stod(row[static_cast<std::size_t>(i)]));
  return m;
}

// Runs the tool with standard output on /dev/full; the exit code and stderr.
inline Outcome run_to_full_disk(const std::vector<std::string>& args) {
  Outcome r;
  const std::filesystem::path err_path = temp_dir() / "stderr-full.txt";
  r.command = shell_quote(HEXATWIST_CLI);
  for (const std::string& a : args) (r.command += ' ') += shell_quote(a);
  const int status = std::system((r.command + " >/dev/full 2>" + shell_quote(err_path.string())).c_str());
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = read_file(err_path);
  return r;
}

inline std::vector<std::string> folder_entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace hexatwist::cli_test
