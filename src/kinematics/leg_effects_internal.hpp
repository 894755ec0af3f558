// SPDX-License-Identifier: BSD-3-Clause
// Internal: the legs' static forces packet by packet (lanes.hpp), shared by static_leg_forces and
// the real-time command (compensation.cpp), which gives them from its pass in registers without a
// LegState: one computation, the same forces from either.
#pragma once

#include <array>

#include "hexatwist/kinematics/leg_effects.hpp"
#include "kinematics/gauss_jordan.hpp"
#include "kinematics/lanes.hpp"

namespace hexatwist::detail {

/// The legs' share of the generalised force of gravity, summed over the packets added so far.
struct LegLoads {
  lanes3 force = {}, moment = {};  ///< sum of f_i and of a_i x f_i over real legs [N, N m]
};

/// Adds packet k of the legs (unit axes s, arms a [m], inverse lengths [1/m]) under `load`: each leg's rod on
/// the platform joint and its housing and rod about the leg's axis, theory §4b:
/// f_i = m_r g + (M / l_i)(g - (s_i . g) s_i), g = (0, 0, -g0).
inline void add_leg_loads(const StaticLoadSpec& load, const lanes3& s, const lanes3& arm, lane_v inv_length, int k,
                          LegLoads& out) noexcept {
  const lane_v real = blend(gj::lane_index(k) < 6.0, splat<lane_v>(1.0), splat<lane_v>(0.0));
  const lane_v moment_over_length = load.leg_moment * inv_length;
  // g - (s . g) s = g0 (s_z s - e_z).
  const lane_v along = real * (load.gravity * moment_over_length * s.z);
  const lanes3 f = {along * s.x, along * s.y,
                    along * s.z - real * (load.gravity * (load.rod_mass + moment_over_length))};
  out.force = {out.force.x + f.x, out.force.y + f.y, out.force.z + f.z};
  const lanes3 m = cross(arm, f);
  out.moment = {out.moment.x + m.x, out.moment.y + m.y, out.moment.z + m.z};
}

/// Solves A^T F = G for the padded rows of A by the pivoted elimination; false where A is singular.
/// Out of line: the rare case, which would crowd the real-time command's registers.
[[gnu::noinline, gnu::cold]] inline bool solve_transposed(const PaddedRows& rows_of_A, const Vector6d& G,
                                                          Vector6d& force) noexcept {
  Columns transposed;  // A^T's columns are A's rows
  for (int i = 0; i < 6; ++i)
    for (int q = 0; q < kPackets; ++q) transposed.c[i][q] = rows_of_A[i][q];
  return gj_solve_system(transposed, G, force) > 0.0;
}

// The block solve below passes 4-lane vectors between inline lambdas only; on a target without AVX
// GCC notes that such a vector would be passed differently across a real call (-Wpsabi).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

/// F = J^-T G once every packet is added, from the padded rows of A = J diag(1, 1, 1, w, w, w)
/// (w = 1 / model.condition_length(), as the limits form it): A^T F = diag(1, 1, 1, w, w, w) G.
/// G adds the load's weight at its centre of mass (pose rotation R_BP) to the legs' share.
/// Returns InvalidArgument without a load, SingularJacobian where J is singular, NonFiniteInput
/// for a non-finite result.
[[nodiscard]] [[gnu::always_inline]] inline Status finish_leg_forces(const Model& model, const StaticLoadSpec& load,
                                                                     const Matrix3d& R_BP, const LegLoads& legs,
                                                                     const PaddedRows& rows_of_A,
                                                                     Vector6d& force) noexcept {
  if (!load.present) return Status::InvalidArgument;
  const Vector3d weight(0.0, 0.0, -load.gravity * load.mass);
  const Vector3d com_B = R_BP * (load.center_of_mass_P - model.spec().pivot_P);
  const Vector3d moment = com_B.cross(weight);
  const double w = 1.0 / model.condition_length();
  Vector6d G;
  G << weight.x() + sum_lanes(legs.force.x), weight.y() + sum_lanes(legs.force.y), weight.z() + sum_lanes(legs.force.z),
      w * (moment.x() + sum_lanes(legs.moment.x)), w * (moment.y() + sum_lanes(legs.moment.y)),
      w * (moment.z() + sum_lanes(legs.moment.z));
  // A^T F = G' by blocks (legs 0, 2, 4 and 1, 3, 5: three legs spread around the platform, whose
  // axes are far from coplanar on any hexapod): cofactor inverses, short chains, no pivot search.
  // Where a block is nearly singular, the pivoted elimination.
  // A^T = [P Q; R T] by columns: column j of P and R is row 2j of A (legs 0, 2, 4: its first and
  // last three entries), of Q and T row 2j + 1; each column a 4-lane vector (x, y, z, 0), the
  // whole solve in a dozen vector operations per step (Eigen's 3x3 blocks went through the stack).
  using M3 = std::array<v4d, 3>;  // columns
  // Entries first .. first + 2 of a row of A as (x, y, z, 0): two shuffles of the row's register
  // with eight lanes, else element by element.
  const auto half = [&](int row, int first) {
#if HEXATWIST_LANE_WIDTH == 8  // (a preprocessor test: clang checks a discarded branch's shuffle indices)
    const lane_v r = rows_of_A[row][0], zero = {};
    return first == 0 ? __builtin_shufflevector(r, zero, 0, 1, 2, 8) : __builtin_shufflevector(r, zero, 3, 4, 5, 8);
#else
    const auto at = [&](int c) { return rows_of_A[row][c / kWidth][c % kWidth]; };
    return v4d{at(first), at(first + 1), at(first + 2), 0.0};
#endif
  };
  M3 P, Q, R, T;
  for (int j = 0; j < 3; ++j) {
    P[j] = half(2 * j, 0);
    R[j] = half(2 * j, 3);
    Q[j] = half(2 * j + 1, 0);
    T[j] = half(2 * j + 1, 3);
  }
  const auto cross = [](v4d u, v4d v) {
    return __builtin_shufflevector(u, u, 1, 2, 0, 3) * __builtin_shufflevector(v, v, 2, 0, 1, 3) -
           __builtin_shufflevector(u, u, 2, 0, 1, 3) * __builtin_shufflevector(v, v, 1, 2, 0, 3);
  };
  const auto dot = [](v4d u, v4d v) {
    const v4d p = u * v;
    return p[0] + p[1] + p[2];
  };
  const auto splat4 = [](double s) { return v4d{s, s, s, s}; };
  // M v for M by columns.
  const auto times = [&](const M3& M, v4d v) {
    return M[0] * splat4(v[0]) + M[1] * splat4(v[1]) + M[2] * splat4(v[2]);
  };
  // The adjugate of M by columns (its rows are the cross products of M's columns) and the
  // determinant; true when M is well away from singular: |det| above a tenth of the product of
  // the columns' norms (a test that does not change with M's scale).
  const auto adjugate = [&](const M3& M, M3& adj, double& det) {
    const v4d r0 = cross(M[1], M[2]), r1 = cross(M[2], M[0]), r2 = cross(M[0], M[1]);
    det = dot(M[0], r0);
    adj = {v4d{r0[0], r1[0], r2[0], 0.0}, v4d{r0[1], r1[1], r2[1], 0.0}, v4d{r0[2], r1[2], r2[2], 0.0}};
    return det * det > 0.01 * (dot(M[0], M[0]) * dot(M[1], M[1]) * dot(M[2], M[2]));
  };
  // The Schur complement scaled by det P, S' = det P (T - R P^-1 Q) = det P T - R adj(P) Q, keeps
  // the division by det P off the critical path: F2 = S'^-1 (det P G2 - R adj(P) G1) and
  // F1 = (adj(P) G1 - adj(P) Q F2) / det P.
  M3 P_adj, S_adj, X, S;
  double det_P = 0.0, det_S = 0.0;
  bool blocks = adjugate(P, P_adj, det_P);
  for (int j = 0; j < 3; ++j) X[j] = times(P_adj, Q[j]);
  const v4d y = times(P_adj, v4d{G[0], G[1], G[2], 0.0});
  for (int j = 0; j < 3; ++j) S[j] = splat4(det_P) * T[j] - times(R, X[j]);
  blocks = adjugate(S, S_adj, det_S) && blocks;
  if (blocks) {
    const v4d F2 = times(S_adj, splat4(det_P) * v4d{G[3], G[4], G[5], 0.0} - times(R, y)) * splat4(1.0 / det_S);
    const v4d F1 = (y - times(X, F2)) * splat4(1.0 / det_P);
    force << F1[0], F2[0], F1[1], F2[1], F1[2], F2[2];
  } else if (!solve_transposed(rows_of_A, G, force)) {
    return Status::SingularJacobian;
  }
  return force.allFinite() ? Status::Ok : Status::NonFiniteInput;
}

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

/// True where resolve_inputs needs the static forces: a leg has a stiffness and an input force is NaN.
[[nodiscard]] inline bool needs_static_forces(const Model& model, const LegInputs& inputs) noexcept {
  return model.has_stiffness() && inputs.force.array().isNaN().any();
}

/// The status for inputs check_leg_inputs refuses (NonFiniteInput for an infinite force or
/// temperature, InvalidArgument for a temperature out of range); Ok for the others.
[[nodiscard]] [[gnu::always_inline]] inline Status input_status(const LegInputs& inputs) noexcept {
  lane_m infinite = {}, out_of_range = {};
  for (int k = 0; k < kPackets; ++k) {
    const lane_v t = load6(inputs.temperature.data(), k), f = load6(inputs.force.data(), k);
    infinite |= (vabs(t) == INFINITY) | (vabs(f) == INFINITY);
    out_of_range |= (t < kMinTemperature) | (t > kMaxTemperature);  // NaN (the reference) passes
  }
  if (!all_lanes(~infinite)) return Status::NonFiniteInput;
  return all_lanes(~out_of_range) ? Status::Ok : Status::InvalidArgument;
}

/// resolve_inputs with the static forces `static_force` and their status `static_status`
/// (read only where needs_static_forces).
[[nodiscard]] [[gnu::always_inline]] inline Status resolve_inputs(const Model& model, const LegInputs& inputs,
                                                                  Status static_status, const Vector6d& static_force,
                                                                  Vector6d& force, Vector6d& temperature) noexcept {
  if (const Status s = input_status(inputs); s != Status::Ok) return s;
  const bool static_forces = needs_static_forces(model, inputs);
  if (static_forces && static_status != Status::Ok) return static_status;
  // A NaN force: the static force where a leg has a stiffness, else 0 (it changes nothing).
  const lane_v reference = splat<lane_v>(model.reference_temperature());
  for (int k = 0; k < kPackets; ++k) {
    const lane_v t = load6(inputs.temperature.data(), k), f = load6(inputs.force.data(), k);
    store6(temperature.data(), blend(t == t, t, reference), k);
    store6(force.data(), blend(f == f, f, static_forces ? load6(static_force.data(), k) : splat<lane_v>(0.0)), k);
  }
  return Status::Ok;
}

/// play_direction's rule in lanes: +1 where `travel` passed `last` upwards, -1 downwards, `kept`
/// where it did not move.
[[gnu::always_inline]] inline lane_v direction_of(lane_v travel, lane_v last, lane_v kept) noexcept {
  return blend(travel > last, splat<lane_v>(1.0), blend(travel < last, splat<lane_v>(-1.0), kept));
}

/// The travel u [m] of travel_under_effects, leg by leg in lanes. u + E(u) = u0 with E linear in
/// w = u - h + k dtheta (leg_effects.hpp): with the home direction (no play term),
/// w = (u0 - h + k dtheta - E_fixed) / (1 + a_P dT) and u = u0 - E; the play's term
/// p = -(b / 2)(d - d_home) then moves u by -p / (1 + a_P dT). With `last` and `kept` (the play
/// state), each leg's direction is decided on the travel without its play term, which goes to
/// `no_play` (may be null), and written to `direction`; without them, `direction` is read.
[[gnu::always_inline]] inline void travel_in_lanes(const Model& model, const Vector6d& u0, const Vector6d& twist_term,
                                                   const Vector6d& force, const Vector6d& temperature,
                                                   const Vector6d* last, const Vector6d* kept, Vector6d& direction,
                                                   Vector6d& travel, Vector6d* no_play) noexcept {
  const LegGeometry& g = model.geometry();
  const lane_v reference = splat<lane_v>(model.reference_temperature());
  for (int k = 0; k < kPackets; ++k) {
    const lane_v dT = load6(temperature.data(), k) - reference;
    const lane_v fixed =
        load6(g.compliance.data(), k) * (load6(force.data(), k) - load6(model.reference_force().data(), k)) +
        dT * load6(g.thermal_length.data(), k);
    const lane_v aP_dT = load6(g.lead_expansion.data(), k) * dT;
    const lane_v inverse_scale = 1.0 / (1.0 + aP_dT);
    const lane_v u = load6(u0.data(), k);
    const lane_v w = (u - load6(g.home_command.data(), k) + load6(twist_term.data(), k)) - fixed;
    const lane_v without_play = u - fixed - aP_dT * w * inverse_scale;
    lane_v d;
    if (last != nullptr) {
      d = direction_of(without_play, load6(last->data(), k), load6(kept->data(), k));
      store6(direction.data(), d, k);
    } else {
      d = load6(direction.data(), k);
    }
    if (no_play != nullptr) store6(no_play->data(), without_play, k);
    const lane_v play = -load6(g.half_play.data(), k) * (d - load6(g.home_direction.data(), k));
    store6(travel.data(), without_play - play * inverse_scale, k);
  }
}

/// The travel [m] a command gives the nut under the effects for the twist-compensated travel u0
/// [m] (travel_under_effects), each leg's play direction decided on the travel without its play
/// term, `no_play` (what the play state moves on to; play may be null: from home).
[[gnu::always_inline]] inline void command_travel(const Model& model, const Vector6d& u0, const Vector6d& twist_term,
                                                  const Vector6d& force, const Vector6d& temperature,
                                                  const PlayState* play, Vector6d& travel, Vector6d& no_play,
                                                  Vector6d& direction) noexcept {
  const bool started = play != nullptr && play->started;
  travel_in_lanes(model, u0, twist_term, force, temperature, started ? &play->last : &model.geometry().home_command,
                  started ? &play->direction : &model.geometry().home_direction, direction, travel, &no_play);
}

/// The play's term of the effects, -(b / 2)(d - d_home) [m].
inline Vector6d play_term(const Model& model, const Vector6d& direction) noexcept {
  const LegGeometry& g = model.geometry();
  return -g.half_play.cwiseProduct(direction - g.home_direction);
}

}  // namespace hexatwist::detail
