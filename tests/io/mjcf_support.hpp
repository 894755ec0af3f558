// SPDX-License-Identifier: BSD-3-Clause
// MuJoCo harness of the MJCF export's tests and benchmark: load the XML of mjcf_model, pose the
// platform, and solve the legs' joints so that every equality holds (Newton on efc_pos).
#pragma once

#include <mujoco/mujoco.h>

#include <unistd.h>
#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "hexatwist/hexatwist.hpp"

namespace hexatwist::test {

/// One loaded MuJoCo model with its data.
class MjSim {
 public:
  /// Loads `xml` (through a temporary file); throws std::runtime_error with MuJoCo's message.
  explicit MjSim(const std::string& xml) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("hexatwist_mjcf_" + std::to_string(::getpid()) + "_" + std::to_string(counter()++) + ".xml");
    { std::ofstream(path) << xml; }
    char error[1000] = "";
    m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
    std::filesystem::remove(path);
    if (m == nullptr) throw std::runtime_error(std::string("mj_loadXML: ") + error);
    d = mj_makeData(m);
  }
  MjSim(const MjSim&) = delete;
  MjSim& operator=(const MjSim&) = delete;
  ~MjSim() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }

  int id(mjtObj type, const std::string& name) const {
    const int i = mj_name2id(m, type, name.c_str());
    if (i < 0) throw std::runtime_error("no MuJoCo object named " + name);
    return i;
  }
  /// qpos of a scalar joint.
  double& q(const std::string& joint) { return d->qpos[m->jnt_qposadr[id(mjOBJ_JOINT, joint)]]; }
  double& qd(const std::string& joint) { return d->qvel[m->jnt_dofadr[id(mjOBJ_JOINT, joint)]]; }
  int platform_dof() const { return m->jnt_dofadr[id(mjOBJ_JOINT, "platform")]; }

  /// Puts the platform's free joint at `x` (hexatwist's placement of the pivot).
  void set_platform(const Model& model, const Placement& x) {
    const int a = m->jnt_qposadr[id(mjOBJ_JOINT, "platform")];
    const Vector3d origin = model.pivot_home_B() + x.t - x.R_BP * model.spec().pivot_P;
    const Eigen::Quaterniond quat(x.R_BP);
    for (int k = 0; k < 3; ++k) d->qpos[a + k] = origin[k];
    d->qpos[a + 3] = quat.w();
    d->qpos[a + 4] = quat.x();
    d->qpos[a + 5] = quat.y();
    d->qpos[a + 6] = quat.z();
  }
  /// The platform's placement from its body pose (after mj_kinematics or a step).
  Placement platform(const Model& model) const {
    const int b = id(mjOBJ_BODY, "platform");
    Placement x;
    x.R_BP = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->xmat + 9 * b);
    x.t = Eigen::Map<const Vector3d>(d->xpos + 3 * b) + x.R_BP * model.spec().pivot_P - model.pivot_home_B();
    return x;
  }

  /// Largest |efc_pos| of the rows of equalities whose name starts with `prefix` ("" = all), after
  /// mj_fwdPosition.
  double max_residual(const std::string& suffix = "") const {
    double r = 0.0;
    for (int k = 0; k < d->nefc; ++k) {
      if (d->efc_type[k] != mjCNSTR_EQUALITY) continue;
      const char* name = mj_id2name(m, mjOBJ_EQUALITY, d->efc_id[k]);
      const std::string n = name != nullptr ? name : "";
      if (!suffix.empty() &&
          (n.size() < suffix.size() || n.compare(n.size() - suffix.size(), suffix.size(), suffix) != 0))
        continue;
      r = std::max(r, std::abs(d->efc_pos[k]));
    }
    return r;
  }

  /// Newton's method on efc_pos over every joint but the platform's: the legs' joints for the
  /// platform's present pose. Returns the final max |efc_pos|.
  double solve_legs(int iterations = 40, double tolerance = 1e-14) {
    const int p = platform_dof();
    Eigen::VectorXd step(m->nv);
    double r = 0.0;
    for (int it = 0; it < iterations; ++it) {
      mj_fwdPosition(m, d);
      const int ne = d->ne;  // the equality rows come first (then dry friction's, which are not positions)
      const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(d->efc_J, ne,
                                                                                                       m->nv);
      const Eigen::Map<const Eigen::VectorXd> pos(d->efc_pos, ne);
      r = pos.cwiseAbs().maxCoeff();
      if (r < tolerance) break;
      Eigen::MatrixXd Jl(ne, m->nv - 6);
      Jl << J.leftCols(p), J.rightCols(m->nv - p - 6);
      const Eigen::VectorXd dx = Jl.completeOrthogonalDecomposition().solve(-pos);
      step.setZero();
      step.head(p) = dx.head(p);
      step.tail(m->nv - p - 6) = dx.tail(m->nv - p - 6);
      mj_integratePos(m, d->qpos, step.data(), 1.0);
    }
    mj_fwdPosition(m, d);
    return r;
  }

  mjModel* m = nullptr;
  mjData* d = nullptr;

 private:
  static int& counter() {
    static int c = 0;
    return c;
  }
};

/// The rotor joint's angle for motor angle `phi` of leg i (docs/theory.md §4, §15) [rad].
inline double rotor_angle(const Leg& leg, double phi) {
  return (leg.driven == DrivenSide::Base ? -1.0 : 1.0) * leg.twist_sign * phi;
}

/// Motor angles relative to home of a placement: (m - m_home) / c, m the compensated motor-side
/// length [rad].
inline Vector6d motor_angles_of(const Rig& rig, const Placement& x) {
  const Model& model = rig.model();
  LegState legs;
  Vector6d dtheta;
  if (inverse_kinematics(model, x, legs) != Status::Ok || twist(model, legs, dtheta) != Status::Ok)
    throw std::runtime_error("inverse kinematics failed");
  const Vector6d m = legs.length - model.geometry().length_offset - model.geometry().twist_gain.cwiseProduct(dtheta);
  const Vector6d m_home = model.length_home() - model.geometry().length_offset;
  return (m - m_home).cwiseQuotient(rig.motor_gain());
}

}  // namespace hexatwist::test
