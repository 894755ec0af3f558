// SPDX-License-Identifier: BSD-3-Clause
// Internal: what the C API's files share: the opaque model, conversions between C arrays and the
// library's types, and the guard that keeps C++ exceptions from crossing into C.
#pragma once

#include <cstring>
#include <string>

#include "hexatwist/c/hexatwist.h"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "hexatwist/kinematics/limits.hpp"
#include "hexatwist/kinematics/model.hpp"
#include "hexatwist/kinematics/pose.hpp"
#include "hexatwist/status.hpp"

/// The opaque model of the C API: a validated hexatwist::Model and its name as a C string.
struct hexatwist_model {
  hexatwist::Model model;
  std::string name;
};

namespace hexatwist::c_api {

/// Pose from {x, y, z, roll, pitch, yaw} [m, rad].
inline Pose to_pose(const double q[6]) noexcept {
  Pose p;
  p.position = Vector3d(q[0], q[1], q[2]);
  p.rpy = Vector3d(q[3], q[4], q[5]);
  return p;
}

/// {x, y, z, roll, pitch, yaw} [m, rad] of a pose.
inline void from_pose(const Pose& p, double q[6]) noexcept {
  for (int k = 0; k < 3; ++k) {
    q[k] = p.position[k];
    q[3 + k] = p.rpy[k];
  }
}

inline Vector6d to_vector(const double v[kLegs]) noexcept { return Eigen::Map<const Vector6d>(v); }

inline void from_vector(const Vector6d& v, double out[kLegs]) noexcept { Eigen::Map<Vector6d>{out} = v; }

inline hexatwist_status to_c(Status s) noexcept {
  return s == Status::InvalidArgument ? HEXATWIST_INVALID_ARGUMENT : static_cast<hexatwist_status>(static_cast<int>(s));
}

/// The C limit report: legs counted from 1, 0 for a limit of the whole platform.
inline void from_limit(const LimitReport& r, hexatwist_limit* out) noexcept {
  if (out == nullptr) return;
  out->status = to_c(r.status);
  out->leg = r.leg + 1;
  out->value = r.value;
  out->bound = r.bound;
}

/// The library's leg inputs from the C struct (NULL: the defaults, NaN everywhere).
inline LegInputs to_leg_inputs(const hexatwist_leg_inputs* inputs) noexcept {
  LegInputs in;
  if (inputs != nullptr) {
    in.force = to_vector(inputs->force);
    in.temperature = to_vector(inputs->temperature);
  }
  return in;
}

/// The library's play state from the C struct (NULL: not started, each leg from home).
inline PlayState to_play_state(const hexatwist_play_state* play) noexcept {
  PlayState state;
  if (play != nullptr) {
    state.started = play->started != 0;
    state.direction = to_vector(play->direction);
    state.last = to_vector(play->last);
  }
  return state;
}

/// Copies `message` into the caller's buffer, truncated and NUL-terminated (nothing if no buffer).
inline void write_error(const char* message, char* error, std::size_t size) noexcept {
  if (error == nullptr || size == 0) return;
  const std::size_t n = std::min(std::strlen(message), size - 1);
  std::memcpy(error, message, n);
  error[n] = '\0';
}

}  // namespace hexatwist::c_api
