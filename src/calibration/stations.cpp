// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/stations.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "calibration/random.hpp"
#include "hexatwist/error.hpp"

namespace hexatwist {

Trajectory measured_test_trajectory(const StudySpec& study, const StudyTest& test, const CalibrationSpec& calibration,
                                    double dt, double& calibration_end) {
  // Home, +step along x, y and z, home: four points that span a volume (theory §12).
  std::array<Vector6d, 5> stations{};
  for (Vector6d& s : stations) s.setZero();
  for (int a = 0; a < 3; ++a) stations[static_cast<std::size_t>(a) + 1][a] = calibration.step;
  Trajectory traj = waypoint_trajectory(stations, calibration.limits, calibration.dwell, dt);
  calibration_end = traj.time(traj.poses.size() - 1);
  const Trajectory sweep = test_trajectory(study, test, dt);
  // Both are at home where they meet: the sweep's first sample is the calibration's last.
  traj.poses.insert(traj.poses.end(), sweep.poses.begin() + 1, sweep.poses.end());
  return traj;
}

// True if `pose` and the poses every 5 mm (5 mrad) on the straight line from `from` to it are
// inside every limit for the commands of `strategy`.
bool reachable_from(const Model& model, Strategy strategy, const Vector6d& from, const Vector6d& pose) {
  constexpr double kCheckStep = 5e-3;  // [m or rad]
  // A line of more than 10^6 checks (5 km or 5,000 rad) is no station move: not reachable. The
  // count is checked in double before the conversion, which would overflow an int.
  const double checks = std::ceil((pose - from).norm() / kCheckStep);
  if (!(checks <= 1e6)) return false;
  const int steps = std::max(1, static_cast<int>(checks));
  Vector6d command;
  LimitReport limit;
  for (int j = 1; j <= steps; ++j) {
    const Vector6d q = from + (pose - from) * (static_cast<double>(j) / steps);
    if (motor_commands(model, Pose::from_vector(q), strategy, command, limit) != Status::Ok) return false;
  }
  return true;
}

void check_stations_spec(const StationsSpec& spec) {
  const auto refuse = [](std::string message, const char* field) {
    throw ParameterError("stations: " + std::move(message), field);
  };
  if (spec.count < 1 || spec.count > kMaxStations)
    refuse(fmt::format("expected 1 to {} stations, got {}", kMaxStations, spec.count), "count");
  if (!(spec.translation >= 0.0 && spec.translation <= kMaxStationTranslation))
    refuse(
        fmt::format("expected a translation range of 0 to {:g} m, got {:g}", kMaxStationTranslation, spec.translation),
        "translation");
  if (!(spec.rotation >= 0.0 && spec.rotation <= kMaxStationRotation))
    refuse(fmt::format("expected a rotation range of 0 to {:g} deg, got {:g} deg", rad2deg(kMaxStationRotation),
                       rad2deg(spec.rotation)),
           "rotation");
  if (spec.translation == 0.0 && spec.rotation == 0.0)
    refuse("expected a range > 0 in translation or rotation: the stations would all be at home", "translation");
  if (!(spec.approach >= 0.0 && spec.approach <= kMaxApproach))
    refuse(fmt::format("approach: expected 0 to {:g} m, got {:g}", kMaxApproach, spec.approach), "approach");
  if (spec.reference_every < 0)
    refuse(fmt::format("reference every: expected 0 (none) or a number of stations, got {}", spec.reference_every),
           "reference_every");
  if (!(spec.dwell > 0.0 && std::isfinite(spec.dwell)))
    refuse(fmt::format("expected a finite dwell > 0 s, got {}", spec.dwell), "dwell");
  const MotionLimits& l = spec.limits;
  for (const double v : {l.velocity, l.acceleration, l.jerk})
    if (!(v > 0.0 && std::isfinite(v)))
      refuse(fmt::format("expected finite move limits > 0, got {}, {}, {}", l.velocity, l.acceleration, l.jerk),
             "limits");
}

std::vector<Vector6d> random_stations(const Model& model, Strategy strategy, const StationsSpec& spec) {
  constexpr int kMaxDraws = 1000;
  check_stations_spec(spec);
  detail::Random rng(spec.seed);
  std::vector<Vector6d> stations;
  Vector6d last = Vector6d::Zero();
  for (int i = 0; i < spec.count; ++i) {
    for (int draw = 0;; ++draw) {
      if (draw == kMaxDraws)
        throw Error(
            fmt::format("station {}: no pose within ±{} m and ±{} rad drawn in {} tries is "
                        "reachable inside the limits; give smaller ranges",
                        i + 1, spec.translation, spec.rotation, kMaxDraws));
      Vector6d q;
      for (int c = 0; c < 6; ++c) q[c] = (c < 3 ? spec.translation : spec.rotation) * rng.symmetric();
      // The way home from the last station is checked with it.
      if (reachable_from(model, strategy, last, q) &&
          (i + 1 < spec.count || reachable_from(model, strategy, q, Vector6d::Zero()))) {
        stations.push_back(q);
        last = q;
        break;
      }
    }
  }
  return stations;
}

std::vector<Vector6d> station_waypoints(const Model& model, Strategy strategy, std::span<const Vector6d> stations,
                                        const StationsSpec& spec) {
  check_stations_spec(spec);
  std::vector<Vector6d> waypoints{Vector6d::Zero()};
  const auto visit = [&](const Vector6d& next, std::size_t i) {
    if (!reachable_from(model, strategy, waypoints.back(), next))
      throw Error(i < stations.size()
                      ? fmt::format("station {}: it, or the straight move to it, leaves a limit", i + 1)
                      : std::string("stations: the straight move home from the last station leaves a limit"));
    waypoints.push_back(next);
  };
  for (std::size_t i = 0; i < stations.size(); ++i) {
    const Vector6d& station = stations[i];
    bool visited = false;
    for (const double side : {1.0, -1.0}) {
      if (!(spec.approach > 0.0)) break;
      Vector6d start = station;
      start[2] += side * spec.approach;
      if (reachable_from(model, strategy, waypoints.back(), start) && reachable_from(model, strategy, start, station)) {
        waypoints.push_back(start);
        waypoints.push_back(station);
        visited = true;
      }
    }
    if (!visited) visit(station, i);
    // Home as a reference, where the moves to it and on to the next station stay inside the limits.
    const Vector6d home = Vector6d::Zero();
    if (spec.reference_every > 0 && (i + 1) % static_cast<std::size_t>(spec.reference_every) == 0 &&
        i + 1 < stations.size() && reachable_from(model, strategy, waypoints.back(), home) &&
        reachable_from(model, strategy, home, stations[i + 1]))
      waypoints.push_back(home);
  }
  visit(Vector6d::Zero(), stations.size());
  return waypoints;
}

Trajectory station_run(const Model& model, Strategy strategy, std::span<const Vector6d> stations,
                       const StationsSpec& spec, double dt) {
  const std::vector<Vector6d> waypoints = station_waypoints(model, strategy, stations, spec);
  return waypoint_trajectory(waypoints, spec.limits, spec.dwell, dt);
}

Trajectory stations_trajectory(const Model& model, Strategy strategy, const StationsSpec& spec, double dt) {
  const std::vector<Vector6d> stations = random_stations(model, strategy, spec);
  return station_run(model, strategy, stations, spec, dt);
}

}  // namespace hexatwist
