// Identification (include/hexatwist/calibration/identification.hpp, theory §13) on synthetic tracker data made
// here: the seed model is the nominal one, the "true" platform has its lead 5 % off, the other
// thread hand, zero errors of up to 1 mm per leg and the observation point a few mm away, and a
// tracker stands at a random place. The commands are the nominal model's compensated commands at
// random poses across the workspace, a tenth of them at home (the paper's four test motions
// determine the offsets too loosely, as one test here shows); the points are the true platform's
// observation point in the tracker frame plus Gaussian noise. Checks: the accuracies, the
// reported standard deviations against the actual errors over seeds, exact recovery without
// noise, the Jacobian against central differences, degenerate data, the travel model of the lead,
// and the corrected model. Seed counts scale with HEXATWIST_STRESS (support.hpp).
#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>
#include <vector>

#include "support.hpp"

namespace hexatwist::test {
namespace {

constexpr double kTrackerNoise = 10e-6;  // the paper's tracker class [m]

double gaussian(std::mt19937_64& rng) { return std::normal_distribution<double>(0.0, 1.0)(rng); }

Matrix3d random_rotation(std::mt19937_64& rng) {
  Eigen::Quaterniond q(gaussian(rng), gaussian(rng), gaussian(rng), gaussian(rng));
  return q.normalized().toRotationMatrix();
}

// Poses of the paper's four tests (Lz, Lx, Rz, Ry, theory §9) every `dt` seconds: the motions a
// user runs anyway, with their dwells at home and at the extremes.
std::vector<Pose> paper_poses(double dt, int only_test = -1) {
  const StudySpec spec;
  std::vector<Pose> poses;
  const std::vector<StudyTest> tests = seed_tests(spec);
  for (std::size_t i = 0; i < tests.size(); ++i) {
    if (only_test >= 0 && static_cast<int>(i) != only_test) continue;
    const Trajectory t = test_trajectory(spec, tests[i], dt);
    poses.insert(poses.end(), t.poses.begin(), t.poses.end());
  }
  return poses;
}

// A platform that differs from the nominal one as issue 5 says, and what it is.
struct Truth {
  ModelSpec spec;        // the real platform (offsets in the spec, the other thread hand)
  PlatformParameters p;  // its identified quantities and the tracker placement
};

Truth random_truth(const Model& nominal, std::mt19937_64& rng) {
  Truth truth;
  truth.spec = nominal.spec();
  const double lead = 1.05 * nominal.leg(0).lead;
  const ThreadSense thread = nominal.leg(0).thread == ThreadSense::Right ? ThreadSense::Left : ThreadSense::Right;
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = truth.spec.legs[static_cast<std::size_t>(i)];
    leg.lead = lead;
    leg.thread = thread;
    leg.length_offset = uniform(rng, -1e-3, 1e-3);
    truth.p.length_offset[i] = leg.length_offset;
  }
  for (int k = 0; k < 3; ++k) truth.spec.observation_P[k] += uniform(rng, -3e-3, 3e-3);
  truth.p.lead = lead;
  truth.p.twist_sign = thread == ThreadSense::Right ? 1.0 : -1.0;
  truth.p.observation_P = truth.spec.observation_P;
  truth.p.X_BT = {random_rotation(rng), Vector3d(uniform(rng, -5, 5), uniform(rng, -5, 5), uniform(rng, -2, 2))};
  return truth;
}

// The nominal model's compensated commands at `poses` and where the true platform puts A, seen by
// the tracker with Gaussian noise `sigma` per coordinate. With the travel effect the drives
// turned the screws by the nominal lead's angles, so the real motor-side lengths move by
// lead/nominal lead times the commanded travel from home.
std::vector<Observation> observe(const Model& nominal, const Truth& truth, const std::vector<Pose>& poses, double sigma,
                                 std::mt19937_64& rng, LeadEffect effect = LeadEffect::TwistOnly) {
  const Model real(truth.spec);
  const RigidTransform X_TB = inverse(truth.p.X_BT);
  std::vector<Observation> out;
  for (const Pose& pose : poses) {
    Observation o;
    LimitReport limit;
    EXPECT_EQ(motor_commands(nominal, pose, Strategy::Compensated, o.motor, limit), Status::Ok) << str(pose);
    Vector6d motor = o.motor;
    if (effect == LeadEffect::TwistAndTravel) {
      const Vector6d home = nominal.length_home() - nominal.geometry().length_offset;
      motor = home + (o.motor - home) * (truth.p.lead / nominal.leg(0).lead);
    }
    FkResult fk;
    EXPECT_EQ(forward_kinematics(real, motor, LengthKind::Motor, placement_from_pose(pose), fk), Status::Ok)
        << str(pose);
    const Vector3d noise(gaussian(rng), gaussian(rng), gaussian(rng));
    o.p_T = apply(X_TB, platform_point_B(real, fk.placement, truth.p.observation_P)) + sigma * noise;
    out.push_back(o);
  }
  return out;
}

// Estimate minus truth in the parameter order (rotation: dw with R_est = exp(dw) R_true).
ParameterVector parameter_error(const PlatformParameters& est, const PlatformParameters& truth) {
  ParameterVector d;
  d[kLeadIndex] = est.lead - truth.lead;
  d.segment<6>(kOffsetIndex) = est.length_offset - truth.length_offset;
  d.segment<3>(kObservationIndex) = est.observation_P - truth.observation_P;
  const Eigen::AngleAxisd r(Matrix3d(est.X_BT.R * truth.X_BT.R.transpose()));
  d.segment<3>(kRotationIndex) = r.angle() * r.axis();
  d.segment<3>(kTranslationIndex) = est.X_BT.t - truth.X_BT.t;
  return d;
}

// The errors issue 5 bounds, and the others.
struct Errors {
  double lead_relative;  // |lead - true| / true
  double offset;         // largest |offset - true| [m]
  double observation;    // |A - true| [m]
  double rotation;       // angle of R_est R_true^T [rad]
  double transfer;       // |X_est c - X_true c| at the points' centroid c [m]
};

Errors errors_of(const PlatformParameters& est, const PlatformParameters& truth, const std::vector<Observation>& obs) {
  Vector3d c = Vector3d::Zero();
  for (const Observation& o : obs) c += o.p_T / static_cast<double>(obs.size());
  const ParameterVector d = parameter_error(est, truth);
  return {std::abs(d[kLeadIndex]) / truth.lead, d.segment<6>(kOffsetIndex).cwiseAbs().maxCoeff(),
          d.segment<3>(kObservationIndex).norm(), d.segment<3>(kRotationIndex).norm(),
          (apply(est.X_BT, c) - apply(truth.X_BT, c)).norm()};
}

// A calibration run: `count` random poses inside every limit of the nominal model (+-0.5 m,
// +-30 deg), a tenth of them at home (the dwells before, between and after the moves).
std::vector<Pose> calibration_poses(int count, std::mt19937_64& rng) {
  std::vector<Pose> poses;
  for (int k = 0; k < count; ++k)
    poses.push_back(k % 10 == 0 ? Pose{} : random_valid_pose(seed_model(), rng, 0.5, deg2rad(30)));
  return poses;
}

// Runs identify on `obs` and expects Ok.
Identification identified(const std::vector<Observation>& obs, const IdentificationOptions& options = {}) {
  Identification id;
  EXPECT_EQ(identify(seed_model(), obs, id, options), Status::Ok) << id.reason;
  return id;
}

TEST(Identification, RecoversLeadSignOffsetsAndObservationPointFromACalibrationRun) {
  // Issue 5: lead within 0.5 %, the sign, offsets within 20 um at 10 um tracker noise. The data
  // are 2000 random poses (a tenth at home): the paper's four tests alone determine the offsets
  // only to 30-110 um (IdentifiabilityOfThePaperTests). The bounds are the issue's; that they
  // hold by design, and not by luck, shows in the reported standard deviations: 4 sd must fit
  // inside each bound (measured sd: lead 0.049 %, offsets 3.1-4.7 um).
  const Model& nominal = seed_model();
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    SCOPED_TRACE(seed);
    std::mt19937_64 rng(kSeed + seed);
    const Truth truth = random_truth(nominal, rng);
    const std::vector<Observation> obs = observe(nominal, truth, calibration_poses(2000, rng), kTrackerNoise, rng);
    const Identification id = identified(obs);
    const Errors e = errors_of(id.estimate, truth.p, obs);
    std::printf("  seed %u: %d observations; rms before %.4g mm, after %.4g um; sigma %.4g um; condition %.3g\n", seed,
                id.count, 1e3 * id.rms_before, 1e6 * id.rms_after, 1e6 * id.sigma, id.condition);
    std::printf("    sign %+.0f, cost ratio %.3g, iterations %d (sign +1) and %d (sign -1)\n", id.estimate.twist_sign,
                id.cost_ratio, id.fits[0].iterations, id.fits[1].iterations);
    std::printf("    lead error %.3g %% (sd %.3g %%); largest offset error %.3g um (sd %.3g-%.3g um)\n",
                100 * e.lead_relative, 100 * id.sd[kLeadIndex] / truth.p.lead, 1e6 * e.offset,
                1e6 * id.sd.segment<6>(kOffsetIndex).minCoeff(), 1e6 * id.sd.segment<6>(kOffsetIndex).maxCoeff());
    std::printf("    A error %.3g um (sd %.2g-%.2g um); rotation error %.3g urad; transfer error %.3g um\n",
                1e6 * e.observation, 1e6 * id.sd.segment<3>(kObservationIndex).minCoeff(),
                1e6 * id.sd.segment<3>(kObservationIndex).maxCoeff(), 1e6 * e.rotation, 1e6 * e.transfer);
    EXPECT_EQ(id.estimate.twist_sign, truth.p.twist_sign);
    EXPECT_LT(e.lead_relative, 0.005);
    EXPECT_LT(e.offset, 20e-6);
    EXPECT_LT(4 * id.sd[kLeadIndex], 0.005 * truth.p.lead);
    EXPECT_LT(4 * id.sd.segment<6>(kOffsetIndex).maxCoeff(), 20e-6);
    // The rejected sign leaves millimetre residuals: its cost is hundreds of times the chosen
    // one's (measured 674-694), and its lead ends at 0.
    EXPECT_GT(id.cost_ratio, 100.0);
    EXPECT_TRUE(id.fits[id.estimate.twist_sign > 0 ? 1 : 0].lead_at_bound);
    // Before: the nominal model misses by the parameter errors (1.08-1.32 mm rms); after: the noise
    // alone. sigma has 3K - 16 degrees of freedom: relative sd 1 %, bound 5 %.
    EXPECT_GT(id.rms_before, 30 * kTrackerNoise);
    EXPECT_NEAR(id.sigma, kTrackerNoise, 0.05 * kTrackerNoise);
    EXPECT_NEAR(id.rms_after, std::sqrt(3.0 * (3 * id.count - kIdentifiedParameters) / (3 * id.count)) * id.sigma,
                1e-12);
  }
}

TEST(Identification, ReportedStandardDeviationsMatchTheActualErrorsOverSeeds) {
  // Over many seeds the errors, normalised by the reported covariance, must look like standard
  // normal draws. The whole covariance is tested through the squared Mahalanobis distance
  // d^2 = err^T C^-1 err, a chi^2 with 16 degrees of freedom: mean(d^2)/16 = 1 within 4 of its
  // standard deviations sqrt(2 / (16 S)). Per parameter, z = err/sd: the mean within 4/sqrt(S),
  // and S times the mean square is a chi^2 with S degrees of freedom, whose tails are heavier than
  // a normal law's: it must lie between its 1e-4 and 1 - 1e-4 quantiles (Wilson-Hilferty; for
  // S = 40, 0.37 to 2.06 for the mean square). A rounding difference between compilers changes
  // which random poses pass the limits and so the draws; a bound at 4 normal sd (1.89) was
  // crossed by one parameter in the clang build (1.94, from one seed at 4.4 sd) while the gcc
  // build passed. An sd off by 1.45 or more fails here; the whole covariance is held to 4 % by
  // d^2. The sign must be right every time.
  const Model& nominal = seed_model();
  const int S = stress(40);
  double d2_sum = 0.0, smallest_ratio = std::numeric_limits<double>::infinity();
  ParameterVector z_sum = ParameterVector::Zero(), z2_sum = ParameterVector::Zero();
  for (int seed = 0; seed < S; ++seed) {
    SCOPED_TRACE(seed);
    std::mt19937_64 rng(kSeed + 1000 + static_cast<std::uint32_t>(seed));
    const Truth truth = random_truth(nominal, rng);
    const std::vector<Observation> obs = observe(nominal, truth, calibration_poses(200, rng), kTrackerNoise, rng);
    const Identification id = identified(obs);
    ASSERT_EQ(id.estimate.twist_sign, truth.p.twist_sign);
    smallest_ratio = std::min(smallest_ratio, id.cost_ratio);
    const ParameterVector err = parameter_error(id.estimate, truth.p);
    d2_sum += err.dot(id.covariance.ldlt().solve(err));
    const ParameterVector z = err.cwiseQuotient(id.sd);
    for (int j = 0; j < kIdentifiedParameters; ++j)
      if (std::abs(z[j]) > 4.0)
        std::printf("  seed %d: %s off by %.2f sd (cost ratio %.3g, iterations %d and %d, %s)\n", seed,
                    std::string(parameter_name(j)).c_str(), z[j], id.cost_ratio, id.fits[0].iterations,
                    id.fits[1].iterations, id.fits[id.estimate.twist_sign > 0 ? 0 : 1].message.c_str());
    z_sum += z;
    z2_sum += z.cwiseAbs2();
  }
  const double d2_mean = d2_sum / (S * kIdentifiedParameters);
  const ParameterVector z_mean = z_sum / S, z2_mean = z2_sum / S;
  std::printf("  %d seeds: mean d^2 / 16 = %.3f (tolerance %.3f); smallest sign cost ratio %.3g\n", S, d2_mean,
              4 * std::sqrt(2.0 / (16.0 * S)), smallest_ratio);
  for (int j = 0; j < kIdentifiedParameters; ++j)
    std::printf("  %-14s mean z %+.3f, mean z^2 %.3f\n", std::string(parameter_name(j)).c_str(), z_mean[j], z2_mean[j]);
  EXPECT_NEAR(d2_mean, 1.0, 4 * std::sqrt(2.0 / (16.0 * S)));
  // Quantile of chi^2 with k degrees of freedom at the standard normal quantile u, over k.
  const auto chi2_mean_quantile = [](double k, double u) {
    const double c = 1.0 - 2.0 / (9.0 * k) + u * std::sqrt(2.0 / (9.0 * k));
    return c * c * c;
  };
  const double u = 3.719;  // 1 - 1e-4 of the standard normal law
  const double low = chi2_mean_quantile(S, -u), high = chi2_mean_quantile(S, u);
  for (int j = 0; j < kIdentifiedParameters; ++j) {
    EXPECT_NEAR(z_mean[j], 0.0, 4 / std::sqrt(S)) << parameter_name(j);
    EXPECT_GT(z2_mean[j], low) << parameter_name(j);
    EXPECT_LT(z2_mean[j], high) << parameter_name(j);
  }
}

TEST(Identification, NoiseFreeDataAreRecoveredToRounding) {
  // Without noise the estimate is the truth up to rounding and the forward kinematics tolerance.
  // Measured: lead 2.3e-11 relative, offsets 1.2e-12 m, A 3e-13 m, rotation 3.8e-13 rad, the
  // tracker transform 1.0e-12 m at the points' centroid, residual rms 2.1e-13 m; bounds ~10x.
  const Model& nominal = seed_model();
  double lead = 0.0, offset = 0.0, observation = 0.0, rotation = 0.0, transfer = 0.0, rms = 0.0;
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    std::mt19937_64 rng(kSeed + 2000 + seed);
    const Truth truth = random_truth(nominal, rng);
    const std::vector<Observation> obs = observe(nominal, truth, calibration_poses(200, rng), 0.0, rng);
    const Identification id = identified(obs);
    EXPECT_EQ(id.estimate.twist_sign, truth.p.twist_sign);
    const Errors e = errors_of(id.estimate, truth.p, obs);
    lead = std::max(lead, e.lead_relative);
    offset = std::max(offset, e.offset);
    observation = std::max(observation, e.observation);
    rotation = std::max(rotation, e.rotation);
    transfer = std::max(transfer, e.transfer);
    rms = std::max(rms, id.rms_after);
  }
  report("residual rms [m]", rms);
  report("relative lead error", lead);
  report("offset error [m]", offset);
  report("A error [m]", observation);
  report("rotation error [rad]", rotation);
  report("transfer error [m]", transfer);
  EXPECT_LT(lead, 3e-10);
  EXPECT_LT(offset, 1.5e-11);
  EXPECT_LT(observation, 3e-12);
  EXPECT_LT(rotation, 4e-12);
  EXPECT_LT(transfer, 1e-11);
  EXPECT_LT(rms, 3e-12);
}

TEST(Identification, JacobianMatchesCentralDifferences) {
  // The implicit-function Jacobian against central differences of the residuals, at a candidate
  // away from the truth, for both signs and both lead models. Step 1e-7 (m or rad); the forward kinematics converges to
  // 1e-14 m here so that its stopping point does not show in the differences. Measured worst difference 4.4e-8 of the
  // column's largest entry.
  const Model& nominal = seed_model();
  std::mt19937_64 rng(kSeed + 3000);
  const Truth truth = random_truth(nominal, rng);
  std::vector<Observation> obs = observe(nominal, truth, calibration_poses(30, rng), kTrackerNoise, rng);
  IdentificationOptions options;
  options.fk.tolerance = 1e-14;
  double worst = 0.0;
  for (const LeadEffect effect : {LeadEffect::TwistOnly, LeadEffect::TwistAndTravel}) {
    options.lead_effect = effect;
    for (const double sign : {1.0, -1.0}) {
      PlatformParameters p = truth.p;
      p.twist_sign = sign;
      p.lead = 0.8 * truth.p.lead;
      for (int i = 0; i < kLegs; ++i) p.length_offset[i] += uniform(rng, -1e-3, 1e-3);
      p.observation_P += Vector3d(2e-3, -3e-3, 1e-3);
      p.X_BT.R = exp_so3(Vector3d(0.01, -0.02, 0.03)) * p.X_BT.R;
      Eigen::VectorXd e, ep, em;
      Eigen::MatrixXd J, unused;
      ASSERT_EQ(identification_residuals(nominal, obs, p, options, e, &J), Status::Ok);
      for (int j = 0; j < kIdentifiedParameters; ++j) {
        constexpr double h = 1e-7;
        const auto moved = [&](double step) {
          PlatformParameters q = p;
          if (j == kLeadIndex)
            q.lead += step;
          else if (j < kObservationIndex)
            q.length_offset[j - kOffsetIndex] += step;
          else if (j < kRotationIndex)
            q.observation_P[j - kObservationIndex] += step;
          else if (j < kTranslationIndex)
            q.X_BT.R = exp_so3(step * Vector3d::Unit(j - kRotationIndex)) * q.X_BT.R;
          else
            q.X_BT.t[j - kTranslationIndex] += step;
          return q;
        };
        ASSERT_EQ(identification_residuals(nominal, obs, moved(h), options, ep, nullptr), Status::Ok);
        ASSERT_EQ(identification_residuals(nominal, obs, moved(-h), options, em, nullptr), Status::Ok);
        const Eigen::VectorXd fd = (ep - em) / (2 * h);
        const double scale = J.col(j).cwiseAbs().maxCoeff();
        ASSERT_GT(scale, 0.0) << parameter_name(j);
        const double diff = (fd - J.col(j)).cwiseAbs().maxCoeff() / scale;
        worst = std::max(worst, diff);
        EXPECT_LT(diff, 5e-7) << parameter_name(j) << " sign " << sign << " travel "
                              << (effect == LeadEffect::TwistAndTravel);
      }
    }
  }
  report("relative Jacobian difference", worst);
}

TEST(Identification, DegenerateDataAreReportedNotSolved) {
  const Model& nominal = seed_model();
  std::mt19937_64 rng(kSeed + 4000);
  const Truth truth = random_truth(nominal, rng);
  Identification id;

  // Every point at one pose: the tracker frame cannot even be registered.
  const std::vector<Observation> home = observe(nominal, truth, std::vector<Pose>(50, Pose{}), kTrackerNoise, rng);
  EXPECT_EQ(identify(nominal, home, id), Status::NotIdentifiable);
  EXPECT_NE(id.reason.find("registration"), std::string::npos) << id.reason;

  // Translations only (the paper's Lz and Lx tests): the platform never turns, so A and the
  // tracker's translation enter only as their difference: three combinations, named.
  std::vector<Pose> translations = paper_poses(0.1, 0);
  const std::vector<Pose> lx = paper_poses(0.1, 1);
  translations.insert(translations.end(), lx.begin(), lx.end());
  EXPECT_EQ(identify(nominal, observe(nominal, truth, translations, kTrackerNoise, rng), id), Status::NotIdentifiable);
  std::printf("  translations only: %s\n", id.reason.c_str());
  EXPECT_NE(id.reason.find("3 combinations"), std::string::npos) << id.reason;
  for (const char* name : {"A x", "A y", "A z", "translation x", "translation y", "translation z"})
    EXPECT_NE(id.reason.find(name), std::string::npos) << name << ": " << id.reason;
  EXPECT_GT(id.condition, 1e12);

  // Too few points for 16 parameters; a NaN; a leg whose twist is undefined.
  std::vector<Observation> few(home.begin(), home.begin() + 5);
  EXPECT_EQ(identify(nominal, few, id), Status::NotIdentifiable);
  EXPECT_NE(id.reason.find("at least 6"), std::string::npos) << id.reason;
  std::vector<Observation> bad = home;
  bad[7].p_T.y() = std::nan("");
  EXPECT_EQ(identify(nominal, bad, id), Status::NonFiniteInput);
  EXPECT_NE(id.reason.find("observation 8"), std::string::npos) << id.reason;
  ModelSpec no_axes = nominal.spec();
  for (LegSpec& leg : no_axes.legs) leg.lead = 0.0;
  no_axes.legs[2].axis_base_B.setZero();
  no_axes.legs[2].axis_platform_P.setZero();
  EXPECT_EQ(identify(Model(no_axes), home, id), Status::NotIdentifiable);
  EXPECT_NE(id.reason.find("leg 3"), std::string::npos) << id.reason;
}

TEST(Identification, EachPaperTestAloneLeavesParametersFreeAndAllFourLeaveTheOffsetsWeak) {
  // Identifiability of the paper's motions (theory §13): each test moves the platform along one
  // coordinate. Lz and Lx move A along a line, which does not even register the tracker; Rz
  // turns about z and Ry about y, which leave A's coordinate along that axis indistinguishable
  // from the tracker's translation along it. The four together determine everything, but the
  // offsets only loosely: measured sd 29-107 um at 516 points, against 6-10 um for as many
  // random poses.
  const Model& nominal = seed_model();
  std::mt19937_64 rng(kSeed + 5000);
  const Truth truth = random_truth(nominal, rng);
  const std::array<std::vector<std::string>, 4> confounded{
      {{"registration"}, {"registration"}, {"A z", "translation z"}, {"A y", "translation y"}}};
  Identification id;
  for (int test = 0; test < 4; ++test) {
    const auto obs = observe(nominal, truth, paper_poses(0.1, test), kTrackerNoise, rng);
    EXPECT_EQ(identify(nominal, obs, id), Status::NotIdentifiable) << test;
    std::printf("  %s alone: %s\n", seed_tests(StudySpec{})[static_cast<std::size_t>(test)].name.c_str(),
                id.reason.c_str());
    for (const std::string& name : confounded[static_cast<std::size_t>(test)])
      EXPECT_NE(id.reason.find(name), std::string::npos) << name << ": " << id.reason;
  }
  const auto paper = observe(nominal, truth, paper_poses(0.1), kTrackerNoise, rng);
  const Identification all = identified(paper);
  EXPECT_EQ(all.estimate.twist_sign, truth.p.twist_sign);
  const auto random = observe(nominal, truth, calibration_poses(all.count, rng), kTrackerNoise, rng);
  const Identification spread = identified(random);
  std::printf("  all four tests (%d points): condition %.3g, lead sd %.3g %%, offset sd %.3g-%.3g um\n", all.count,
              all.condition, 100 * all.sd[kLeadIndex] / truth.p.lead, 1e6 * all.sd.segment<6>(kOffsetIndex).minCoeff(),
              1e6 * all.sd.segment<6>(kOffsetIndex).maxCoeff());
  std::printf("  random poses (%d points): condition %.3g, lead sd %.3g %%, offset sd %.3g-%.3g um\n", spread.count,
              spread.condition, 100 * spread.sd[kLeadIndex] / truth.p.lead,
              1e6 * spread.sd.segment<6>(kOffsetIndex).minCoeff(), 1e6 * spread.sd.segment<6>(kOffsetIndex).maxCoeff());
  std::printf("  paper tests' least-determined combination (column-scaled):");
  for (int j = 0; j < kIdentifiedParameters; ++j)
    if (std::abs(all.weakest[j]) >= 0.1)
      std::printf(" %+.2f %s", all.weakest[j], std::string(parameter_name(j)).c_str());
  std::printf("\n  sign cost ratio: paper tests %.3g, random poses %.3g\n", all.cost_ratio, spread.cost_ratio);
  EXPECT_GT(all.sd.segment<6>(kOffsetIndex).maxCoeff(), 5 * spread.sd.segment<6>(kOffsetIndex).maxCoeff());
}

TEST(Identification, TravelModelOfTheLeadIsRecoveredAndTheTwistOnlyModelDoesNotFitIt) {
  // Drives that convert lengths to angles with the nominal lead move the legs by lead/nominal
  // times the commanded travel: 5 % of up to 0.5 m. The travel model recovers every parameter
  // within 4 of its reported sd, the lead to about a part per million; the twist-only model
  // cannot explain such data, and its sigma says so (measured 8.8 mm, 900 times the tracker's).
  const Model& nominal = seed_model();
  std::mt19937_64 rng(kSeed + 6000);
  const Truth truth = random_truth(nominal, rng);
  const auto obs = observe(nominal, truth, calibration_poses(500, rng), kTrackerNoise, rng, LeadEffect::TwistAndTravel);
  IdentificationOptions travel;
  travel.lead_effect = LeadEffect::TwistAndTravel;
  const Identification id = identified(obs, travel);
  const Errors e = errors_of(id.estimate, truth.p, obs);
  std::printf("  travel model: lead error %.3g (sd %.3g) relative, offsets %.3g um, sigma %.3g um, cost ratio %.3g\n",
              e.lead_relative, id.sd[kLeadIndex] / truth.p.lead, 1e6 * e.offset, 1e6 * id.sigma, id.cost_ratio);
  EXPECT_EQ(id.estimate.twist_sign, truth.p.twist_sign);
  const ParameterVector z = parameter_error(id.estimate, truth.p).cwiseQuotient(id.sd);
  for (int j = 0; j < kIdentifiedParameters; ++j) EXPECT_LT(std::abs(z[j]), 4.0) << parameter_name(j);
  EXPECT_LT(id.sd[kLeadIndex], 1e-5 * truth.p.lead);
  EXPECT_NEAR(id.sigma, kTrackerNoise, 0.1 * kTrackerNoise);
  EXPECT_GT(id.cost_ratio, 100.0);

  Identification twist_only;
  const Status s = identify(nominal, obs, twist_only);
  std::printf("  twist-only model on the same data: %s, sigma %.3g mm\n", std::string(to_string(s)).c_str(),
              1e3 * twist_only.sigma);
  EXPECT_GT(twist_only.sigma, 100 * kTrackerNoise);
}

TEST(Identification, CorrectedModelPutsTheRealPlatformOnTarget) {
  // The point of it all: the corrected model's compensated commands, sent to the real platform,
  // put A where it was commanded. Measured on 200 random poses: 11 um at worst, against 3.9 mm
  // with the nominal model. The corrected model carries the estimate in its own fields.
  const Model& nominal = seed_model();
  std::mt19937_64 rng(kSeed + 7000);
  const Truth truth = random_truth(nominal, rng);
  const auto obs = observe(nominal, truth, calibration_poses(2000, rng), kTrackerNoise, rng);
  const Identification id = identified(obs);
  const ModelSpec spec = corrected_spec(nominal.spec(), id.estimate);
  const Model corrected(spec);
  for (int i = 0; i < kLegs; ++i) {
    EXPECT_EQ(corrected.leg(i).lead, id.estimate.lead);
    EXPECT_EQ(corrected.leg(i).twist_sign, id.estimate.twist_sign);
    EXPECT_EQ(corrected.leg(i).length_offset, id.estimate.length_offset[i]);
    EXPECT_EQ(corrected.leg(i).driven, nominal.leg(i).driven);
  }
  EXPECT_EQ(spec.observation_P, id.estimate.observation_P);

  const Model real(truth.spec);
  double worst_corrected = 0.0, worst_nominal = 0.0;
  for (int n = 0; n < 200; ++n) {
    // A pose inside the limits of both models (the corrected commands differ by the offsets).
    Pose pose = random_valid_pose(corrected, rng, 0.5, deg2rad(30));
    for (CommandReport r; compute_commands(nominal, pose, r) != Status::Ok;)
      pose = random_valid_pose(corrected, rng, 0.5, deg2rad(30));
    const Vector3d target = platform_point_B(real, placement_from_pose(pose), truth.p.observation_P);
    for (const Model* model : {&corrected, &nominal}) {
      Vector6d command;
      LimitReport limit;
      ASSERT_EQ(motor_commands(*model, pose, Strategy::Compensated, command, limit), Status::Ok) << str(pose);
      FkResult fk;
      ASSERT_EQ(forward_kinematics(real, command, LengthKind::Motor, placement_from_pose(pose), fk), Status::Ok);
      const double miss = (platform_point_B(real, fk.placement, truth.p.observation_P) - target).norm();
      (model == &corrected ? worst_corrected : worst_nominal) =
          std::max(model == &corrected ? worst_corrected : worst_nominal, miss);
    }
  }
  report("miss of A with the corrected model [m]", worst_corrected);
  report("miss of A with the nominal model [m]", worst_nominal);
  EXPECT_LT(worst_corrected, 100e-6);
  EXPECT_GT(worst_nominal, 100 * worst_corrected);
}

}  // namespace
}  // namespace hexatwist::test
