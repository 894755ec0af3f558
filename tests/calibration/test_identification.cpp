// SPDX-License-Identifier: BSD-3-Clause
// Identification (include/hexatwist/calibration/identification.hpp, theory §13) on synthetic tracker
// data made here (calibration_support.hpp): a real platform whose joint centres, leads, thread
// sense, zero offsets and observation point differ from the seed by known amounts, seen by a
// tracker at a random place at stations where the nominal model's commands hold it still. Checks:
// the truth recovered within its reported standard deviations, and those honest over many seeds;
// exact recovery without noise; the Jacobian against central differences (joints, axes, both
// lead models, both senses, several targets); the decisions (undetermined data, a model that
// leaves an error, a thread sense the data do not decide); cross-validation against its
// expectation; per-leg threads and leads; several targets; the corrected platform on target at
// poses not used, against the accuracy the covariance predicts. Seed counts scale with
// HEXATWIST_STRESS (support.hpp).
#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>
#include <vector>

#include "calibration/calibration_support.hpp"

namespace hexatwist::test {
namespace {

constexpr double kTrackerNoise = 10e-6;  // the paper's tracker class [m]

// The seed's tracker data: `stations` random stations within +-0.25 m and +-15 deg (home first),
// `points` points of each target at each.
std::vector<Observation> station_data(const Truth& truth, int stations, int points, double sigma, std::mt19937_64& rng,
                                      Strategy strategy = Strategy::Compensated) {
  const Model real(truth.spec);
  const std::vector<Pose> poses = random_station_poses(seed_model(), real, stations, 0.25, deg2rad(15), rng);
  return observe(seed_model(), truth, poses, points, sigma, rng, strategy);
}

IdentificationOptions quick(IdentificationOptions o = {}) {
  o.folds = 0;
  o.accuracy_poses = 50;
  return o;
}

TEST(Identification, GeometryRecoversEveryJointCentreLeadOffsetAndPointWithinItsStandardDeviations) {
  // The case: joints off by up to 1 mm, the lead 2.5 % long, offsets +-0.5 mm, A off by
  // 2 mm, 40 stations at 10 um. Every parameter within 4 sd of the truth; the joints determined
  // to 5-80 um (issue 21).
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE(seed);
    std::mt19937_64 rng(kSeed + seed);
    const Truth truth = random_truth(seed_model(), TruthErrors{}, rng);
    const std::vector<Observation> obs = station_data(truth, 42, 20, kTrackerNoise, rng);
    Identification id;
    ASSERT_EQ(identify(seed_model(), obs, id, quick()), Status::Ok) << id.reason;
    const Eigen::VectorXd d = parameter_error(id, truth);
    double worst = 0.0;
    for (int k = 0; k < id.parameters.size(); ++k) {
      EXPECT_LT(std::abs(d[k]), 4.0 * id.sd[k]) << id.parameters.name(k);
      worst = std::max(worst, std::abs(d[k]) / id.sd[k]);
    }
    const double joint_sd = std::max(id.base_shift_sd.maxCoeff(), id.platform_shift_sd.maxCoeff());
    std::printf("  seed %u: worst error %.2f sd; joints sd %.1f-%.1f um; lead %.2g (sd %.2g); sigma %.2f um\n", seed,
                worst, 1e6 * std::min(id.base_shift_sd.minCoeff(), id.platform_shift_sd.minCoeff()), 1e6 * joint_sd,
                d[0] / truth.spec.legs[0].lead, id.sd[0] / truth.spec.legs[0].lead, 1e6 * id.sigma);
    EXPECT_LT(joint_sd, 200e-6);  // issue 21: "5-80 um" on its run; random stations here
    EXPECT_EQ(id.twist_sign, 1.0);
    EXPECT_NEAR(id.sigma, kTrackerNoise, 0.05 * kTrackerNoise);
    EXPECT_LT(id.fit_z, 5.0);
  }
}

TEST(Identification, ReportedStandardDeviationsAreHonestOverFiftySeeds) {
  // Over many seeds the errors, normalised by the reported standard deviations, must look like
  // standard normal draws: the fraction inside 1 sd near 68.3 % (issue 21), and the whole
  // covariance through the squared Mahalanobis distance d^2 = err^T C^-1 err, a chi^2 with p
  // degrees of freedom: its mean over the seeds / p within 4 of its standard deviations sqrt(2/(p S)).
  const int S = stress(50);
  int inside = 0, total = 0;
  double d2_sum = 0.0;
  int p = 0;
  for (int seed = 1; seed <= S; ++seed) {
    std::mt19937_64 rng(kSeed + 1000 + static_cast<std::uint32_t>(seed));
    TruthErrors e;
    e.flip = seed % 2 == 0;
    const Truth truth = random_truth(seed_model(), e, rng);
    const std::vector<Observation> obs = station_data(truth, 32, 8, kTrackerNoise, rng);
    Identification id;
    ASSERT_EQ(identify(seed_model(), obs, id, quick()), Status::Ok) << "seed " << seed << ": " << id.reason;
    const Eigen::VectorXd d = parameter_error(id, truth);
    for (int k = 0; k < d.size(); ++k) inside += std::abs(d[k]) < id.sd[k] ? 1 : 0;
    total += static_cast<int>(d.size());
    p = static_cast<int>(d.size());
    d2_sum += d.dot(id.covariance.ldlt().solve(d));
  }
  const double fraction = static_cast<double>(inside) / total, mean_d2 = d2_sum / (S * p);
  std::printf("  %d seeds x %d parameters: %.1f %% inside 1 sd; mean d^2 / p = %.3f (+- %.3f)\n", S, p, 100 * fraction,
              mean_d2, std::sqrt(2.0 / (p * S)));
  EXPECT_NEAR(fraction, 0.683, 0.05);
  EXPECT_NEAR(mean_d2, 1.0, 4.0 * std::sqrt(2.0 / (p * S)) + 0.02);
}

TEST(Identification, NoiseFreeDataAreRecoveredToRounding) {
  // Joints, axes (all fitted), leads, offsets, two targets: without noise the truth comes back to
  // rounding (the tracker's noise given, since there is no scatter to measure).
  std::mt19937_64 rng(kSeed + 7);
  TruthErrors e;
  e.axes = deg2rad(0.5);
  e.extra_targets = {Vector3d(-0.4, 0.6, 0.05)};
  const Truth truth = random_truth(seed_model(), e, rng);
  const std::vector<Observation> obs = station_data(truth, 60, 1, 0.0, rng);
  IdentificationOptions o = quick();
  o.axes = AxisFit::All;
  o.tracker_noise = kTrackerNoise;
  Identification id;
  ASSERT_EQ(identify(seed_model(), obs, id, o), Status::Ok) << id.reason;
  const Eigen::VectorXd d = parameter_error(id, truth);
  const ParameterSet& set = id.parameters;
  std::printf("  %d iterations, cost %.3g, condition %.3g: %s\n", id.fits[0].iterations, id.fits[0].cost, id.condition,
              id.fits[0].message.c_str());
  EXPECT_LT(std::abs(d[0]) / truth.spec.legs[0].lead, 1e-9);
  EXPECT_LT(d.segment(set.offset_index(), kLegs).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(d.segment(set.base_index(), 2 * (3 * kLegs - 6)).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(d.segment(set.axis_index(), set.axis_count()).cwiseAbs().maxCoeff(), 1e-7);
  EXPECT_LT(d.segment(set.target_index(), 6).cwiseAbs().maxCoeff(), 1e-9);
  report("largest joint error without noise [m]",
         d.segment(set.base_index(), 2 * (3 * kLegs - 6)).cwiseAbs().maxCoeff());
  report("largest axis error without noise [rad]", d.segment(set.axis_index(), set.axis_count()).cwiseAbs().maxCoeff());
}

TEST(Identification, JacobianMatchesCentralDifferences) {
  // The residuals' Jacobian (implicit function theorem through twist-aware FK, joints and axes by
  // dual numbers) against central differences of the residuals, every column, both lead models,
  // both senses, two targets, a drive scale in the nominal model.
  std::mt19937_64 rng(kSeed + 11);
  TruthErrors e;
  e.axes = deg2rad(1.0);
  e.extra_targets = {Vector3d(0.3, -0.8, 0.1)};
  const Truth truth = random_truth(seed_model(), e, rng);
  const std::vector<Observation> obs = station_data(truth, 12, 1, 0.0, rng);
  AxisSelection all;
  all.fill(true);
  for (const LeadEffect effect : {LeadEffect::TwistOnly, LeadEffect::TwistAndTravel})
    for (const double sign : {1.0, -1.0}) {
      SCOPED_TRACE(effect == LeadEffect::TwistOnly ? "twist only" : "travel");
      SCOPED_TRACE(sign);
      const ParameterSet set(seed_model(), CalibrationModel::Geometry, effect, all, 2);
      Eigen::VectorXd theta = truth_vector(set, truth);
      theta.segment<3>(set.rotation_index()).setZero();
      Eigen::VectorXd e0;
      Eigen::MatrixXd J;
      FkOptions tight;
      tight.tolerance = 1e-14;
      ASSERT_EQ(identification_residuals(set, obs, theta, sign, truth.X_BT, tight, e0, &J), Status::Ok);
      double worst = 0.0;
      for (int c = 0; c < set.size(); ++c) {
        const bool rotation = c >= set.rotation_index() && c < set.rotation_index() + 3;
        // Steps that move the residuals well above the forward kinematics' tolerance (an axis
        // moves A by microns per degree) and keep the truncation error far below it.
        const bool axis = c >= set.axis_index() && c < set.axis_index() + set.axis_count();
        const double h = c < set.lead_count() ? 1e-5 * theta[c] : axis ? 1e-4 : 1e-6;
        Eigen::VectorXd ep, em;
        Eigen::VectorXd tp = theta, tm = theta;
        RigidTransform Xp = truth.X_BT, Xm = truth.X_BT;
        if (rotation) {
          Xp.R = exp_so3(Vector3d::Unit(c - set.rotation_index()) * h) * truth.X_BT.R;
          Xm.R = exp_so3(-Vector3d::Unit(c - set.rotation_index()) * h) * truth.X_BT.R;
        } else if (c >= set.translation_index()) {
          Xp.t[c - set.translation_index()] += h;
          Xm.t[c - set.translation_index()] -= h;
        } else {
          tp[c] += h;
          tm[c] -= h;
        }
        ASSERT_EQ(identification_residuals(set, obs, tp, sign, Xp, tight, ep, nullptr), Status::Ok);
        ASSERT_EQ(identification_residuals(set, obs, tm, sign, Xm, tight, em, nullptr), Status::Ok);
        const Eigen::VectorXd fd = (ep - em) / (2 * h);
        const double scale = std::max(J.col(c).cwiseAbs().maxCoeff(), 1e-12);
        const double diff = (fd - J.col(c)).cwiseAbs().maxCoeff() / scale;
        worst = std::max(worst, diff);
        EXPECT_LT(diff, 1e-6) << set.name(c);
      }
      report("largest column difference / column max", worst);
    }
}

TEST(Identification, UndeterminedDataAreReportedNotSolved) {
  std::mt19937_64 rng(kSeed + 13);
  const Truth truth = random_truth(seed_model(), TruthErrors{}, rng);
  Identification id;
  // Too few stations for the geometry model's 40 parameters: named, nothing solved.
  const std::vector<Observation> few = station_data(truth, 8, 5, kTrackerNoise, rng);
  EXPECT_EQ(identify(seed_model(), few, id, quick()), Status::NotIdentifiable);
  EXPECT_NE(id.reason.find("stations are needed"), std::string::npos) << id.reason;
  EXPECT_FALSE(id.fitted);
  // One station only for the basic model.
  std::vector<Observation> one(few.begin(), few.begin() + 5);
  IdentificationOptions basic = quick();
  basic.model = CalibrationModel::Basic;
  EXPECT_EQ(identify(seed_model(), one, id, basic), Status::NotIdentifiable);
  // Translations along z only: the points lie on a line, no tracker frame (theory §11).
  std::vector<Pose> lz, lxz;
  for (int k = -4; k <= 4; ++k) {
    Pose p;
    p.position.z() = 0.05 * k;
    lz.push_back(p);
    lxz.push_back(p);
    p.position = Vector3d(0.05 * k, 0.0, 0.0);
    lxz.push_back(p);
  }
  EXPECT_EQ(identify(seed_model(), observe(seed_model(), truth, lz, 5, kTrackerNoise, rng), id, basic),
            Status::NotIdentifiable);
  EXPECT_NE(id.reason.find("registration"), std::string::npos) << id.reason;
  // Along x and z: translations only, so A and the tracker's translation are confounded (theory
  // §13), and named.
  EXPECT_EQ(identify(seed_model(), observe(seed_model(), truth, lxz, 5, kTrackerNoise, rng), id, basic),
            Status::NotIdentifiable);
  EXPECT_NE(id.reason.find("do not determine"), std::string::npos) << id.reason;
  EXPECT_NE(id.reason.find("A x"), std::string::npos) << id.reason;
  EXPECT_NE(id.reason.find("translation"), std::string::npos) << id.reason;
  // Points without repeats and no tracker noise given: the noise is unknown.
  const std::vector<Observation> single = station_data(truth, 60, 1, kTrackerNoise, rng);
  EXPECT_EQ(identify(seed_model(), single, id, quick()), Status::NotIdentifiable);
  EXPECT_NE(id.reason.find("noise is unknown"), std::string::npos) << id.reason;
}

TEST(Identification, TheBasicModelOnJointErrorDataIsRefusedWithTheHint) {
  // Issue 21: the basic model absorbs joint errors into its offsets and leaves millimetres; the
  // model-fit test refuses it, names the worst station and points at the geometry model.
  std::mt19937_64 rng(kSeed + 17);
  const Truth truth = random_truth(seed_model(), TruthErrors{}, rng);
  const std::vector<Observation> obs = station_data(truth, 42, 20, kTrackerNoise, rng);
  IdentificationOptions o = quick();
  o.model = CalibrationModel::Basic;
  Identification id;
  EXPECT_EQ(identify(seed_model(), obs, id, o), Status::ModelMismatch);
  EXPECT_GT(id.fit_z, 50.0);
  EXPECT_FALSE(id.worst.empty());
  EXPECT_NE(id.hint.find("geometry"), std::string::npos) << id.hint;
  // The same data without joint errors: the basic model explains them.
  TruthErrors e;
  e.joints = 0.0;
  const Truth plain = random_truth(seed_model(), e, rng);
  EXPECT_EQ(identify(seed_model(), station_data(plain, 42, 20, kTrackerNoise, rng), id, o), Status::Ok) << id.reason;
  EXPECT_LT(id.fit_z, 5.0);
}

TEST(Identification, AnErrorTheModelDoesNotHaveIsRefused) {
  // Data of the conventional commands identified as compensated (the other --strategy, issue 22),
  // and axes turned by 3 degrees with the axes kept: both leave more than the noise.
  std::mt19937_64 rng(kSeed + 19);
  const Truth truth = random_truth(seed_model(), TruthErrors{}, rng);
  Identification id;
  const std::vector<Observation> conventional = station_data(truth, 42, 20, kTrackerNoise, rng, Strategy::Conventional);
  // The observations carry the compensated commands of the same poses.
  std::vector<Observation> relabelled = conventional;
  for (Observation& o : relabelled) {
    FkResult fk;
    ASSERT_EQ(forward_kinematics(seed_model(), o.motor, LengthKind::Geometric, Placement{}, fk), Status::Ok);
    LimitReport limit;
    ASSERT_EQ(motor_commands(seed_model(), fk.pose, Strategy::Compensated, o.motor, limit), Status::Ok);
  }
  EXPECT_EQ(identify(seed_model(), relabelled, id, quick()), Status::ModelMismatch) << id.reason;
  TruthErrors turned;
  turned.axes = deg2rad(3.0);
  const Truth axes = random_truth(seed_model(), turned, rng);
  IdentificationOptions none = quick();
  none.axes = AxisFit::None;
  EXPECT_EQ(identify(seed_model(), station_data(axes, 42, 20, kTrackerNoise, rng), id, none), Status::ModelMismatch)
      << id.reason;
  EXPECT_NE(id.hint.find("axes"), std::string::npos) << id.hint;
}

TEST(Identification, AThreadSenseTheDataDoNotDecideIsRefused) {
  // Drives with the right lead (the twist term alone sees it): for the wrong sense the best fit is
  // no twist at all (its lead at the bound 0). Whether that is worse than the right sense by more
  // than the noise explains decides; under noise that hides the twist (2 mm against its 0.1-0.5 mm
  // effect) it does not, and the estimate is refused, not reported with an undecided hand.
  TruthErrors e;
  e.lead = 0.0;
  IdentificationOptions o = quick();
  o.lead_effect = LeadEffect::TwistOnly;
  std::mt19937_64 rng(kSeed + 23);
  const Truth truth = random_truth(seed_model(), e, rng);
  Identification id;
  ASSERT_EQ(identify(seed_model(), station_data(truth, 42, 20, kTrackerNoise, rng), id, o), Status::Ok) << id.reason;
  EXPECT_EQ(id.twist_sign, 1.0);
  EXPECT_TRUE(id.fits[1].lead_at_bound);
  EXPECT_GT(id.sign_separation, 1e3);
  EXPECT_EQ(identify(seed_model(), station_data(truth, 42, 20, 2e-3, rng), id, o), Status::SignUndecided) << id.reason;
  EXPECT_LT(id.sign_separation, o.sign_separation_min);
  EXPECT_NE(id.reason.find("thread senses"), std::string::npos) << id.reason;
}

TEST(Identification, AxesAreFittedOnlyWhereTheDataDetermineThem) {
  // With 42 stations at 10 um the axes are not determined to 0.1 deg (their effect on A is a few
  // um per 0.5 deg, issue 21): Auto fits none and says how well each is known.
  std::mt19937_64 rng(kSeed + 23);
  const Truth truth = random_truth(seed_model(), TruthErrors{}, rng);
  Identification id;
  ASSERT_EQ(identify(seed_model(), station_data(truth, 42, 20, kTrackerNoise, rng), id, quick()), Status::Ok);
  EXPECT_EQ(id.parameters.axis_count(), 0);
  double lo = INFINITY;
  for (const double sd : id.axis_sd) {
    ASSERT_TRUE(std::isfinite(sd));
    lo = std::min(lo, sd);
  }
  std::printf("  axes' sd if fitted: %.3g deg at best\n", rad2deg(lo));
  EXPECT_GT(lo, deg2rad(0.1));
  // Noise a hundred times smaller determines many of them: every axis fitted comes back within
  // its standard deviations, and Auto fits exactly those whose predicted sd is within 0.1 deg.
  TruthErrors e;
  e.axes = deg2rad(1.0);
  const Truth turned = random_truth(seed_model(), e, rng);
  const std::vector<Observation> obs = station_data(turned, 60, 20, 0.1e-6, rng);
  IdentificationOptions all = quick();
  all.axes = AxisFit::All;
  ASSERT_EQ(identify(seed_model(), obs, id, all), Status::Ok) << id.reason;
  EXPECT_EQ(id.parameters.axis_count(), 24);
  const Eigen::VectorXd d = parameter_error(id, turned);
  for (int k = id.parameters.axis_index(); k < id.parameters.axis_index() + id.parameters.axis_count(); ++k)
    EXPECT_LT(std::abs(d[k]), 4.0 * id.sd[k]) << id.parameters.name(k);
  Identification automatic;
  (void)identify(seed_model(), obs, automatic, quick());
  int fitted = 0;
  for (std::size_t a = 0; a < automatic.axis_sd.size(); ++a) {
    EXPECT_EQ(automatic.parameters.axes()[a], automatic.axis_sd[a] <= deg2rad(0.1)) << "axis " << a;
    fitted += automatic.parameters.axes()[a] ? 1 : 0;
  }
  std::printf("  at 0.1 um: %d of 12 axes determined to 0.1 deg\n", fitted);
  EXPECT_GT(fitted, 0);
}

TEST(Identification, CrossValidationPredictsLeftOutStationsAsTheCovarianceExpects) {
  std::mt19937_64 rng(kSeed + 29);
  const Truth truth = random_truth(seed_model(), TruthErrors{}, rng);
  IdentificationOptions o = quick();
  o.folds = 5;
  Identification id;
  ASSERT_EQ(identify(seed_model(), station_data(truth, 42, 20, kTrackerNoise, rng), id, o), Status::Ok);
  const CrossValidation& cv = id.cross_validation;
  std::printf("  cross-validation: %d groups, rms %.2f um, expected %.2f um, largest %.2f um\n", cv.predicted,
              1e6 * cv.rms, 1e6 * cv.expected, 1e6 * cv.max);
  EXPECT_EQ(cv.folds, 5);
  EXPECT_EQ(cv.predicted, 42);
  EXPECT_NEAR(cv.rms / cv.expected, 1.0, 0.35);
  // The basic model's folds on the same data would miss by the joints' effect; the geometry's
  // left-out stations are within a few noise levels of a mean.
  EXPECT_LT(cv.max, 5.0 * cv.expected);
}

TEST(Identification, PerLegThreadsAndLeadsAreIdentifiedAndKept) {
  // A legs configuration whose leg 3 is left-handed and legs 5-6 have a 12 mm lead (issue 21: a
  // per-leg thread was ignored, a per-leg lead blamed on the data).
  ModelSpec spec = seed_model().spec();
  spec.legs[2].thread = ThreadSense::Left;
  spec.legs[4].lead = spec.legs[5].lead = 0.012;
  const Model nominal(spec);
  std::mt19937_64 rng(kSeed + 31);
  const Truth truth = random_truth(nominal, TruthErrors{}, rng);
  EXPECT_EQ(truth.spec.legs[2].thread, ThreadSense::Left);
  const Model real(truth.spec);
  const std::vector<Pose> poses = random_station_poses(nominal, real, 42, 0.25, deg2rad(15), rng);
  const std::vector<Observation> obs = observe(nominal, truth, poses, 20, kTrackerNoise, rng);
  Identification id;
  ASSERT_EQ(identify(nominal, obs, id, quick()), Status::Ok) << id.reason;
  EXPECT_EQ(id.parameters.lead_count(), kLegs);
  EXPECT_EQ(id.twist_sign, 1.0);
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_EQ(id.corrected.legs[static_cast<std::size_t>(i)].thread,
              truth.spec.legs[static_cast<std::size_t>(i)].thread)
        << "leg " << i + 1;
    EXPECT_NEAR(id.corrected.legs[static_cast<std::size_t>(i)].lead, truth.spec.legs[static_cast<std::size_t>(i)].lead,
                4.0 * id.sd[i])
        << "leg " << i + 1;
  }
  // The same with every hand flipped: the global sense is found, leg 3 stays the odd one.
  TruthErrors flipped;
  flipped.flip = true;
  const Truth other = random_truth(nominal, flipped, rng);
  ASSERT_EQ(identify(nominal, observe(nominal, other, poses, 20, kTrackerNoise, rng), id, quick()), Status::Ok)
      << id.reason;
  EXPECT_EQ(id.twist_sign, -1.0);
  EXPECT_EQ(id.corrected.legs[2].thread, ThreadSense::Right);
  EXPECT_EQ(id.corrected.legs[0].thread, ThreadSense::Left);
}

TEST(Identification, SeveralTargetsEachGetTheirPointAndSharpenTheEstimate) {
  std::mt19937_64 rng(kSeed + 37);
  TruthErrors e;
  e.extra_targets = {Vector3d(-0.6, 1.0, 0.02), Vector3d(-0.6, -1.0, -0.03)};
  const Truth truth = random_truth(seed_model(), e, rng);
  const Model real(truth.spec);
  const std::vector<Pose> poses = random_station_poses(seed_model(), real, 42, 0.25, deg2rad(15), rng);
  Identification three, one;
  ASSERT_EQ(identify(seed_model(), observe(seed_model(), truth, poses, 20, kTrackerNoise, rng), three, quick()),
            Status::Ok)
      << three.reason;
  ASSERT_EQ(three.parameters.targets(), 3);
  const Eigen::VectorXd d = parameter_error(three, truth);
  for (int k = three.parameters.target_index(); k < three.parameters.rotation_index(); ++k)
    EXPECT_LT(std::abs(d[k]), 4.0 * three.sd[k]) << three.parameters.name(k);
  Truth single = truth;
  single.targets.resize(1);
  ASSERT_EQ(identify(seed_model(), observe(seed_model(), single, poses, 20, kTrackerNoise, rng), one, quick()),
            Status::Ok);
  // Three targets see the orientation too: the joints come out better determined.
  const double sd3 = three.base_shift_sd.maxCoeff(), sd1 = one.base_shift_sd.maxCoeff();
  std::printf("  largest base joint sd: %.1f um with one target, %.1f um with three\n", 1e6 * sd1, 1e6 * sd3);
  EXPECT_LT(sd3, 0.8 * sd1);
}

TEST(Identification, TheCorrectedPlatformHitsPosesNotUsedAsTheCovariancePredicts) {
  // Under the contract (the drives keep their reference and scale, theory §4): commands of the
  // corrected model at poses not used, run on the real platform, put its A where the corrected
  // model says, within 2.5 times the predicted accuracy in the gauge frames and, after a rigid
  // re-alignment, within the 15 um median and 50 um worst; the nominal model misses by mm.
  for (const double joints : {0.5e-3, 2e-3}) {
    SCOPED_TRACE(joints);
    std::mt19937_64 rng(kSeed + 41 + static_cast<std::uint32_t>(1e4 * joints));
    TruthErrors e;
    e.joints = joints;
    e.flip = joints > 1e-3;
    const Truth truth = random_truth(seed_model(), e, rng);
    IdentificationOptions o = quick();
    o.accuracy_poses = 400;
    Identification id;
    ASSERT_EQ(identify(seed_model(), station_data(truth, 42, 20, kTrackerNoise, rng), id, o), Status::Ok) << id.reason;
    const HeldOut h = held_out(seed_model(), id, truth, 0.2, deg2rad(12), 200, rng);
    print_held_out(joints > 1e-3 ? "joints +-2.0 mm" : "joints +-0.5 mm", h, id);
    EXPECT_LT(h.gauge_median(), 2.5 * id.accuracy.median);
    EXPECT_LT(h.aligned_median(), 15e-6);
    EXPECT_LT(h.aligned.back(), 50e-6);
    EXPECT_LT(h.aligned_median(), 2.5 * id.accuracy.aligned_median + 1e-6);
    EXPECT_GT(h.nominal_miss, 0.5e-3);
  }
}

TEST(Identification, AMachineToolHexapodFromAPublishedTableIsCalibrated) {
  // A second machine, small and of another shape (tests/calibration/data/machine_tool_hexapod.yaml:
  // the nominal joints of a published calibration, Liu, Chen and Gao 2022, Table 2), whose real
  // joints are that table's identified ones (up to 3.6 mm off; their rigid part is the gauge's),
  // with a 1 % lead error, zero offsets, the target 1 mm off. 40 stations within +-40 mm and
  // +-8 deg, 10 um noise: identified, every parameter within 4 sd, and the corrected platform on
  // target at poses not used as the covariance predicts.
  const std::string path = std::string(HEXATWIST_SOURCE_DIR) + "/tests/calibration/data/machine_tool_hexapod.yaml";
  const Model nominal = load_model(read_text_file(path, "configuration", 1 << 20), path);
  // Identified minus nominal joint centres [m] (the table's a_i are the platform joints, b_i the base's).
  LegVectors db, dp;
  db << -1.509, -1.287, -2.325, 1.608, 0.163, -3.332, 2.334, -0.077, -3.022, -0.798, 1.998, -3.613, -0.794, 2.085,
      -3.393, -1.430, -0.976, -2.962;
  dp << 0.732, 0.177, 0.150, -0.156, 0.283, 0.135, -0.673, 0.491, -0.166, -0.156, -0.460, -0.029, -0.123, -0.850,
      -0.056, 0.400, -0.104, 0.122;
  ParameterErrors pe;
  pe.base_offset_B = without_rigid_part(nominal.geometry().base_B, 1e-3 * db);
  pe.platform_offset_P = without_rigid_part(nominal.geometry().arm_P, 1e-3 * dp);
  pe.lead_error.setConstant(0.01);
  pe.zero_offset << 0.12e-3, -0.08e-3, 0.2e-3, -0.15e-3, 0.05e-3, 0.1e-3;
  pe.observation_offset_P = Vector3d(1e-3, -0.5e-3, 0.8e-3);
  std::mt19937_64 rng(kSeed + 61);
  Truth truth;
  truth.spec = real_model(nominal, pe).spec();
  truth.targets = {truth.spec.observation_P};
  truth.X_BT = {random_rotation(rng), Vector3d(1.5, -2.0, 0.4)};
  const Model real(truth.spec);
  const std::vector<Pose> stations = random_station_poses(nominal, real, 42, 0.04, deg2rad(8), rng);
  Identification id;
  IdentificationOptions o = quick();
  o.accuracy_poses = 400;
  ASSERT_EQ(identify(nominal, observe(nominal, truth, stations, 20, kTrackerNoise, rng), id, o), Status::Ok)
      << id.reason;
  EXPECT_LT(id.fit_z, 5.0);
  const Eigen::VectorXd d = parameter_error(id, truth);
  for (int k = 0; k < id.parameters.size(); ++k) EXPECT_LT(std::abs(d[k]), 4.0 * id.sd[k]) << id.parameters.name(k);
  const HeldOut h = held_out(nominal, id, truth, 0.03, deg2rad(6), 200, rng);
  print_held_out("machine-tool hexapod", h, id);
  EXPECT_LT(h.gauge_median(), 2.5 * id.accuracy.median);
  EXPECT_LT(h.aligned_median(), 15e-6);
  EXPECT_LT(h.aligned.back(), 50e-6);
  EXPECT_GT(h.nominal_miss, 0.5e-3);
  // The basic model on the same data leaves the joints' error and is refused.
  o.model = CalibrationModel::Basic;
  EXPECT_EQ(identify(nominal, observe(nominal, truth, stations, 20, kTrackerNoise, rng), id, o), Status::ModelMismatch);
}

}  // namespace
}  // namespace hexatwist::test
