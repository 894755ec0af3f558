// SPDX-License-Identifier: BSD-3-Clause
// Test support: seeded random platforms and poses, an independent joint-chain twist, pose errors,
// stress counts and measured-residual reports.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <optional>
#include <random>
#include <string>
#include <string_view>

#include "hexatwist/hexatwist.hpp"

namespace hexatwist::test {

/// Seed of every random generator in the suite (printed by failing tests through SCOPED_TRACE).
inline constexpr std::uint32_t kSeed = 20211124u;

/// `count` times the environment variable HEXATWIST_STRESS (an integer, default 1), for the
/// seeded random stress tests: `HEXATWIST_STRESS=1000 ctest -R Trajectory` for a long run.
inline int stress(int count) {
  const char* s = std::getenv("HEXATWIST_STRESS");
  const int factor = s != nullptr ? std::atoi(s) : 1;
  return count * std::max(factor, 1);
}

/// `f` must throw hexatwist::Error whose message is one line, starts with `start` (e.g.
/// "bad.csv:3:14: column 'pitch':") and contains every one of `parts`.
template <class F>
void expect_error_line(F&& f, std::string_view start, std::initializer_list<std::string_view> parts = {}) {
  std::string msg;
  try {
    f();
    ADD_FAILURE() << "no error was thrown; expected one starting with " << start;
    return;
  } catch (const Error& e) {
    msg = e.what();
  }
  SCOPED_TRACE("message: " + msg);
  EXPECT_EQ(msg.find('\n'), std::string::npos) << "not a single line";
  EXPECT_EQ(msg.find('\r'), std::string::npos) << "carries a carriage return";
  EXPECT_EQ(msg.rfind(start, 0), 0u) << "does not start with " << start;
  for (const std::string_view p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "does not name '" << p << "'";
}

/// Prints a measured residual (the tolerances are set about 10x these).
inline void report(const char* what, double value) { std::printf("  measured %s: %.3g\n", what, value); }

/// The embedded seed platform (configs/seed.yaml).
inline const Model& seed_model() {
  static const Model m = default_model();
  return m;
}

/// The embedded seed platform with its servo, load and mechanism (configs/seed.yaml).
inline const Rig& seed_rig() {
  static const Config config = load_config(std::string(seed_config_yaml()), "seed.yaml");
  return config.rig;
}

/// Uniform double in [lo, hi].
inline double uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

/// Random pose with |x,y,z| <= dpos [m] and |roll,pitch,yaw| <= drot [rad].
inline Pose random_pose(std::mt19937_64& rng, double dpos, double drot) {
  Pose p;
  for (int k = 0; k < 3; ++k) p.position[k] = uniform(rng, -dpos, dpos);
  for (int k = 0; k < 3; ++k) p.rpy[k] = uniform(rng, -drot, drot);
  return p;
}

/// Random pose inside every limit of `model`, its compensated command included (rejection sampling).
inline Pose random_valid_pose(const Model& model, std::mt19937_64& rng, double dpos, double drot) {
  CommandReport report;
  for (;;) {
    const Pose p = random_pose(rng, dpos, drot);
    if (compute_commands(model, p, report) == Status::Ok) return p;
  }
}

/// The seed platform with stroke and bend limits wide enough for a pure yaw to 90 deg: only the
/// platform-singularity limit stops it (the condition proof and the exact number decide there).
inline Model seed_with_wide_limits() {
  ModelSpec spec = seed_model().spec();
  spec.limits.length_min = 0.5;
  spec.limits.length_max = 4.0;
  spec.limits.bend_max = deg2rad(89);
  return Model(spec);
}

/// The seed platform with zero errors (length offsets) drawn uniformly in [-max_offset, max_offset] [m].
inline Model seed_with_offsets(std::mt19937_64& rng, double max_offset) {
  ModelSpec spec = seed_model().spec();
  for (LegSpec& leg : spec.legs) leg.length_offset = uniform(rng, -max_offset, max_offset);
  return Model(spec);
}

/// A random, asymmetric but well-conditioned platform: joints scattered around two circles,
/// fixed axes tilted at random, a random lead and sign of the twist term.
inline Model random_platform(std::mt19937_64& rng) {
  for (;;) {
    ModelSpec spec;
    spec.name = "random asymmetric platform";
    const double Rb = uniform(rng, 0.6, 1.6), Ra = uniform(rng, 0.4, 1.2);
    spec.home_height = uniform(rng, 0.8, 1.8);
    for (int i = 0; i < kLegs; ++i) {
      LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
      const double pair = (i / 2) * 2.0 * kPi / 3.0;
      const double beta = pair + (i % 2 == 0 ? -1 : 1) * uniform(rng, 0.1, 0.5) + uniform(rng, -0.1, 0.1);
      const double alpha = pair + kPi / 3.0 + (i % 2 == 0 ? 1 : -1) * uniform(rng, 0.6, 0.9);
      leg.base_B = Vector3d(Rb * std::cos(beta), Rb * std::sin(beta), uniform(rng, -0.05, 0.05));
      leg.platform_P = Vector3d(Ra * std::cos(alpha), Ra * std::sin(alpha), uniform(rng, -0.05, 0.05));
      leg.axis_base_B = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
      leg.axis_platform_P = Vector3d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
      leg.lead = uniform(rng, 0.002, 0.02);
      leg.thread = uniform(rng, 0, 1) < 0.5 ? ThreadSense::Right : ThreadSense::Left;
      leg.driven = uniform(rng, 0, 1) < 0.5 ? DrivenSide::Base : DrivenSide::Platform;
    }
    spec.limits = {0.1, 10.0, deg2rad(45.0), deg2rad(15.0)};
    spec.observation_P = spec.legs[0].platform_P;
    spec.pivot_P = Vector3d(uniform(rng, -0.1, 0.1), uniform(rng, -0.1, 0.1), uniform(rng, -0.1, 0.1));
    try {
      return Model(spec);
    } catch (const Error&) {
      // axis too close to its leg, or a badly conditioned layout: draw again
    }
  }
}

/// Rotation of a U-joint whose first axis u is fixed and whose second (cross) axis is
/// w = unit(s0 x u) at home, that turns the home leg direction s0 onto s: Rot(u, a) * Rot(w, b).
/// Solved from the joint angles, independently of the library's twist formula.
inline Matrix3d ujoint_rotation(const Vector3d& u, const Vector3d& s0, const Vector3d& s) {
  const Vector3d w = s0.cross(u).normalized();
  const double phi0 = std::atan2(s0.cross(u).norm(), s0.dot(u));
  const double phi = std::atan2(s.cross(u).norm(), s.dot(u));
  const double b = phi0 - phi;  // turning s0 about w by +b brings it b closer to u
  const Vector3d v = Eigen::AngleAxisd(b, w) * s0;
  const Vector3d vp = v - v.dot(u) * u, sp = s - s.dot(u) * u;
  const double a = std::atan2(u.dot(vp.cross(sp)), vp.dot(sp));
  return (Eigen::AngleAxisd(a, u) * Eigen::AngleAxisd(b, w)).toRotationMatrix();
}

/// Twist of leg i by the joint chain (notes §3): housing = base U-joint rotation, rod = platform
/// rotation * platform U-joint rotation; their relative rotation is about s0, its angle is the
/// twist. Returns nullopt if the relative rotation is not about the leg axis (a broken chain).
inline std::optional<double> twist_by_joint_chain(const Model& model, const LegState& st, int i) {
  const Leg& leg = model.leg(i);
  const Vector3d& s0 = leg.s_home_B;
  const Vector3d s = st.s_B.row(i).transpose();
  const Matrix3d R_housing = ujoint_rotation(leg.axis_base_B, s0, s);
  const Matrix3d R_rod = st.R_BP * ujoint_rotation(leg.axis_platform_P, s0, st.R_BP.transpose() * s);
  const Matrix3d R_rel = R_housing.transpose() * R_rod;
  if ((R_rel * s0 - s0).norm() > 1e-12) return std::nullopt;
  const Vector3d v = s0.unitOrthogonal();
  const Vector3d Rv = R_rel * v;
  return std::atan2(s0.dot(v.cross(Rv)), v.dot(Rv));
}

/// Position error [m] and rotation angle error [rad] between two placements.
struct PoseError {
  double position;
  double rotation;
};
inline PoseError pose_error(const Placement& a, const Placement& b) {
  const Eigen::AngleAxisd d(a.R_BP.transpose() * b.R_BP);
  return {(a.t - b.t).norm(), std::abs(d.angle())};
}

/// "x y z roll pitch yaw" for failure messages.
inline std::string str(const Pose& p) {
  std::ostringstream os;
  os.precision(17);
  os << p.to_vector().transpose();
  return os.str();
}

}  // namespace hexatwist::test
