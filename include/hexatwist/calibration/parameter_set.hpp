// SPDX-License-Identifier: BSD-3-Clause
// The parameters an identification estimates, their order, names and gauge: screw leads, zero
// offsets, the twelve U-joint centres (in the gauge that keeps B and P the least-squares frames of
// their joints), the U-joint axes where the data determine them, the targets on the platform and
// the tracker frame; and the platform a parameter vector describes. Theory:
// docs/theory/calibration.md §13.
#pragma once

#include <array>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "hexatwist/kinematics/model.hpp"

namespace hexatwist {

/// Which platform parameters an identification fits.
enum class CalibrationModel {
  Basic,     ///< leads, thread sense, zero offsets, targets, tracker frame (the joints as configured)
  Geometry,  ///< also the twelve U-joint centres, and the axes AxisSelection names (theory §13)
};

/// How a lead that differs from the nominal one shows in the measurements (theory §13).
enum class LeadEffect {
  TwistOnly,  ///< through the twist term only: the drives' travel is right (their scale was set with the real lead)
  TwistAndTravel,  ///< also through the travel: the drives turn the screws by the nominal lead's angles
};

/// How many screw leads an identification fits (theory §13).
enum class LeadFit {
  Shared,  ///< one for every leg, unless the nominal leads differ (then one per leg)
  /// one per leg: screws of one type differ by their lead class, which the drives' travel shows
  /// (LeadEffect::TwistAndTravel: 50 ppm over a 0.2 m stroke is 10 um)
  PerLeg,
};

/// Which of the legs' effects (kinematics/leg_effects.hpp) an identification fits besides the
/// geometry, each as a shift of the legs' lengths linear in its parameters (theory §13b).
struct EffectFit {
  /// One compliance c for every leg [m/N]: the deflection c (F - F_ref) under the configuration's
  /// static load, F the static force at the station's pose (the nominal model's).
  bool load = false;
  /// Each leg's play b_i [m]: -(b_i / 2)(d - d_home), d the direction of the leg's approach to the
  /// station (from the stations' order: a leg approached from both sides determines its play).
  bool play = false;
  /// Each leg's length drift over the run a_i [m] and its curvature q_i [m], and the screws' common
  /// lead drift r [-]: a_i s + q_i s^2 + r s (u_i - h_i), s the run's time fraction (0 at the first
  /// observation, 1 at the last), u_i - h_i the travel from the drive's reference: the legs and
  /// screws warming as the motors and the hall do, at any rate that levels off or speeds up; the
  /// offsets and the lead are the legs' at the run's start.
  bool heat = false;
  /// Heat from the log's temperatures (every observation has one; identify decides): each leg's
  /// growth per kelvin k_i [m/K] and the screws' lead expansion a_P [1/K], k_i dT + a_P dT (u_i -
  /// h_i), dT the temperature above the run's first, `reference_temperature` [degC] (no
  /// curvature: the expansion is linear). The corrected configuration records them
  /// (length_expansion = k_i / length at home, lead_expansion, reference_temperature).
  bool measured = false;
  double reference_temperature = std::numeric_limits<double>::quiet_NaN();
  bool any() const noexcept { return load || play || heat; }
  /// Number of parameters: 1 + 6 + 13 at most.
  int count() const noexcept {
    return (load ? 1 : 0) + (play ? kLegs : 0) + (heat ? (measured ? kLegs + 1 : 2 * kLegs + 1) : 0);
  }
  /// "load,play,heat" (those fitted), "none" without any.
  std::string names() const;
};

/// The effects a comma-separated list names: "load", "play", "heat" in any order, or "none".
/// Throws hexatwist::Error naming the word that is none of them.
EffectFit effect_fit(std::string_view names);

/// One flag per U-joint fixed axis: legs 1..6 at the base, then legs 1..6 at the platform.
using AxisSelection = std::array<bool, 2 * kLegs>;

/// The layout of the parameter vector theta (caller-owned, built once per identification).
/// Order: leads (one, or one per leg where the nominal leads differ or LeadFit::PerLeg), the six zero offsets, the
/// legs' effects (EffectFit: compliance, plays, drifts and their curvatures), the base joints (12 gauge coordinates),
/// the platform joints (12), the selected axes (2 each), three coordinates per target [m, P], the tracker rotation dw
/// [rad, B] and translation [m, B]. Joints and axes only in the Geometry model.
class ParameterSet {
 public:
  /// The layout for `nominal` (its leads and `leads` decide one or six lead parameters).
  ParameterSet(const Model& nominal, CalibrationModel model, LeadEffect lead_effect, const AxisSelection& axes,
               int targets, LeadFit leads = LeadFit::Shared, EffectFit effects = {});
  ParameterSet() = default;

  CalibrationModel model() const noexcept { return model_; }
  LeadEffect lead_effect() const noexcept { return lead_effect_; }
  /// Number of parameters, the tracker frame's six included.
  int size() const noexcept { return size_; }
  /// Number of platform parameters (all but the tracker frame's six).
  int platform_size() const noexcept { return rotation_; }
  int lead_index() const noexcept { return 0; }
  int lead_count() const noexcept { return lead_count_; }
  int offset_index() const noexcept { return offset_; }
  /// The legs' effects fitted and their parameters' indices (-1 where not fitted): the compliance,
  /// the first of the six plays, the first of the six drifts (expansions per kelvin where
  /// measured), the first of their six curvatures (none where measured), the lead drift (lead
  /// expansion where measured).
  const EffectFit& effects() const noexcept { return effects_; }
  int effect_index() const noexcept { return offset_ + kLegs; }  ///< the first effect's parameter
  int compliance_index() const noexcept { return compliance_; }
  int play_index() const noexcept { return play_; }
  int drift_index() const noexcept { return drift_; }
  int curvature_index() const noexcept { return curvature_; }
  int lead_drift_index() const noexcept { return lead_drift_; }
  /// First gauge coordinate of the base / platform joints; -1 in the Basic model.
  int base_index() const noexcept { return base_; }
  int platform_index() const noexcept { return platform_; }
  /// First axis parameter; each selected axis has two (rotations about e1, e2 across it).
  int axis_index() const noexcept { return axis_; }
  const AxisSelection& axes() const noexcept { return axes_; }
  int axis_count() const noexcept { return axis_count_; }
  int target_index() const noexcept { return target_; }
  int targets() const noexcept { return targets_; }
  int rotation_index() const noexcept { return rotation_; }
  int translation_index() const noexcept { return rotation_ + 3; }

  /// The parameter's name for reports: "lead" or "lead 1" (and so on), "offset 1", "base joints g1"
  /// (gauge coordinates), "platform joints g1", "base axis 2 e1", "A x" (target 0) or "target 2 x",
  /// "rotation x", "translation x"; "?" outside.
  std::string name(int i) const;
  /// The parameter group a name belongs to ("lead", "offsets", "base joints", ...).
  std::string group(int i) const;

  /// Gauge basis of the base / platform joint displacements: an orthonormal 18 x 12 matrix whose
  /// columns span the displacements (joint i's x, y, z in rows 3i..3i+2) without a rigid part; the
  /// joint displacement is basis * (gauge coordinates).
  const Eigen::MatrixXd& base_basis() const noexcept { return base_basis_; }
  const Eigen::MatrixXd& platform_basis() const noexcept { return platform_basis_; }
  /// The two unit directions across selected axis `a` (0..11) of the nominal model, e1 and e2.
  const std::array<Vector3d, 2>& axis_directions(int a) const noexcept {
    return axis_directions_[static_cast<std::size_t>(a)];
  }

  /// The nominal parameters (tracker frame zero; targets other than 0 at zero until the data place them).
  Eigen::VectorXd nominal_vector() const;

  /// The platform that theta describes with the thread sense `sign` (+1: every leg's hand as
  /// configured, -1: every one flipped): the nominal specification with the joints, axes, leads,
  /// threads, zero offsets and target 0 (the observation point) replaced. The drives keep the
  /// nominal model's reference (home_command) and, with TwistAndTravel, its drive lead (theory §4).
  /// The fitted effects: with `with_effects` the stiffness 1 / c (rigid where c <= 0) and the plays
  /// (at least 0) replace the nominal ones (the corrected platform; the drift belongs to the run,
  /// not the platform); without it the legs are rigid and play-free in those effects, which the
  /// identification applies as length shifts (the measurement model).
  ModelSpec platform(const Eigen::VectorXd& theta, double sign, bool with_effects = false) const;

  /// Target t's position in theta [m, P].
  Vector3d target(const Eigen::VectorXd& theta, int t) const { return theta.segment<3>(target_ + 3 * t); }

  /// The nominal model's specification this layout was built from.
  const ModelSpec& nominal() const noexcept { return nominal_; }

 private:
  ModelSpec nominal_;
  Vector6d nominal_drive_lead_ = Vector6d::Zero();
  Vector6d nominal_home_command_ = Vector6d::Zero();
  CalibrationModel model_ = CalibrationModel::Basic;
  LeadEffect lead_effect_ = LeadEffect::TwistAndTravel;
  AxisSelection axes_{};
  EffectFit effects_{};
  int compliance_ = -1, play_ = -1, drift_ = -1, curvature_ = -1, lead_drift_ = -1;
  Vector6d length_home_ = Vector6d::Zero();  ///< the nominal legs' lengths at home [m]
  int lead_count_ = 1, offset_ = 1, base_ = -1, platform_ = -1, axis_ = -1, axis_count_ = 0, target_ = 7, targets_ = 1,
      rotation_ = 10, size_ = 16;
  Eigen::MatrixXd base_basis_, platform_basis_;
  std::array<std::array<Vector3d, 2>, 2 * kLegs> axis_directions_{};
};

/// Gauge basis of six points' displacements without a rigid part: an orthonormal 18 x 12 basis of
/// the displacements d with sum d_i = 0 and sum (x_i - c) x d_i = 0 (c the centroid), the exact
/// conditions under which the least-squares (Kabsch) frame of the moved points is that of `points`.
Eigen::MatrixXd gauge_basis(const LegVectors& points);

}  // namespace hexatwist
