// SPDX-License-Identifier: BSD-3-Clause
#include "design_options.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>

#include "cli_common.hpp"
#include "json.hpp"

namespace hexatwist::cli {

const char* const kLimitGroups[5] = {"stroke: shortest leg", "stroke: longest leg", "U-joint bend",
                                     "U-joint singularity", "platform singularity"};

int limit_group(Status s) {
  switch (s) {
    case Status::StrokeBelowMin:
      return 0;
    case Status::StrokeAboveMax:
      return 1;
    case Status::BendBase:
    case Status::BendPlatform:
      return 2;
    case Status::SingularBase:
    case Status::SingularPlatform:
      return 3;
    case Status::PlatformSingularity:
      return 4;
    default:
      return -1;
  }
}

void add_required_options(CLI::App& app, RequiredOptions& o) {
  const RequiredWorkspaceSpec d;  // the library's defaults
  auto* w = app.add_option(
      "--workspace", o.workspace,
      fmt::format("The required workspace, key=value separated by commas (every key optional): tests=on|off (the "
                  "study's four tests at their amplitudes), test_samples={} (poses per test, 2 to {}), random={} "
                  "(combined poses drawn uniformly in +-linear [m] and +-angular [deg] in every coordinate at once, "
                  "kept where the platform reaches them), linear={:g} (0 to {:g} m), angular={:g} (0 to 180 deg), "
                  "seed={}",
                  d.test_samples, kMaxTestSamples, d.random, d.linear, kMaxRequiredLinear, rad2deg(d.angular), d.seed));
  auto* t = app.add_option("--trajectory", o.trajectories,
                           "Instead: CSV files (simulate's format: t,x,y,z,roll,pitch,yaw in s, m, deg), every row a "
                           "required pose; each must be inside every limit")
                ->expected(1, -1);
  w->excludes(t);
}

RequiredWorkspaceSpec parse_workspace_spec(const std::string& text) {
  RequiredWorkspaceSpec s;
  if (text.empty()) return s;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    const std::size_t end = std::min(text.find(',', begin), text.size());
    const std::string item = text.substr(begin, end - begin);
    begin = end + 1;
    const std::size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    const auto fail = [&](const std::string& what) {
      throw ExitError(kExitBadInput, fmt::format("--workspace '{}': {}", printable(item), what));
    };
    if (eq == std::string::npos) fail("expected key=value (tests, test_samples, random, linear, angular, seed)");
    const auto number = [&]() {
      char* stop = nullptr;
      const double v = std::strtod(value.c_str(), &stop);
      if (value.empty() || *stop != '\0' || !std::isfinite(v)) fail("expected a finite number");
      return v;
    };
    // A whole number an int holds; its range is the library's (check_required_workspace_spec).
    const auto count = [&]() {
      const double v = number();
      if (v != std::floor(v) || v < 0.0 || v > 2147483647.0) fail("expected a whole number >= 0");
      return v;
    };
    if (key == "tests") {
      if (value == "on" || value == "1" || value == "yes") {
        s.tests = true;
      } else if (value == "off" || value == "0" || value == "no") {
        s.tests = false;
      } else {
        fail("expected on or off");
      }
    } else if (key == "test_samples" || key == "samples") {  // samples: the name before 0.1.0's vocabulary
      s.test_samples = static_cast<int>(count());
    } else if (key == "random") {
      s.random = static_cast<int>(count());
    } else if (key == "linear") {
      s.linear = number();
    } else if (key == "angular") {
      s.angular = deg2rad(number());
    } else if (key == "seed") {
      s.seed = static_cast<std::uint64_t>(count());
    } else {
      fail("unknown key; expected tests, test_samples, random, linear, angular, seed");
    }
    if (end == text.size()) break;
  }
  // The library's ranges, the field named as its key of --workspace.
  try {
    check_required_workspace_spec(s);
  } catch (const ParameterError& e) {
    throw ExitError(kExitBadInput, fmt::format("--workspace ({}): {}", e.parameter(), e.what()));
  }
  return s;
}

RequiredPoses required_poses(const Config& config, const RequiredOptions& o) {
  RequiredPoses r;
  const Model& model = config.rig.model();
  if (o.trajectories.empty()) {
    r.spec = parse_workspace_spec(o.workspace);
    if (const Status s = required_workspace(model, config.study, r.spec, Strategy::Compensated, r.workspace);
        s != Status::Ok)
      throw ExitError(kExitOutOfLimit, fmt::format("--workspace: {}", describe(s)));
    r.poses = r.workspace.poses;
    const RequiredWorkspace& w = r.workspace;
    std::string tests = r.spec.tests ? fmt::format("the four tests at their amplitudes, {} poses", w.test_poses) : "";
    if (w.tests_dropped > 0) tests += fmt::format(" ({} out of reach left out)", w.tests_dropped);
    const std::string random =
        r.spec.random > 0
            ? fmt::format("{} of {} random combined poses within +-{:g} m / +-{:g} deg reached (seed {})",
                          w.random_reached, w.random_drawn, r.spec.linear, rad2deg(r.spec.angular), r.spec.seed)
            : "";
    r.description =
        fmt::format("{} poses ({}{}{})", r.poses.size(), tests, !tests.empty() && !random.empty() ? "; " : "", random);
    return r;
  }
  r.from_spec = false;
  Vector6d command;
  LimitReport report;
  for (const std::string& path : o.trajectories) {
    const std::string text = read_text_file(path, "--trajectory", "trajectory CSV file", kMaxDataBytes);
    TimedPoses rows;
    try {
      rows = parse_trajectory_csv(text, path);
    } catch (const Error& e) {
      throw ExitError(kExitBadInput, e.what());
    }
    for (std::size_t k = 0; k < rows.poses.size(); ++k) {
      if (motor_commands(model, rows.poses[k], Strategy::Compensated, command, report) != Status::Ok)
        throw ExitError(kExitOutOfLimit,
                        fmt::format("{}:{}: t = {:g} s: {}; every pose of a required trajectory must be inside every "
                                    "limit",
                                    printable(path), k < rows.lines.size() ? rows.lines[k] : static_cast<int>(k + 2),
                                    rows.t[k], describe(report)));
      r.poses.push_back(rows.poses[k]);
    }
  }
  r.description = fmt::format("{} poses from {} trajector{}", r.poses.size(), o.trajectories.size(),
                              o.trajectories.size() == 1 ? "y" : "ies");
  return r;
}

void write_spec_json(JsonWriter& j, const RequiredWorkspaceSpec& s) {
  j.begin_object();
  j.field("tests", s.tests);
  j.field("test_samples", s.test_samples);
  j.field("random", s.random);
  j.field("linear", s.linear);
  j.field("angular", s.angular);
  j.field("seed", static_cast<std::uint64_t>(s.seed));
  j.end_object();
}

void write_required_json(JsonWriter& j, const RequiredPoses& r) {
  j.begin_object();
  j.field("poses", static_cast<std::uint64_t>(r.poses.size()));
  j.field("description", r.description);
  if (r.from_spec) {
    j.key("spec");
    write_spec_json(j, r.spec);
    j.field("test_poses", static_cast<std::uint64_t>(r.workspace.test_poses));
    j.field("tests_dropped", static_cast<std::uint64_t>(r.workspace.tests_dropped));
    j.field("random_drawn", static_cast<std::uint64_t>(r.workspace.random_drawn));
    j.field("random_reached", static_cast<std::uint64_t>(r.workspace.random_reached));
  }
  j.end_object();
}

void add_cell_option(CLI::App& app, double& cell) {
  app.add_option("--cell", cell, "the volume's grid cell [m] (0: the bounds' larger side / 64)")->capture_default_str();
}

void check_cell_option(double cell) {
  check_option(cell >= 0.0 && cell <= 1.0, "--cell", cell, "0 (automatic) to 1 m");
}

void add_scheduler_option(CLI::App& app, std::string& scheduler) {
  app.add_option(
         "--scheduler", scheduler,
         "Run on a Dask cluster: the scheduler's address tcp://HOST:PORT (the workers generate and evaluate the "
         "samples, only summaries come back; the result equals the local run bit for bit). Needs the hexatwist "
         "Python package and dask.distributed (HEXATWIST_PYTHON names the interpreter)")
      ->check([](const std::string& v) {
        const auto colon = v.rfind(':');
        if (v.rfind("tcp://", 0) != 0 || colon == std::string::npos || colon < 7 || colon + 1 >= v.size() ||
            v.find_first_not_of("0123456789", colon + 1) != std::string::npos)
          return std::string("expected tcp://HOST:PORT");
        return std::string();
      });
}

}  // namespace hexatwist::cli
