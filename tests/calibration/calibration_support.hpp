// SPDX-License-Identifier: BSD-3-Clause
// Test support for the calibration tests: a real platform that differs from the nominal one by
// known errors (joint centres and axes, leads, thread sense, zero offsets, targets, a tracker
// frame), and what a laser tracker sees of it at stations where the nominal model's commands hold
// it still, with Gaussian noise.
#pragma once

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include "support.hpp"

namespace hexatwist::test {

inline double gaussian(std::mt19937_64& rng) { return std::normal_distribution<double>(0.0, 1.0)(rng); }

inline Matrix3d random_rotation(std::mt19937_64& rng) {
  Eigen::Quaterniond q(gaussian(rng), gaussian(rng), gaussian(rng), gaussian(rng));
  return q.normalized().toRotationMatrix();
}

/// What the errors of a truth are drawn from.
struct TruthErrors {
  double joints = 1e-3;                 ///< joint centres within +-joints per coordinate [m]
  double lead = 0.025;                  ///< every lead (1 + lead) times the nominal [-]
  bool flip = false;                    ///< every thread hand the other one
  double offsets = 0.5e-3;              ///< zero offsets within +-offsets [m]
  double point = 2e-3;                  ///< the observation point within +-point per coordinate [m]
  double axes = 0.0;                    ///< axes turned within +-axes about the two directions across them [rad]
  std::vector<Vector3d> extra_targets;  ///< more targets [m, P], placed exactly
};

/// The real platform and the tracker.
struct Truth {
  ModelSpec spec;                 ///< the real platform, in the gauge frames (no rigid part in its joint errors)
  std::vector<Vector3d> targets;  ///< target 0 = spec.observation_P, then the extra ones [m, P]
  RigidTransform X_BT;            ///< the tracker frame
  double lead_scale = 1.0;        ///< real lead over the nominal one
};

/// A truth drawn from `e`: the drives keep the nominal lead and reference (theory §4).
inline Truth random_truth(const Model& nominal, const TruthErrors& e, std::mt19937_64& rng) {
  Truth t;
  t.spec = nominal.spec();
  t.lead_scale = 1.0 + e.lead;
  ParameterErrors pe;
  pe.lead_error.setConstant(e.lead);
  pe.flip_twist_sign = e.flip;
  LegVectors db, dp;
  for (int i = 0; i < kLegs; ++i)
    for (int a = 0; a < 3; ++a) {
      db(i, a) = uniform(rng, -e.joints, e.joints);
      dp(i, a) = uniform(rng, -e.joints, e.joints);
    }
  pe.base_offset_B = without_rigid_part(nominal.geometry().base_B, db);
  pe.platform_offset_P = without_rigid_part(nominal.geometry().arm_P, dp);
  for (int i = 0; i < kLegs; ++i) {
    pe.zero_offset[i] = uniform(rng, -e.offsets, e.offsets);
    const auto across = [&](const Vector3d& axis) {
      const Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1).normalized();
      return Vector3d(uniform(rng, -e.axes, e.axes) * e1 + uniform(rng, -e.axes, e.axes) * e2);
    };
    pe.base_axis_rotation.row(i) = across(nominal.leg(i).axis_base_B).transpose();
    pe.platform_axis_rotation.row(i) = across(nominal.leg(i).axis_platform_P).transpose();
  }
  for (int k = 0; k < 3; ++k) pe.observation_offset_P[k] = uniform(rng, -e.point, e.point);
  t.spec = real_model(nominal, pe).spec();
  t.targets.push_back(t.spec.observation_P);
  t.targets.insert(t.targets.end(), e.extra_targets.begin(), e.extra_targets.end());
  t.X_BT = {random_rotation(rng), Vector3d(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -2, 2))};
  return t;
}

/// `count` stations at random poses within +-translation and +-rotation inside every limit of the
/// nominal model (and of the real one).
inline std::vector<Pose> random_station_poses(const Model& nominal, const Model& real, int count, double translation,
                                              double rotation, std::mt19937_64& rng) {
  std::vector<Pose> poses{Pose{}};
  Vector6d command;
  LimitReport limit;
  while (static_cast<int>(poses.size()) < count) {
    const Pose p = random_pose(rng, translation, rotation);
    if (motor_commands(nominal, p, Strategy::Compensated, command, limit) != Status::Ok) continue;
    FkResult fk;
    if (forward_kinematics(real, command, LengthKind::Motor, placement_from_pose(p), fk) != Status::Ok) continue;
    poses.push_back(p);
  }
  return poses;
}

/// At each station the nominal model's commands (of `strategy`), the pose the real platform takes
/// for them, and `points` tracker points of every target with noise `sigma` per coordinate.
inline std::vector<Observation> observe(const Model& nominal, const Truth& truth, const std::vector<Pose>& stations,
                                        int points, double sigma, std::mt19937_64& rng,
                                        Strategy strategy = Strategy::Compensated) {
  const Model real(truth.spec);
  const RigidTransform X_TB = inverse(truth.X_BT);
  std::vector<Observation> out;
  for (const Pose& pose : stations) {
    Vector6d command;
    LimitReport limit;
    EXPECT_EQ(motor_commands(nominal, pose, strategy, command, limit), Status::Ok) << str(pose);
    FkResult fk;
    EXPECT_EQ(forward_kinematics(real, command, LengthKind::Motor, placement_from_pose(pose), fk), Status::Ok)
        << str(pose);
    for (int k = 0; k < points; ++k)
      for (std::size_t t = 0; t < truth.targets.size(); ++t) {
        Observation o;
        o.motor = command;
        o.target = static_cast<int>(t);
        const Vector3d noise(gaussian(rng), gaussian(rng), gaussian(rng));
        o.p_T = apply(X_TB, platform_point_B(real, fk.placement, truth.targets[t])) + sigma * noise;
        out.push_back(o);
      }
  }
  return out;
}

// The truth in the order of `set` (tracker rotation: zero; compare X_BT apart).
inline Eigen::VectorXd truth_vector(const ParameterSet& set, const Truth& truth) {
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(set.size());
  const ModelSpec& nominal = set.nominal();
  for (int j = 0; j < set.lead_count(); ++j) theta[j] = truth.spec.legs[static_cast<std::size_t>(j)].lead;
  for (int i = 0; i < kLegs; ++i)
    theta[set.offset_index() + i] = truth.spec.legs[static_cast<std::size_t>(i)].length_offset;
  if (set.model() == CalibrationModel::Geometry) {
    Eigen::VectorXd db(3 * kLegs), dp(3 * kLegs);
    for (int i = 0; i < kLegs; ++i) {
      db.segment<3>(3 * i) =
          truth.spec.legs[static_cast<std::size_t>(i)].base_B - nominal.legs[static_cast<std::size_t>(i)].base_B;
      dp.segment<3>(3 * i) = truth.spec.legs[static_cast<std::size_t>(i)].platform_P -
                             nominal.legs[static_cast<std::size_t>(i)].platform_P;
    }
    theta.segment(set.base_index(), 3 * kLegs - 6) = set.base_basis().transpose() * db;
    theta.segment(set.platform_index(), 3 * kLegs - 6) = set.platform_basis().transpose() * dp;
    for (int a = 0, k = set.axis_index(); a < 2 * kLegs; ++a) {
      if (!set.axes()[static_cast<std::size_t>(a)]) continue;
      const LegSpec& n = nominal.legs[static_cast<std::size_t>(a % kLegs)];
      const LegSpec& r = truth.spec.legs[static_cast<std::size_t>(a % kLegs)];
      const Vector3d axis0 = (a < kLegs ? n.axis_base_B : n.axis_platform_P).normalized();
      Vector3d axis = a < kLegs ? r.axis_base_B : r.axis_platform_P;
      axis /= axis.dot(axis0);  // axis0 + u1 e1 + u2 e2
      theta[k] = axis.dot(set.axis_directions(a)[0]);
      theta[k + 1] = axis.dot(set.axis_directions(a)[1]);
      k += 2;
    }
  }
  for (std::size_t t = 0; t < truth.targets.size(); ++t)
    theta.segment<3>(set.target_index() + 3 * static_cast<int>(t)) = truth.targets[t];
  theta.segment<3>(set.translation_index()) = truth.X_BT.t;
  return theta;
}

// Estimate minus truth, the tracker rotation as dw with R_est = exp(dw) R_true.
inline Eigen::VectorXd parameter_error(const Identification& id, const Truth& truth) {
  Eigen::VectorXd d = id.estimate - truth_vector(id.parameters, truth);
  const Eigen::AngleAxisd r(Matrix3d(id.X_BT.R * truth.X_BT.R.transpose()));
  d.segment<3>(id.parameters.rotation_index()) = r.angle() * r.axis();
  return d;
}

// How well a corrected model commands the real platform on poses not used: its commands at
// `count` random poses within +-translation, +-rotation, run on the real platform, against where
// the corrected model puts its A; in the gauge frames and after a rigid re-alignment (sorted), and
// the largest miss of the nominal model's commands.
struct HeldOut {
  std::vector<double> gauge, aligned;
  double nominal_miss = 0.0;
  double gauge_median() const { return gauge[gauge.size() / 2]; }
  double aligned_median() const { return aligned[aligned.size() / 2]; }
};

inline HeldOut held_out(const Model& nominal, const Identification& id, const Truth& truth, double translation,
                        double rotation, int count, std::mt19937_64& rng) {
  const Model corrected(id.corrected), real(truth.spec);
  std::vector<Vector6d> poses;
  HeldOut out;
  while (static_cast<int>(poses.size()) < count) {
    const Pose p = random_pose(rng, translation, rotation);
    Vector6d command, command_nominal;
    LimitReport limit;
    if (motor_commands(corrected, p, Strategy::Compensated, command, limit) != Status::Ok) continue;
    if (motor_commands(nominal, p, Strategy::Compensated, command_nominal, limit) != Status::Ok) continue;
    FkResult fk_nominal;
    EXPECT_EQ(forward_kinematics(real, command_nominal, LengthKind::Motor, placement_from_pose(p), fk_nominal),
              Status::Ok);
    out.nominal_miss =
        std::max(out.nominal_miss, (platform_point_B(real, fk_nominal.placement, truth.spec.observation_P) -
                                    platform_point_B(nominal, placement_from_pose(p), nominal.spec().observation_P))
                                       .norm());
    poses.push_back(p.to_vector());
  }
  CommandAccuracy accuracy;
  EXPECT_EQ(command_accuracy(corrected, real, poses, accuracy), Status::Ok);
  out.gauge = accuracy.gauge;
  out.aligned = accuracy.aligned;
  return out;
}

inline void print_held_out(const char* what, const HeldOut& h, const Identification& id) {
  std::printf(
      "  %s: gauge frames median %.1f um (predicted %.1f), worst %.1f um; aligned median %.2f um (predicted %.2f), "
      "worst %.2f um; nominal model misses by up to %.2f mm\n",
      what, 1e6 * h.gauge_median(), 1e6 * id.accuracy.median, 1e6 * h.gauge.back(), 1e6 * h.aligned_median(),
      1e6 * id.accuracy.aligned_median, 1e6 * h.aligned.back(), 1e3 * h.nominal_miss);
}

}  // namespace hexatwist::test
