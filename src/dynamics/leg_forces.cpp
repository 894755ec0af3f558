// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/dynamics/leg_forces.hpp"

#include <cmath>

#include "hexatwist/kinematics/leg_effects.hpp"

namespace hexatwist {

PlatformMotion trajectory_motion(const Trajectory& trajectory, std::size_t k) noexcept {
  const std::vector<Pose>& poses = trajectory.poses;
  const std::size_t n = poses.size();
  const double dt = trajectory.dt;
  const std::size_t a = k == 0 ? 0 : k - 1;
  const std::size_t b = k + 1 >= n ? k : k + 1;
  Vector6d rate = Vector6d::Zero();
  if (b > a) rate = (poses[b].to_vector() - poses[a].to_vector()) / (dt * static_cast<double>(b - a));
  Vector6d acceleration = Vector6d::Zero();
  if (k > 0 && k + 1 < n)
    acceleration = (poses[k + 1].to_vector() - 2.0 * poses[k].to_vector() + poses[k - 1].to_vector()) / (dt * dt);
  return platform_motion(poses[k], rate, acceleration);
}

Status inertial_leg_forces(const Rig& rig, const PlatformMotion& motion, Vector6d& force) noexcept {
  InverseDynamics id;
  const Status s = inverse_dynamics(rig, motion, id);
  if (s != Status::Ok) return s;
  // screw_force = -(gravity + platform inertia + leg bodies + velocity products) / gain: all but
  // gravity's share, each of which vanishes at rest.
  force = -(id.platform_inertia + id.legs + id.velocity_product).cwiseQuotient(rig.motor_gain());
  return Status::Ok;
}

Status trajectory_leg_forces(const Rig& rig, const Trajectory& trajectory, std::vector<Vector6d>& force,
                             std::size_t& failed_at) {
  force.clear();
  failed_at = 0;
  const std::size_t n = trajectory.poses.size();
  if (!check_trajectory_samples(trajectory.t0, trajectory.dt, n).empty()) return Status::InvalidArgument;
  const Model& model = rig.model();
  force.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    failed_at = k;
    const PlatformMotion motion = trajectory_motion(trajectory, k);
    LegState legs;
    Vector6d inertial;
    Status s = inverse_kinematics(model, motion.placement, legs);
    if (s == Status::Ok) s = static_leg_forces(model, model.spec().static_load, legs, force[k]);
    if (s == Status::Ok) s = inertial_leg_forces(rig, motion, inertial);
    if (s != Status::Ok) {
      force.clear();
      return s;
    }
    force[k] += inertial;
  }
  failed_at = 0;
  return Status::Ok;
}

}  // namespace hexatwist
