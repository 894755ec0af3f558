// Internal: the legs' static forces packet by packet (lanes.hpp), shared by static_leg_forces and
// the real-time command (compensation.cpp), which gives them from its pass in registers without a
// LegState: one computation, the same forces from either.
#pragma once

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
  alignas(64) double a[6][8];
  std::memcpy(a, rows_of_A, sizeof a);
  Matrix3d P, Q, R, T;  // A^T = [P Q; R T]: columns of P and R from legs 0, 2, 4
  for (int j = 0; j < 3; ++j)
    for (int c = 0; c < 3; ++c) {
      P(c, j) = a[2 * j][c];
      R(c, j) = a[2 * j][c + 3];
      Q(c, j) = a[2 * j + 1][c];
      T(c, j) = a[2 * j + 1][c + 3];
    }
  const auto cofactor_inverse = [](const Matrix3d& M, Matrix3d& inverse) {
    const Vector3d c0 = M.col(1).cross(M.col(2)), c1 = M.col(2).cross(M.col(0)), c2 = M.col(0).cross(M.col(1));
    const double det = M.col(0).dot(c0);
    const double inv_det = 1.0 / det;
    inverse.row(0) = inv_det * c0.transpose();
    inverse.row(1) = inv_det * c1.transpose();
    inverse.row(2) = inv_det * c2.transpose();
    // Well away from singular: |det| above a tenth of the product of the columns' norms.
    return det * det > 0.01 * (M.col(0).squaredNorm() * M.col(1).squaredNorm() * M.col(2).squaredNorm());
  };
  Matrix3d P_inv, S_inv;
  bool blocks = cofactor_inverse(P, P_inv);
  const Matrix3d X = P_inv * Q;
  const Vector3d y = P_inv * G.head<3>();
  blocks = blocks && cofactor_inverse(T - R * X, S_inv);
  if (blocks) {
    const Vector3d F2 = S_inv * (G.tail<3>() - R * y);
    const Vector3d F1 = y - X * F2;
    force << F1[0], F2[0], F1[1], F2[1], F1[2], F2[2];
  } else {
    Columns transposed;  // A^T's columns are A's rows
    for (int i = 0; i < 6; ++i)
      for (int q = 0; q < kPackets; ++q) transposed.c[i][q] = rows_of_A[i][q];
    if (!(gj_solve_system(transposed, G, force) > 0.0)) return Status::SingularJacobian;
  }
  return force.allFinite() ? Status::Ok : Status::NonFiniteInput;
}

/// True where resolve_inputs needs the static forces: a leg has a stiffness and an input force is NaN.
[[nodiscard]] bool needs_static_forces(const Model& model, const LegInputs& inputs) noexcept;
/// resolve_inputs with the static forces `static_force` and their status `static_status`
/// (read only where needs_static_forces).
[[nodiscard]] Status resolve_inputs(const Model& model, const LegInputs& inputs, Status static_status,
                                    const Vector6d& static_force, Vector6d& force, Vector6d& temperature) noexcept;

/// The travel [m] a command gives the nut under the effects for the twist-compensated travel u0
/// [m] (travel_under_effects), each leg's play direction decided on the travel without its play
/// term, `no_play` (what the play state moves on to; play may be null: from home).
void command_travel(const Model& model, const Vector6d& u0, const Vector6d& twist_term, const Vector6d& force,
                    const Vector6d& temperature, const PlayState* play, Vector6d& travel, Vector6d& no_play,
                    Vector6d& direction) noexcept;

}  // namespace hexatwist::detail
