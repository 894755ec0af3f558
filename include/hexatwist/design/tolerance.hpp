// SPDX-License-Identifier: BSD-3-Clause
// Tolerance analysis (docs/theory/design.md §18): how accurate a platform built with manufacturing
// errors is, before it is built. Monte Carlo over sampled platforms driven by the nominal
// compensated commands, and the linearised (covariance) answer, checked against each other; a
// calibration step plugs in between the sampled platform and its controller.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "hexatwist/calibration/registration.hpp"
#include "hexatwist/kinematics/forward.hpp"

namespace hexatwist {

/// Standard deviations of the manufacturing errors, the same for every leg, independent.
struct ToleranceSigmas {
  double base_joint = 50e-6;            ///< base U-joint centre, per coordinate [m, B]
  double platform_joint = 50e-6;        ///< platform U-joint centre, per coordinate [m, P]
  double base_axis = deg2rad(0.1);      ///< fixed axis ja, rotation about each of two normals to it [rad]
  double platform_axis = deg2rad(0.1);  ///< fixed axis jd alike [rad]
  double lead = 50e-6;                  ///< relative lead error (the screw's lead class) [-]
  double offset = 0.1e-3;               ///< zero offset of the leg (length at the drive's reference) [m]
};

/// The widest sigmas a study takes: 0.1 m for a joint's centre and the zero offset (1e5 um),
/// 10 deg for an axis, 0.1 (1e5 ppm) for the lead (beyond, the errors are not small and the
/// linear model and the sampled platforms stop meaning a manufacturing tolerance).
inline constexpr double kMaxSigmaLength = 0.1, kMaxSigmaAxis = 0.17453292519943295, kMaxSigmaLead = 0.1;

/// The one check of ToleranceSigmas (the study's functions run it; the CLI and Python reach it
/// through them or call it first): throws hexatwist::ParameterError naming the field (base_joint,
/// platform_joint, base_axis, platform_axis, lead, offset) that is not from 0 to its maximum.
void check_tolerance_sigmas(const ToleranceSigmas& sigmas);

/// Errors per leg, in this order: base joint x, y, z [m, B]; platform joint x, y, z [m, P]; base
/// axis turned about e1, e2 [rad]; platform axis alike [rad]; relative lead error [-]; zero
/// offset [m]. e1 = unit(axis x z) (unit(axis x x) for a vertical axis), e2 = axis x e1.
inline constexpr int kLegErrors = 12;
/// Errors of a platform: leg 1's twelve, then leg 2's, ...
inline constexpr int kPlatformErrors = kLegs * kLegErrors;
using PlatformErrors = Eigen::Matrix<double, kPlatformErrors, 1>;

/// The standard deviations in the order of PlatformErrors (0 for the lead of a leg without lead).
PlatformErrors error_sigmas(const Model& nominal, const ToleranceSigmas& sigmas);

/// The errors of sample `index` of a study seeded `seed`: independent normals scaled by
/// error_sigmas, the same for a given (seed, index) whatever else is drawn.
PlatformErrors sample_errors(const Model& nominal, const ToleranceSigmas& sigmas, std::uint64_t seed,
                             std::uint64_t index);

/// The platform built with `errors`: joints moved, fixed axes turned, each lead scaled by (1 +
/// error) while its drive converts lengths with the nominal lead, zero offsets added; the drives
/// referenced to the nominal home commands (what the controller's homing sets).
ModelSpec real_platform(const Model& nominal, const PlatformErrors& errors);

/// What a calibration leaves a sampled platform: the configuration its controller runs, and the
/// frames of the calibrated machine, in which the study measures its errors.
struct CalibratedController {
  ModelSpec spec;  ///< the controller's configuration (preset to the nominal one)
  /// The real platform's base frame B in the controller's base frame, as the calibration places it
  /// (identity: the controller's B is the real one).
  RigidTransform X_CB;
  /// The controller's platform frame in the real platform's P (identity: the real P).
  RigidTransform X_PC;
};

/// A calibration: from the nominal model and a sampled real platform (`index` of the study), its
/// controller. A status other than Ok counts the platform as failed. Point A's error is then the
/// real observation point against where the controller's model puts it, in the frames above.
using CalibrationStep = std::function<Status(const Model& nominal, const Model& real, std::uint64_t index,
                                             CalibratedController& controller)>;

/// The floor of every calibration: a controller that runs the real platform's own model, in its frames.
CalibrationStep perfect_calibration_step();

/// Settings of a study.
struct ToleranceOptions {
  ToleranceSigmas sigmas;
  std::uint64_t seed = 1;
  CalibrationStep calibration;  ///< empty: the controller runs the nominal model
  bool linear_worst = true;     ///< also the linear model's worst point error per platform
  int threads = 1;              ///< 0 = every core; the result does not depend on it
};

/// Counts of errors in logarithmic bins: 1e-12 m (or rad) to 1e3, 200 bins a decade, plus one
/// below and one above; mergeable exactly (integer counts).
struct ErrorHistogram {
  static constexpr double kLowest = 1e-12;
  static constexpr int kPerDecade = 200;
  static constexpr int kDecades = 15;
  static constexpr int kBins = kPerDecade * kDecades + 2;
  std::vector<std::uint64_t> counts = std::vector<std::uint64_t>(kBins, 0);
  /// Counts one value [m or rad].
  void add(double value) noexcept;
  /// Adds another histogram's counts.
  void merge(const ErrorHistogram& other) noexcept;
  /// Values counted.
  std::uint64_t total() const noexcept;
  /// The q-quantile (0 < q < 1), interpolated geometrically inside its bin; NaN when empty.
  double quantile(double q) const noexcept;
  /// The share of the values counted that are at most `value`, interpolated as quantile() (its
  /// inverse); NaN when empty.
  double cdf(double value) const noexcept;
};

/// What a study returns for a range of sampled platforms: per platform its worst and RMS errors
/// over the poses, and the pooled histograms of every (platform, pose) error. Platform k's numbers
/// depend only on (seed, k) and the poses: chunks concatenate to the whole study bit for bit.
struct ToleranceChunk {
  std::uint64_t first = 0;              ///< index of the first platform
  std::vector<double> max_point;        ///< largest |point A error| over the poses [m]
  std::vector<double> rms_point;        ///< its RMS over the poses [m]
  std::vector<double> max_position;     ///< largest |pivot position error| [m]
  std::vector<double> max_orientation;  ///< largest orientation error (rotation angle) [rad]
  /// Largest |point A error| of the linear model, same errors [m] (after a calibration, the same
  /// tracker noise: ToleranceLinear::draw)
  std::vector<double> max_point_linear;
  std::vector<std::uint32_t> failures;    ///< poses where the controller refused or the FK failed (all: no controller)
  std::vector<std::uint8_t> calibration;  ///< the status of each platform's calibration (Ok without one)
  ErrorHistogram point, position, orientation;  ///< pooled over platforms and poses [m, m, rad]
  std::size_t size() const noexcept { return max_point.size(); }
};

/// The linearised model of the errors at each pose: the pose error dx = A(q) e for errors e
/// (implicit function theorem through the motor-side residual, its parameter derivatives by
/// central differences on real_platform), and the covariances it gives.
struct ToleranceLinear {
  std::vector<Eigen::Matrix<double, 3, kPlatformErrors>> point;  ///< d(point A) / d(errors) per pose [m per unit]
  std::vector<Matrix3d> point_covariance;                        ///< per pose [m^2]
  std::vector<Matrix3d> position_covariance;                     ///< [m^2]
  std::vector<Matrix3d> orientation_covariance;                  ///< [rad^2]
  /// After a calibration (calibrated_linear, tolerance_calibration.hpp), instead of `point`: J L per
  /// pose, d(point A error)/d(identified parameters) times a square root of their covariance
  /// C = L L^T, so that J L z is the linear model's point error for the parameter errors L z [m]
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>> point_factor;
  /// With point_factor: the coordinates z (standard normal) of platform `index`'s parameter errors
  /// that the linear model gives its calibration's errors (its tracker noise)
  std::function<void(std::uint64_t index, Eigen::VectorXd& z)> draw;
};

/// The linear model at every pose of `poses` for the nominal commands. Returns the status of a
/// pose whose commands or Jacobian fail (a pose outside the nominal workspace).
[[nodiscard]] Status tolerance_linear(const Model& nominal, const std::vector<Pose>& poses,
                                      const ToleranceSigmas& sigmas, ToleranceLinear& out, int threads = 1);

/// Platforms [first, first + count) of the study over `poses` (each inside the nominal
/// workspace): each sampled (sample_errors), built (real_platform), calibrated if asked, driven by
/// its controller's compensated commands at every pose, its pose found by twist-aware forward
/// kinematics from the commanded one; errors against the commanded pose (in the calibration's frames).
/// `linear` (required when options.linear_worst) gives the linear model for max_point_linear.
/// Returns the status of a pose the nominal model refuses.
[[nodiscard]] Status tolerance_chunk(const Model& nominal, const std::vector<Pose>& poses,
                                     const ToleranceOptions& options, std::uint64_t first, std::size_t count,
                                     ToleranceChunk& out, const ToleranceLinear* linear = nullptr);

/// Appends `next` (whose first platform follows `into`'s last) to `into`.
void append_chunk(ToleranceChunk& into, const ToleranceChunk& next);

/// Median, 95th percentile and largest value of an error.
struct ErrorQuantiles {
  double median = NAN;
  double p95 = NAN;
  double max = NAN;
};

/// The probability that |z| <= r for z ~ N(0, C) in 3-D (C symmetric positive semi-definite):
/// one axis by Gauss-Legendre, the other two in closed form over a circle of directions.
double gaussian_norm_cdf(const Matrix3d& C, double r) noexcept;

/// The q-quantile of |z| for z drawn from an equal mixture of N(0, C_k) (a pose drawn uniformly,
/// then the errors): the linearised study's answer [m or rad].
double gaussian_norm_mixture_quantile(const std::vector<Matrix3d>& covariances, double q, int threads = 1);

/// The linearised study's cumulative distribution of |z| (the equal mixture of N(0, C_k)) at each
/// of `values` [m or rad].
std::vector<double> gaussian_norm_mixture_cdf(const std::vector<Matrix3d>& covariances,
                                              const std::vector<double>& values, int threads = 1);

/// A study's summary.
struct ToleranceSummary {
  std::size_t platforms = 0, poses = 0;
  std::uint64_t failures = 0;  ///< (platform, pose) pairs without an error (refused, FK or calibration failed)
  /// Platforms by the status of their calibration (index: the Status; all Ok without one)
  std::array<std::uint64_t, static_cast<std::size_t>(kLastStatus) + 1> calibration{};
  ErrorQuantiles point, position, orientation;                       ///< Monte Carlo, pooled over platforms and poses
  ErrorQuantiles point_linear, position_linear, orientation_linear;  ///< the covariance answer (no max)
  ErrorQuantiles worst_point;         ///< per platform, the largest point error over the poses: Monte Carlo
  ErrorQuantiles worst_point_linear;  ///< the same with the linear model and the same errors
  ErrorQuantiles worst_position, worst_orientation;
};

/// The covariance answer's quantiles (point_linear, position_linear, orientation_linear: median
/// and 95th percentile of the pooled mixtures, gaussian_norm_mixture_quantile) into `summary`.
void linear_quantiles(const ToleranceLinear& linear, ToleranceSummary& summary, int threads = 1);

/// The summary of a whole study (`chunk` from platform 0) and its linear model (may be null: the
/// linear quantiles stay NaN; linear_quantiles fills them).
ToleranceSummary summarize_tolerance(const ToleranceChunk& chunk, std::size_t poses, const ToleranceLinear* linear,
                                     int threads = 1);

}  // namespace hexatwist
