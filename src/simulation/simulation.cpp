// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/simulation/simulation.hpp"

#include <Eigen/LU>
#include <cmath>

#include "dynamics/mechanism_internal.hpp"
#include "hexatwist/dynamics/leg_forces.hpp"
#include "hexatwist/dynamics/mechanism.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "hexatwist/simulation/servo.hpp"
#include "simulation_internal.hpp"

namespace hexatwist {
namespace {

// How often progress is reported [ticks].
constexpr std::size_t kProgressEvery = 500;

// The leg lengths forward kinematics of the plant takes for the nuts' travel `travel` (the motor
// angles through the real lead, theory §4): the drives' motor-side lengths when the plant twists
// (LengthKind::Motor), the real lengths (the legs' zero errors added back) when it does not
// (LengthKind::Geometric).
Vector6d plant_lengths(const Model& model, const Vector6d& travel, bool twist_in_plant) noexcept {
  return twist_in_plant ? model.motor_from_travel(travel) : Vector6d(travel + model.geometry().length_offset);
}

// Forward kinematics of the plant: on a model whose legs have effects (theory §4b), at the
// reference temperature, with the play's directions from the nuts' dead band, which `nuts`
// follows along the run, and the legs' forces `force` [N] (null: the static load at the pose).
// The closed loop's legs carry the planned motion's forces: the servo's error moves the platform
// by tens of micrometres from its pose, which changes the seed's static forces by newtons
// (nanometres of deflection); the rigid coupling of the motors' accelerations would put their
// control-rate ripple into the forces, which legs of finite stiffness do not pass on.
Status plant_fk(const Model& model, const Vector6d& lengths, LengthKind kind, const Placement& guess, NutGap& nuts,
                const Vector6d* force, FkResult& fk) noexcept {
  if (kind == LengthKind::Motor && model.has_leg_effects()) {
    const Vector6d direction = follow_nuts(model, lengths, nuts);
    LegInputs inputs;
    if (force != nullptr && model.has_stiffness()) inputs.force = *force;
    return forward_kinematics(model, lengths, inputs, &direction, guess, fk);
  }
  return forward_kinematics(model, lengths, kind, guess, fk);
}

// The targets of a whole trajectory, computed (and checked) before the loop runs.
struct Plan {
  std::vector<Vector6d> command;          // motor-side target [m]
  std::vector<Vector6d> force;            // the legs' forces along the run [N] (empty: rigid legs)
  std::vector<ServoReference> reference;  // the same at the motor shaft, with speed and acceleration
  std::vector<double> error_twist_only;   // observation error with perfect servos [m]
};

// Fills `plan` for one way of running (the commands of `strategy`, or the IK lengths for a plant
// without twist) and checks every sample (compute_commands checks both commands against the stroke
// whatever the strategy). `check_holding`: also the holding torque at every pose, which depends on
// the pose only (check_trajectory checks it once for both strategies).
Status make_plan(const Rig& rig, const Trajectory& trajectory, Strategy strategy, bool twist_in_plant, Plan* plan,
                 SimulationIssue& issue, bool check_holding = true) {
  const Model& model = rig.model();
  const std::size_t n = trajectory.poses.size();
  const bool compensated = twist_in_plant && strategy == Strategy::Compensated;
  std::vector<Vector6d> command(n);
  CommandReport report;
  Vector6d still;
  const double torque_limit = rig.servo().torque_limit;
  // The compensated commands of legs with play follow each leg's direction along the run, from
  // home where homing left it. Legs with a stiffness carry the forces of the planned motion, the
  // static load at its pose plus its accelerations' share (theory §4b, dynamics/leg_forces.hpp),
  // which the compensated commands know. A check without a plan (check_trajectory) of commands that
  // do not know them has no use for them.
  PlayState play;
  start_play(model, model.home_command(), play);
  std::vector<Vector6d> force;
  if (twist_in_plant && model.has_stiffness() && n > 1 && (compensated || plan != nullptr)) {
    std::size_t at = 0;
    if (const Status s = trajectory_leg_forces(rig, trajectory, force, at); s != Status::Ok)
      return detail::fail_at(issue, s, at, trajectory);
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (const Status s = compute_commands(model, trajectory.poses[k], report); s != Status::Ok)
      return detail::fail_at(issue, s, k, trajectory, report.limit);
    command[k] = compensated ? report.compensated : report.conventional;
    if (compensated && (model.has_play() || !force.empty())) {
      LegInputs inputs;
      if (!force.empty()) inputs.force = force[k];
      LimitReport limit;
      if (const Status s =
              motor_commands(model, trajectory.poses[k], Strategy::Compensated, inputs, &play, command[k], limit);
          s != Status::Ok)
        return detail::fail_at(issue, s, k, trajectory, limit);
    }
    if (!check_holding) continue;
    // Every motor must at least be able to hold the mechanism standing still at every pose.
    if (const Status s = holding_torque(rig, trajectory.poses[k], still); s != Status::Ok)
      return detail::fail_at(issue, s, k, trajectory);
    for (int i = 0; i < kLegs; ++i) {
      const double hold = std::abs(still[i]);
      if (hold > accepted_max(torque_limit)) {  // on the limit is inside it (limits.hpp)
        LimitReport limit;
        limit.status = Status::TorqueAboveMax;
        limit.leg = i;
        limit.value = hold;
        limit.bound = torque_limit;
        return detail::fail_at(issue, Status::TorqueAboveMax, k, trajectory, limit);
      }
    }
  }
  // Motor speed by central differences of the targets (one-sided at the ends).
  const double T = trajectory.dt;
  const Vector6d& gain = rig.motor_gain();
  const Vector6d inv_gain = gain.cwiseInverse();
  // The motor angles: the drives turn the commands into angles with their own lead about their
  // reference, and the nut travels by the real lead (theory §4: u = h + s (m - h)).
  std::vector<Vector6d> travel(n);
  for (std::size_t k = 0; k < n; ++k) travel[k] = model.travel_from_motor(command[k]);
  std::vector<ServoReference> reference(n);
  for (std::size_t k = 0; k < n; ++k) {
    ServoReference& r = reference[k];
    r.angle = (travel[k] - model.length_home()).cwiseProduct(inv_gain);
    if (n < 2) continue;
    const std::size_t a = k == 0 ? 0 : k - 1;
    const std::size_t b = k + 1 == n ? k : k + 1;
    r.speed = (travel[b] - travel[a]).cwiseProduct(inv_gain) / (T * static_cast<double>(b - a));
    if (k > 0 && k + 1 < n)
      r.acceleration = (travel[k + 1] - 2.0 * travel[k] + travel[k - 1]).cwiseProduct(inv_gain) / (T * T);
    for (int i = 0; i < kLegs; ++i)
      if (std::abs(r.speed[i]) > accepted_max(rig.servo().max_speed)) {
        LimitReport limit;
        limit.status = Status::MotorSpeedAboveMax;
        limit.leg = i;
        limit.value = std::abs(r.speed[i]);
        limit.bound = rig.servo().max_speed;
        return detail::fail_at(issue, Status::MotorSpeedAboveMax, k, trajectory, limit);
      }
  }
  if (plan == nullptr) return Status::Ok;
  // What the twist alone does: the pose the motors reach if they follow the targets exactly.
  const LengthKind kind = twist_in_plant ? LengthKind::Motor : LengthKind::Geometric;
  plan->error_twist_only.resize(n);
  FkResult fk;
  Placement guess = placement_from_pose(trajectory.poses[0]);
  const Vector3d& obs = model.spec().observation_P;
  NutGap nuts;
  for (std::size_t k = 0; k < n; ++k) {
    if (const Status s = plant_fk(model, plant_lengths(model, travel[k], twist_in_plant), kind, guess, nuts,
                                  force.empty() ? nullptr : &force[k], fk);
        s != Status::Ok)
      return detail::fail_at(issue, s, k, trajectory);
    guess = fk.placement;
    const Placement desired = placement_from_pose(trajectory.poses[k]);
    plan->error_twist_only[k] =
        (platform_point_B(model, fk.placement, obs) - platform_point_B(model, desired, obs)).norm();
  }
  plan->command = std::move(command);
  plan->reference = std::move(reference);
  plan->force = std::move(force);
  return Status::Ok;
}

}  // namespace

Status holding_torque(const Rig& rig, const Pose& pose, Vector6d& torque) noexcept {
  PlatformMotion rest;
  rest.placement = placement_from_pose(pose);
  InverseDynamics still;
  const Status s = inverse_dynamics(rig, rest, still);
  torque = still.gravity;
  return s;
}

Status check_trajectory(const Rig& rig, const Trajectory& trajectory, SimulationIssue& issue) {
  issue = SimulationIssue{};
  if (trajectory.poses.empty()) return Status::Ok;
  // compute_commands checks the pose and both commands; the speed is checked for both strategies,
  // the holding torque (the pose's alone) once.
  if (const Status s = make_plan(rig, trajectory, Strategy::Conventional, true, nullptr, issue); s != Status::Ok)
    return s;
  if (!rig.model().has_twist()) return Status::Ok;
  return make_plan(rig, trajectory, Strategy::Compensated, true, nullptr, issue, false);
}

Status simulate(const Rig& rig, const Trajectory& trajectory, const SimulationOptions& options,
                std::vector<SimulationSample>& samples, SimulationIssue& issue) {
  samples.clear();
  issue = SimulationIssue{};
  const std::size_t n = trajectory.poses.size();
  if (n == 0) return Status::Ok;
  if (std::abs(trajectory.dt - rig.control_period()) > 1e-9 * rig.control_period() && n > 1)
    return detail::fail_at(issue, Status::NonFiniteInput, 0, trajectory);
  if (n > kMaxTrajectorySamples) return detail::fail_at(issue, Status::InvalidArgument, 0, trajectory);
  // make_plan checks every sample of the commands this run sends (limits, stroke, motor speed,
  // holding torque) before the loop starts; check_trajectory adds the other strategy's commands.
  Plan plan;
  if (const Status s = make_plan(rig, trajectory, options.strategy, options.twist_in_plant, &plan, issue);
      s != Status::Ok)
    return s;

  const Model& model = rig.model();
  const LengthKind kind = options.twist_in_plant ? LengthKind::Motor : LengthKind::Geometric;
  const Vector6d& gain = rig.motor_gain();
  const Vector3d& obs = model.spec().observation_P;

  // Start settled at the first target: motors on it, at its speed, the integrators holding the load.
  DriveState drives;
  drives.angle = plan.reference[0].angle;
  drives.speed = plan.reference[0].speed;
  Vector6d motor = model.length_home() + gain.cwiseProduct(drives.angle);
  FkResult fk;
  NutGap nuts;
  if (const Status s =
          plant_fk(model, plant_lengths(model, motor, options.twist_in_plant), kind,
                   placement_from_pose(trajectory.poses[0]), nuts, plan.force.empty() ? nullptr : &plan.force[0], fk);
      s != Status::Ok)
    return detail::fail_at(issue, s, 0, trajectory);
  // The mechanism's load on the motors (docs/theory.md §9, §14), at the start and then once per
  // control period, held over it.
  detail::DriveLoad load;
  Vector6d motor_acceleration = plan.reference[0].acceleration;
  if (const Status s = detail::drive_load(rig, fk.legs, drives.speed, motor_acceleration, options.twist_in_plant, load);
      s != Status::Ok)
    return detail::fail_at(issue, s, 0, trajectory);
  // Holding torque: the motor balances the load (and the viscous friction at its speed).
  const Vector6d holding = rig.servo().viscous_friction * drives.speed - load.load + load.thread_loss;
  Vector6d measured;
  read_encoder(rig, drives.angle, measured);
  ControllerState controller;
  start_controller(rig, measured, holding, controller);
  drives.torque = holding;

  Vector6d twist_ref = Vector6d::Zero();
  Vector6d twist_now;
  Vector6d torque;
  samples.reserve(n);
  for (std::size_t k = 0; k < n; ++k) {
    read_encoder(rig, drives.angle, measured);
    update_controller(rig, plan.reference[k], measured, controller, torque);

    SimulationSample& out = samples.emplace_back();
    out.time = trajectory.time(k);
    out.desired = trajectory.poses[k].to_vector();
    out.actual = pose_from_placement(fk.placement).to_vector();
    out.command = plan.command[k];
    out.encoder = model.motor_from_travel(model.length_home() + gain.cwiseProduct(measured));
    out.motor = model.motor_from_travel(motor);
    out.length = fk.legs.length;
    if (twist_continued(model, fk.legs, twist_ref, twist_now) == Status::Ok) twist_ref = twist_now;
    out.twist = twist_ref;
    out.torque = torque;
    const Placement desired = placement_from_pose(trajectory.poses[k]);
    out.error = (platform_point_B(model, fk.placement, obs) - platform_point_B(model, desired, obs)).norm();
    out.error_twist_only = plan.error_twist_only[k];
    if (options.progress && (k % kProgressEvery == 0 || k + 1 == n)) options.progress(k + 1, n);
    if (k + 1 == n) break;

    // The load at the current state, held over the control period; the thread's efficiency loss
    // from the screw torque at the last period's motor acceleration.
    if (k > 0)
      if (const Status s =
              detail::drive_load(rig, fk.legs, drives.speed, motor_acceleration, options.twist_in_plant, load);
          s != Status::Ok)
        return detail::fail_at(issue, s, k, trajectory);
    const Vector6d speed_before = drives.speed;
    integrate_drives(rig, load.inverse_inertia, load.load - load.thread_loss, torque, drives);
    motor_acceleration = (drives.speed - speed_before) / rig.control_period();
    motor = model.length_home() + gain.cwiseProduct(drives.angle);
    const Placement previous = fk.placement;  // warm start from the last tick
    if (const Status s = plant_fk(model, plant_lengths(model, motor, options.twist_in_plant), kind, previous, nuts,
                                  plan.force.empty() ? nullptr : &plan.force[k + 1], fk);
        s != Status::Ok)
      return detail::fail_at(issue, s, k + 1, trajectory);
  }
  return Status::Ok;
}

}  // namespace hexatwist
