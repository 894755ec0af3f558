// SPDX-License-Identifier: BSD-3-Clause
// The legs' effects in an identification (EffectFit, theory §13b): a real platform whose legs
// deflect under the load, have play and warm over the run is refused without them and recovered
// with them; their Jacobian columns against central differences; what they need, asked for.
#include "calibration_support.hpp"

namespace hexatwist::test {
namespace {

constexpr double kStiffness = 2.0e8;                                              // [N/m]
const Vector6d kPlay = (Vector6d() << 50, 40, 60, 50, 20, 80).finished() * 1e-6;  // [m]
constexpr double kExpansion = 11.5e-6;                                            // length and lead [1/K]
constexpr double kRise = 1.0;                                                     // [K] over the run

// The seed's nominal model with its static load (the Rig's), and a truth with joint errors whose
// legs have the effects above.
struct EffectsCase {
  Config config = default_config();
  Truth truth;
  ModelSpec real_spec;
  double rise = kRise;           ///< the legs' warming over the run [K]
  bool log_temperature = false;  ///< each observation carries the legs' temperature (a sensor)
};

// Each effect's size in a case; zero leaves it out.
struct EffectSizes {
  double joints = 0.5e-3;
  double stiffness = kStiffness;
  Vector6d play = kPlay;
  double expansion = kExpansion;
  double rise = kRise;
};

EffectsCase effects_case(std::mt19937_64& rng, const EffectSizes& sizes = {}) {
  EffectsCase c;
  TruthErrors e;
  e.joints = sizes.joints;
  e.lead = 0.02;
  c.truth = random_truth(c.config.rig.model(), e, rng);
  c.real_spec = c.truth.spec;
  c.rise = sizes.rise;
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = c.real_spec.legs[static_cast<std::size_t>(i)];
    leg.stiffness = sizes.stiffness;
    leg.play = sizes.play[i];
    leg.length_expansion = sizes.expansion;
    leg.lead_expansion = sizes.expansion;
  }
  return c;
}

// At each station, in order, `points` points of target 0 taken 1 s apart in a run of 2 s per
// station: the real legs under the static load at their pose, each approached in the direction of
// its last change of command, warming along 1 - exp(-t / T).
std::vector<Observation> observe_with_effects(const EffectsCase& c, const std::vector<Pose>& stations, int points,
                                              double sigma, std::mt19937_64& rng) {
  const Model& nominal = c.config.rig.model();
  const Model real(c.real_spec);
  const RigidTransform X_TB = inverse(c.truth.X_BT);
  const double T = 2.0 * static_cast<double>(stations.size());
  Vector6d last = nominal.home_command(), direction = real.geometry().home_direction;
  std::vector<Observation> out;
  for (std::size_t s = 0; s < stations.size(); ++s) {
    Vector6d command;
    LimitReport limit;
    EXPECT_EQ(motor_commands(nominal, stations[s], Strategy::Compensated, command, limit), Status::Ok);
    for (int i = 0; i < kLegs; ++i)
      if (std::abs(command[i] - last[i]) > 1e-9) direction[i] = command[i] > last[i] ? 1.0 : -1.0;
    last = command;
    for (int k = 0; k < points; ++k) {
      const double t = 2.0 * static_cast<double>(s) + 0.5 * k / points;
      LegInputs inputs;
      inputs.temperature.setConstant(real.reference_temperature() +
                                     c.rise * (1.0 - std::exp(-t / T)) / (1.0 - std::exp(-1.0)));
      FkResult fk;
      EXPECT_EQ(forward_kinematics(real, command, inputs, &direction, placement_from_pose(stations[s]), fk),
                Status::Ok);
      Observation o;
      o.motor = command;
      o.time = t;
      if (c.log_temperature) o.temperature = inputs.temperature[0];
      o.approach = direction;  // a 1 m run: longer than any play
      o.p_T = apply(X_TB, platform_point_B(real, fk.placement, c.truth.targets[0])) +
              sigma * Vector3d(gaussian(rng), gaussian(rng), gaussian(rng));
      out.push_back(o);
    }
  }
  return out;
}

// A run of `count` random stations within +-0.25 m and +-15 deg on the case's real machine, with
// `points` points at each (10 um of noise).
std::vector<Observation> effects_run(const EffectsCase& c, int count, int points, std::mt19937_64& rng,
                                     std::vector<Pose>* stations_out = nullptr) {
  const std::vector<Pose> stations =
      random_station_poses(c.config.rig.model(), Model(c.real_spec), count, 0.25, deg2rad(15), rng);
  if (stations_out != nullptr) *stations_out = stations;
  return observe_with_effects(c, stations, points, 10e-6, rng);
}

TEST(IdentificationEffects, LoadPlayAndHeatAreRefusedWithoutThemAndRecoveredWithThem) {
  std::mt19937_64 rng(kSeed + 501);
  const EffectsCase c = effects_case(rng);
  const Model& nominal = c.config.rig.model();
  std::vector<Pose> stations;
  const std::vector<Observation> obs = effects_run(c, 60, 8, rng, &stations);
  IdentificationOptions options;
  options.folds = 0;
  options.accuracy_poses = 50;
  Identification without;
  EXPECT_EQ(identify(nominal, obs, without, options), Status::ModelMismatch) << without.reason;
  report("fit test without the effects [sigma]", without.fit_z);
  EXPECT_NE(without.hint.find("--effects"), std::string::npos) << without.hint;

  options.effects = effect_fit("heat,load,play");
  Identification id;
  ASSERT_EQ(identify(nominal, obs, id, options), Status::Ok) << id.reason;
  report("fit test with them [sigma]", id.fit_z);
  const ParameterSet& ps = id.parameters;
  ASSERT_GE(ps.compliance_index(), 0);
  const auto within = [&](int k, double truth, double sds) {
    EXPECT_LT(std::abs(id.estimate[k] - truth), sds * id.sd[k])
        << ps.name(k) << ": " << id.estimate[k] << " +- " << id.sd[k] << " against " << truth;
  };
  within(ps.compliance_index(), 1.0 / kStiffness, 4.0);
  for (int i = 0; i < kLegs; ++i) within(ps.play_index() + i, kPlay[i], 4.0);
  // The lead drift: the rise at the last observation times the lead's expansion.
  const double t_last = obs.back().time, T = 2.0 * static_cast<double>(stations.size());
  const double rise_end = kRise * (1.0 - std::exp(-t_last / T)) / (1.0 - std::exp(-1.0));
  within(ps.lead_drift_index(), kExpansion * rise_end, 4.0);
  // Measured: 4.4 sd from zero (60 stations, 10 um noise): the load's deflection is seen.
  EXPECT_GT(id.estimate[ps.compliance_index()], 3.0 * id.sd[ps.compliance_index()]) << "the load is determined";
  // The corrected platform records the stiffness and the plays, not the run's drift.
  for (int i = 0; i < kLegs; ++i) {
    const LegSpec& leg = id.corrected.legs[static_cast<std::size_t>(i)];
    EXPECT_NEAR(leg.stiffness, 1.0 / id.estimate[ps.compliance_index()], 1e-6 * leg.stiffness);
    EXPECT_EQ(leg.play, id.estimate[ps.play_index() + i]);
    EXPECT_EQ(leg.length_expansion, 0.0);
  }
  EXPECT_NO_THROW(Model{id.corrected});
}

// The truth of the fitted effects' parameters in `theta` (id.parameters' order): the compliance
// 1 / stiffness, each play, and for heat the projection of the true warming (each leg's length
// and lead growing with 1 - exp(-t / T)) on the model's smooth drift, the least-squares fit of its
// regressors (per leg f and f^2, a shared f (m - h); f the run's fraction) to the true length
// shifts at the stations.
void effects_truth(const EffectsCase& c, const Identification& id, const std::vector<Observation>& obs,
                   Eigen::VectorXd& theta) {
  const ParameterSet& ps = id.parameters;
  const LegSpec& leg = c.real_spec.legs[0];
  if (ps.compliance_index() >= 0) theta[ps.compliance_index()] = 1.0 / leg.stiffness;  // 0 for rigid legs
  for (int i = 0; i < kLegs && ps.play_index() >= 0; ++i)
    theta[ps.play_index() + i] = c.real_spec.legs[static_cast<std::size_t>(i)].play;
  if (ps.drift_index() < 0) return;
  const Model nominal(ps.nominal());
  const double t0 = obs.front().time, t1 = obs.back().time;
  const double T = t1 - std::fmod(t1, 2.0) + 2.0;  // observe_with_effects: 2 s per station
  std::vector<const Observation*> firsts;          // one observation per station
  for (std::size_t k = 0; k < obs.size(); ++k)
    if (k == 0 || obs[k].motor != obs[k - 1].motor) firsts.push_back(&obs[k]);
  const auto rows = static_cast<Eigen::Index>(kLegs * firsts.size());
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, 2 * kLegs + 1);
  Eigen::VectorXd b(rows);
  for (std::size_t s = 0; s < firsts.size(); ++s) {
    const Observation& o = *firsts[s];
    const double f = (o.time - t0) / (t1 - t0);
    const double dT = c.rise * (1.0 - std::exp(-o.time / T)) / (1.0 - std::exp(-1.0));
    for (int i = 0; i < kLegs; ++i) {
      const auto r = static_cast<Eigen::Index>(kLegs * s + static_cast<std::size_t>(i));
      const double travel = o.motor[i] - nominal.home_command()[i];
      A(r, i) = f;
      A(r, kLegs + i) = f * f;
      A(r, 2 * kLegs) = f * travel;
      b[r] = dT * (leg.length_expansion * nominal.length_home()[i] + leg.lead_expansion * travel);
    }
  }
  theta.segment(ps.drift_index(), 2 * kLegs + 1) = A.colPivHouseholderQr().solve(b);
}

TEST(IdentificationEffects, TheIssuesRealMachineIsCalibratedAndHitsPosesNotUsed) {
  // Issue 27's evidence: joints +-1 mm, lead +2 %, legs warming 2 K over a 40-station run, 200 N/um
  // legs under the seed's load, 50 um of play; and each effect alone. auto finds the effects;
  // every parameter within 3 sd of the truth; the corrected platform's commands at poses not used
  // (at the run's starting temperature, approached from home) miss by at most twice the predicted
  // accuracy after a rigid re-alignment; the same data without the effects are refused, naming them.
  constexpr double kRigid = std::numeric_limits<double>::infinity();
  struct Scenario {
    const char* name;
    double stiffness, play, rise;
    const char* chosen;
  };
  for (const Scenario& sc :
       {Scenario{"all three", kStiffness, 50e-6, 2.0, "load,play,heat"},
        Scenario{"heat alone", kRigid, 0.0, 2.0, "heat"}, Scenario{"load alone", kStiffness, 0.0, 0.0, "load"},
        Scenario{"play alone", kRigid, 50e-6, 0.0, "play"}}) {
    SCOPED_TRACE(sc.name);
    std::mt19937_64 rng(kSeed + 510);
    EffectSizes sizes;
    sizes.joints = 1e-3;
    sizes.stiffness = sc.stiffness;
    sizes.play.setConstant(sc.play);
    sizes.rise = sc.rise;
    const EffectsCase c = effects_case(rng, sizes);
    const Model& nominal = c.config.rig.model();
    // 40 points per station, as a 100 Hz tracker gives in the 0.4 s of each rest.
    const std::vector<Observation> obs = effects_run(c, 40, 40, rng);
    IdentificationOptions options;
    options.folds = 0;
    options.accuracy_poses = 300;
    options.auto_effects = true;
    Identification id;
    ASSERT_EQ(identify(nominal, obs, id, options), Status::Ok) << id.reason;
    EXPECT_EQ(id.parameters.effects().names(), sc.chosen) << id.effects_choice;
    Eigen::VectorXd truth = truth_vector(id.parameters, c.truth);
    effects_truth(c, id, obs, truth);
    Eigen::VectorXd d = id.estimate - truth;
    const Eigen::AngleAxisd r(Matrix3d(id.X_BT.R * c.truth.X_BT.R.transpose()));
    d.segment<3>(id.parameters.rotation_index()) = r.angle() * r.axis();
    double worst = 0.0;
    for (int k = 0; k < id.parameters.size(); ++k) {
      EXPECT_LT(std::abs(d[k]), 3.0 * id.sd[k]) << id.parameters.name(k);
      worst = std::max(worst, std::abs(d[k]) / id.sd[k]);
    }
    Truth real_truth = c.truth;
    real_truth.spec = c.real_spec;
    const HeldOut h = held_out(nominal, id, real_truth, 0.2, deg2rad(12), 200, rng);
    std::printf("  %s: fit %.2f sigma, worst parameter %.2f sd\n", sc.name, id.fit_z, worst);
    print_held_out(sc.name, h, id);
    EXPECT_LT(h.aligned_median(), 2.0 * id.accuracy.aligned_median);
    EXPECT_LT(h.aligned.back(), 2.0 * id.accuracy.aligned_max);
    // Without the effects: refused, and the hint names the option that models them; or, for the
    // load alone, whose deflection varies smoothly over the poses, accepted with the deflection
    // in the joints, where poses not used show it.
    IdentificationOptions plain = options;
    plain.auto_effects = false;
    plain.effects = effect_fit("none");
    Identification without;
    const Status s = identify(nominal, obs, without, plain);
    if (sc.rise > 0.0 || sc.play > 0.0) {
      EXPECT_EQ(s, Status::ModelMismatch) << without.reason;
      // The residuals point to each effect the machine has (tried alone on the geometry).
      if (sc.rise > 0.0) {
        EXPECT_NE(without.hint.find("a trend with time (heat"), std::string::npos) << without.hint;
      }
      if (sc.play > 0.0) {
        EXPECT_NE(without.hint.find("a trend with the approach direction (play"), std::string::npos) << without.hint;
      }
      EXPECT_NE(without.hint.find("--effects"), std::string::npos) << without.hint;
      std::printf("  %s: unexplained %.2f um without the effects, %.2f um with them\n", sc.name,
                  1e6 * without.unexplained, 1e6 * id.unexplained);
      EXPECT_GT(without.unexplained, 5.0 * id.unexplained + 1e-6);
    } else {
      ASSERT_EQ(s, Status::Ok) << without.reason;
      const HeldOut rigid = held_out(nominal, without, real_truth, 0.2, deg2rad(12), 200, rng);
      print_held_out("load alone, fitted without it", rigid, without);
      EXPECT_GT(rigid.aligned_median(), 1.5 * h.aligned_median());  // measured 1.7x
      EXPECT_GT(rigid.gauge_median(), 1.5 * h.gauge_median());      // measured 2.1x
    }
  }
}

TEST(IdentificationEffects, ALogsTemperaturesGiveTheExpansionsTheCorrectedPlatformKeeps) {
  // The issue's machine with a temperature sensor read with each point (2 K over the run): heat
  // fits each leg's growth per kelvin and the lead's expansion (no drift shape), within 3 sd of the
  // truth (11.5 ppm/K on the length between the joints and on the lead); the corrected
  // configuration keeps them with the run's first temperature as its reference, so that its
  // commands at a temperature 2 K above it, run on the real machine at that temperature, hit poses
  // not used as well as at the reference, where the same commands without the temperature miss by
  // the legs' growth.
  std::mt19937_64 rng(kSeed + 520);
  EffectSizes sizes;
  sizes.joints = 1e-3;
  sizes.rise = 2.0;
  EffectsCase c = effects_case(rng, sizes);
  c.log_temperature = true;
  const Model& nominal = c.config.rig.model();
  const std::vector<Observation> obs = effects_run(c, 40, 40, rng);
  IdentificationOptions options;
  options.folds = 0;
  options.accuracy_poses = 300;
  options.effects = effect_fit("heat,load,play");
  Identification id;
  ASSERT_EQ(identify(nominal, obs, id, options), Status::Ok) << id.reason;
  const ParameterSet& ps = id.parameters;
  ASSERT_TRUE(ps.effects().measured);
  EXPECT_EQ(ps.curvature_index(), -1);
  EXPECT_EQ(ps.name(ps.lead_drift_index()), "lead expansion");
  const Model real(c.real_spec);
  double worst = 0.0;
  for (int i = 0; i < kLegs; ++i) {
    const int k = ps.drift_index() + i;
    const double truth = kExpansion * nominal.length_home()[i];
    EXPECT_LT(std::abs(id.estimate[k] - truth), 3.0 * id.sd[k]) << ps.name(k);
    worst = std::max(worst, std::abs(id.estimate[k] - truth) / id.sd[k]);
  }
  const int lead = ps.lead_drift_index();
  EXPECT_LT(std::abs(id.estimate[lead] - kExpansion), 3.0 * id.sd[lead]);
  worst = std::max(worst, std::abs(id.estimate[lead] - kExpansion) / id.sd[lead]);
  std::printf("  expansions within %.2f sd; lead expansion %.2f +- %.2f ppm/K (true %.1f)\n", worst,
              1e6 * id.estimate[lead], 1e6 * id.sd[lead], 1e6 * kExpansion);
  // The corrected configuration: the expansions per leg and the reference.
  const Model corrected(id.corrected);
  EXPECT_EQ(id.corrected.reference_temperature, obs.front().temperature);
  for (int i = 0; i < kLegs; ++i)
    // a_L times the corrected leg's length at home, the fit's k_i a_L times the nominal's: they
    // differ by the legs' change of length (< 1 mm of 1.9 m).
    EXPECT_NEAR(corrected.geometry().thermal_length[i], id.estimate[ps.drift_index() + i],
                1e-3 * kExpansion * nominal.length_home()[i]);
  // Commands at +2 K: with the temperature, as good as at the reference; without, off by the growth.
  std::vector<PointPair> with, without;
  LegInputs warm;
  warm.temperature.setConstant(corrected.reference_temperature() + 2.0);
  LegInputs real_warm;
  real_warm.temperature.setConstant(real.reference_temperature() + 2.0);
  while (with.size() < 100) {
    const Pose p = random_pose(rng, 0.2, deg2rad(12));
    Vector6d command, cold;
    LimitReport limit;
    if (motor_commands(corrected, p, Strategy::Compensated, warm, nullptr, command, limit) != Status::Ok) continue;
    if (motor_commands(corrected, p, Strategy::Compensated, cold, limit) != Status::Ok) continue;
    const Vector3d target = platform_point_B(corrected, placement_from_pose(p), id.corrected.observation_P);
    for (const auto& [cmd, out] : {std::pair{&command, &with}, std::pair{&cold, &without}}) {
      FkResult fk;
      ASSERT_EQ(forward_kinematics(real, *cmd, real_warm, nullptr, placement_from_pose(p), fk), Status::Ok);
      out->push_back({target, platform_point_B(real, fk.placement, c.truth.targets[0])});
    }
  }
  const auto aligned_median = [](const std::vector<PointPair>& pairs) {
    Registration reg;
    EXPECT_EQ(register_points(pairs, reg), Status::Ok);
    std::vector<double> e;
    for (const PointPair& q : pairs) e.push_back((apply(reg.X_BT, q.p_T) - q.p_B).norm());
    std::sort(e.begin(), e.end());
    return e[e.size() / 2];
  };
  const double m_with = aligned_median(with), m_without = aligned_median(without);
  std::printf(
      "  at +2 K: aligned median %.2f um with the temperature, %.2f um without (predicted at the "
      "reference %.2f um)\n",
      1e6 * m_with, 1e6 * m_without, 1e6 * id.accuracy.aligned_median);
  EXPECT_LT(m_with, 2.0 * id.accuracy.aligned_median + 1e-6);
  EXPECT_GT(m_without, 2.0 * m_with);
}

TEST(IdentificationEffects, AutoChoosesTheEffectsTheDataShowAndNoneOtherwise) {
  std::mt19937_64 rng(kSeed + 504);
  EffectsCase c = effects_case(rng);
  // Softer legs than the other tests' (100 N/um): at 200 N/um the load shows at 1.4 sigma only
  // here (50 stations of 6 points), and auto rightly leaves it out.
  for (LegSpec& leg : c.real_spec.legs) leg.stiffness = 1.0e8;
  const Model& nominal = c.config.rig.model();
  const Model real(c.real_spec);
  const std::vector<Pose> stations = random_station_poses(nominal, real, 50, 0.25, deg2rad(15), rng);
  IdentificationOptions options;
  options.folds = 0;
  options.accuracy_poses = 50;
  options.auto_effects = true;
  Identification id;
  ASSERT_EQ(identify(nominal, observe_with_effects(c, stations, 6, 10e-6, rng), id, options), Status::Ok) << id.reason;
  EXPECT_EQ(id.parameters.effects().names(), "load,play,heat") << id.effects_choice;
  // The same platform without the effects: none is chosen (each below 5 sigma).
  EffectsCase rigid = c;
  rigid.real_spec = c.truth.spec;
  Identification plain;
  ASSERT_EQ(identify(nominal, observe_with_effects(rigid, stations, 6, 10e-6, rng), plain, options), Status::Ok)
      << plain.reason;
  EXPECT_EQ(plain.parameters.effects().names(), "none") << plain.effects_choice;
  EXPECT_EQ(plain.effects_choice.rfind("auto: none", 0), 0u) << plain.effects_choice;
}

TEST(IdentificationEffects, TheEffectsColumnsMatchCentralDifferences) {
  // Heat by the run's time (drift, curvature, lead drift) and by the log's temperatures
  // (expansions per kelvin, lead expansion).
  for (const bool measured : {false, true}) {
    SCOPED_TRACE(measured ? "temperatures" : "time");
    std::mt19937_64 rng(kSeed + 502);
    EffectsCase c = effects_case(rng);
    c.log_temperature = measured;
    const Model& nominal = c.config.rig.model();
    const std::vector<Pose> stations = random_station_poses(nominal, Model(c.real_spec), 12, 0.2, deg2rad(10), rng);
    const std::vector<Observation> obs = observe_with_effects(c, stations, 1, 0.0, rng);
    AxisSelection axes{};
    EffectFit fit = effect_fit("load,play,heat");
    fit.measured = measured;
    fit.reference_temperature = obs.front().temperature;
    const ParameterSet set(nominal, CalibrationModel::Geometry, LeadEffect::TwistAndTravel, axes, 1, LeadFit::Shared,
                           fit);
    Eigen::VectorXd theta = set.nominal_vector();
    // Away from zero, so that the candidate has every effect.
    theta[set.compliance_index()] = 4e-9;
    for (int i = 0; i < kLegs; ++i) {
      theta[set.play_index() + i] = 30e-6 + 5e-6 * i;
      theta[set.drift_index() + i] = 10e-6 * (i - 2);
      if (!measured) theta[set.curvature_index() + i] = -3e-6 * i;
    }
    theta[set.lead_drift_index()] = 8e-6;
    Eigen::VectorXd e;
    Eigen::MatrixXd J;
    ASSERT_EQ(identification_residuals(set, obs, theta, 1.0, c.truth.X_BT, {}, e, &J), Status::Ok);
    double worst = 0.0;
    for (int k = set.effect_index(); k < set.effect_index() + set.effects().count(); ++k) {
      const double h = k == set.compliance_index() ? 1e-11 : 1e-6;
      Eigen::VectorXd up = theta, down = theta, e_up, e_down;
      up[k] += h;
      down[k] -= h;
      ASSERT_EQ(identification_residuals(set, obs, up, 1.0, c.truth.X_BT, {}, e_up, nullptr), Status::Ok);
      ASSERT_EQ(identification_residuals(set, obs, down, 1.0, c.truth.X_BT, {}, e_down, nullptr), Status::Ok);
      const Eigen::VectorXd fd = (e_up - e_down) / (2.0 * h);
      const double scale = std::max(fd.cwiseAbs().maxCoeff(), 1e-12);
      worst = std::max(worst, (fd - J.col(k)).cwiseAbs().maxCoeff() / scale);
      EXPECT_GT(J.col(k).cwiseAbs().maxCoeff(), 0.0) << set.name(k) << " moves the points";
    }
    report("largest relative difference of an effect's column from central differences", worst);
    EXPECT_LT(worst, 1e-6);  // measured 2.4e-8
  }
}

TEST(IdentificationEffects, WhatAnEffectNeedsIsAskedFor) {
  std::mt19937_64 rng(kSeed + 503);
  const EffectsCase c = effects_case(rng);
  const Model& nominal = c.config.rig.model();
  const std::vector<Pose> stations = random_station_poses(nominal, Model(c.real_spec), 30, 0.2, deg2rad(10), rng);
  std::vector<Observation> obs = observe_with_effects(c, stations, 3, 10e-6, rng);
  for (Observation& o : obs) o.time = std::numeric_limits<double>::quiet_NaN();
  IdentificationOptions options;
  options.effects.heat = true;
  Identification id;
  EXPECT_EQ(identify(nominal, obs, id, options), Status::NotIdentifiable);
  EXPECT_EQ(id.reason.rfind("heat:", 0), 0u) << id.reason;
  // Temperatures that do not change over the run: no expansion can be fitted from them.
  for (Observation& o : obs) o.temperature = 21.5;
  EXPECT_EQ(identify(nominal, obs, id, options), Status::NotIdentifiable);
  EXPECT_NE(id.reason.find("heat: the log's temperatures vary by 0 K"), std::string::npos) << id.reason;
  for (Observation& o : obs) o.temperature = std::numeric_limits<double>::quiet_NaN();
  // Load without the configuration's load.
  ModelSpec bare = nominal.spec();
  bare.static_load = StaticLoadSpec{};
  options.effects = effect_fit("load");
  EXPECT_EQ(identify(Model(bare), obs, id, options), Status::NotIdentifiable);
  EXPECT_EQ(id.reason.rfind("load:", 0), 0u) << id.reason;
  // The names: one vocabulary for the CLI, C++ and Python.
  EXPECT_EQ(effect_fit("play,heat").names(), "play,heat");
  EXPECT_EQ(effect_fit("none").count(), 0);
  EXPECT_EQ(effect_fit("load,play,heat").count(), 1 + 6 + 13);
  try {
    (void)effect_fit("load,warp");
    ADD_FAILURE() << "an unknown effect was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("'warp'"), std::string::npos) << e.what();
  }
}

TEST(EffectFit, AListNamesEachEffectOnceAndNoneOrAutoStandAlone) {
  EXPECT_EQ(effect_fit("heat,load").names(), "load,heat");
  EXPECT_EQ(effect_fit("none").count(), 0);
  for (const char* bad : {"heat,heat", "load,play,load", "none,heat", "heat,auto", "heat,", ""}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW((void)effect_fit(bad), Error);
  }
}

}  // namespace
}  // namespace hexatwist::test
