// What a real platform may have that its nominal model does not, in the parameters a laser tracker
// can reveal: the screw lead, the sign of the twist term, each leg's zero-length offset and the
// observation point. `hexatwist synth` builds a platform with known errors from these; an
// identification estimates them (docs/theory.md §12, §13).
#pragma once

#include "hexatwist/kinematics/model.hpp"

namespace hexatwist {

/// The real platform against the nominal model. The default is no error.
struct ParameterErrors {
  /// Relative error of the lead on every leg: real lead = (1 + lead_error) nominal lead [-]. The
  /// nut then travels (1 + lead_error) times as far per motor turn, and the twist term
  /// (twist_gain, Eq. 10) is (1 + lead_error) times as large.
  double lead_error = 0.0;
  /// The real twist term has the opposite sign (the other thread hand than the model says; the
  /// sign the paper's Eq. 9 loses).
  bool flip_twist_sign = false;
  /// Real minus nominal motor-side length of each leg at the same motor angle [m]: the error of
  /// each leg's zero (home) length.
  Vector6d zero_offset = Vector6d::Zero();
  /// Real minus nominal observation point [m, P].
  Vector3d observation_offset_P = Vector3d::Zero();
};

/// The real platform's model: `nominal` with every leg's lead scaled by 1 + lead_error, the thread
/// hand flipped if flip_twist_sign, and the observation point moved by observation_offset_P.
/// Throws hexatwist::Error (from Model) if that model is invalid, e.g. lead_error <= -1.
Model real_model(const Model& nominal, const ParameterErrors& errors);

/// The real motor-side lengths [m] of the legs when the nominal model reads `motor_nominal` [m]
/// from the encoders: each leg is at its motor angle theta = (m - l_home) / c, where the real nut
/// has travelled (1 + lead_error) c theta and the leg's zero is off by zero_offset:
/// m_real = l_home + zero_offset + (1 + lead_error) (m - l_home).
void real_motor_lengths(const Model& nominal, const ParameterErrors& errors, const Vector6d& motor_nominal,
                        Vector6d& motor_real) noexcept;

}  // namespace hexatwist
