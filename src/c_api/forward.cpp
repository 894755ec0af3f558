// SPDX-License-Identifier: BSD-3-Clause
// C API: forward kinematics from a guess and along a motion (the tracker); real-time.
#include "hexatwist/kinematics/forward.hpp"
#include "c_api.hpp"

using namespace hexatwist;

namespace {

bool valid_kind(hexatwist_length_kind kind) noexcept { return kind == HEXATWIST_GEOMETRIC || kind == HEXATWIST_MOTOR; }

LengthKind to_kind(hexatwist_length_kind kind) noexcept {
  return kind == HEXATWIST_MOTOR ? LengthKind::Motor : LengthKind::Geometric;
}

FkOptions to_options(const hexatwist_fk_options* o) noexcept {
  FkOptions options;
  if (o == nullptr) return options;
  options.max_iterations = o->max_iterations;
  options.tolerance = o->tolerance;
  options.max_step_translation = o->max_step_translation;
  options.max_step_rotation = o->max_step_rotation;
  return options;
}

void from_result(const FkResult& r, hexatwist_fk_result* out) noexcept {
  c_api::from_pose(pose_from_placement(r.placement), out->pose);
  out->iterations = r.iterations;
  out->residual = r.residual;
  out->condition = r.condition;
}

FkTracker to_tracker(const hexatwist_fk_tracker& t) noexcept {
  FkTracker tracker;
  tracker.last.t = Vector3d(t.t[0], t.t[1], t.t[2]);
  tracker.last.R_BP = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(t.R);
  tracker.det_sign = t.det_sign;
  tracker.valid = t.valid != 0;
  return tracker;
}

void from_tracker(const FkTracker& tracker, hexatwist_fk_tracker& t) noexcept {
  for (int k = 0; k < 3; ++k) t.t[k] = tracker.last.t[k];
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(t.R) = tracker.last.R_BP;
  t.det_sign = tracker.det_sign;
  t.valid = tracker.valid ? 1 : 0;
}

}  // namespace

extern "C" {

hexatwist_fk_options hexatwist_fk_default_options(void) {
  const FkOptions o;
  return hexatwist_fk_options{o.max_iterations, o.tolerance, o.max_step_translation, o.max_step_rotation};
}

hexatwist_status hexatwist_forward_kinematics(const hexatwist_model* model, const double lengths[HEXATWIST_LEGS],
                                              hexatwist_length_kind kind, const double guess[6],
                                              const hexatwist_fk_options* options, hexatwist_fk_result* result) {
  if (model == nullptr || lengths == nullptr || result == nullptr || !valid_kind(kind))
    return HEXATWIST_INVALID_ARGUMENT;
  const Placement start = guess != nullptr ? placement_from_pose(c_api::to_pose(guess)) : Placement{};
  FkResult r;
  const Status s =
      forward_kinematics(model->model, c_api::to_vector(lengths), to_kind(kind), start, r, to_options(options));
  from_result(r, result);
  return c_api::to_c(s);
}

hexatwist_status hexatwist_forward_kinematics_tracked(const hexatwist_model* model,
                                                      const double lengths[HEXATWIST_LEGS], hexatwist_length_kind kind,
                                                      hexatwist_fk_tracker* tracker,
                                                      const hexatwist_fk_options* options,
                                                      hexatwist_fk_result* result) {
  if (model == nullptr || lengths == nullptr || tracker == nullptr || result == nullptr || !valid_kind(kind))
    return HEXATWIST_INVALID_ARGUMENT;
  FkTracker t = to_tracker(*tracker);
  FkResult r;
  const Status s =
      forward_kinematics_tracked(model->model, c_api::to_vector(lengths), to_kind(kind), t, r, to_options(options));
  from_result(r, result);
  if (s == Status::Ok) from_tracker(t, *tracker);
  return c_api::to_c(s);
}

hexatwist_status hexatwist_forward_kinematics_tracked_under(
    const hexatwist_model* model, const double motor[HEXATWIST_LEGS], const hexatwist_leg_inputs* inputs,
    const hexatwist_play_state* play, hexatwist_fk_tracker* tracker, const hexatwist_fk_options* options,
    hexatwist_fk_result* result) {
  if (model == nullptr || motor == nullptr || tracker == nullptr || result == nullptr)
    return HEXATWIST_INVALID_ARGUMENT;
  FkTracker t = to_tracker(*tracker);
  FkResult r;
  const bool started = play != nullptr && play->started != 0;
  const Vector6d direction = started ? c_api::to_vector(play->direction) : Vector6d::Zero();
  const Status s = forward_kinematics_tracked(model->model, c_api::to_vector(motor), c_api::to_leg_inputs(inputs),
                                              started ? &direction : nullptr, t, r, to_options(options));
  from_result(r, result);
  if (s == Status::Ok) from_tracker(t, *tracker);
  return c_api::to_c(s);
}

void hexatwist_fk_tracker_reset(hexatwist_fk_tracker* tracker) {
  if (tracker != nullptr) *tracker = hexatwist_fk_tracker{};
}

hexatwist_status hexatwist_fk_tracker_set(const hexatwist_model* model, hexatwist_fk_tracker* tracker,
                                          const double pose[6], hexatwist_length_kind kind) {
  if (model == nullptr || tracker == nullptr || pose == nullptr || !valid_kind(kind)) return HEXATWIST_INVALID_ARGUMENT;
  FkTracker t;
  if (const Status s = fk_tracker_set(model->model, placement_from_pose(c_api::to_pose(pose)), to_kind(kind), t);
      s != Status::Ok)
    return c_api::to_c(s);
  from_tracker(t, *tracker);
  return HEXATWIST_OK;
}

}  // extern "C"
