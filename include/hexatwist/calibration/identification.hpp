// Identification of what the model needs from tracker measurements (issue 5): the screw lead, the
// sign of the twist term, the legs' zero-length offsets, the observation point and the tracker
// frame, by nonlinear least squares on the observation point's positions at commanded motor-side
// lengths, with standard deviations and an identifiability check. Theory: docs/theory.md §13.
#pragma once

#include <array>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "hexatwist/calibration/registration.hpp"
#include "hexatwist/kinematics/forward.hpp"

namespace hexatwist {

/// One tracker measurement: where the observation point was seen while the legs stood at the
/// motor-side lengths they were commanded to.
struct Observation {
  Vector6d motor = Vector6d::Zero();  ///< commanded motor-side lengths m_k [m]
  Vector3d p_T = Vector3d::Zero();    ///< measured observation point [m, T]
};

/// How a lead that differs from the nominal one shows in the measurements (theory §13).
enum class LeadEffect {
  TwistOnly,       ///< through the twist term only: the commanded lengths are the real motor-side lengths
  TwistAndTravel,  ///< also through the travel: the drives turned the screws by the nominal lead's angles
};

/// Number of continuous parameters identified: lead, six offsets, A, rotation and translation of X_BT.
inline constexpr int kIdentifiedParameters = 16;
/// Fewest observations an identification accepts: 3K equations must exceed the 16 parameters.
inline constexpr int kMinObservations = kIdentifiedParameters / 3 + 1;
/// Position of each group in ParameterVector, covariance and Jacobian columns.
inline constexpr int kLeadIndex = 0;          ///< lead [m]
inline constexpr int kOffsetIndex = 1;        ///< length offsets of legs 1..6 [m]
inline constexpr int kObservationIndex = 7;   ///< observation point x, y, z [m, P]
inline constexpr int kRotationIndex = 10;     ///< rotation of X_BT: R_BT -> exp(dw) R_BT, dw [rad, B]
inline constexpr int kTranslationIndex = 13;  ///< translation of X_BT [m, B]

using ParameterVector = Eigen::Matrix<double, kIdentifiedParameters, 1>;
using ParameterMatrix = Eigen::Matrix<double, kIdentifiedParameters, kIdentifiedParameters>;

/// Name of parameter `i` for reports: "lead", "offset 1".."offset 6", "A x".., "rotation x"..,
/// "translation x".. ("?" outside 0..15).
std::string_view parameter_name(int i) noexcept;

/// One candidate for the platform and the tracker placement.
struct PlatformParameters {
  double lead = 0.0;                          ///< screw lead, one for all six legs [m]
  double twist_sign = 1.0;                    ///< sign of the twist term: +1 right-hand thread, -1 left (theory §4)
  Vector6d length_offset = Vector6d::Zero();  ///< real minus commanded motor-side length delta_i [m]
  Vector3d observation_P = Vector3d::Zero();  ///< observation point A [m, P]
  RigidTransform X_BT;                        ///< tracker frame in the base frame: p_B = R p_T + t
};

/// Settings of identify.
struct IdentificationOptions {
  LeadEffect lead_effect = LeadEffect::TwistOnly;  ///< measurement model of the lead
  int max_iterations = 100;                        ///< solver iterations per sign
  /// Largest accepted condition number of the column-scaled Jacobian; above it some parameter
  /// combination is undetermined (exact confounding gives about 1e15).
  double max_condition = 1e8;
  FkOptions fk;  ///< forward kinematics of every observation
};

/// The solve with the twist sign held at one value.
struct SignFit {
  double twist_sign = 0.0;                      ///< the sign held
  Status status = Status::SolverNoConvergence;  ///< Ok, SolverNoConvergence or what forward kinematics returned
  double cost = std::numeric_limits<double>::infinity();  ///< half the sum of squared residuals at the end [m^2]
  int iterations = 0;                                     ///< solver iterations
  bool lead_at_bound = false;                             ///< the lead ended at 0: this sign cannot explain the data
  std::string message;                                    ///< the solver's account of why it stopped
  PlatformParameters estimate;                            ///< where it stopped
};

/// Result of identify (caller-owned). `estimate`, `sd`, `covariance` and the residuals after are
/// meaningful when the status is Ok (and, as the solver left them, for SolverNoConvergence).
struct Identification {
  PlatformParameters estimate;                   ///< least-squares estimate with the chosen sign
  ParameterVector sd = ParameterVector::Zero();  ///< standard deviations, parameter order [m; rad for the rotation]
  ParameterMatrix covariance = ParameterMatrix::Zero();  ///< sigma^2 (J^T J)^-1 in the parameter order
  /// Noise per coordinate from the fit, sqrt(sum |e|^2 / (3K - 16)) [m]: compare with the tracker's.
  double sigma = std::numeric_limits<double>::quiet_NaN();
  int count = 0;              ///< observations K
  Registration registration;  ///< the start: Kabsch of the points onto the nominal model's A
  double rms_before =
      std::numeric_limits<double>::quiet_NaN();  ///< rms 3-D residual of the nominal model after Kabsch [m]
  double rms_after = std::numeric_limits<double>::quiet_NaN();  ///< rms 3-D residual at the estimate [m]
  double max_after = std::numeric_limits<double>::quiet_NaN();  ///< largest 3-D residual at the estimate [m]
  int max_after_index = -1;                                     ///< 0-based observation with the largest residual
  std::vector<Vector3d> residual_B;  ///< per observation, X_BT p_T minus the model's A at the estimate [m, B]
  std::array<SignFit, 2> fits;       ///< the solves with sign +1 ([0]) and -1 ([1])
  /// Cost of the rejected sign over the chosen one: far above 1 when the data fix the sign.
  double cost_ratio = std::numeric_limits<double>::quiet_NaN();
  /// Condition number of the column-scaled Jacobian at the estimate (at the start if the check there failed).
  double condition = std::numeric_limits<double>::infinity();
  ParameterVector weakest = ParameterVector::Zero();  ///< least-determined unit combination of column-scaled parameters
  std::string reason;  ///< for a status other than Ok: what failed, naming the parameters or the observation
};

/// Estimates lead, twist sign, length offsets, observation point and X_BT from the observations
/// by nonlinear least squares (Ceres, Levenberg-Marquardt, exact Jacobians by the implicit
/// function theorem through twist-aware forward kinematics), once per twist sign from the
/// nominal model and a Kabsch start; keeps the sign of lower cost. Returns Ok, NonFiniteInput,
/// NotIdentifiable (too few observations, a failed start registration, a rank-deficient
/// Jacobian, a leg without U-joint axes), SolverNoConvergence, or a forward kinematics status
/// that stopped both solves; `out.reason` says which in one line.
[[nodiscard]] Status identify(const Model& nominal, std::span<const Observation> observations, Identification& out,
                              const IdentificationOptions& options = {});

/// Residuals e_k = X_BT p_T,k - A_B,k of the candidate `p` (3K, observation k at rows 3k..3k+2)
/// [m, B], and optionally their Jacobian (3K x 16) with respect to the parameters in the order
/// of ParameterVector (rotation as the left perturbation dw). Forward kinematics starts from home
/// for every observation. TwistAndTravel needs nominal leads > 0 (identify checks it). Returns Ok
/// or the first failing forward kinematics status.
[[nodiscard]] Status identification_residuals(const Model& nominal, std::span<const Observation> observations,
                                              const PlatformParameters& p, const IdentificationOptions& options,
                                              Eigen::VectorXd& residuals, Eigen::MatrixXd* J);

/// The nominal specification corrected by an estimate: every leg's lead, its thread from the twist
/// sign (driven side kept, theory §4) and its length offset; the observation point.
ModelSpec corrected_spec(const ModelSpec& nominal, const PlatformParameters& estimate);

}  // namespace hexatwist
