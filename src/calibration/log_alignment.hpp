// SPDX-License-Identifier: BSD-3-Clause
// Internal: how a point log's points sit in the commanded run's time, shared by the measurement
// and the observations of an identification (docs/theory/calibration.md §12).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "hexatwist/calibration/point_log.hpp"
#include "hexatwist/kinematics/model.hpp"
#include "hexatwist/motion/trajectory.hpp"

namespace hexatwist::detail {

/// Times this close to the trajectory's ends count as on them (stamps are printed with finite decimals) [s].
inline constexpr double kTimeTolerance = 1e-9;
/// Two commanded poses closer than this in every coordinate are the same pose [m, rad].
inline constexpr double kSamePose = 1e-12;

/// True if the commanded pose is the same over [t - settle, t] (before the trajectory starts, the
/// platform stood at its first pose).
bool at_rest(const TimedPoses& commanded, double t, const Vector6d& pose, double settle);

/// "log:line:column" of point k, for messages.
std::string point_location(const PointLog& log, std::size_t k);

/// The trajectory time of every point, each checked to lie in the commanded trajectory's span.
std::vector<double> aligned_times(const TimedPoses& commanded, const PointLog& log, const TimeAlignment& alignment);

/// Throws unless settle is finite and >= 0.
void check_settle(const std::string& source, double settle);

/// Throws naming the first point of the log that no point of `model`'s platform can be: farther
/// from the log's median point than (1 + sqrt 3) R, R the farthest any platform point (joints and
/// the observation point) can be from the base frame's origin (a typing or export error: its
/// error, its registration or its identification would mean nothing).
void check_within_reach(const Model& model, const PointLog& log);

}  // namespace hexatwist::detail
