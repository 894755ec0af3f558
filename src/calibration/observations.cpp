// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/observations.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include "calibration/log_alignment.hpp"
#include "hexatwist/error.hpp"

namespace hexatwist {

ObservationGroups group_observations(std::span<const Observation> observations) {
  ObservationGroups g;
  g.group_of.assign(observations.size(), -1);
  // Stations are runs of one command; within a station, one group per target.
  std::size_t begin = 0;
  while (begin < observations.size()) {
    std::size_t end = begin + 1;
    while (end < observations.size() &&
           (observations[end].motor - observations[begin].motor).cwiseAbs().maxCoeff() <= kSameCommand)
      ++end;
    const int station = g.stations++;
    const auto first_group = static_cast<int>(g.station.size());
    for (std::size_t k = begin; k < end; ++k) {
      const int target = observations[k].target;
      g.targets = std::max(g.targets, target + 1);
      int group = -1;
      for (int h = first_group; h < static_cast<int>(g.station.size()); ++h)
        if (g.target[static_cast<std::size_t>(h)] == target) group = h;
      if (group < 0) {
        group = static_cast<int>(g.station.size());
        g.station.push_back(station);
        g.target.push_back(target);
        g.count.push_back(0);
        g.first.push_back(k);
        g.mean_T.push_back(Vector3d::Zero());
      }
      g.group_of[k] = group;
      ++g.count[static_cast<std::size_t>(group)];
      g.mean_T[static_cast<std::size_t>(group)] += observations[k].p_T;
    }
    begin = end;
  }
  for (std::size_t h = 0; h < g.station.size(); ++h) g.mean_T[h] /= static_cast<double>(g.count[h]);
  for (std::size_t k = 0; k < observations.size(); ++k)
    g.scatter_sum += (observations[k].p_T - g.mean_T[static_cast<std::size_t>(g.group_of[k])]).squaredNorm();
  g.scatter_dof = 3 * (observations.size() - g.station.size());
  return g;
}

double tracker_scatter(const ObservationGroups& groups) noexcept {
  return groups.scatter_dof >= 3 ? std::sqrt(groups.scatter_sum / static_cast<double>(groups.scatter_dof))
                                 : std::numeric_limits<double>::quiet_NaN();
}

namespace {

// Each leg's approach to the pose `at` held at time t: walking back along the commanded
// trajectory, the last monotone run of its command (a reversal of 1 um or more ends it), followed
// back until it reaches 1 mm (kMaxPlay: longer than any play) or the trajectory's start; 0 where the
// trajectory never moved the leg so far.
Vector6d approach_runs(const Model& model, const TimedPoses& commanded, double t, const Pose& at, const Vector6d& motor,
                       Strategy strategy) {
  constexpr double kMoved = 1e-6;  // [m]
  Vector6d sense = Vector6d::Zero(), extreme = motor;
  std::array<bool, kLegs> done{};
  auto it = std::upper_bound(commanded.t.begin(), commanded.t.end(), t);
  for (auto j = static_cast<std::ptrdiff_t>(it - commanded.t.begin()) - 1; j >= 0; --j) {
    const Pose& p = commanded.poses[static_cast<std::size_t>(j)];
    if ((p.to_vector() - at.to_vector()).cwiseAbs().maxCoeff() <= detail::kSamePose) continue;
    Vector6d m;
    LimitReport limit;
    if (motor_commands(model, p, strategy, m, limit) != Status::Ok) continue;
    bool all = true;
    for (int i = 0; i < kLegs; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (done[k]) continue;
      if (sense[i] == 0.0) {
        if (std::abs(motor[i] - m[i]) >= kMoved) {
          sense[i] = motor[i] > m[i] ? 1.0 : -1.0;
          extreme[i] = m[i];
        }
      } else if (sense[i] * (m[i] - extreme[i]) < 0.0) {
        extreme[i] = m[i];  // further back along the run
      } else if (sense[i] * (m[i] - extreme[i]) > kMoved) {
        done[k] = true;  // the run began at the extreme
      }
      if (sense[i] != 0.0 && std::abs(motor[i] - extreme[i]) >= kMaxPlay) done[k] = true;
      all = all && done[k];
    }
    if (all) break;
  }
  return motor - extreme;
}

}  // namespace

ObservationSet observations_at_rest(const Model& model, const TimedPoses& commanded, const PointLog& log,
                                    const TimeAlignment& time, Strategy strategy, double settle) {
  detail::check_settle(log.source, settle);
  detail::check_within_reach(model, log);
  const std::vector<double> times = detail::aligned_times(commanded, log, time);
  const std::vector<Pose> desired = interpolate(commanded, times);
  ObservationSet set;
  set.settle = settle;
  set.targets = log.target_names.empty() ? std::vector<std::string>{"A"} : log.target_names;
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (!detail::at_rest(commanded, times[k], desired[k].to_vector(), settle)) continue;
    Observation o;
    LimitReport limit;
    if (const Status s = motor_commands(model, desired[k], strategy, o.motor, limit); s != Status::Ok)
      throw Error(fmt::format("{}: the commanded pose at t = {} s is outside a limit ({}); no command reached it",
                              detail::point_location(log, k), times[k], describe(s)));
    o.p_T = log.points_T[k];
    o.time = times[k];
    if (!log.temperatures.empty()) o.temperature = log.temperatures[k];
    o.target = k < log.targets.size() ? log.targets[k] : 0;
    if (set.points.empty() ||
        (desired[k].to_vector() - desired[set.points.back()].to_vector()).cwiseAbs().maxCoeff() > detail::kSamePose) {
      ++set.poses;
      o.approach = approach_runs(model, commanded, times[k], desired[k], o.motor, strategy);
    } else {
      o.approach = set.observations.back().approach;
    }
    set.observations.push_back(o);
    set.points.push_back(k);
  }
  if (set.observations.size() < kMinObservations)
    throw Error(fmt::format(
        "{}: only {} of the {} points {}; an identification needs at least {} (lower the settle time, or record "
        "a run that stops at more poses: a stations run)",
        log.source, set.observations.size(), times.size(),
        settle > 0.0 ? fmt::format("are at rest (commanded pose unchanged for {} s)", settle)
                     : std::string("are usable"),
        kMinObservations));
  return set;
}

}  // namespace hexatwist
