// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/synthesis.hpp"

#include <fmt/format.h>

#include <cmath>

#include "calibration/random.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "hexatwist/simulation/effect_cost.hpp"

namespace hexatwist {

Model real_platform(const Model& nominal, const SynthesisOptions& options) {
  return options.real ? Model(*options.real) : real_model(nominal, options.errors);
}
using detail::Random;

RigidTransform random_tracker_frame(std::uint64_t seed) {
  Random rng(seed);
  // Uniform on SO(3): a uniform unit quaternion (Shoemake, Graphics Gems III, 1992).
  const double u1 = rng.uniform(), u2 = 2.0 * kPi * rng.uniform(), u3 = 2.0 * kPi * rng.uniform();
  const Eigen::Quaterniond q(std::sqrt(u1) * std::cos(u3), std::sqrt(1.0 - u1) * std::sin(u2),
                             std::sqrt(1.0 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3));
  const double distance = 3.0 + 3.0 * rng.uniform(), azimuth = 2.0 * kPi * rng.uniform();
  const double height = 2.0 * rng.uniform();
  return {q.toRotationMatrix(), Vector3d(distance * std::cos(azimuth), distance * std::sin(azimuth), height)};
}

Vector6d random_zero_offsets(double bound, std::uint64_t seed) {
  if (!(std::isfinite(bound) && bound >= 0.0))
    throw ParameterError(fmt::format("zero offsets: expected a finite bound >= 0 m, got {:g}", bound), "zero_offset");
  Vector6d offsets = Vector6d::Zero();
  if (bound == 0.0) return offsets;
  Random rng(seed ^ 0xD1B54A32D192ED03ull);
  for (int i = 0; i < kLegs; ++i) offsets[i] = bound * rng.symmetric();
  return offsets;
}

void check_synthesis_options(const Model& nominal, const SynthesisOptions& o) {
  const auto refuse = [](const char* field, const std::string& message) {
    throw ParameterError(fmt::format("synthesis: {}", message), field);
  };
  const LimitSpec& limits = nominal.spec().limits;
  const double stroke = limits.length_max - limits.length_min;
  if (!(std::isfinite(o.noise) && o.noise >= 0.0 && o.noise < stroke))
    refuse("noise", fmt::format("expected a tracker noise >= 0 and below the stroke ({:g} m, limits.length_max - "
                                "limits.length_min: it would drown every motion), got {:g} m",
                                stroke, o.noise));
  if (!(std::isfinite(o.rate) && o.rate > 0.0))
    refuse("rate", fmt::format("expected a sample rate > 0 Hz, got {:g}", o.rate));
  const ParameterErrors& e = o.errors;
  for (int i = 0; i < kLegs; ++i) {
    if (!(e.lead_error[i] > -1.0 && e.lead_error[i] < 1.0))
      refuse("lead_error", fmt::format("expected each leg's relative lead error above -1 (a zero lead) and below 1, "
                                       "got {:g} on leg {}",
                                       e.lead_error[i], i + 1));
    if (!(std::abs(e.zero_offset[i]) < stroke))
      refuse("zero_offset", fmt::format("expected each leg's zero offset below the stroke ({:g} m) in magnitude, got "
                                        "{:g} m on leg {}",
                                        stroke, e.zero_offset[i], i + 1));
    if (!(e.base_offset_B.row(i).cwiseAbs().maxCoeff() <= kMaxJointError &&
          e.platform_offset_P.row(i).cwiseAbs().maxCoeff() <= kMaxJointError))
      refuse("joint_errors", fmt::format("expected joint-centre errors of at most {:g} m per coordinate, leg {}",
                                         kMaxJointError, i + 1));
    if (!(e.base_axis_rotation.row(i).norm() <= kMaxAxisError &&
          e.platform_axis_rotation.row(i).norm() <= kMaxAxisError))
      refuse("axis_errors",
             fmt::format("expected axis rotations of at most {:g} rad (10 deg), leg {}", kMaxAxisError, i + 1));
    if (!std::isnan(e.stiffness[i]) && !(e.stiffness[i] >= kMinStiffness && e.stiffness[i] <= kMaxStiffness) &&
        e.stiffness[i] != INFINITY)
      refuse("stiffness", fmt::format("expected an axial stiffness from {:g} to {:g} N/m (or inf: rigid), got {:g} on "
                                      "leg {}",
                                      kMinStiffness, kMaxStiffness, e.stiffness[i], i + 1));
    if (!std::isnan(e.play[i]) && !(e.play[i] >= 0.0 && e.play[i] <= kMaxPlay))
      refuse("play", fmt::format("expected a play from 0 to {:g} m, got {:g} on leg {}", kMaxPlay, e.play[i], i + 1));
    if (!(std::isfinite(o.temperature_rise[i]) && std::abs(o.temperature_rise[i]) <= kMaxTemperature - kMinTemperature))
      refuse("temperature_rise", fmt::format("expected a finite temperature rise of at most {:g} K in magnitude, got "
                                             "{:g} on leg {}",
                                             kMaxTemperature - kMinTemperature, o.temperature_rise[i], i + 1));
  }
  if (!(e.observation_offset_P.allFinite() && e.observation_offset_P.cwiseAbs().maxCoeff() < stroke))
    refuse("observation_offset",
           fmt::format("expected the observation point's offset below the stroke ({:g} m) per coordinate", stroke));
  for (const double x : {e.length_expansion, e.lead_expansion})
    if (!std::isnan(x) && !(x >= kMinExpansion && x <= kMaxExpansion))
      refuse("expansion",
             fmt::format("expected expansions from {:g} to {:g} 1/K, got {:g}", kMinExpansion, kMaxExpansion, x));
  if (o.extra_targets_P.size() + 1 > kMaxTargets)
    refuse("targets", fmt::format("{} targets, at most {}", o.extra_targets_P.size() + 1, kMaxTargets));
  for (const Vector3d& t : o.extra_targets_P)
    if (!t.allFinite()) refuse("targets", "expected finite points [m, P], got NaN or inf");
}

Status synthesize(const Rig& rig, const Trajectory& trajectory, const SynthesisOptions& options, SyntheticLog& out,
                  SimulationIssue& issue) {
  check_synthesis_options(rig.model(), options);
  out = SyntheticLog{};
  issue = SimulationIssue{};
  const double control_rate = rig.simulation().control_rate;
  const double ratio = control_rate / options.rate;
  if (!(std::isfinite(options.rate) && options.rate > 0.0) || ratio < 1.0 - 1e-9 ||
      std::abs(ratio - std::round(ratio)) > 1e-9 * ratio)
    throw Error(fmt::format("rate: {} Hz does not divide the control rate {} Hz (choose {} Hz, {} Hz, ...)",
                            options.rate, control_rate, control_rate, control_rate / 2.0));
  // At most 10^9 control periods per sample, so that the divisor converts exactly.
  if (!(ratio <= 1e9))
    throw Error(fmt::format("rate: {} Hz is below the control rate {} Hz / 1e9", options.rate, control_rate));
  const Model real = real_platform(rig.model(), options);
  const auto every = static_cast<std::size_t>(std::round(ratio));

  SimulationOptions sim;
  sim.strategy = options.strategy;
  if (const Status s = simulate(rig, trajectory, sim, out.simulation, issue); s != Status::Ok) return s;

  out.X_BT = random_tracker_frame(options.seed);
  const RigidTransform X_TB = inverse(out.X_BT);
  Random noise(options.seed ^ 0x9E3779B97F4A7C15ull);  // another stream than the placement's
  out.log.source = "synthetic log";
  // Target 0 is the observation point; the others follow it at every sample, in their order.
  std::vector<Vector3d> targets{real.spec().observation_P};
  targets.insert(targets.end(), options.extra_targets_P.begin(), options.extra_targets_P.end());
  out.log.target_names.push_back("A");
  for (std::size_t t = 1; t < targets.size(); ++t) out.log.target_names.push_back(fmt::format("T{}", t + 1));
  FkResult fk;
  Placement guess = placement_from_pose(trajectory.poses.front());
  // The play's dead band follows the drives' commands: a servo's settling within the gap (its
  // overshoot of a few um at the end of a move) is left out, since a leg's load and friction hold
  // the nut there.
  NutGap nuts;
  Vector6d direction = real.geometry().home_direction;
  const double duration = out.simulation.empty() ? 0.0 : out.simulation.back().time;
  std::size_t played = 0;  // the ticks the dead band has followed
  // The legs' temperatures at a time of the run [degC].
  const auto temperature_at = [&](double t) -> Vector6d {
    return Vector6d::Constant(real.reference_temperature()) + options.temperature_rise * warm_up_share(t, duration);
  };
  for (std::size_t k = 0; k < out.simulation.size(); k += every) {
    const SimulationSample& sample = out.simulation[k];
    for (; played <= k; ++played) {
      const SimulationSample& tick = out.simulation[played];
      direction = real.has_thermal() && real.has_play()
                      ? follow_nuts(real, tick.command, temperature_at(tick.time), nuts)
                      : follow_nuts(real, tick.command, nuts);
    }
    // The drives' motor-side lengths on the real platform: its leads, joints, offsets and the
    // drives' reference and scale (real_model) give the pose the platform takes, under its legs'
    // effects (the direction d = -2 g / b gives the play's term g - g_home).
    LegInputs inputs;
    inputs.temperature = temperature_at(sample.time);
    const Status fk_status = real.has_leg_effects()
                                 ? forward_kinematics(real, sample.motor, inputs, &direction, guess, fk)
                                 : forward_kinematics(real, sample.motor, LengthKind::Motor, guess, fk);
    if (const Status s = fk_status; s != Status::Ok) {
      issue.status = s;
      issue.index = k;
      issue.time = sample.time;
      issue.limit = LimitReport{};
      issue.limit.status = s;
      return s;
    }
    guess = fk.placement;
    for (std::size_t t = 0; t < targets.size(); ++t) {
      const Vector3d p_B = platform_point_B(real, fk.placement, targets[t]);
      Vector3d p_T = apply(X_TB, p_B);
      for (int a = 0; a < 3; ++a) p_T[a] += options.noise * noise.normal();
      out.true_B.push_back(p_B);
      out.ticks.push_back(k);
      out.log.stamps.push_back(sample.time);
      out.log.points_T.push_back(p_T);
      if (options.log_temperature) out.log.temperatures.push_back(inputs.temperature.mean());
      out.log.targets.push_back(static_cast<int>(t));
      out.log.lines.push_back(static_cast<int>(out.log.lines.size()) + 2);
      out.log.stamp_columns.push_back(1);
    }
  }
  return Status::Ok;
}

}  // namespace hexatwist
