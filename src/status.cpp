// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/status.hpp"

namespace hexatwist {

std::string_view to_string(Status s) noexcept {
  switch (s) {
    case Status::Ok:
      return "ok";
    case Status::NonFiniteInput:
      return "non_finite_input";
    case Status::StrokeBelowMin:
      return "stroke_below_min";
    case Status::StrokeAboveMax:
      return "stroke_above_max";
    case Status::BendBase:
      return "bend_base";
    case Status::BendPlatform:
      return "bend_platform";
    case Status::SingularBase:
      return "singular_base";
    case Status::SingularPlatform:
      return "singular_platform";
    case Status::NoConvergence:
      return "no_convergence";
    case Status::SingularJacobian:
      return "singular_jacobian";
    case Status::MotorSpeedAboveMax:
      return "motor_speed_above_max";
    case Status::TorqueAboveMax:
      return "torque_above_max";
    case Status::MalformedInput:
      return "malformed_input";
    case Status::TooFewPoints:
      return "too_few_points";
    case Status::DegenerateRegistration:
      return "degenerate_registration";
    case Status::NotIdentifiable:
      return "not_identifiable";
    case Status::SolverNoConvergence:
      return "solver_no_convergence";
    case Status::PlatformSingularity:
      return "platform_singularity";
    case Status::AssemblyModeChanged:
      return "assembly_mode_changed";
    case Status::InvalidArgument:
      return "invalid_argument";
    case Status::SignUndecided:
      return "sign_undecided";
    case Status::ModelMismatch:
      return "model_mismatch";
  }
  return "unknown";
}

std::string_view describe(Status s) noexcept {
  switch (s) {
    case Status::Ok:
      return "ok";
    case Status::NonFiniteInput:
      return "input holds NaN or inf";
    case Status::StrokeBelowMin:
      return "leg shorter than its minimum length";
    case Status::StrokeAboveMax:
      return "leg longer than its maximum length";
    case Status::BendBase:
      return "base U-joint bent past its limit";
    case Status::BendPlatform:
      return "platform U-joint bent past its limit";
    case Status::SingularBase:
      return "leg too close to the base U-joint's fixed axis (singular joint)";
    case Status::SingularPlatform:
      return "leg too close to the platform U-joint's fixed axis (singular joint)";
    case Status::NoConvergence:
      return "forward kinematics did not converge";
    case Status::SingularJacobian:
      return "forward kinematics met a singular platform Jacobian";
    case Status::MotorSpeedAboveMax:
      return "a motor would have to turn faster than its speed limit";
    case Status::TorqueAboveMax:
      return "holding the load would take more torque than a motor's limit";
    case Status::MalformedInput:
      return "the input is not six comma-separated numbers";
    case Status::TooFewPoints:
      return "a registration needs at least three point pairs";
    case Status::DegenerateRegistration:
      return "the registration points are coincident or (nearly) collinear and do not fix the rotation";
    case Status::NotIdentifiable:
      return "the measurements do not determine every identified parameter (rank-deficient Jacobian or too few points)";
    case Status::SolverNoConvergence:
      return "the least-squares solver stopped before it converged";
    case Status::PlatformSingularity:
      return "the pose is too close to a platform singularity: the Jacobian's condition number exceeds its limit";
    case Status::AssemblyModeChanged:
      return "forward kinematics found a solution on another assembly mode than its start (the Jacobian determinant "
             "changed sign)";
    case Status::InvalidArgument:
      return "an option or argument is outside its documented range";
    case Status::SignUndecided:
      return "both thread senses explain the measurements about as well: the twist's sign is not decided";
    case Status::ModelMismatch:
      return "the identified model leaves an error that the tracker's noise does not explain";
  }
  return "unknown status";
}

}  // namespace hexatwist
