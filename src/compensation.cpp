#include "hexatwist/compensation.hpp"

namespace hexatwist {
namespace {

// Names a failure that is not a limit (non-finite input, singular joint) in the report.
Status fail(LimitReport& report, Status status) noexcept {
  report = LimitReport{};
  report.status = status;
  return status;
}

}  // namespace

void length_error(const Model& model, const Vector6d& dtheta, Vector6d& error) noexcept {
  // Eq. (10): lenP_i = dtheta_i / 2pi * P_h, with the thread-hand sign in twist_gain.
  error = model.geometry().twist_gain.cwiseProduct(dtheta);
}

Status compute_commands(const Model& model, const Pose& pose, CommandReport& out) noexcept {
  out.limit = LimitReport{};
  if (!pose.is_finite()) return fail(out.limit, Status::NonFiniteInput);
  if (const Status s = inverse_kinematics(model, pose, out.legs); s != Status::Ok) return fail(out.limit, s);
  const Status pose_status = check_limits(model, out.legs, out.limit);
  // The twist is defined wherever no U-joint is singular, also outside the other limits.
  if (const Status s = twist(model, out.legs, out.twist); s != Status::Ok) {
    if (pose_status != Status::Ok) return pose_status;
    return fail(out.limit, s);
  }
  length_error(model, out.twist, out.length_error);
  // Eq. (11)-(12) as absolute motor-side lengths; both commands take the legs' zero errors out.
  out.conventional = out.legs.length - model.geometry().length_offset;
  out.compensated = out.conventional - out.length_error;
  if (pose_status != Status::Ok) return pose_status;
  return check_stroke(model, out.compensated, out.limit);
}

Status motor_commands(const Model& model, const Pose& pose, Strategy strategy, Vector6d& command,
                      LimitReport& report) noexcept {
  LegState legs;
  if (!pose.is_finite()) return fail(report, Status::NonFiniteInput);
  // The Placement overload: the Pose one would test finiteness a second time.
  if (const Status s = inverse_kinematics(model, placement_from_pose(pose), legs); s != Status::Ok)
    return fail(report, s);
  if (const Status s = check_limits(model, legs, report); s != Status::Ok) return s;
  const Vector6d& offset = model.geometry().length_offset;
  if (strategy == Strategy::Conventional || !model.has_twist()) {
    command = legs.length - offset;
    return Status::Ok;
  }
  Vector6d dtheta;
  if (const Status s = twist(model, legs, dtheta); s != Status::Ok) return fail(report, s);
  Vector6d compensated = legs.length - offset - model.geometry().twist_gain.cwiseProduct(dtheta);  // Eq. (12)
  if (const Status s = check_stroke(model, compensated, report); s != Status::Ok) return s;
  command = compensated;
  return Status::Ok;
}

}  // namespace hexatwist
