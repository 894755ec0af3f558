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
};

EffectsCase effects_case(std::mt19937_64& rng) {
  EffectsCase c;
  TruthErrors e;
  e.joints = 0.5e-3;
  e.lead = 0.02;
  c.truth = random_truth(c.config.rig.model(), e, rng);
  c.real_spec = c.truth.spec;
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = c.real_spec.legs[static_cast<std::size_t>(i)];
    leg.stiffness = kStiffness;
    leg.play = kPlay[i];
    leg.length_expansion = kExpansion;
    leg.lead_expansion = kExpansion;
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
                                     kRise * (1.0 - std::exp(-t / T)) / (1.0 - std::exp(-1.0)));
      FkResult fk;
      EXPECT_EQ(forward_kinematics(real, command, inputs, &direction, placement_from_pose(stations[s]), fk),
                Status::Ok);
      Observation o;
      o.motor = command;
      o.time = t;
      o.approach = direction;  // a 1 m run: longer than any play
      o.p_T = apply(X_TB, platform_point_B(real, fk.placement, c.truth.targets[0])) +
              sigma * Vector3d(gaussian(rng), gaussian(rng), gaussian(rng));
      out.push_back(o);
    }
  }
  return out;
}

TEST(IdentificationEffects, LoadPlayAndHeatAreRefusedWithoutThemAndRecoveredWithThem) {
  std::mt19937_64 rng(kSeed + 501);
  const EffectsCase c = effects_case(rng);
  const Model& nominal = c.config.rig.model();
  const Model real(c.real_spec);
  const std::vector<Pose> stations = random_station_poses(nominal, real, 60, 0.25, deg2rad(15), rng);
  const std::vector<Observation> obs = observe_with_effects(c, stations, 8, 10e-6, rng);
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
  within(ps.curvature_index() + kLegs, kExpansion * rise_end, 4.0);
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
  std::mt19937_64 rng(kSeed + 502);
  const EffectsCase c = effects_case(rng);
  const Model& nominal = c.config.rig.model();
  const std::vector<Pose> stations = random_station_poses(nominal, Model(c.real_spec), 12, 0.2, deg2rad(10), rng);
  const std::vector<Observation> obs = observe_with_effects(c, stations, 1, 0.0, rng);
  AxisSelection axes{};
  const ParameterSet set(nominal, CalibrationModel::Geometry, LeadEffect::TwistAndTravel, axes, 1, LeadFit::Shared,
                         effect_fit("load,play,heat"));
  Eigen::VectorXd theta = set.nominal_vector();
  // Away from zero, so that the candidate has every effect.
  theta[set.compliance_index()] = 4e-9;
  for (int i = 0; i < kLegs; ++i) {
    theta[set.play_index() + i] = 30e-6 + 5e-6 * i;
    theta[set.drift_index() + i] = 10e-6 * (i - 2);
    theta[set.curvature_index() + i] = -3e-6 * i;
  }
  theta[set.curvature_index() + kLegs] = 8e-6;
  Eigen::VectorXd e;
  Eigen::MatrixXd J;
  ASSERT_EQ(identification_residuals(set, obs, theta, 1.0, c.truth.X_BT, {}, e, &J), Status::Ok);
  double worst = 0.0;
  for (int k = set.effect_index(); k < set.effect_index() + set.effects().count(); ++k) {
    const double h = k == set.compliance_index() ? 1e-11 : k == set.curvature_index() + kLegs ? 1e-6 : 1e-6;
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

}  // namespace
}  // namespace hexatwist::test
