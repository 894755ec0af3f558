// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/parameter_set.hpp"

#include <fmt/format.h>

#include "hexatwist/error.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace hexatwist {

Eigen::MatrixXd gauge_basis(const LegVectors& points) {
  // The six linear conditions G d = 0 (theory §13); the basis spans G's null space.
  const Vector3d c = points.colwise().mean().transpose();
  Eigen::Matrix<double, 6, 3 * kLegs> G = Eigen::Matrix<double, 6, 3 * kLegs>::Zero();
  for (int i = 0; i < kLegs; ++i) {
    const Vector3d r = points.row(i).transpose() - c;
    G.block<3, 3>(0, 3 * i).setIdentity();
    Matrix3d skew_r;
    skew_r << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
    G.block<3, 3>(3, 3 * i) = skew_r;  // r x d
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(G, Eigen::ComputeFullV);
  return svd.matrixV().rightCols(3 * kLegs - 6);
}

std::string EffectFit::names() const {
  std::string out;
  for (const auto& [on, name] : {std::pair{load, "load"}, std::pair{play, "play"}, std::pair{heat, "heat"}}) {
    if (!on) continue;
    if (!out.empty()) out += ',';
    out += name;
  }
  return out.empty() ? "none" : out;
}

EffectFit effect_fit(std::string_view names) {
  EffectFit fit;
  if (names == "none") return fit;
  std::size_t begin = 0;
  while (begin <= names.size()) {
    const std::size_t end = std::min(names.find(',', begin), names.size());
    const std::string_view word = names.substr(begin, end - begin);
    bool* named = word == "load" ? &fit.load : word == "play" ? &fit.play : word == "heat" ? &fit.heat : nullptr;
    if (named != nullptr && *named) throw Error(fmt::format("effects: '{}' is named twice in '{}'", word, names));
    if (word == "none" || word == "auto")
      throw Error(fmt::format("effects: '{}' stands alone, not in a list ('{}')", word, names));
    if (named != nullptr)
      *named = true;
    else
      throw Error(
          fmt::format("effects: '{}' is not one of load, play, heat (a comma-separated list), none, or auto (identify: "
                      "those the data show)",
                      word));
    begin = end + 1;
  }
  return fit;
}

ParameterSet::ParameterSet(const Model& nominal, CalibrationModel model, LeadEffect lead_effect,
                           const AxisSelection& axes, int targets, LeadFit leads, EffectFit effects)
    : nominal_(nominal.spec()),
      model_(model),
      lead_effect_(lead_effect),
      effects_(effects),
      targets_(std::max(targets, 1)) {
  bool same_lead = true;
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = nominal.leg(i);
    nominal_drive_lead_[i] = leg.lead > 0.0 ? leg.lead / leg.drive_scale : 0.0;
    nominal_home_command_[i] = nominal.home_command()[i];
    same_lead = same_lead && leg.lead == nominal.leg(0).lead;
  }
  lead_count_ = same_lead && leads == LeadFit::Shared ? 1 : kLegs;
  offset_ = lead_count_;
  int next = offset_ + kLegs;
  if (effects_.load) compliance_ = next++;
  if (effects_.play) {
    play_ = next;
    next += kLegs;
  }
  if (effects_.heat) {
    drift_ = next;
    next += kLegs;
    if (!effects_.measured) {
      curvature_ = next;
      next += kLegs;
    }
    lead_drift_ = next++;
  }
  length_home_ = nominal.length_home();
  if (model_ == CalibrationModel::Geometry) {
    base_ = next;
    platform_ = base_ + 3 * kLegs - 6;
    next = platform_ + 3 * kLegs - 6;
    base_basis_ = gauge_basis(nominal.geometry().base_B);
    platform_basis_ = gauge_basis(nominal.geometry().arm_P);
    axes_ = axes;
    axis_ = next;
    for (int a = 0; a < 2 * kLegs; ++a) {
      if (!axes_[static_cast<std::size_t>(a)]) continue;
      const Leg& leg = nominal.leg(a % kLegs);
      if (std::isnan(leg.theta_home)) {
        axes_[static_cast<std::size_t>(a)] = false;  // a leg without axes has nothing to fit
        continue;
      }
      const Vector3d axis = a < kLegs ? leg.axis_base_B : leg.axis_platform_P;
      const Vector3d e1 = axis.unitOrthogonal();
      axis_directions_[static_cast<std::size_t>(a)] = {e1, axis.cross(e1).normalized()};
      axis_count_ += 2;
    }
    next = axis_ + axis_count_;
  }
  target_ = next;
  rotation_ = target_ + 3 * targets_;
  size_ = rotation_ + 6;
}

std::string ParameterSet::group(int i) const {
  if (i < 0 || i >= size_) return "?";
  if (i < offset_) return "lead";
  if (i < offset_ + kLegs) return "offsets";
  if (i == compliance_) return "load";
  if (play_ >= 0 && i >= play_ && i < play_ + kLegs) return "play";
  if (drift_ >= 0 && i >= drift_ && i <= lead_drift_) return "heat";
  if (base_ >= 0 && i < platform_) return "base joints";
  if (platform_ >= 0 && i < axis_) return "platform joints";
  if (axis_count_ > 0 && i >= axis_ && i < axis_ + axis_count_) return "axes";
  if (i < rotation_) return "targets";
  return "tracker frame";
}

std::string ParameterSet::name(int i) const {
  if (i < 0 || i >= size_) return "?";
  if (i < offset_) return lead_count_ == 1 ? std::string("lead") : fmt::format("lead {}", i + 1);
  if (i < offset_ + kLegs) return fmt::format("offset {}", i - offset_ + 1);
  if (i == compliance_) return "compliance";
  if (play_ >= 0 && i >= play_ && i < play_ + kLegs) return fmt::format("play {}", i - play_ + 1);
  if (drift_ >= 0 && i >= drift_ && i < drift_ + kLegs)
    return fmt::format("{} {}", effects_.measured ? "expansion" : "drift", i - drift_ + 1);
  if (curvature_ >= 0 && i >= curvature_ && i < curvature_ + kLegs)
    return fmt::format("curvature {}", i - curvature_ + 1);
  if (i == lead_drift_) return effects_.measured ? "lead expansion" : "lead drift";
  if (base_ >= 0 && i < platform_) return fmt::format("base joints g{}", i - base_ + 1);
  if (platform_ >= 0 && i < axis_) return fmt::format("platform joints g{}", i - platform_ + 1);
  if (axis_count_ > 0 && i >= axis_ && i < axis_ + axis_count_) {
    int k = axis_;
    for (int a = 0; a < 2 * kLegs; ++a) {
      if (!axes_[static_cast<std::size_t>(a)]) continue;
      if (i < k + 2) return fmt::format("{} axis {} e{}", a < kLegs ? "base" : "platform", a % kLegs + 1, i - k + 1);
      k += 2;
    }
  }
  if (i < rotation_) {
    const int t = (i - target_) / 3, c = (i - target_) % 3;
    return t == 0 ? fmt::format("A {}", "xyz"[c]) : fmt::format("target {} {}", t + 1, "xyz"[c]);
  }
  if (i < rotation_ + 3) return fmt::format("rotation {}", "xyz"[i - rotation_]);
  return fmt::format("translation {}", "xyz"[i - rotation_ - 3]);
}

Eigen::VectorXd ParameterSet::nominal_vector() const {
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(size_);
  for (int j = 0; j < lead_count_; ++j) theta[j] = nominal_.legs[static_cast<std::size_t>(j)].lead;
  for (int i = 0; i < kLegs; ++i) theta[offset_ + i] = nominal_.legs[static_cast<std::size_t>(i)].length_offset;
  theta.segment<3>(target_) = nominal_.observation_P;
  // The effects start where the configuration puts them: its compliance and plays, no drift.
  if (compliance_ >= 0) {
    for (const LegSpec& leg : nominal_.legs) theta[compliance_] += 1.0 / leg.stiffness / kLegs;  // their mean
  }
  for (int i = 0; i < kLegs && play_ >= 0; ++i) theta[play_ + i] = nominal_.legs[static_cast<std::size_t>(i)].play;
  return theta;
}

ModelSpec ParameterSet::platform(const Eigen::VectorXd& theta, double sign, bool with_effects) const {
  ModelSpec spec = nominal_;
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
    if (compliance_ >= 0)
      // Stiffer than the Model's plausible range (1e11 N/m) is rigid to a tracker.
      leg.stiffness = with_effects && theta[compliance_] > 1e-11 ? 1.0 / theta[compliance_]
                                                                 : std::numeric_limits<double>::infinity();
    if (play_ >= 0) leg.play = with_effects ? std::max(theta[play_ + i], 0.0) : 0.0;
    if (effects_.measured && drift_ >= 0) {
      // The expansions from the log's temperatures, about the run's first (EffectFit::measured).
      leg.length_expansion = with_effects ? theta[drift_ + i] / length_home_[i] : 0.0;
      leg.lead_expansion = with_effects ? theta[lead_drift_] : 0.0;
    }
    leg.lead = theta[lead_count_ == 1 ? 0 : i];
    if (sign < 0.0) leg.thread = leg.thread == ThreadSense::Right ? ThreadSense::Left : ThreadSense::Right;
    leg.length_offset = theta[offset_ + i];
    leg.home_command = nominal_home_command_[i];
    // The drives' scale (theory §4): with the travel effect they keep converting with the nominal
    // lead; without it their travel is right, whatever the lead.
    leg.drive_lead = lead_effect_ == LeadEffect::TwistAndTravel && nominal_drive_lead_[i] > 0.0
                         ? nominal_drive_lead_[i]
                         : std::numeric_limits<double>::quiet_NaN();
  }
  if (effects_.measured && drift_ >= 0 && with_effects) spec.reference_temperature = effects_.reference_temperature;
  if (model_ == CalibrationModel::Geometry) {
    const Eigen::VectorXd db = base_basis_ * theta.segment(base_, 3 * kLegs - 6);
    const Eigen::VectorXd dp = platform_basis_ * theta.segment(platform_, 3 * kLegs - 6);
    int k = axis_;
    for (int i = 0; i < kLegs; ++i) {
      LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
      leg.base_B += db.segment<3>(3 * i);
      leg.platform_P += dp.segment<3>(3 * i);
    }
    for (int a = 0; a < 2 * kLegs; ++a) {
      if (!axes_[static_cast<std::size_t>(a)]) continue;
      LegSpec& leg = spec.legs[static_cast<std::size_t>(a % kLegs)];
      Vector3d& axis = a < kLegs ? leg.axis_base_B : leg.axis_platform_P;
      const std::array<Vector3d, 2>& e = axis_directions_[static_cast<std::size_t>(a)];
      // The axis turned towards e1 and e2 (any length: the Model normalises it).
      axis = axis.normalized() + theta[k] * e[0] + theta[k + 1] * e[1];
      k += 2;
    }
  }
  spec.observation_P = theta.segment<3>(target_);
  return spec;
}

}  // namespace hexatwist
