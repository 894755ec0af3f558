// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/dynamics/dynamics.hpp"
#include "kinematics/geometry.hpp"

#include <Eigen/LU>

namespace hexatwist {
namespace {

// Centre of mass relative to the pivot [m, B].
Vector3d com_from_pivot_B(const Model& model, const LoadSpec& load, const Matrix3d& R_BP) noexcept {
  return R_BP * (load.center_of_mass_P - model.spec().pivot_P);
}

}  // namespace

void platform_mass_matrix(const Model& model, const LoadSpec& load, const Matrix3d& R_BP, Matrix6d& M) noexcept {
  // Velocity of the centre of mass: v + w x c = v - [c]x w. Kinetic energy
  // 1/2 m |v - [c]x w|^2 + 1/2 w^T I_B w, with I_B = R I_P R^T about the centre of mass.
  const Vector3d c = com_from_pivot_B(model, load, R_BP);
  const Matrix3d C = detail::skew(c);
  const Matrix3d I_B = R_BP * load.inertia_tensor() * R_BP.transpose();
  const double m = load.mass;
  M.topLeftCorner<3, 3>() = m * Matrix3d::Identity();
  M.topRightCorner<3, 3>() = -m * C;
  M.bottomLeftCorner<3, 3>() = m * C;
  M.bottomRightCorner<3, 3>() = I_B - m * C * C;
}

void gravity_wrench(const Model& model, const LoadSpec& load, const Matrix3d& R_BP, Vector6d& w) noexcept {
  const Vector3d f(0.0, 0.0, -load.mass * load.gravity);
  w.head<3>() = f;
  w.tail<3>() = com_from_pivot_B(model, load, R_BP).cross(f);
}

Status leg_dynamics(const Model& model, const LoadSpec& load, const LegState& legs, LengthKind kind,
                    LegDynamics& out) noexcept {
  if (const Status s = length_jacobian(model, legs, kind, out.jacobian); s != Status::Ok) return s;
  const Eigen::PartialPivLU<Matrix6d> lu(out.jacobian);
  // |det| relative to the product of row norms: 0 for a singular J, 1 for orthogonal rows.
  double scale = 1.0;
  for (int i = 0; i < 6; ++i) scale *= out.jacobian.row(i).norm();
  if (!(std::abs(lu.determinant()) > 1e-12 * scale)) return Status::SingularJacobian;
  const Matrix6d Jinv = lu.inverse();
  Matrix6d M;
  platform_mass_matrix(model, load, legs.R_BP, M);
  Vector6d w;
  gravity_wrench(model, load, legs.R_BP, w);
  // Virtual work: w . dx = F . dm with dm = J dx, so F = J^-T w; likewise for the inertia.
  out.mass.noalias() = Jinv.transpose() * M * Jinv;
  out.gravity.noalias() = Jinv.transpose() * w;
  return Status::Ok;
}

}  // namespace hexatwist
