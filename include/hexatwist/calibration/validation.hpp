// SPDX-License-Identifier: BSD-3-Clause
// Checking a calibration before trusting it (docs/theory/calibration.md §13c): what changed, joint
// by joint, between two platforms (a corrected configuration and the nominal one, a later
// calibration, or the real platform of a rehearsal), and where one's commands put point A on the
// other at held-out stations, in the gauge frames and after a rigid re-alignment.
#pragma once

#include <span>
#include <vector>

#include "hexatwist/calibration/registration.hpp"
#include "hexatwist/calibration/stations.hpp"
#include "hexatwist/kinematics/model.hpp"

namespace hexatwist {

/// One leg of `b` against the same leg of `a` (b minus a).
struct LegDifference {
  Vector3d base = Vector3d::Zero();      ///< base joint centre [m, B]
  Vector3d platform = Vector3d::Zero();  ///< platform joint centre [m, P]
  double base_axis = 0.0;                ///< angle between the fixed base axes [rad]
  double platform_axis = 0.0;            ///< angle between the fixed platform axes [rad]
  double lead = 0.0;                     ///< screw lead [m]
  double drive_lead = 0.0;               ///< the drive's lead (its scale's reference) [m]
  double length_offset = 0.0;            ///< zero offset [m]
  double home_command = 0.0;             ///< the drive's reading at its reference [m]
  double compliance = 0.0;               ///< 1 / stiffness [m/N]
  double play = 0.0;                     ///< [m]
  bool thread_differs = false;           ///< the threads' hands differ
};

/// Everything that differs between two platforms (b minus a).
struct PlatformDifference {
  PerLeg<LegDifference> legs;
  Vector3d observation = Vector3d::Zero();  ///< observation point A [m, P]
  double home_height = 0.0;                 ///< [m]
  double largest_joint = 0.0;               ///< the largest |base| or |platform| [m]
  int largest_joint_leg = 0;                ///< its leg, 0-based
  bool largest_on_platform = false;         ///< it is a platform joint
};

/// b minus a, leg by leg.
[[nodiscard]] PlatformDifference compare_platforms(const Model& a, const Model& b) noexcept;

/// Where the compensated commands of `commanding` put point A on the platform `actual`: at each
/// pose, `actual`'s forward kinematics of the commands against `commanding`'s point A there.
struct CommandAccuracy {
  std::vector<double> gauge;                   ///< the distance at each pose in the gauge frames, sorted [m]
  std::vector<double> aligned;                 ///< the same after the best rigid re-alignment of the points, sorted [m]
  double gauge_median = 0.0, gauge_max = 0.0;  ///< [m]
  double aligned_median = 0.0, aligned_max = 0.0;  ///< [m]
  RigidTransform alignment;  ///< the re-alignment: points of `actual` = alignment of `commanding`'s targets
};

/// Fewest stations command_accuracy takes (a rigid re-alignment of fewer says little).
inline constexpr int kMinAccuracyStations = 4;

/// CommandAccuracy at `poses` [m, rad] (at least kMinAccuracyStations, each inside every limit of `commanding`, as
/// random_stations draws them). Returns the first failure: a limit of the commands (the pose is
/// not one to validate on), the forward kinematics on `actual`, or the registration of the points.
[[nodiscard]] Status command_accuracy(const Model& commanding, const Model& actual, std::span<const Vector6d> poses,
                                      CommandAccuracy& out);

}  // namespace hexatwist
