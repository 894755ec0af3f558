// SPDX-License-Identifier: BSD-3-Clause
#include "calibration/evaluator.hpp"

#include <ceres/jet.h>

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "hexatwist/kinematics/twist.hpp"
#include "kinematics/geometry.hpp"

namespace hexatwist::detail {
namespace {

// Leg-local parameters differentiated with dual numbers: the base joint (0..2), the platform joint
// (3..5), the base axis turned towards e1, e2 (6, 7) and the platform axis likewise (8, 9).
constexpr int kLocal = 10;
using Jet = ceres::Jet<double, kLocal>;
using Jet3 = std::array<Jet, 3>;

Jet3 sub(const Jet3& a, const Jet3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Jet dot(const Jet3& a, const Jet3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Jet3 cross(const Jet3& a, const Jet3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Jet3 rotate(const Matrix3d& R, const Jet3& v) {
  Jet3 out;
  for (int r = 0; r < 3; ++r) out[r] = R(r, 0) * v[0] + R(r, 1) * v[1] + R(r, 2) * v[2];
  return out;
}
Jet3 constant(const Vector3d& v) { return {Jet(v.x()), Jet(v.y()), Jet(v.z())}; }
// v + d v / d(variable k..k+2) = the unit vectors.
Jet3 variable(const Vector3d& v, int k) { return {Jet(v.x(), k), Jet(v.y(), k + 1), Jet(v.z(), k + 2)}; }
// An axis turned towards e1 (variable k) and e2 (variable k + 1).
Jet3 axis_variable(const Vector3d& a, const std::array<Vector3d, 2>& e, int k) {
  Jet3 out = constant(a);
  for (int c = 0; c < 3; ++c) {
    out[static_cast<std::size_t>(c)].v[k] = e[0][c];
    out[static_cast<std::size_t>(c)].v[k + 1] = e[1][c];
  }
  return out;
}

// The twist angle jb -> je about s, theory §3: atan2(s . (ja x jd), ja . jd - (ja . s)(jd . s)),
// homogeneous in the axes' lengths (so they need no normalising).
Jet twist_angle(const Jet3& s, const Jet3& ja, const Jet3& jd) {
  return atan2(dot(s, cross(ja, jd)), dot(ja, jd) - dot(ja, s) * dot(jd, s));
}

// d(|L_i| - k_i dtheta_i) with respect to leg i's local parameters at the placement x (theory §13):
// the length and the twist since home, whose home angle moves with the joints and axes too.
Eigen::Matrix<double, 1, kLocal> leg_gradient(const Model& candidate, const ParameterSet& set, int i,
                                              const Placement& x) {
  const ModelSpec& spec = candidate.spec();
  const LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
  const Jet3 b = variable(leg.base_B, 0), p = variable(leg.platform_P, 3);
  const Jet3 arm = sub(p, constant(spec.pivot_P));
  const Jet3 Rarm = rotate(x.R_BP, arm);
  const Vector3d origin = candidate.pivot_home_B() + x.t;
  const Jet3 L = sub({Rarm[0] + origin.x(), Rarm[1] + origin.y(), Rarm[2] + origin.z()}, b);
  const Jet length = sqrt(dot(L, L));
  Jet f = length;
  const double k = candidate.leg(i).twist_gain;
  if (!std::isnan(candidate.leg(i).theta_home) && k != 0.0) {
    const Jet3 s = {L[0] / length, L[1] / length, L[2] / length};
    const Jet3 ja = axis_variable(leg.axis_base_B, set.axis_directions(i), 6);
    const Jet3 jd = axis_variable(leg.axis_platform_P, set.axis_directions(kLegs + i), 8);
    const Jet3 L0 = sub({p[0], p[1], p[2] + spec.home_height}, b);
    const Jet length0 = sqrt(dot(L0, L0));
    const Jet3 s0 = {L0[0] / length0, L0[1] / length0, L0[2] / length0};
    f -= k * (twist_angle(s, ja, rotate(x.R_BP, jd)) - twist_angle(s0, ja, jd));
  }
  return f.v.transpose();
}

}  // namespace

Status pose_sensitivity(const Model& candidate, const ParameterSet& set, const FkResult& fk, const Vector6d& motor,
                        Eigen::Matrix<double, 6, Eigen::Dynamic>& dx_dtheta,
                        const Eigen::Matrix<double, 6, Eigen::Dynamic>* effects) {
  Matrix6d J_f_x;
  if (const Status s = length_jacobian(candidate, fk.legs, LengthKind::Motor, J_f_x); s != Status::Ok) return s;
  // The twist even where a lead is 0: the lead's own column is the twist (a sense that drove the
  // lead to its bound still has a determined lead column there).
  Vector6d dtheta = Vector6d::Zero();
  if (const Status s = twist(candidate, fk.legs, dtheta); s != Status::Ok) return s;
  const int n = set.platform_size();
  Eigen::Matrix<double, 6, Eigen::Dynamic> df(6, n);
  df.setZero();
  const bool travel = set.lead_effect() == LeadEffect::TwistAndTravel;
  const bool geometry = set.model() == CalibrationModel::Geometry;
  const int joints = 3 * kLegs - 6;
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = candidate.leg(i);
    // The lead enters the twist term and, with the travel effect, the nut's travel about the
    // drives' reference: u = h + (P / P_drive)(m - h) (theory §4, §13).
    double d_lead = -leg.twist_sign * dtheta[i] / (2.0 * kPi);
    if (travel && leg.lead > 0.0) d_lead -= (motor[i] - candidate.home_command()[i]) * leg.drive_scale / leg.lead;
    df(i, set.lead_count() == 1 ? 0 : i) = d_lead;
    df(i, set.offset_index() + i) = -1.0;
    if (effects != nullptr && effects->cols() > 0)
      df.row(i).segment(set.effect_index(), effects->cols()) = -effects->row(i);
    if (!geometry) continue;
    const Eigen::Matrix<double, 1, kLocal> g = leg_gradient(candidate, set, i, fk.placement);
    df.row(i).segment(set.base_index(), joints) = g.segment<3>(0) * set.base_basis().middleRows<3>(3 * i);
    df.row(i).segment(set.platform_index(), joints) = g.segment<3>(3) * set.platform_basis().middleRows<3>(3 * i);
    int k = set.axis_index();
    for (int a = 0; a < 2 * kLegs; ++a) {
      if (!set.axes()[static_cast<std::size_t>(a)]) continue;
      if (a % kLegs == i) df.row(i).segment<2>(k) = g.segment<2>(a < kLegs ? 6 : 8);
      k += 2;
    }
  }
  const Eigen::PartialPivLU<Matrix6d> lu(J_f_x);
  if (!(std::abs(lu.determinant()) > 0.0)) return Status::SingularJacobian;
  dx_dtheta = -lu.solve(df);
  return Status::Ok;
}

Vector3d target_B(const Model& candidate, const Placement& x, const ParameterSet& set, const Eigen::VectorXd& theta,
                  int target) {
  return platform_point_B(candidate, x, set.target(theta, target));
}

Eigen::Matrix<double, 3, Eigen::Dynamic> point_sensitivity(const ParameterSet& set, const FkResult& fk,
                                                           const Eigen::Matrix<double, 6, Eigen::Dynamic>& dx_dtheta,
                                                           const Eigen::VectorXd& theta, int target) {
  // A_B = pivot_home + t + R (A_P - pivot_P): a left perturbation of R turns the arm (theory §13).
  const Vector3d arm_B = fk.placement.R_BP * (set.target(theta, target) - set.nominal().pivot_P);
  Eigen::Matrix<double, 3, 6> dA_dx;
  dA_dx.leftCols<3>().setIdentity();
  dA_dx.rightCols<3>() = -skew(arm_B);
  Eigen::Matrix<double, 3, Eigen::Dynamic> G = dA_dx * dx_dtheta;
  G.middleCols<3>(set.target_index() + 3 * target) += fk.placement.R_BP;
  return G;
}

void play_terms(const Model& nominal, const Vector6d& approach, const Vector6d& play, Vector6d& coefficient,
                Vector6d& constant, Vector6d& direction) noexcept {
  for (int i = 0; i < kLegs; ++i) {
    const double sense = approach[i] >= 0.0 ? 1.0 : -1.0, run = std::abs(approach[i]);
    const double home = nominal.geometry().home_direction[i];
    if (play[i] <= run) {
      coefficient[i] = -0.5 * (sense - home);
      constant[i] = 0.0;
      direction[i] = sense;
    } else {
      coefficient[i] = 0.5 * (sense + home);
      constant[i] = -sense * run;
      direction[i] = sense * (2.0 * run / play[i] - 1.0);
    }
  }
}

EffectRegressors effect_regressors(const ParameterSet& set, std::span<const Observation> observations,
                                   const ObservationGroups& groups, const std::vector<Vector6d>& station_motor) {
  EffectRegressors out;
  const Model nominal(set.nominal());
  const std::size_t stations = station_motor.size();
  // Each leg's approach: the observations', or where they do not say (Observation::approach 0) the
  // sense of its last change of command between stations, from home in the homing direction, as a
  // run longer than any play.
  std::vector<Vector6d> given(stations, Vector6d::Zero());
  for (std::size_t g = 0; g < groups.station.size(); ++g)
    given[static_cast<std::size_t>(groups.station[g])] = observations[groups.first[g]].approach;
  Vector6d last = nominal.home_command(), direction = nominal.geometry().home_direction;
  for (std::size_t s = 0; s < stations; ++s) {
    const Vector6d& m = station_motor[s];
    Vector6d approach;
    for (int i = 0; i < kLegs; ++i) {
      if (std::abs(m[i] - last[i]) > kSameCommand) direction[i] = m[i] > last[i] ? 1.0 : -1.0;
      last[i] = m[i];
      approach[i] = given[s][i] != 0.0 ? given[s][i] : direction[i] * 2.0 * kMaxPlay;
      if (given[s][i] != 0.0) direction[i] = given[s][i] > 0.0 ? 1.0 : -1.0;
    }
    out.approach.push_back(approach);
  }
  out.constant.assign(stations, Vector6d::Zero());
  const EffectFit& fit = set.effects();
  out.regressors.assign(stations, Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, fit.count()));
  if (!fit.any()) return out;
  const auto fail = [&](std::string reason) {
    out.status = Status::NotIdentifiable;
    out.reason = std::move(reason);
    return out;
  };
  // Each station's time as a fraction of the run's (heat).
  std::vector<double> time(stations, std::numeric_limits<double>::quiet_NaN());
  double t0 = INFINITY, t1 = -INFINITY;
  for (const Observation& o : observations) {
    t0 = std::min(t0, o.time);
    t1 = std::max(t1, o.time);
  }
  // Each station's temperature above the run's first (heat from the log's temperatures).
  std::vector<double> warming(stations, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t g = 0; g < groups.station.size(); ++g) {
    time[static_cast<std::size_t>(groups.station[g])] = observations[groups.first[g]].time;
    warming[static_cast<std::size_t>(groups.station[g])] =
        observations[groups.first[g]].temperature - fit.reference_temperature;
  }
  if (fit.heat && fit.measured &&
      !(std::isfinite(fit.reference_temperature) &&
        std::all_of(warming.begin(), warming.end(), [](double w) { return std::isfinite(w); })))
    return fail("heat: the legs' expansion needs each observation's temperature and the run's first");
  if (fit.heat && fit.measured) {
    const auto [low, high] = std::minmax_element(warming.begin(), warming.end());
    if (!(*high - *low >= kMinTemperatureSpread))
      return fail(
          fmt::format("heat: the log's temperatures vary by {:.3g} K over the run; the legs' expansion per "
                      "kelvin needs at least {:g} K (a machine that does not warm needs no heat: leave it "
                      "out, --effects without heat)",
                      *high - *low, kMinTemperatureSpread));
  }
  if (fit.heat && !fit.measured &&
      !(std::isfinite(t0) && std::isfinite(t1) && t1 > t0 &&
        std::all_of(observations.begin(), observations.end(),
                    [](const Observation& o) { return std::isfinite(o.time); })))
    return fail("heat: the legs' drift needs each observation's time, over a run of some duration");
  if (fit.load && !nominal.spec().static_load.present)
    return fail("load: the legs' forces need the configuration's load (its load and mechanism sections)");
  Placement guess;
  for (std::size_t s = 0; s < stations; ++s) {
    Eigen::Matrix<double, 6, Eigen::Dynamic>& r = out.regressors[s];
    int k = 0;
    if (fit.load) {
      FkResult fk;
      Vector6d force;
      const Status st = forward_kinematics(nominal, station_motor[s], LengthKind::Motor, guess, fk);
      if (st != Status::Ok || static_leg_forces(nominal, nominal.spec().static_load, fk.legs, force) != Status::Ok)
        return fail(fmt::format("load: station {}: the nominal model's forces there cannot be computed ({})", s + 1,
                                describe(st)));
      guess = fk.placement;
      r.col(k++) = force - nominal.reference_force();
    }
    if (fit.play) k += kLegs;  // play_terms, at each evaluation's plays
    if (fit.heat && fit.measured) {
      const double dT = warming[s];  // k_i dT + a_P dT (u_i - h_i)
      for (int i = 0; i < kLegs; ++i) {
        r(i, k + i) = dT;
        r(i, k + kLegs) = dT * (station_motor[s][i] - nominal.home_command()[i]);
      }
    } else if (fit.heat) {
      const double f = (time[s] - t0) / (t1 - t0);
      for (int i = 0; i < kLegs; ++i) {
        r(i, k + i) = f;
        r(i, k + kLegs + i) = f * f;
        r(i, k + 2 * kLegs) = f * (station_motor[s][i] - nominal.home_command()[i]);
      }
    }
  }
  return out;
}

Evaluator::Evaluator(const ParameterSet& set, std::span<const Observation> observations,
                     const ObservationGroups& groups, const FkOptions& fk)
    : set_(set), observations_(observations), groups_(groups), fk_options_(fk) {
  station_motor_.resize(static_cast<std::size_t>(groups.stations));
  for (std::size_t g = 0; g < groups.station.size(); ++g)
    station_motor_[static_cast<std::size_t>(groups.station[g])] = observations[groups.first[g]].motor;
  poses_.assign(station_motor_.size(), Placement{});
  effects_ = effect_regressors(set, observations, groups, station_motor_);
}

Status Evaluator::evaluate(const Eigen::VectorXd& theta, double sign, const RigidTransform& X_BT, Eigen::VectorXd& e,
                           Eigen::MatrixXd* J, std::span<const char> skip) {
  candidate_.reset();
  if (effects_.status != Status::Ok) {
    failed_station_ = -1;
    return effects_.status;
  }
  try {
    candidate_.emplace(set_.platform(theta, sign));
  } catch (const Error&) {
    failed_station_ = -1;
    return Status::NonFiniteInput;  // a lead, offset or joint the Model refuses
  }
  const Model& model = *candidate_;
  const auto stations = static_cast<std::size_t>(groups_.stations);
  const auto skipped = [&](std::size_t s) { return s < skip.size() && skip[s] != 0; };
  std::vector<FkResult> fk(stations);
  const int fitted = set_.effects().count();
  const Eigen::VectorXd effect_theta = theta.segment(set_.effect_index(), fitted);
  // The plays: fitted ones from theta, the configuration's own otherwise.
  Vector6d play = 2.0 * model.geometry().half_play;
  if (set_.play_index() >= 0) play = theta.segment<kLegs>(set_.play_index());
  for (std::size_t s = 0; s < stations; ++s) {
    if (skipped(s)) continue;
    Vector6d coefficient, constant, direction;
    play_terms(model, effects_.approach[s], play, coefficient, constant, direction);
    if (set_.play_index() >= 0) {
      const int column = set_.play_index() - set_.effect_index();
      for (int i = 0; i < kLegs; ++i) effects_.regressors[s](i, column + i) = coefficient[i];
      effects_.constant[s] = constant;
    }
    // The fitted effects shift the legs' lengths, so the nut's travel: the drives' command by that
    // over their scale. The configuration's own effects act at the station's approach direction.
    Vector6d motor = station_motor_[s];
    if (fitted > 0) {
      const Vector6d shift = effects_.regressors[s] * effect_theta + effects_.constant[s];
      for (int i = 0; i < kLegs; ++i) motor[i] += shift[i] / model.leg(i).drive_scale;
    }
    const Status st = model.has_leg_effects()
                          ? forward_kinematics(model, motor, LegInputs{}, &direction, poses_[s], fk[s], fk_options_)
                          : forward_kinematics(model, motor, LengthKind::Motor, poses_[s], fk[s], fk_options_);
    if (st != Status::Ok && st != Status::AssemblyModeChanged) {
      failed_station_ = static_cast<int>(s);
      return st;
    }
    poses_[s] = fk[s].placement;
  }
  std::vector<Eigen::Matrix<double, 6, Eigen::Dynamic>> dx(J != nullptr ? stations : 0);
  for (std::size_t s = 0; s < dx.size(); ++s) {
    if (skipped(s)) continue;
    if (const Status st = pose_sensitivity(model, set_, fk[s], station_motor_[s], dx[s], &effects_.regressors[s]);
        st != Status::Ok) {
      failed_station_ = static_cast<int>(s);
      return st;
    }
  }
  const auto groups = static_cast<Eigen::Index>(groups_.station.size());
  e.setZero(3 * groups);
  if (J != nullptr) J->setZero(3 * groups, set_.size());
  for (Eigen::Index g = 0; g < groups; ++g) {
    const auto s = static_cast<std::size_t>(groups_.station[static_cast<std::size_t>(g)]);
    if (skipped(s)) continue;
    const int target = groups_.target[static_cast<std::size_t>(g)];
    const double w = std::sqrt(static_cast<double>(groups_.count[static_cast<std::size_t>(g)]));
    const Vector3d p_B = X_BT.R * groups_.mean_T[static_cast<std::size_t>(g)];
    e.segment<3>(3 * g) = w * (p_B + X_BT.t - target_B(model, fk[s].placement, set_, theta, target));
    if (J == nullptr) continue;
    J->block(3 * g, 0, 3, set_.platform_size()) = -w * point_sensitivity(set_, fk[s], dx[s], theta, target);
    J->block<3, 3>(3 * g, set_.rotation_index()) = -w * skew(p_B);  // exp(dw) R p = R p + dw x R p
    J->block<3, 3>(3 * g, set_.translation_index()) = w * Matrix3d::Identity();
  }
  return Status::Ok;
}

}  // namespace hexatwist::detail
