// SPDX-License-Identifier: BSD-3-Clause
// Dynamics of the whole mechanism (mechanism.hpp): inverse dynamics over (N, 6) poses with their
// rates and accelerations (per-pose status, GIL released), and for one pose the mass matrix, the
// bias force, forward dynamics, the energies, the motor angles and their Jacobian.
// Platform velocity everywhere: x' = [v of the pivot [m/s, B]; w [rad/s, B]].
#include <array>
#include <cmath>

#include "common.hpp"

namespace hexatwist::python {
namespace {

py::array_t<double> matrix6(const Matrix6d& M) {
  py::array_t<double> a({6, 6});
  for (int i = 0; i < 6; ++i)
    for (int k = 0; k < 6; ++k) a.mutable_data()[6 * i + k] = M(i, k);
  return a;
}
py::array_t<double> array6(const Vector6d& v) { return py::array_t<double>(6, v.data()); }

void require_finite(const Rows6& r, const char* name) {
  for (std::size_t i = 0; i < 6 * r.rows; ++i)
    if (!std::isfinite(r.data[i]))
      raise_input(std::string(name) + ": row " + std::to_string(i / 6) + " holds NaN or inf");
}

Rows6 matching(const py::object& obj, const char* name, const Rows6& poses) {
  Rows6 r = rows6(obj, name);
  if (r.rows != poses.rows || r.single != poses.single)
    raise_input(std::string(name) + ": expected the shape of poses, " +
                (poses.single ? std::string("(6,)") : "(" + std::to_string(poses.rows) + ", 6)"));
  return r;
}

constexpr std::array<const char*, 14> kParts{
    "torque",           "angle", "speed",  "acceleration", "power",       "gravity",      "platform_inertia",
    "velocity_product", "legs",  "drives", "friction",     "screw_force", "thread_speed", "thread_dissipation"};

py::dict inverse_dynamics_batch(const py::object& config, const py::object& poses_in, const py::object& rates_in,
                                const py::object& accelerations_in) {
  const auto rig = rig_of(config);
  const Rows6 poses = rows6(poses_in, "poses");
  const Rows6 rates = matching(rates_in, "pose_rates", poses);
  const Rows6 accelerations = matching(accelerations_in, "pose_accelerations", poses);
  require_finite(poses, "poses");
  require_finite(rates, "pose_rates");
  require_finite(accelerations, "pose_accelerations");
  const std::size_t n = poses.rows;
  std::array<py::array_t<double>, kParts.size()> out;
  std::array<double*, kParts.size()> p{};
  for (std::size_t j = 0; j < kParts.size(); ++j) {
    out[j] = new_rows(n, 6, poses.single);
    p[j] = out[j].mutable_data();
  }
  auto status = new_column<std::int8_t>(n, poses.single);
  std::int8_t* ps = status.mutable_data();
  const Rig& r = rig->config->rig;
  parallel_blocks(n, [&](std::size_t begin, std::size_t end) {
    InverseDynamics id;
    for (std::size_t i = begin; i < end; ++i) {
      const PlatformMotion motion =
          platform_motion(pose_row(poses.data, i), Eigen::Map<const Vector6d>(rates.data + 6 * i),
                          Eigen::Map<const Vector6d>(accelerations.data + 6 * i));
      const Status s = inverse_dynamics(r, motion, id);
      ps[i] = static_cast<std::int8_t>(s);
      const std::array<const Vector6d*, kParts.size()> v{&id.torque,
                                                         &id.angle,
                                                         &id.speed,
                                                         &id.acceleration,
                                                         &id.power,
                                                         &id.gravity,
                                                         &id.platform_inertia,
                                                         &id.velocity_product,
                                                         &id.legs,
                                                         &id.drives,
                                                         &id.friction,
                                                         &id.screw_force,
                                                         &id.thread_speed,
                                                         &id.thread_dissipation};
      for (std::size_t j = 0; j < kParts.size(); ++j)
        for (int k = 0; k < 6; ++k) p[j][6 * i + k] = s == Status::Ok ? (*v[j])[k] : NAN;
    }
  });
  py::dict d;
  for (std::size_t j = 0; j < kParts.size(); ++j) d[kParts[j]] = out[j];
  d["status"] = status;
  return d;
}

py::dict platform_motion_batch(const py::object& poses_in, const py::object& rates_in,
                               const py::object& accelerations_in) {
  const Rows6 poses = rows6(poses_in, "poses");
  const Rows6 rates = matching(rates_in, "pose_rates", poses);
  const Rows6 accelerations = matching(accelerations_in, "pose_accelerations", poses);
  const std::size_t n = poses.rows;
  auto velocity = new_rows(n, 6, poses.single), acceleration = new_rows(n, 6, poses.single);
  double *pv = velocity.mutable_data(), *pa = acceleration.mutable_data();
  parallel_blocks(n, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const PlatformMotion m = platform_motion(pose_row(poses.data, i), Eigen::Map<const Vector6d>(rates.data + 6 * i),
                                               Eigen::Map<const Vector6d>(accelerations.data + 6 * i));
      for (int k = 0; k < 6; ++k) {
        pv[6 * i + k] = m.velocity[k];
        pa[6 * i + k] = m.acceleration[k];
      }
    }
  });
  py::dict d;
  d["velocity"] = velocity;
  d["acceleration"] = acceleration;
  return d;
}

Placement placement_of(const py::object& pose) { return placement_from_pose(Pose::from_vector(vector6(pose, "pose"))); }

void check(Status s, const char* what) {
  if (s == Status::NonFiniteInput) raise_input(std::string(what) + ": pose holds NaN or inf");
  if (s != Status::Ok) raise_status(s, std::string(what) + " at this pose");
}

}  // namespace

void expose_mechanism(py::module_& m) {
  m.def("_inverse_dynamics", &inverse_dynamics_batch, py::arg("rig"), py::arg("poses"), py::arg("pose_rates"),
        py::arg("pose_accelerations"));
  m.def("_platform_motion", &platform_motion_batch, py::arg("poses"), py::arg("pose_rates"),
        py::arg("pose_accelerations"));
  m.def(
      "mass_matrix",
      [](const py::object& config, const py::object& pose) {
        const auto rig = rig_of(config);
        Matrix6d M;
        check(mechanism_mass_matrix(rig->config->rig, placement_of(pose), M), "mass_matrix");
        return matrix6(M);
      },
      py::arg("rig"), py::arg("pose"),
      "The mechanism's mass matrix M (6, 6) at `pose` [m, rad], every body included: kinetic energy = "
      "1/2 x'^T M x' with x' = [v of the pivot [m/s, B]; w [rad/s, B]]; units kg, kg m, kg m^2 by block. "
      "Raises StatusError where the pose has no inverse kinematics or twist.");
  m.def(
      "bias",
      [](const py::object& config, const py::object& pose, const py::object& velocity) {
        const auto rig = rig_of(config);
        Vector6d b;
        check(mechanism_bias(rig->config->rig, placement_of(pose), vector6(velocity, "velocity"), b), "bias");
        return array6(b);
      },
      py::arg("rig"), py::arg("pose"), py::arg("velocity"),
      "Generalised force of everything but the motors and friction at zero acceleration (velocity products "
      "minus gravity) (6,) [N; N m, B], so that M x'' + bias = J_phi^T (torque - friction). `velocity` = "
      "[v of the pivot m/s; w rad/s, B].");
  m.def(
      "forward_dynamics",
      [](const py::object& config, const py::object& pose, const py::object& velocity, const py::object& torque) {
        const auto rig = rig_of(config);
        Vector6d a;
        check(forward_dynamics(rig->config->rig, placement_of(pose), vector6(velocity, "velocity"),
                               vector6(torque, "torque"), a),
              "forward_dynamics");
        return array6(a);
      },
      py::arg("rig"), py::arg("pose"), py::arg("velocity"), py::arg("torque"),
      "Platform acceleration x'' (6,) [v' m/s^2; w' rad/s^2, B] for the net motor torques `torque` (6,) [N m] "
      "at the shafts (friction not included: pass torque - friction), from M x'' = J_phi^T torque - bias, at "
      "`pose` [m, rad] moving with `velocity` [v of the pivot m/s; w rad/s, B].");
  m.def(
      "kinetic_energy",
      [](const py::object& config, const py::object& pose, const py::object& velocity) {
        const auto rig = rig_of(config);
        double e = 0.0;
        check(kinetic_energy(rig->config->rig, placement_of(pose), vector6(velocity, "velocity"), e), "kinetic_energy");
        return e;
      },
      py::arg("rig"), py::arg("pose"), py::arg("velocity"),
      "Kinetic energy of every body [J] at `pose` [m, rad] moving with `velocity` [v of the pivot m/s; w rad/s, B].");
  m.def(
      "potential_energy",
      [](const py::object& config, const py::object& pose) {
        const auto rig = rig_of(config);
        double e = 0.0;
        check(potential_energy(rig->config->rig, placement_of(pose), e), "potential_energy");
        return e;
      },
      py::arg("rig"), py::arg("pose"), "Potential energy in gravity of every body, zero at home [J].");
  m.def(
      "motor_angles",
      [](const py::object& config, const py::object& pose) {
        const auto rig = rig_of(config);
        Vector6d a;
        check(motor_angles(rig->config->rig, placement_of(pose), a), "motor_angles");
        return array6(a);
      },
      py::arg("rig"), py::arg("pose"), "Motor angles relative to home (6,) [rad] at `pose` [m, rad] (twist included).");
  m.def(
      "motor_jacobian",
      [](const py::object& config, const py::object& pose) {
        const auto rig = rig_of(config);
        const Rig& r = rig->config->rig;
        LegState legs;
        check(inverse_kinematics(r.model(), Pose::from_vector(vector6(pose, "pose")), legs), "motor_jacobian");
        Matrix6d J;
        check(motor_jacobian(r, legs, J), "motor_jacobian");
        return matrix6(J);
      },
      py::arg("rig"), py::arg("pose"),
      "Jacobian J_phi (6, 6) of the motor angles: phi' = J_phi x', x' = [v of the pivot m/s; w rad/s, B] "
      "[rad/m | rad/rad].");
  m.def(
      "peak_torque_at",
      [](const py::object& config, double speed) {
        if (!std::isfinite(speed)) raise_input("speed: expected a finite motor speed [rad/s]");
        return peak_torque_at(rig_of(config)->config->rig.servo(), speed);
      },
      py::arg("rig"), py::arg("speed"),
      "The motor's intermittent torque envelope at `speed` [rad/s] (its magnitude is used) [N m].");
}

}  // namespace hexatwist::python
