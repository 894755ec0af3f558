// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/identification.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "calibration/evaluator.hpp"
#include "calibration/solver.hpp"
#include "hexatwist/error.hpp"

namespace hexatwist {
namespace {

using detail::Evaluator;

// What identify refuses before any solve: NaN, legs it cannot model, too few data.
Status check_inputs(const Model& nominal, std::span<const Observation> observations, const ObservationGroups& groups,
                    const ParameterSet& set, const IdentificationOptions& options, std::string& reason) {
  for (std::size_t k = 0; k < observations.size(); ++k) {
    const Observation& o = observations[k];
    if (!o.motor.allFinite() || !o.p_T.allFinite()) {
      reason = fmt::format("observation {} holds NaN or inf", k + 1);
      return Status::NonFiniteInput;
    }
    if (o.target < 0 || o.target >= static_cast<int>(kMaxTargets)) {
      reason = fmt::format("observation {}: target {} is not one of 0..{}", k + 1, o.target, kMaxTargets - 1);
      return Status::NotIdentifiable;
    }
  }
  for (int i = 0; i < kLegs; ++i) {
    if (std::isnan(nominal.leg(i).theta_home)) {
      reason = fmt::format("leg {} has no U-joint axes: its twist and so the lead and its sign are undefined", i + 1);
      return Status::NotIdentifiable;
    }
    if (options.lead_effect == LeadEffect::TwistAndTravel && !(nominal.leg(i).lead > 0.0)) {
      reason = fmt::format("leg {} has lead 0 in the nominal model: the drives' travel is unknown", i + 1);
      return Status::NotIdentifiable;
    }
  }
  std::vector<char> seen(static_cast<std::size_t>(groups.targets), 0);
  for (const int t : groups.target) seen[static_cast<std::size_t>(t)] = 1;
  for (int t = 0; t < groups.targets; ++t)
    if (seen[static_cast<std::size_t>(t)] == 0) {
      reason = fmt::format("target {} has no observation (targets are numbered from 0 without gaps)", t);
      return Status::NotIdentifiable;
    }
  // A pose visited twice (home at both ends of a run) gives the same equations twice: only distinct
  // commands (per target) count.
  std::vector<std::array<double, kLegs + 1>> keys;
  for (std::size_t g = 0; g < groups.station.size(); ++g) {
    std::array<double, kLegs + 1> key{};
    const Vector6d& m = observations[groups.first[g]].motor;
    for (int i = 0; i < kLegs; ++i) key[static_cast<std::size_t>(i)] = std::round(m[i] / kSameCommand);
    key[kLegs] = groups.target[g];
    keys.push_back(key);
  }
  std::sort(keys.begin(), keys.end());
  const auto distinct = static_cast<int>(std::unique(keys.begin(), keys.end()) - keys.begin());
  const int equations = 3 * distinct;
  if (equations <= set.size()) {
    reason = fmt::format(
        "{} stations ({} distinct poses and targets; a pose visited twice counts once) give {} equations (3 per "
        "pose and target) for {} parameters: at least {} distinct stations are needed",
        groups.stations, distinct, equations, set.size(),
        (set.size() / 3 + 1 + groups.targets - 1) / std::max(groups.targets, 1));
    return Status::NotIdentifiable;
  }
  return Status::Ok;
}

// The start: the nominal platform, the tracker frame by Kabsch of target 0's mean points onto the
// nominal model's predictions, the other targets placed by least squares from their points.
Status start_point(const ParameterSet& set, Evaluator& evaluator, const ObservationGroups& groups, double max_misfit,
                   Eigen::VectorXd& theta, RigidTransform& X_BT, Registration& registration, std::string& reason) {
  theta = set.nominal_vector();
  Eigen::VectorXd e;
  if (const Status s = evaluator.evaluate(theta, 1.0, RigidTransform{}, e, nullptr); s != Status::Ok) {
    reason = evaluator.failed_station() < 0
                 ? fmt::format("the nominal model is invalid ({})", describe(s))
                 : fmt::format("nominal model: station {}: {}", evaluator.failed_station() + 1, describe(s));
    return s;
  }
  const Model& model = *evaluator.candidate();
  std::vector<PointPair> pairs;
  for (std::size_t g = 0; g < groups.station.size(); ++g) {
    if (groups.target[g] != 0) continue;
    const Placement& x = evaluator.poses()[static_cast<std::size_t>(groups.station[g])];
    pairs.push_back({groups.mean_T[g], detail::target_B(model, x, set, theta, 0)});
  }
  if (const Status s = register_points(pairs, registration); s != Status::Ok) {
    reason = fmt::format("the start registration of the mean points onto the nominal model failed: {}", describe(s));
    return Status::NotIdentifiable;
  }
  // A log of another run (or in other units) is refused as measure_points refuses it.
  if (std::string why = shape_misfit(pairs, registration, max_misfit); !why.empty()) {
    reason = std::move(why);
    return Status::InvalidArgument;
  }
  X_BT = registration.X_BT;
  theta.segment<3>(set.translation_index()) = X_BT.t;
  // Every other target: A_P = R_k^T (X_BT p - pivot_home - t_k) + pivot_P, averaged over its groups.
  for (int t = 1; t < set.targets(); ++t) {
    Vector3d sum = Vector3d::Zero();
    int n = 0;
    for (std::size_t g = 0; g < groups.station.size(); ++g) {
      if (groups.target[g] != t) continue;
      const Placement& x = evaluator.poses()[static_cast<std::size_t>(groups.station[g])];
      sum += x.R_BP.transpose() * (apply(X_BT, groups.mean_T[g]) - model.pivot_home_B() - x.t) + set.nominal().pivot_P;
      ++n;
    }
    theta.segment<3>(set.target_index() + 3 * t) = sum / n;
  }
  return Status::Ok;
}

// The per-observation residuals at (theta, sign, X_BT) from the evaluator's last poses.
void point_residuals(const ParameterSet& set, const Evaluator& evaluator, std::span<const Observation> observations,
                     const ObservationGroups& groups, const Eigen::VectorXd& theta, const RigidTransform& X_BT,
                     std::vector<Vector3d>& residual_B) {
  const Model& model = *evaluator.candidate();
  residual_B.resize(observations.size());
  for (std::size_t k = 0; k < observations.size(); ++k) {
    const auto g = static_cast<std::size_t>(groups.group_of[k]);
    const Placement& x = evaluator.poses()[static_cast<std::size_t>(groups.station[g])];
    residual_B[k] = apply(X_BT, observations[k].p_T) - detail::target_B(model, x, set, theta, groups.target[g]);
  }
}

// The axes the data determine: the covariance of the fit with every axis added, at the estimate.
void axis_observability(const Model& nominal, const IdentificationOptions& options,
                        std::span<const Observation> observations, const ObservationGroups& groups,
                        const ParameterSet& fitted, const Identification& id, double sigma,
                        std::array<double, 2 * kLegs>& axis_sd) {
  AxisSelection all;
  all.fill(true);
  const ParameterSet every(nominal, CalibrationModel::Geometry, options.lead_effect, all, fitted.targets(),
                           options.leads, fitted.effects());
  // The estimate in the larger layout: the same values, the axes at zero.
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(every.size());
  theta.head(fitted.axis_index()) = id.estimate.head(fitted.axis_index());
  theta.segment(every.target_index(), every.size() - every.target_index()) =
      id.estimate.segment(fitted.target_index(), fitted.size() - fitted.target_index());
  Evaluator evaluator(every, observations, groups, options.fk);
  Eigen::VectorXd e;
  Eigen::MatrixXd J;
  if (evaluator.evaluate(theta, id.twist_sign, id.X_BT, e, &J) != Status::Ok) return;
  const detail::Conditioning c = detail::conditioning(every, J, 1e300);
  if (!std::isfinite(c.condition)) return;
  const Eigen::VectorXd sd = (sigma * sigma * c.inverse_normal).diagonal().cwiseSqrt();
  // An axis turned by u1 e1 + u2 e2 from its unit direction turns by |u| rad.
  for (int a = 0, k = every.axis_index(); a < 2 * kLegs; ++a, k += 2)
    axis_sd[static_cast<std::size_t>(a)] = std::max(sd[k], sd[k + 1]);
}

// Fills the statistics of the fit at the estimate: residuals, sigma, covariance, conditioning, the
// joints' shifts and the model-fit test. Returns the conditioning's verdict.
Status fit_statistics(const ParameterSet& set, Evaluator& evaluator, std::span<const Observation> observations,
                      const ObservationGroups& groups, const IdentificationOptions& options, Identification& out) {
  Eigen::VectorXd e;
  Eigen::MatrixXd J;
  if (const Status s = evaluator.evaluate(out.estimate, out.twist_sign, out.X_BT, e, &J); s != Status::Ok) {
    out.reason = fmt::format("estimate: station {}: {}", evaluator.failed_station() + 1, describe(s));
    return s;
  }
  const int K = static_cast<int>(observations.size()), p = set.size();
  point_residuals(set, evaluator, observations, groups, out.estimate, out.X_BT, out.residual_B);
  double sum2 = 0.0;
  out.max_after = 0.0;
  for (int k = 0; k < K; ++k) {
    const double r = out.residual_B[static_cast<std::size_t>(k)].norm();
    sum2 += r * r;
    if (r >= out.max_after) {
      out.max_after = r;
      out.max_after_index = k;
    }
  }
  out.rms_after = std::sqrt(sum2 / K);
  out.sigma = std::sqrt(sum2 / (3 * K - p));
  // The model-fit test: the groups' mean residuals against the tracker's noise, an F test of
  // (between / dof) over (within / scatter dof) (theory §13).
  const double between = e.squaredNorm();
  out.fit_dof = static_cast<int>(e.size()) - p;
  const double var = out.tracker_noise * out.tracker_noise;
  out.fit_statistic = between / var;
  const double d2 = std::isnan(options.tracker_noise) ? static_cast<double>(groups.scatter_dof) : 0.0;
  out.fit_z = detail::f_normal_deviate(out.fit_statistic / out.fit_dof, out.fit_dof, d2);
  // The systematic part: sum over groups of count |mean error|^2 is the statistic's excess over its
  // expectation (dof noise variances), per point and coordinate.
  out.unexplained = std::sqrt(std::max(0.0, between - out.fit_dof * var) / (3.0 * K));
  std::vector<StationResidual> shares;
  for (std::size_t g = 0; g < groups.station.size(); ++g) {
    const Vector3d mean = e.segment<3>(3 * static_cast<Eigen::Index>(g)) / std::sqrt(groups.count[g]);
    shares.push_back({groups.station[g], groups.target[g], groups.first[g], groups.count[g], mean.norm(),
                      e.segment<3>(3 * static_cast<Eigen::Index>(g)).squaredNorm() / var});
  }
  std::sort(shares.begin(), shares.end(), [](const auto& a, const auto& b) { return a.statistic > b.statistic; });
  shares.resize(std::min<std::size_t>(shares.size(), 5));
  out.worst = shares;
  // Covariance from the Jacobian of all points: the groups' weighted rows give the same J^T J.
  const detail::Conditioning c = detail::conditioning(set, J, options.max_condition);
  out.condition = c.condition;
  out.weakest = c.weakest;
  out.undetermined = c.involved;
  if (c.undetermined > 0) {
    out.reason = fmt::format(
        "the data do not determine {} combination{} of {} (column-scaled condition number {:.3g}, limit {:.3g})",
        c.undetermined, c.undetermined == 1 ? "" : "s", c.involved, c.condition, options.max_condition);
    out.hint = "record a run that stops at more stations spread over the workspace: hexatwist stations plans one";
    return Status::NotIdentifiable;
  }
  out.covariance = out.sigma * out.sigma * c.inverse_normal;
  out.sd = out.covariance.diagonal().cwiseSqrt();
  if (set.model() == CalibrationModel::Geometry) {
    const int m = 3 * kLegs - 6;
    const Eigen::VectorXd db = set.base_basis() * out.estimate.segment(set.base_index(), m);
    const Eigen::VectorXd dp = set.platform_basis() * out.estimate.segment(set.platform_index(), m);
    const Eigen::MatrixXd Cb = set.base_basis() * out.covariance.block(set.base_index(), set.base_index(), m, m) *
                               set.base_basis().transpose();
    const Eigen::MatrixXd Cp = set.platform_basis() *
                               out.covariance.block(set.platform_index(), set.platform_index(), m, m) *
                               set.platform_basis().transpose();
    for (int i = 0; i < kLegs; ++i)
      for (int a = 0; a < 3; ++a) {
        out.base_shift(i, a) = db[3 * i + a];
        out.platform_shift(i, a) = dp[3 * i + a];
        out.base_shift_sd(i, a) = std::sqrt(Cb(3 * i + a, 3 * i + a));
        out.platform_shift_sd(i, a) = std::sqrt(Cp(3 * i + a, 3 * i + a));
      }
  }
  return Status::Ok;
}

// K-fold cross-validation over the stations: each fold's stations left out, the rest fitted from
// the estimate, the left-out groups' mean points predicted (theory §13).
CrossValidation cross_validate(const ParameterSet& set, std::span<const Observation> observations,
                               const ObservationGroups& groups, const IdentificationOptions& options,
                               const Identification& id) {
  CrossValidation cv;
  const int folds = options.folds;
  if (folds < 2 || groups.stations < 2 * folds) return cv;
  cv.folds = folds;
  double sum2 = 0.0, expected2 = 0.0;
  cv.max = 0.0;
  for (int f = 0; f < folds; ++f) {
    std::vector<char> skip(static_cast<std::size_t>(groups.stations), 0);
    for (int s = f; s < groups.stations; s += folds) skip[static_cast<std::size_t>(s)] = 1;
    int kept = 0;
    for (std::size_t g = 0; g < groups.station.size(); ++g)
      kept += skip[static_cast<std::size_t>(groups.station[g])] ? 0 : 1;
    if (3 * kept <= set.size()) continue;  // too little left to fit
    Evaluator evaluator(set, observations, groups, options.fk);
    const SignFit fit = detail::solve(set, evaluator, id.twist_sign, id.estimate, id.X_BT, options, 0.0, skip);
    if (!std::isfinite(fit.cost)) {
      cv.status = fit.status;
      continue;
    }
    Eigen::VectorXd e;
    Eigen::MatrixXd J;
    if (const Status s = evaluator.evaluate(fit.theta, id.twist_sign, fit.X_BT, e, &J); s != Status::Ok) {
      cv.status = s;
      continue;
    }
    // The fold's covariance from its own stations, the prediction's from it and the noise.
    Eigen::MatrixXd J_fit = J;
    for (std::size_t g = 0; g < groups.station.size(); ++g)
      if (skip[static_cast<std::size_t>(groups.station[g])])
        J_fit.middleRows<3>(3 * static_cast<Eigen::Index>(g)).setZero();
    const detail::Conditioning c = detail::conditioning(set, J_fit, 1e300);
    if (!std::isfinite(c.condition)) continue;
    const double var = id.tracker_noise * id.tracker_noise;
    for (std::size_t g = 0; g < groups.station.size(); ++g) {
      if (!skip[static_cast<std::size_t>(groups.station[g])]) continue;
      const double w = std::sqrt(static_cast<double>(groups.count[g]));
      const Vector3d mean = e.segment<3>(3 * static_cast<Eigen::Index>(g)) / w;
      const Eigen::MatrixXd G = J.middleRows<3>(3 * static_cast<Eigen::Index>(g)) / w;
      sum2 += mean.squaredNorm();
      expected2 += 3.0 * var / groups.count[g] + var * (G * c.inverse_normal * G.transpose()).trace();
      cv.max = std::max(cv.max, mean.norm());
      ++cv.predicted;
    }
  }
  if (cv.predicted > 0) {
    cv.rms = std::sqrt(sum2 / cv.predicted);
    cv.expected = std::sqrt(expected2 / cv.predicted);
  }
  return cv;
}

// Chooses the thread sense, refits with the axes the data determine (AxisFit::Auto) and keeps
// the estimate. Returns the chosen fit's status.
Status fit_both_senses(const Model& nominal, ParameterSet& set, std::span<const Observation> observations,
                       const ObservationGroups& groups, const IdentificationOptions& options,
                       const Eigen::VectorXd& start, const RigidTransform& X_start, Identification& out) {
  const double scatter_cost = 0.5 * groups.scatter_sum;
  {
    Evaluator evaluator(set, observations, groups, options.fk);
    for (int i = 0; i < 2; ++i)
      out.fits[static_cast<std::size_t>(i)] =
          detail::solve(set, evaluator, i == 0 ? 1.0 : -1.0, start, X_start, options, scatter_cost);
  }
  const std::size_t best = out.fits[1].cost < out.fits[0].cost ? 1 : 0;
  const SignFit& fit = out.fits[best];
  const SignFit& other = out.fits[1 - best];
  if (!std::isfinite(fit.cost)) {
    out.reason = fmt::format("no solve ended with a usable solution: {}", fit.message);
    return fit.status;
  }
  out.fitted = true;
  out.twist_sign = fit.twist_sign;
  out.estimate = fit.theta;
  out.X_BT = fit.X_BT;
  out.cost_ratio = other.cost / fit.cost;
  Status status = fit.status;
  if (set.model() == CalibrationModel::Geometry && options.axes != AxisFit::None) {
    // Which axes do the data determine? The covariance with every axis added says; fit those (or
    // all), from the estimate without them: their effect is small, so a start far off lets the
    // solver wander to another minimum (theory §13).
    const double sigma = std::sqrt(2.0 * fit.cost / (3.0 * observations.size() - set.size()));
    axis_observability(nominal, options, observations, groups, set, out, sigma, out.axis_sd);
    AxisSelection chosen{};
    bool any = false;
    for (std::size_t a = 0; a < chosen.size(); ++a) {
      chosen[a] = options.axes == AxisFit::All || out.axis_sd[a] <= options.axis_sd_max;
      any = any || chosen[a];
    }
    if (any) {
      ParameterSet with_axes(nominal, CalibrationModel::Geometry, options.lead_effect, chosen, set.targets(),
                             options.leads, set.effects());
      Eigen::VectorXd theta = Eigen::VectorXd::Zero(with_axes.size());
      theta.head(set.axis_index()) = out.estimate.head(set.axis_index());
      theta.tail(with_axes.size() - with_axes.target_index()) = out.estimate.tail(set.size() - set.target_index());
      Evaluator evaluator(with_axes, observations, groups, options.fk);
      const SignFit refit = detail::solve(with_axes, evaluator, out.twist_sign, theta, out.X_BT, options, scatter_cost);
      if (std::isfinite(refit.cost)) {
        set = with_axes;
        out.fits[best] = refit;
        out.estimate = refit.theta;
        out.X_BT = refit.X_BT;
        out.cost_ratio = other.cost / refit.cost;
        status = refit.status;
      }
    }
  }
  return status;
}

}  // namespace

namespace {

Status identify_fixed(const Model& nominal, std::span<const Observation> observations, Identification& out,
                      const IdentificationOptions& options, bool diagnose);

constexpr const char* kEffectNames[3] = {"load", "play", "heat"};

// One more effect `e` (0 load, 1 play, 2 heat) on top of `chosen`: the fit, and the drop of the fit
// statistic from `base_statistic` as a normal deviate (chi-square on the effect's parameters if it
// is absent); NaN where the solve cannot carry it (undetermined, not converging: one that absorbs
// another error of the model).
double effect_drop(const Model& nominal, std::span<const Observation> observations, const IdentificationOptions& trial,
                   const EffectFit& chosen, int e, double base_statistic, Identification& fit) {
  EffectFit candidate = chosen;
  (e == 0 ? candidate.load : e == 1 ? candidate.play : candidate.heat) = true;
  IdentificationOptions o = trial;
  o.effects = candidate;
  (void)identify_fixed(nominal, observations, fit, o, false);
  const bool usable =
      fit.status == Status::Ok || fit.status == Status::ModelMismatch || fit.status == Status::SignUndecided;
  if (!fit.fitted || !usable || !std::isfinite(fit.fit_statistic)) return std::numeric_limits<double>::quiet_NaN();
  const double dof = candidate.count() - chosen.count();
  return (base_statistic - fit.fit_statistic - dof) / std::sqrt(2.0 * dof);
}

// Options for the trial fits of effect_drop: no cross-validation, no accuracy map.
IdentificationOptions trial_options(const IdentificationOptions& options) {
  IdentificationOptions trial = options;
  trial.auto_effects = false;
  trial.folds = 0;
  trial.accuracy_poses = 0;
  return trial;
}

// Forward selection of the legs' effects (IdentificationOptions::auto_effects, theory §13b).
Status identify_choosing_effects(const Model& nominal, std::span<const Observation> observations, Identification& out,
                                 const IdentificationOptions& options) {
  IdentificationOptions trial = trial_options(options);
  trial.effects = EffectFit{};
  Identification base;
  std::string log;
  // On the basic model the joints' errors would go into the effects: none is chosen there.
  if (options.model == CalibrationModel::Geometry) (void)identify_fixed(nominal, observations, base, trial, false);
  if (options.model != CalibrationModel::Geometry)
    log = "the basic model keeps the joints as configured, whose errors the effects would absorb";
  else if (base.fitted && std::isfinite(base.fit_statistic)) {
    for (;;) {
      const EffectFit chosen = trial.effects;
      EffectFit best = chosen;
      bool found = false;
      Identification best_fit;
      double best_z = options.effect_sigmas;
      std::string tried;
      for (int e = 0; e < 3; ++e) {
        if (e == 0 ? chosen.load : e == 1 ? chosen.play : chosen.heat) continue;
        Identification r;
        const double z = effect_drop(nominal, observations, trial, chosen, e, base.fit_statistic, r);
        const char* name = kEffectNames[e];
        if (std::isnan(z)) {
          tried += fmt::format("{}{} cannot be fitted", tried.empty() ? "" : ", ", name);
          continue;
        }
        tried += fmt::format("{}{} {:.1f} sigma", tried.empty() ? "" : ", ", name, z);
        if (z > best_z) {
          found = true;
          best_z = z;
          best = r.parameters.effects();
          best_fit = std::move(r);
        }
      }
      if (!tried.empty())
        log += fmt::format("{}{}{}", log.empty() ? "" : "; then ", chosen.any() ? "with " + chosen.names() + ": " : "",
                           tried);
      if (!found) break;
      trial.effects = best;
      base = std::move(best_fit);
    }
  }
  IdentificationOptions final_options = options;
  final_options.auto_effects = false;
  final_options.effects = trial.effects;
  const Status s = identify_fixed(nominal, observations, out, final_options, true);
  out.effects_choice =
      fmt::format("auto: {} (each effect's drop of the fit statistic, {:g} sigma needed: {})", trial.effects.names(),
                  options.effect_sigmas, log.empty() ? "the data could not be fitted without effects" : log);
  return s;
}

}  // namespace

void check_identification_options(const IdentificationOptions& o) {
  const auto refuse = [](std::string message, const char* field) {
    throw ParameterError("identification: " + std::move(message), field);
  };
  const auto positive = [&](double v, const char* field, const char* what) {
    if (!(v > 0.0 && std::isfinite(v))) refuse(fmt::format("expected a finite {} > 0, got {}", what, v), field);
  };
  if (!std::isnan(o.tracker_noise) && !(o.tracker_noise > 0.0 && o.tracker_noise < kMaxTrackerNoise))
    refuse(fmt::format("expected the tracker's noise > 0 and below {:g} m (or unknown: its scatter), got {:g}",
                       kMaxTrackerNoise, o.tracker_noise),
           "tracker_noise");
  if (!(o.tracker_noise_floor >= 0.0 && o.tracker_noise_floor < kMaxTrackerNoise))
    refuse(fmt::format("expected a noise floor of 0 to {:g} m, got {}", kMaxTrackerNoise, o.tracker_noise_floor),
           "tracker_noise_floor");
  positive(o.fit_sigmas, "fit_sigmas", "number of normal deviates");
  positive(o.effect_sigmas, "effect_sigmas", "number of normal deviates");
  positive(o.sign_separation_min, "sign_separation_min", "separation");
  positive(o.axis_sd_max, "axis_sd_max", "standard deviation [rad]");
  positive(o.max_registration_misfit, "max_registration_misfit", "share");
  if (!(o.folds == 0 || (o.folds >= 2 && o.folds <= kMaxFolds)))
    refuse(fmt::format("expected 0 folds (no cross-validation) or 2 to {}, got {}", kMaxFolds, o.folds), "folds");
  if (o.accuracy_poses < 0 || o.accuracy_poses > 100000)
    refuse(fmt::format("expected 0 (none) to 100000 accuracy poses, got {}", o.accuracy_poses), "accuracy_poses");
  if (o.max_iterations < 1)
    refuse(fmt::format("expected max iterations >= 1, got {}", o.max_iterations), "max_iterations");
  if (!(o.max_condition > 1.0 && std::isfinite(o.max_condition)))
    refuse(fmt::format("expected a finite max condition > 1, got {}", o.max_condition), "max_condition");
  if (const std::string_view why = check_fk_options(o.fk); !why.empty()) refuse(std::string(why), "fk");
}

Status identify(const Model& nominal, std::span<const Observation> observations, Identification& out,
                const IdentificationOptions& options) {
  check_identification_options(options);
  if (options.auto_effects) return identify_choosing_effects(nominal, observations, out, options);
  return identify_fixed(nominal, observations, out, options, true);
}

namespace {

// What the residuals of a refused fit point to: each effect not fitted, added alone (theory §13b).
// The hint names those above options.effect_sigmas with the trend each one is, and the option.
std::string diagnose_effects(const Model& nominal, std::span<const Observation> observations,
                             const IdentificationOptions& options, Identification& out) {
  const EffectFit chosen = out.parameters.effects();
  const IdentificationOptions trial = trial_options(options);
  std::string pointed, others;
  EffectFit all = chosen;
  constexpr const char* kTrend[3] = {"with the legs' forces", "with the approach direction", "with time"};
  for (int e = 0; e < 3; ++e) {
    if (e == 0 ? chosen.load : e == 1 ? chosen.play : chosen.heat) continue;
    Identification fit;
    const double z = effect_drop(nominal, observations, trial, chosen, e, out.fit_statistic, fit);
    out.diagnosis.push_back({kEffectNames[e], z});
    // An effect that lacks what it needs says what (its reason names it: "heat: ...").
    const bool lacks = !fit.fitted && fit.status == Status::NotIdentifiable && !fit.reason.empty();
    const std::string said = !std::isnan(z) ? fmt::format("{} {:.1f} sigma", kEffectNames[e], z)
                             : lacks        ? fmt::format("{}", fit.reason)
                                            : fmt::format("{} cannot be fitted", kEffectNames[e]);
    if (z > options.effect_sigmas) {
      pointed += fmt::format("{}a trend {} ({})", pointed.empty() ? "" : ", ", kTrend[e], said);
      (e == 0 ? all.load : e == 1 ? all.play : all.heat) = true;
    } else {
      others += fmt::format("{}{}", others.empty() ? "" : ", ", said);
    }
  }
  const std::string generic =
      "another configuration, log, run or strategy than the machine's, a servo still moving (a longer settle "
      "time), or U-joint axes (fit them all: --axes all)";
  if (out.diagnosis.empty()) return {};
  if (pointed.empty())
    return fmt::format(
        "the residuals point to none of the legs' effects ({}; {:g} sigma needed): an error the "
        "model does not have: {}",
        others, options.effect_sigmas, generic);
  // Those effects together must explain the data; a larger error (another model, log or run) is
  // reduced by any of them without being explained.
  IdentificationOptions with = trial;
  with.effects = all;
  Identification fit;
  (void)identify_fixed(nominal, observations, fit, with, false);
  if (!(fit.fitted && fit.fit_z <= options.fit_sigmas))
    return fmt::format(
        "the legs' effects reduce the residuals ({}{}) but do not explain them (--effects {} leaves "
        "{:.1f} sigma): an error the model does not have: {}",
        pointed, others.empty() ? "" : ", " + others, all.names(), fit.fit_z, generic);
  return fmt::format(
      "the residuals point to {}{}: fit them (--effects {}, or --effects auto to let the data "
      "choose)",
      pointed, others.empty() ? "" : fmt::format("; not to {}", others), all.names());
}

Status identify_fixed(const Model& nominal, std::span<const Observation> observations, Identification& out,
                      const IdentificationOptions& options, bool diagnose) {
  out = Identification{};
  const ObservationGroups groups = group_observations(observations);
  out.observations = static_cast<int>(observations.size());
  out.stations = groups.stations;
  out.groups = static_cast<int>(groups.station.size());
  // Heat from the log's temperatures where every observation has one, about the run's first.
  EffectFit effects = options.effects;
  effects.measured = effects.heat && !observations.empty() &&
                     std::all_of(observations.begin(), observations.end(),
                                 [](const Observation& o) { return std::isfinite(o.temperature); });
  effects.reference_temperature =
      effects.measured ? observations.front().temperature : std::numeric_limits<double>::quiet_NaN();
  // The axes, if any, are added once the rest is fitted (fit_both_senses).
  ParameterSet set(nominal, options.model, options.lead_effect, AxisSelection{}, std::max(groups.targets, 1),
                   options.leads, effects);
  out.parameters = set;
  const auto fail = [&](Status s, std::string reason = {}, std::string hint = {}) {
    if (!reason.empty()) out.reason = std::move(reason);
    if (!hint.empty()) out.hint = std::move(hint);
    out.status = s;
    out.parameters = set;
    return s;
  };
  if (observations.empty()) return fail(Status::NotIdentifiable, "no observations");
  std::string reason;
  if (const Status s = check_inputs(nominal, observations, groups, set, options, reason); s != Status::Ok)
    return fail(s, reason, "record a run that stops at more stations: hexatwist stations plans one");
  out.scatter = tracker_scatter(groups);
  out.tracker_noise =
      std::max(std::isnan(options.tracker_noise) ? out.scatter : options.tracker_noise, options.tracker_noise_floor);
  if (!(std::isfinite(out.tracker_noise) && out.tracker_noise > 0.0))
    return fail(Status::NotIdentifiable,
                "the tracker's noise is unknown: no station holds two points of one target to measure its scatter",
                "record several points at each station, or give the tracker's noise (--tracker-noise-um)");

  // The start, its residual and the identifiability there.
  Evaluator evaluator(set, observations, groups, options.fk);
  if (evaluator.effects().status != Status::Ok)
    return fail(evaluator.effects().status, evaluator.effects().reason,
                "give the configuration's load, or fit other effects (--effects)");
  Eigen::VectorXd start;
  RigidTransform X_start;
  Registration registration;
  if (const Status s =
          start_point(set, evaluator, groups, options.max_registration_misfit, start, X_start, registration, reason);
      s != Status::Ok)
    return fail(s, reason);
  out.nominal = start;
  {
    std::vector<Vector3d> residual;
    point_residuals(set, evaluator, observations, groups, start, X_start, residual);
    double sum2 = 0.0;
    for (const Vector3d& r : residual) sum2 += r.squaredNorm();
    out.rms_before = std::sqrt(sum2 / static_cast<double>(residual.size()));
    Eigen::VectorXd e;
    Eigen::MatrixXd J;
    if (const Status s = evaluator.evaluate(start, 1.0, X_start, e, &J); s != Status::Ok)
      return fail(s, fmt::format("nominal model: station {}: {}", evaluator.failed_station() + 1, describe(s)));
    if (const detail::Conditioning c = detail::conditioning(set, J, options.max_condition); c.undetermined > 0) {
      out.condition = c.condition;
      out.weakest = c.weakest;
      out.undetermined = c.involved;
      return fail(
          Status::NotIdentifiable,
          fmt::format("the data do not determine {} combination{} of {} (column-scaled condition number "
                      "{:.3g}, limit {:.3g})",
                      c.undetermined, c.undetermined == 1 ? "" : "s", c.involved, c.condition, options.max_condition),
          "record a run that stops at more stations spread over the workspace: hexatwist stations plans one");
    }
  }

  const Status solved = fit_both_senses(nominal, set, observations, groups, options, start, X_start, out);
  out.parameters = set;
  if (!out.fitted) return fail(solved);
  Evaluator at_estimate(set, observations, groups, options.fk);
  if (const Status s = fit_statistics(set, at_estimate, observations, groups, options, out); s != Status::Ok)
    return fail(s);
  out.corrected = set.platform(out.estimate, out.twist_sign, true);
  if (solved != Status::Ok)
    return fail(solved, fmt::format("sign {:+.0f}: {}", out.twist_sign, out.fits[out.twist_sign > 0 ? 0 : 1].message));

  // The decisions (theory §13): does the model explain the data as the tracker measures?
  if (!(out.fit_z <= options.fit_sigmas)) {
    const StationResidual& w = out.worst.front();
    const std::string pointed = diagnose && set.model() == CalibrationModel::Geometry
                                    ? diagnose_effects(nominal, observations, options, out)
                                    : std::string();
    return fail(
        Status::ModelMismatch,
        fmt::format("the fit leaves {:.4g} mm per axis where the tracker's noise is {:.4g} mm: a test statistic "
                    "{:.4g} on {} degrees of freedom, {:.1f} sigma (at most {:g}); the worst station is number {} "
                    "({} points, mean residual {:.4g} mm)",
                    1e3 * out.sigma, 1e3 * out.tracker_noise, out.fit_statistic, out.fit_dof, out.fit_z,
                    options.fit_sigmas, w.station + 1, w.count, 1e3 * w.mean_error),
        set.model() == CalibrationModel::Basic
            ? "the joint geometry is off: identify the joint centres too, the geometry model (--model geometry)"
        : !pointed.empty()
            ? pointed
            : "an error the model does not have: legs that warm, deflect under the load or have play (--effects "
              "auto fits those the data show), another configuration, log, run or strategy than the machine's, a "
              "servo still moving (a longer settle time), or U-joint axes (fit them all: --axes all)");
  }
  // Is the thread sense decided? The rejected sense must fit worse than the noise explains.
  {
    const SignFit& chosen = out.fits[out.twist_sign > 0 ? 0 : 1];
    const SignFit& rejected = out.fits[out.twist_sign > 0 ? 1 : 0];
    out.sign_separation = 2.0 * (rejected.cost - chosen.cost) / (out.sigma * out.sigma);
    if (rejected.status == Status::Ok && !(out.sign_separation >= options.sign_separation_min))
      return fail(Status::SignUndecided,
                  fmt::format("the two thread senses fit the data equally well (cost ratio {:.4g}, difference {:.3g} "
                              "noise variances, {:g} needed): the twist sign and lead are not decided",
                              out.cost_ratio, out.sign_separation, options.sign_separation_min),
                  "record a run with rotations (a stations run)");
  }
  out.cross_validation = cross_validate(set, observations, groups, options, out);
  {
    // The calibrated range: the stations' poses under the estimate.
    Vector6d low = Vector6d::Constant(INFINITY), high = Vector6d::Constant(-INFINITY);
    for (const Placement& x : at_estimate.poses()) {
      const Vector6d q = pose_from_placement(x).to_vector();
      low = low.cwiseMin(q);
      high = high.cwiseMax(q);
    }
    const Eigen::MatrixXd C = out.covariance.topLeftCorner(set.platform_size(), set.platform_size());
    if (const Status s = predicted_accuracy(set, out.estimate, out.twist_sign, C, low, high, options.accuracy_poses,
                                            options.accuracy_seed, out.accuracy);
        s != Status::Ok && s != Status::NotIdentifiable)
      return fail(s, fmt::format("the predicted accuracy could not be evaluated: {}", describe(s)));
  }
  out.status = Status::Ok;
  return Status::Ok;
}

}  // namespace

Status identification_residuals(const ParameterSet& set, std::span<const Observation> observations,
                                const Eigen::VectorXd& theta, double sign, const RigidTransform& X_BT,
                                const FkOptions& fk, Eigen::VectorXd& residuals, Eigen::MatrixXd* J) {
  // One group per observation (each its own station), so the weighted residuals are the points'.
  std::vector<Observation> single(observations.begin(), observations.end());
  ObservationGroups groups;
  groups.group_of.resize(single.size());
  for (std::size_t k = 0; k < single.size(); ++k) {
    groups.group_of[k] = static_cast<int>(k);
    groups.station.push_back(static_cast<int>(k));
    groups.target.push_back(single[k].target);
    groups.count.push_back(1);
    groups.first.push_back(k);
    groups.mean_T.push_back(single[k].p_T);
    groups.targets = std::max(groups.targets, single[k].target + 1);
  }
  groups.stations = static_cast<int>(single.size());
  Evaluator evaluator(set, single, groups, fk);
  return evaluator.evaluate(theta, sign, X_BT, residuals, J);
}

}  // namespace hexatwist
