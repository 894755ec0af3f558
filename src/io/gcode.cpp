// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/io/gcode.hpp"

#include <fmt/format.h>

#include <cmath>

#include "hexatwist/error.hpp"

namespace hexatwist {
namespace {

// A comment LinuxCNC reads as one: no parentheses or line breaks inside.
std::string comment(std::string_view text) {
  std::string out = "(";
  for (const char c : text) out += c == '(' ? '[' : c == ')' ? ']' : (c == '\n' || c == '\r') ? ' ' : c;
  return out + ")\n";
}

}  // namespace

std::string waypoint_program(const Model& model, std::span<const Vector6d> waypoints, const MotionLimits& limits,
                             double dwell, std::string_view title) {
  if (waypoints.size() < 2) throw Error("waypoint_program: at least 2 waypoints are needed");
  for (const Vector6d& w : waypoints)
    if (!w.allFinite()) throw Error("waypoint_program: a waypoint is not finite");
  if (!(std::isfinite(dwell) && dwell >= 0.0))
    throw Error(fmt::format("waypoint_program: dwell: expected a time >= 0 s, got {}", dwell));
  const double home_z = model.spec().home_height;
  const auto world = [&](const Vector6d& p) {
    return fmt::format("X{:.9f} Y{:.9f} Z{:.9f} A{:.9f} B{:.9f} C{:.9f}", 1e3 * p[0], 1e3 * p[1], 1e3 * (home_z + p[2]),
                       rad2deg(p[3]), rad2deg(p[4]), rad2deg(p[5]));
  };
  const std::size_t stations = waypoints.size() - 2;  // home at the start and the end
  std::string g;
  g += comment(fmt::format("hexatwist: {}", title));
  g += comment("LinuxCNC units: X Y Z mm in the base frame, Z absolute as [TRAJ] HOME; A B C roll pitch yaw deg");
  g += comment("G93 inverse time: each move takes its planned time; G61 exact stop; G4 dwells at each station");
  g += "G21 G90 G61 G40 G17\n";
  g += comment("start: at the first pose of the plan");
  g += "G0 " + world(waypoints[0]) + "\n";
  g += "G93\n";
  double t = 0.0;
  if (dwell > 0.0) g += fmt::format("G4 P{:.6f}\n", dwell);
  t += dwell;
  for (std::size_t k = 1; k < waypoints.size(); ++k) {
    const JerkLimitedMove move((waypoints[k] - waypoints[k - 1]).norm(), limits);
    const std::string name = k <= stations ? fmt::format("station {} of {}", k, stations) : std::string("home");
    g += comment(fmt::format("{}: arrive at t = {:.6f} s, leave at t = {:.6f} s", name, t + move.duration(),
                             t + move.duration() + dwell));
    if (move.duration() > 0.0)
      g += fmt::format("G1 {} F{:.9g}\n", world(waypoints[k]), 60.0 / move.duration());  // F: moves per minute
    t += move.duration();
    if (dwell > 0.0) g += fmt::format("G4 P{:.6f}\n", dwell);
    t += dwell;
  }
  g += "G94\n";
  g += comment(fmt::format("end: {:.6f} s after the start", t));
  g += "M2\n";
  return g;
}

}  // namespace hexatwist
