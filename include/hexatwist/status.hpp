// SPDX-License-Identifier: BSD-3-Clause
// Outcome codes of the numerical functions (the real-time path never throws).
#pragma once

#include <string_view>

namespace hexatwist {

/// Result of a numerical call. `Ok` is the only success; every other value names what failed.
enum class Status : int {
  Ok = 0,
  NonFiniteInput,          ///< a pose, length or guess holds NaN or inf
  StrokeBelowMin,          ///< a leg is shorter than its minimum length
  StrokeAboveMax,          ///< a leg is longer than its maximum length
  BendBase,                ///< the base U-joint bends further than the bend limit
  BendPlatform,            ///< the platform U-joint bends further than the bend limit
  SingularBase,            ///< the leg is (nearly) parallel to the base U-joint's fixed axis
  SingularPlatform,        ///< the leg is (nearly) parallel to the platform U-joint's fixed axis
  NoConvergence,           ///< forward kinematics did not reach its tolerance
  SingularJacobian,        ///< forward kinematics met a singular platform Jacobian
  MotorSpeedAboveMax,      ///< a trajectory needs a motor faster than its speed limit
  TorqueAboveMax,          ///< holding the load at a pose needs more torque than a motor's limit
  MalformedInput,          ///< an input line is not six numbers (see LineParse)
  TooFewPoints,            ///< a point registration got fewer than three point pairs
  DegenerateRegistration,  ///< registration points are coincident or (nearly) collinear: the rotation is not determined
  NotIdentifiable,         ///< the measurements do not determine every identified parameter
  SolverNoConvergence,     ///< the least-squares solver stopped before converging
  PlatformSingularity,     ///< the pose is too close to a platform (Jacobian) singularity: the motor-side Jacobian's
                           ///< condition number exceeds limits.jacobian_condition_max
  AssemblyModeChanged,  ///< forward kinematics found a solution on another assembly mode than its start (the Jacobian
                        ///< determinant changed sign)
  InvalidArgument,      ///< an option or argument outside its documented range (check_fk_options, a length <= 0)
  SignUndecided,        ///< an identification: both thread senses explain the measurements about as well
  ModelMismatch,  ///< an identification: the identified model leaves an error the tracker's noise does not explain
};

/// The last status: every status is in Ok .. kLastStatus.
inline constexpr Status kLastStatus = Status::ModelMismatch;

/// True for the statuses that mean "this pose is outside a limit".
constexpr bool is_limit(Status s) noexcept {
  return s == Status::StrokeBelowMin || s == Status::StrokeAboveMax || s == Status::BendBase ||
         s == Status::BendPlatform || s == Status::SingularBase || s == Status::SingularPlatform ||
         s == Status::MotorSpeedAboveMax || s == Status::TorqueAboveMax || s == Status::PlatformSingularity;
}

/// Stable snake_case name of a status, as written in JSON (`"stroke_above_max"`).
std::string_view to_string(Status s) noexcept;

/// One-sentence description of a status for people.
std::string_view describe(Status s) noexcept;

}  // namespace hexatwist
