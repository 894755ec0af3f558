// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/dynamics/motor_sizing.hpp"

#include <algorithm>
#include <cmath>

#include "hexatwist/dynamics/leg_forces.hpp"
#include "hexatwist/kinematics/compensation.hpp"

namespace hexatwist {
namespace {

Status fail(MotorSizing& out, Status status, std::size_t index, const Trajectory& trajectory) {
  out.status = status;
  out.failed_index = index;
  out.failed_time = trajectory.time(index);
  return status;
}

// True if violation `a` comes before `b` in the order MotorSizing::violation documents.
bool earlier(const EnvelopeViolation& a, const EnvelopeViolation& b) {
  if (b.check == EnvelopeCheck::None) return a.check != EnvelopeCheck::None;
  if (a.check == EnvelopeCheck::None) return false;
  const bool a_rms = a.check == EnvelopeCheck::ContinuousTorque, b_rms = b.check == EnvelopeCheck::ContinuousTorque;
  if (a_rms != b_rms) return b_rms;
  if (a.index != b.index) return a.index < b.index;
  if (a.leg != b.leg) return a.leg < b.leg;
  return a.check == EnvelopeCheck::Speed && b.check == EnvelopeCheck::PeakTorque;
}

void summarize(const Rig& rig, const std::vector<MotorSample>& samples, double dt, int leg, MotorSummary& m) {
  const ServoSpec& servo = rig.servo();
  m = MotorSummary{};
  double sum_torque2 = 0.0;
  std::array<double, kTorqueTerms> sum_term2{};
  for (std::size_t k = 0; k < samples.size(); ++k) {
    const MotorSample& s = samples[k];
    const double tau = s.torque[leg], w = s.speed[leg], p = s.power[leg];
    const double abs_tau = std::abs(tau), abs_w = std::abs(w);
    if (abs_tau > m.peak_torque) {
      m.peak_torque = abs_tau;
      m.peak_torque_time = s.time;
    }
    if (abs_w > m.peak_speed) {
      m.peak_speed = abs_w;
      m.peak_speed_time = s.time;
    }
    if (p > m.peak_power) {
      m.peak_power = p;
      m.peak_power_time = s.time;
    }
    // Energy by the rectangle rule over the sample period (the samples are the trajectory's).
    (p > 0.0 ? m.energy_driven : m.energy_regenerated) += std::abs(p) * dt;
    sum_torque2 += tau * tau;
    for (int t = 0; t < kTorqueTerms; ++t) sum_term2[t] += s.terms[t][leg] * s.terms[t][leg];

    // The pointwise checks, speed first: beyond max_speed the peak torque is 0 and means nothing more.
    // On a bound is inside it, with the tolerance of limits.hpp.
    if (abs_w > accepted_max(servo.max_speed)) {
      if (m.violation.check == EnvelopeCheck::None)
        m.violation = {EnvelopeCheck::Speed, leg, k, s.time, abs_w, servo.max_speed};
      continue;
    }
    const double peak = peak_torque_at(servo, std::min(abs_w, servo.max_speed));
    const double usage = peak > 0.0 ? abs_tau / peak : (abs_tau > 0.0 ? INFINITY : 0.0);
    if (usage > m.peak_usage) {
      m.peak_usage = usage;
      m.peak_usage_time = s.time;
    }
    if (abs_tau > accepted_max(peak) && m.violation.check == EnvelopeCheck::None)
      m.violation = {EnvelopeCheck::PeakTorque, leg, k, s.time, abs_tau, peak};
  }
  const double n = static_cast<double>(samples.size());
  m.rms_torque = std::sqrt(sum_torque2 / n);
  for (int t = 0; t < kTorqueTerms; ++t)
    m.share[t] = m.rms_torque > 0.0 ? std::sqrt(sum_term2[t] / n) / m.rms_torque : 0.0;
  m.speed_usage = m.peak_speed / servo.max_speed;
  m.rms_usage = m.rms_torque / servo.continuous_torque;
  if (m.rms_torque > accepted_max(servo.continuous_torque) && m.violation.check == EnvelopeCheck::None)
    m.violation = {EnvelopeCheck::ContinuousTorque, leg, samples.size() - 1, samples.back().time, m.rms_torque,
                   servo.continuous_torque};
}

}  // namespace

std::string_view to_string(TorqueTerm term) noexcept {
  switch (term) {
    case TorqueTerm::Gravity:
      return "gravity";
    case TorqueTerm::PlatformInertia:
      return "platform_inertia";
    case TorqueTerm::VelocityProduct:
      return "velocity_product";
    case TorqueTerm::Legs:
      return "legs";
    case TorqueTerm::Drives:
      return "drives";
    case TorqueTerm::Friction:
      return "friction";
  }
  return "unknown";
}

std::string_view to_string(EnvelopeCheck check) noexcept {
  switch (check) {
    case EnvelopeCheck::None:
      return "none";
    case EnvelopeCheck::Speed:
      return "speed";
    case EnvelopeCheck::PeakTorque:
      return "peak_torque";
    case EnvelopeCheck::ContinuousTorque:
      return "continuous_torque";
  }
  return "unknown";
}

Status size_motors(const Rig& rig, const Trajectory& trajectory, MotorSizing& out) {
  out = MotorSizing{};
  const std::vector<Pose>& poses = trajectory.poses;
  const std::size_t n = poses.size();
  if (n < 2 || !(trajectory.dt > 0.0) || !std::isfinite(trajectory.dt) || !std::isfinite(trajectory.t0))
    return fail(out, Status::NonFiniteInput, 0, trajectory);
  if (!check_trajectory_samples(trajectory.t0, trajectory.dt, n).empty())
    return fail(out, Status::InvalidArgument, 0, trajectory);
  const double dt = trajectory.dt;
  out.samples.reserve(n);
  CommandReport commands;
  InverseDynamics id;
  for (std::size_t k = 0; k < n; ++k) {
    // The motor's speed and torque are the envelope's to judge; the pose must be inside its limits.
    if (const Status s = compute_commands(rig.model(), poses[k], commands); s != Status::Ok) {
      out.limit = commands.limit;
      return fail(out, s, k, trajectory);
    }
    // Differences as make_plan (simulation.cpp) takes them of the motor references.
    const PlatformMotion motion = trajectory_motion(trajectory, k);
    if (const Status s = inverse_dynamics(rig, motion, id); s != Status::Ok) return fail(out, s, k, trajectory);
    MotorSample& sample = out.samples.emplace_back();
    sample.time = trajectory.time(k);
    sample.torque = id.torque;
    sample.speed = id.speed;
    sample.power = id.power;
    sample.terms[static_cast<int>(TorqueTerm::Gravity)] = id.gravity;
    sample.terms[static_cast<int>(TorqueTerm::PlatformInertia)] = id.platform_inertia;
    sample.terms[static_cast<int>(TorqueTerm::VelocityProduct)] = id.velocity_product;
    sample.terms[static_cast<int>(TorqueTerm::Legs)] = id.legs;
    sample.terms[static_cast<int>(TorqueTerm::Drives)] = id.drives;
    sample.terms[static_cast<int>(TorqueTerm::Friction)] = id.friction;
  }
  for (int i = 0; i < kLegs; ++i) {
    summarize(rig, out.samples, dt, i, out.motors[i]);
    if (earlier(out.motors[i].violation, out.violation)) out.violation = out.motors[i].violation;
  }
  return Status::Ok;
}

TorqueSpeedFigure torque_speed_figure(const Rig& rig, const MotorSizing& sizing, int envelope_points) {
  const ServoSpec& servo = rig.servo();
  TorqueSpeedFigure fig;
  fig.continuous_torque = servo.continuous_torque;
  fig.max_speed = servo.max_speed;
  for (int i = 0; i < kLegs; ++i) {
    Curve& c = fig.operating[i];
    c.speed.reserve(sizing.samples.size());
    c.torque.reserve(sizing.samples.size());
    for (const MotorSample& s : sizing.samples) {
      c.speed.push_back(s.speed[i]);
      c.torque.push_back(s.torque[i]);
    }
  }
  // Speeds of one half, 0 to max_speed, with the corner exactly (the envelope's kink).
  const int count = std::max(envelope_points, 2);
  std::vector<double> half;
  for (int j = 0; j < count; ++j) half.push_back(servo.max_speed * j / (count - 1));
  if (servo.peak_corner_speed > 0.0 && servo.peak_corner_speed < servo.max_speed)
    half.push_back(servo.peak_corner_speed);
  std::sort(half.begin(), half.end());
  half.erase(std::unique(half.begin(), half.end()), half.end());
  // The top from -max to +max, the bottom back; peak_torque_at at max_speed itself is the
  // envelope's end value (beyond it, 0).
  Curve& e = fig.envelope;
  const auto add = [&](double w, double t) {
    e.speed.push_back(w);
    e.torque.push_back(t);
  };
  for (auto it = half.rbegin(); it != half.rend(); ++it) add(-*it, peak_torque_at(servo, *it));
  for (std::size_t j = 1; j < half.size(); ++j) add(half[j], peak_torque_at(servo, half[j]));
  for (auto it = half.rbegin(); it != half.rend(); ++it) add(*it, -peak_torque_at(servo, *it));
  for (std::size_t j = 1; j < half.size(); ++j) add(-half[j], -peak_torque_at(servo, half[j]));
  add(e.speed.front(), e.torque.front());
  return fig;
}

}  // namespace hexatwist
