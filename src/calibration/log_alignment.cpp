// SPDX-License-Identifier: BSD-3-Clause
#include "calibration/log_alignment.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "hexatwist/error.hpp"

namespace hexatwist::detail {

// True if the commanded pose is the same over [t - settle, t] (before the trajectory starts, the
// platform stood at its first pose). The interpolant is flat between two equal samples, so it is
// enough that every sample from the last one at or before t - settle up to t equals the pose.
bool at_rest(const TimedPoses& commanded, double t, const Vector6d& pose, double settle) {
  if (settle <= 0.0) return true;
  const std::vector<double>& ts = commanded.t;
  auto begin = std::upper_bound(ts.begin(), ts.end(), t - settle);
  if (begin != ts.begin()) --begin;
  const auto end = std::upper_bound(ts.begin(), ts.end(), t);
  for (auto it = begin; it != end; ++it) {
    const Vector6d q = commanded.poses[static_cast<std::size_t>(it - ts.begin())].to_vector();
    if ((q - pose).cwiseAbs().maxCoeff() > kSamePose) return false;
  }
  return true;
}

// "log:line:column" of point k, for messages.
std::string point_location(const PointLog& log, std::size_t k) {
  return fmt::format("{}:{}:{}", log.source, log.lines[k], k < log.stamp_columns.size() ? log.stamp_columns[k] : 1);
}

// The trajectory time of every point, each checked to lie in the commanded trajectory's span.
std::vector<double> aligned_times(const TimedPoses& commanded, const PointLog& log, const TimeAlignment& alignment) {
  if (commanded.t.size() < 2)
    throw Error(fmt::format("{}: the commanded trajectory has fewer than 2 poses", log.source));
  std::vector<double> times = trajectory_times(log, alignment);
  const double front = commanded.t.front(), back = commanded.t.back();
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (!(times[k] >= front - kTimeTolerance && times[k] <= back + kTimeTolerance))
      throw ParameterError(
          fmt::format("{}: point at t = {} s{} is outside the commanded trajectory's time span [{}, {}] s (check the "
                      "time offset{})",
                      point_location(log, k), times[k],
                      log.indexed ? fmt::format(" (index {})", log.stamps[k]) : std::string(), front, back,
                      log.indexed ? " and the sample rate" : ""),
          "time_offset");
    times[k] = std::clamp(times[k], front, back);
  }
  return times;
}

void check_settle(const std::string& source, double settle) {
  if (!(std::isfinite(settle) && settle >= 0.0))
    throw ParameterError(fmt::format("{}: settle time: expected a finite number >= 0 s, got {}", source, settle),
                         "settle");
}

void check_within_reach(const Model& model, const PointLog& log) {
  const ModelSpec& spec = model.spec();
  double base = 0.0, platform = spec.observation_P.norm();
  for (const LegSpec& leg : spec.legs) {
    base = std::max(base, leg.base_B.norm());
    platform = std::max(platform, leg.platform_P.norm());
  }
  const double reach = base + spec.limits.length_max + platform;
  const double bound = (1.0 + std::sqrt(3.0)) * reach;
  if (log.points_T.empty()) return;
  Vector3d median;
  std::vector<double> c(log.points_T.size());
  for (int a = 0; a < 3; ++a) {
    for (std::size_t k = 0; k < c.size(); ++k) c[k] = log.points_T[k][a];
    std::nth_element(c.begin(), c.begin() + static_cast<std::ptrdiff_t>(c.size() / 2), c.end());
    median[a] = c[c.size() / 2];
  }
  for (std::size_t k = 0; k < log.points_T.size(); ++k) {
    const double d = (log.points_T[k] - median).norm();
    if (!(d <= bound))
      throw Error(fmt::format(
          "{}: the point ({:.6g}, {:.6g}, {:.6g}) m is farther than {:.4g} m from the log's median point, farther "
          "than two points of this platform can be apart (a joint reaches {:.4g} m from the base frame's origin): "
          "not a point of this run",
          point_location(log, k), log.points_T[k].x(), log.points_T[k].y(), log.points_T[k].z(), bound, reach));
  }
}

}  // namespace hexatwist::detail
