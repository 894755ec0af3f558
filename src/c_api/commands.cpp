// SPDX-License-Identifier: BSD-3-Clause
// C API: motor commands (paper Eq. 1-12), the full command report and the twist; real-time.
#include "c_api.hpp"
#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "hexatwist/kinematics/twist.hpp"

using namespace hexatwist;
using hexatwist::c_api::to_leg_inputs;
using hexatwist::c_api::to_play_state;

extern "C" {

hexatwist_status hexatwist_motor_commands(const hexatwist_model* model, const double pose[6],
                                          hexatwist_strategy strategy, double command[HEXATWIST_LEGS],
                                          hexatwist_limit* limit) {
  if (model == nullptr || pose == nullptr || command == nullptr ||
      (strategy != HEXATWIST_CONVENTIONAL && strategy != HEXATWIST_COMPENSATED))
    return HEXATWIST_INVALID_ARGUMENT;
  Vector6d cmd;
  LimitReport report;
  const Status s =
      motor_commands(model->model, c_api::to_pose(pose),
                     strategy == HEXATWIST_COMPENSATED ? Strategy::Compensated : Strategy::Conventional, cmd, report);
  c_api::from_limit(report, limit);
  if (s == Status::Ok) c_api::from_vector(cmd, command);
  return c_api::to_c(s);
}

hexatwist_leg_inputs hexatwist_leg_inputs_default(void) {
  hexatwist_leg_inputs in;
  for (int i = 0; i < HEXATWIST_LEGS; ++i) in.force[i] = in.temperature[i] = NAN;
  return in;
}

void hexatwist_play_start(const hexatwist_model* model, hexatwist_play_state* play) {
  if (model == nullptr || play == nullptr) return;
  PlayState p;
  start_play(model->model, model->model.home_command(), p);
  play->started = 1;
  c_api::from_vector(p.direction, play->direction);
  c_api::from_vector(p.last, play->last);
}

hexatwist_status hexatwist_motor_commands_under(const hexatwist_model* model, const double pose[6],
                                                hexatwist_strategy strategy, const hexatwist_leg_inputs* inputs,
                                                hexatwist_play_state* play, double command[HEXATWIST_LEGS],
                                                hexatwist_limit* limit) {
  if (model == nullptr || pose == nullptr || command == nullptr ||
      (strategy != HEXATWIST_CONVENTIONAL && strategy != HEXATWIST_COMPENSATED))
    return HEXATWIST_INVALID_ARGUMENT;
  const LegInputs in = to_leg_inputs(inputs);
  PlayState state = to_play_state(play);
  Vector6d cmd;
  LimitReport report;
  const Status s = motor_commands(model->model, c_api::to_pose(pose),
                                  strategy == HEXATWIST_COMPENSATED ? Strategy::Compensated : Strategy::Conventional,
                                  in, play != nullptr ? &state : nullptr, cmd, report);
  c_api::from_limit(report, limit);
  if (s == Status::Ok) {
    c_api::from_vector(cmd, command);
    if (play != nullptr) {
      play->started = state.started ? 1 : 0;
      c_api::from_vector(state.direction, play->direction);
      c_api::from_vector(state.last, play->last);
    }
  }
  return c_api::to_c(s);
}

hexatwist_status hexatwist_compute_commands(const hexatwist_model* model, const double pose[6],
                                            hexatwist_command_report* report) {
  return hexatwist_compute_commands_under(model, pose, nullptr, nullptr, report);
}

hexatwist_status hexatwist_compute_commands_under(const hexatwist_model* model, const double pose[6],
                                                  const hexatwist_leg_inputs* inputs, const hexatwist_play_state* play,
                                                  hexatwist_command_report* report) {
  if (model == nullptr || pose == nullptr || report == nullptr) return HEXATWIST_INVALID_ARGUMENT;
  CommandReport r;
  const PlayState state = to_play_state(play);
  const Status s = compute_commands(model->model, c_api::to_pose(pose), to_leg_inputs(inputs),
                                    play != nullptr ? &state : nullptr, r);
  c_api::from_vector(r.legs.length, report->length);
  c_api::from_vector(r.twist, report->twist);
  c_api::from_vector(r.length_error, report->length_error);
  c_api::from_vector(r.conventional, report->conventional);
  c_api::from_vector(r.compensated, report->compensated);
  c_api::from_limit(r.limit, &report->limit);
  // The condition number and the nearest limit exist wherever inverse kinematics does.
  double condition = NAN;
  LimitReport nearest;
  double margin = NAN;
  if (s != Status::NonFiniteInput && r.legs.length.allFinite()) {
    (void)jacobian_condition(model->model, r.legs, condition);  // PlatformSingularity still gives the number
    nearest_limit(model->model, r.legs, condition, nearest, margin);
  }
  report->condition = condition;
  c_api::from_limit(nearest, &report->nearest);
  report->nearest_margin = margin;
  return c_api::to_c(s);
}

hexatwist_status hexatwist_twist(const hexatwist_model* model, const double pose[6], double twist_out[HEXATWIST_LEGS]) {
  if (model == nullptr || pose == nullptr || twist_out == nullptr) return HEXATWIST_INVALID_ARGUMENT;
  LegState legs;
  if (const Status s = inverse_kinematics(model->model, c_api::to_pose(pose), legs); s != Status::Ok)
    return c_api::to_c(s);
  Vector6d dtheta;
  const Status s = twist(model->model, legs, dtheta);
  if (s == Status::Ok) c_api::from_vector(dtheta, twist_out);
  return c_api::to_c(s);
}

}  // extern "C"
