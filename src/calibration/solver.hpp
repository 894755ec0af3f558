// SPDX-License-Identifier: BSD-3-Clause
// Internal: the least-squares solve of an identification (Ceres' Levenberg-Marquardt on the
// groups' residuals, the tracker rotation on SO(3)), and the column-scaled conditioning that
// decides which parameters the data determine (docs/theory/calibration.md §13).
#pragma once

#include <span>
#include <string>

#include <Eigen/Core>

#include "calibration/evaluator.hpp"
#include "hexatwist/calibration/identification.hpp"

namespace hexatwist::detail {

/// Levenberg-Marquardt from (theta, X_BT) with the thread sense held at `sign`; stations flagged
/// in `skip` are left out. The leads are bounded below by 0; a solve whose lead reaches it stops
/// and finishes with the leads held there (SignFit::lead_at_bound). `scatter_cost` (half the groups'
/// scatter, [m^2]) is added to the cost so that it is that of all points.
SignFit solve(const ParameterSet& set, Evaluator& evaluator, double sign, const Eigen::VectorXd& theta,
              const RigidTransform& X_BT, const IdentificationOptions& options, double scatter_cost,
              std::span<const char> skip = {});

/// Conditioning of J after scaling every column to unit norm (units and scales drop out).
struct Conditioning {
  double condition = std::numeric_limits<double>::infinity();
  Eigen::VectorXd weakest;         ///< least-determined unit combination of scaled parameters
  Eigen::MatrixXd inverse_normal;  ///< (J^T J)^-1, valid if the condition is finite
  int undetermined = 0;            ///< combinations above max_condition
  std::string involved;            ///< the parameters in them, by name (joints named per joint)
};

/// The conditioning of J (columns in set's order) against `max_condition`.
Conditioning conditioning(const ParameterSet& set, const Eigen::MatrixXd& J, double max_condition);

/// The normal deviate of an F(d1, d2) variate f by Paulson's approximation (Wilson-Hilferty for
/// both chi-squares); d2 = 0 means a known variance (chi-square of d1 over d1).
double f_normal_deviate(double f, double d1, double d2) noexcept;

}  // namespace hexatwist::detail
