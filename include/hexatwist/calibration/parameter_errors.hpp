// SPDX-License-Identifier: BSD-3-Clause
// What a real platform may have that its nominal model does not, in the parameters a laser tracker
// can reveal: the U-joint centres and fixed axes, the screw leads, the sign of the twist term, each
// leg's zero-length offset and the observation point. `hexatwist synth` builds a platform with known
// errors from these; an identification estimates them (docs/theory/calibration.md §12, §13).
#pragma once

#include <cstdint>
#include <limits>

#include "hexatwist/kinematics/model.hpp"

namespace hexatwist {

/// The real platform against the nominal model. The default is no error.
struct ParameterErrors {
  /// Relative error of each leg's lead: real lead = (1 + lead_error_i) nominal lead [-]. The drives
  /// still turn their motors by the nominal lead's angles, so the nut travels (1 + lead_error_i)
  /// times as far per commanded metre about the drives' reference, and the twist term (Eq. 10) is
  /// (1 + lead_error_i) times as large.
  Vector6d lead_error = Vector6d::Zero();
  /// The real twist term has the opposite sign on every leg (the other thread hand than the model
  /// says; the sign the paper's Eq. 9 loses).
  bool flip_twist_sign = false;
  /// Real minus nominal motor-side length of each leg at the same motor angle [m]: the error of
  /// each leg's zero (home) length.
  Vector6d zero_offset = Vector6d::Zero();
  /// Real minus nominal observation point [m, P].
  Vector3d observation_offset_P = Vector3d::Zero();
  /// Real minus nominal base U-joint centres [m, B] (rows: legs). Without a rigid part (no common
  /// translation, no common small rotation about the centroid): B stays the least-squares frame
  /// of the six centres, the gauge of an identification (theory §13).
  LegVectors base_offset_B = LegVectors::Zero();
  /// Real minus nominal platform U-joint centres [m, P] (rows: legs), without a rigid part likewise.
  LegVectors platform_offset_P = LegVectors::Zero();
  /// Small rotation of each base U-joint's fixed axis, a rotation vector [rad, B] (rows: legs).
  LegVectors base_axis_rotation = LegVectors::Zero();
  /// Small rotation of each platform U-joint's fixed axis [rad, P] (rows: legs).
  LegVectors platform_axis_rotation = LegVectors::Zero();
  /// The real legs' effects (kinematics/leg_effects.hpp) where the nominal model has none or others:
  /// each leg's axial stiffness [N/m] (NaN = the nominal one; inf = rigid), play [m] (NaN = the
  /// nominal one), and the expansions of the length between the joints and of the lead [1/K]
  /// (NaN = the nominal ones). A machine is never exactly its model: these make it so in `synth`.
  Vector6d stiffness = Vector6d::Constant(std::numeric_limits<double>::quiet_NaN());
  Vector6d play = Vector6d::Constant(std::numeric_limits<double>::quiet_NaN());
  double length_expansion = std::numeric_limits<double>::quiet_NaN();
  double lead_expansion = std::numeric_limits<double>::quiet_NaN();
};

/// The real platform's model: `nominal` with the joints and axes moved, every leg's lead scaled by
/// 1 + lead_error_i while its drive keeps the nominal lead (LegSpec::drive_lead) and reference
/// (LegSpec::home_command), the thread hands flipped if flip_twist_sign, the zero offsets added to
/// the length offsets, the observation point moved and the legs' effects that `errors` gives set. Motor-side forward
/// kinematics of the nominal model's commands on it gives the pose the real platform takes. Throws hexatwist::Error
/// (from Model) if that model is invalid, e.g. a lead error <= -1.
Model real_model(const Model& nominal, const ParameterErrors& errors);

/// The displacements `d` of six points `points` (rows) with their rigid part removed: d minus the
/// common translation and the small rotation about the points' centroid that fit d best, so that
/// the least-squares frame of the moved points is the frame of the original ones (theory §13).
LegVectors without_rigid_part(const LegVectors& points, const LegVectors& d);

/// Joint-centre errors drawn independently and uniformly in [-bound, bound] per coordinate [m],
/// their rigid part per set removed (without_rigid_part); axis rotations likewise within
/// `axis_bound` [rad] about the two directions across each axis. A portable generator: the same
/// seed gives the same errors everywhere. Throws ParameterError ("joint_errors", "axis_errors") for
/// a bound not in [0, kMaxJointError] or an axis bound not in [0, kMaxAxisError].
void random_geometry_errors(const Model& nominal, double bound, double axis_bound, std::uint64_t seed,
                            ParameterErrors& errors);

/// The largest joint-centre error a synthetic platform may have, per coordinate [m] (50 mm).
inline constexpr double kMaxJointError = 0.05;
/// The largest rotation of a U-joint's fixed axis a synthetic platform may have [rad] (10 deg).
inline constexpr double kMaxAxisError = 10.0 * kPi / 180.0;

}  // namespace hexatwist
