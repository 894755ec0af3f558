// SPDX-License-Identifier: BSD-3-Clause
// Tolerance analysis (tolerance.hpp, docs/theory/design.md §18): the linearised answer against the
// Monte Carlo (the 10 %), the linear model against FK of one platform, chunks and threads
// bit for bit, a perfect calibration, the norm of a Gaussian against closed forms and sampling, the
// histogram's quantiles and the sampled errors' statistics.
#include "hexatwist/design/tolerance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "design/design_support.hpp"
#include "hexatwist/design/required_workspace.hpp"

namespace hexatwist {
namespace {

std::vector<Pose> workspace(int random) { return test::required_poses(random); }

TEST(Tolerance, LinearisedAndMonteCarloMediansAndNinetyFifthPercentilesAgreeToTenPercent) {
  const Model& seed = test::seed_model();
  const std::vector<Pose> poses = workspace(200);
  ToleranceOptions o;
  o.threads = 0;
  ToleranceLinear lin;
  ASSERT_EQ(tolerance_linear(seed, poses, o.sigmas, lin, 0), Status::Ok);
  ToleranceChunk c;
  ASSERT_EQ(tolerance_chunk(seed, poses, o, 0, 1000, c, &lin), Status::Ok);
  const ToleranceSummary s = summarize_tolerance(c, poses.size(), &lin, 0);
  EXPECT_EQ(s.failures, 0u);
  const auto check = [](const char* what, const ErrorQuantiles& mc, const ErrorQuantiles& linear) {
    SCOPED_TRACE(what);
    test::report((std::string(what) + " median, Monte Carlo / linearised - 1").c_str(), mc.median / linear.median - 1);
    test::report((std::string(what) + " p95, Monte Carlo / linearised - 1").c_str(), mc.p95 / linear.p95 - 1);
    EXPECT_NEAR(mc.median / linear.median, 1.0, 0.10);
    EXPECT_NEAR(mc.p95 / linear.p95, 1.0, 0.10);
  };
  check("point", s.point, s.point_linear);
  check("position", s.position, s.position_linear);
  check("orientation", s.orientation, s.orientation_linear);
  // The same errors through the linear model: the worst point error per platform to 0.5 %.
  test::report("worst point error, Monte Carlo / linear model - 1", s.worst_point.p95 / s.worst_point_linear.p95 - 1);
  EXPECT_NEAR(s.worst_point.median / s.worst_point_linear.median, 1.0, 0.005);
  EXPECT_NEAR(s.worst_point.p95 / s.worst_point_linear.p95, 1.0, 0.005);
  // Joint errors of 50 um on 2 m legs: point errors of a few tenths of a millimetre.
  EXPECT_GT(s.point.median, 50e-6);
  EXPECT_LT(s.point.median, 1e-3);
}

TEST(Tolerance, TheLinearModelPredictsOnePlatformsPoseErrorToSecondOrder) {
  const Model& seed = test::seed_model();
  const std::vector<Pose> poses = workspace(20);
  ToleranceSigmas sigmas;
  ToleranceLinear lin;
  ASSERT_EQ(tolerance_linear(seed, poses, sigmas, lin), Status::Ok);
  double worst = 0.0;
  for (const double scale : {1.0, 0.1}) {
    const PlatformErrors e = scale * sample_errors(seed, sigmas, 7, 3);
    const Model real(real_platform(seed, e));
    worst = 0.0;
    double largest = 0.0;
    for (std::size_t k = 0; k < poses.size(); ++k) {
      Vector6d m;
      LimitReport r;
      ASSERT_EQ(motor_commands(seed, poses[k], Strategy::Compensated, m, r), Status::Ok);
      FkResult fk;
      const Placement x = placement_from_pose(poses[k]);
      ASSERT_EQ(forward_kinematics(real, m, LengthKind::Motor, x, fk), Status::Ok);
      const Vector3d a = seed.spec().observation_P;
      const Vector3d moved = platform_point_B(seed, fk.placement, a) - platform_point_B(seed, x, a);
      worst = std::max(worst, (moved - lin.point[k] * e).norm());
      largest = std::max(largest, moved.norm());
    }
    test::report("largest |nonlinear - linear| / largest error", worst / largest);
    // The remainder is second order: a tenth of the errors leaves a hundredth of it.
    EXPECT_LT(worst, (scale == 1.0 ? 1e-2 : 1e-3) * largest);
  }
}

TEST(Tolerance, ChunksAndThreadsGiveTheWholeStudyBitForBit) {
  const Model& seed = test::seed_model();
  const std::vector<Pose> poses = workspace(30);
  ToleranceOptions o;
  ToleranceLinear lin;
  ASSERT_EQ(tolerance_linear(seed, poses, o.sigmas, lin), Status::Ok);
  ToleranceChunk whole, parts, a, b;
  ASSERT_EQ(tolerance_chunk(seed, poses, o, 0, 40, whole, &lin), Status::Ok);
  o.threads = 3;
  ASSERT_EQ(tolerance_chunk(seed, poses, o, 0, 17, a, &lin), Status::Ok);
  ASSERT_EQ(tolerance_chunk(seed, poses, o, 17, 23, b, &lin), Status::Ok);
  append_chunk(parts, a);
  append_chunk(parts, b);
  EXPECT_EQ(parts.max_point, whole.max_point);
  EXPECT_EQ(parts.rms_point, whole.rms_point);
  EXPECT_EQ(parts.max_orientation, whole.max_orientation);
  EXPECT_EQ(parts.max_point_linear, whole.max_point_linear);
  EXPECT_EQ(parts.point.counts, whole.point.counts);
  EXPECT_EQ(parts.orientation.counts, whole.orientation.counts);
  EXPECT_EQ(parts.point.total(), 40 * poses.size());
  // Another seed, other platforms.
  o.seed = 2;
  ToleranceChunk other;
  ASSERT_EQ(tolerance_chunk(seed, poses, o, 0, 40, other, &lin), Status::Ok);
  EXPECT_NE(other.max_point, whole.max_point);
}

TEST(Tolerance, APerfectCalibrationLeavesNoError) {
  // The hook a calibration plugs into: a controller that runs the real platform's own model.
  const Model& seed = test::seed_model();
  const std::vector<Pose> poses = workspace(30);
  ToleranceOptions o;
  o.linear_worst = false;
  std::atomic<int> calls{0};
  const CalibrationStep perfect = perfect_calibration_step();
  o.calibration = [&](const Model& nominal, const Model& real, std::uint64_t index, CalibratedController& controller) {
    ++calls;
    return perfect(nominal, real, index, controller);
  };
  ToleranceChunk c;
  ASSERT_EQ(tolerance_chunk(seed, poses, o, 0, 20, c), Status::Ok);
  EXPECT_EQ(calls, 20);
  for (std::size_t k = 0; k < c.size(); ++k) EXPECT_LT(c.max_point[k], 1e-11);
  // A calibration that fails counts every pose of its platform as failed.
  o.calibration = [](const Model&, const Model&, std::uint64_t index, CalibratedController&) {
    return index == 3 ? Status::NotIdentifiable : Status::Ok;
  };
  ASSERT_EQ(tolerance_chunk(seed, poses, o, 0, 5, c), Status::Ok);
  EXPECT_EQ(c.failures[3], poses.size());
  EXPECT_TRUE(std::isnan(c.max_point[3]));
  EXPECT_EQ(c.failures[2], 0u);
}

TEST(Tolerance, SampledErrorsHaveTheirStandardDeviationsAndAreTheSameForTheSameIndex) {
  const Model& seed = test::seed_model();
  ToleranceSigmas s;
  const PlatformErrors sd = error_sigmas(seed, s);
  EXPECT_EQ(sample_errors(seed, s, 1, 12345), sample_errors(seed, s, 1, 12345));
  EXPECT_NE(sample_errors(seed, s, 1, 12345), sample_errors(seed, s, 1, 12346));
  const int n = 20000;
  PlatformErrors sum = PlatformErrors::Zero(), sum2 = PlatformErrors::Zero();
  for (int k = 0; k < n; ++k) {
    const PlatformErrors e = sample_errors(seed, s, 3, static_cast<std::uint64_t>(k)).cwiseQuotient(sd);
    sum += e;
    sum2 += e.cwiseProduct(e);
  }
  for (int j = 0; j < kPlatformErrors; ++j) {
    EXPECT_NEAR(sum[j] / n, 0.0, 4.0 / std::sqrt(n));
    EXPECT_NEAR(std::sqrt(sum2[j] / n), 1.0, 4.0 / std::sqrt(2.0 * n));
  }
}

TEST(Tolerance, ARealPlatformWithoutErrorsIsTheNominalOne) {
  const Model& seed = test::seed_model();
  const Model real(real_platform(seed, PlatformErrors::Zero()));
  std::mt19937_64 rng(test::kSeed);
  for (int k = 0; k < 50; ++k) {
    const Pose p = test::random_valid_pose(seed, rng, 0.2, 0.2);
    Vector6d m;
    LimitReport r;
    ASSERT_EQ(motor_commands(seed, p, Strategy::Compensated, m, r), Status::Ok);
    FkResult fk;
    ASSERT_EQ(forward_kinematics(real, m, LengthKind::Motor, Placement{}, fk), Status::Ok);
    EXPECT_LT(test::pose_error(fk.placement, placement_from_pose(p)).position, 1e-11);
  }
  // A joint moved by 1 mm moves that joint and nothing else.
  PlatformErrors e = PlatformErrors::Zero();
  e[kLegErrors * 2 + 1] = 1e-3;
  const ModelSpec moved = real_platform(seed, e);
  EXPECT_NEAR((moved.legs[2].base_B - seed.spec().legs[2].base_B - Vector3d(0, 1e-3, 0)).norm(), 0.0, 1e-15);
  EXPECT_EQ(moved.legs[1].base_B, seed.spec().legs[1].base_B);
}

TEST(GaussianNorm, MatchesTheChiDistributionTheNormalAndSampling) {
  // Isotropic: |z| / sigma is chi with 3 degrees of freedom.
  const double sigma = 0.3;
  for (const double r : {0.1, 0.3, 0.6, 1.0}) {
    const double x = r / sigma;
    const double chi3 = std::erf(x / std::sqrt(2.0)) - std::sqrt(2.0 / kPi) * x * std::exp(-0.5 * x * x);
    EXPECT_NEAR(gaussian_norm_cdf(sigma * sigma * Matrix3d::Identity(), r), chi3, 1e-9);
  }
  // One direction only: |z| is the half-normal.
  const Vector3d u = Vector3d(1, 2, -1).normalized();
  const Matrix3d line = 0.04 * u * u.transpose();
  for (const double r : {0.05, 0.2, 0.5})
    EXPECT_NEAR(gaussian_norm_cdf(line, r), std::erf(r / (0.2 * std::sqrt(2.0))), 1e-9);
  // Anisotropic, against sampling.
  std::mt19937_64 rng(test::kSeed);
  std::normal_distribution<double> normal;
  Matrix3d L;
  L << 1.0, 0, 0, 0.4, 0.3, 0, -0.2, 0.1, 0.05;
  const Matrix3d C = L * L.transpose();
  std::vector<double> norms(400'000);
  for (double& v : norms) v = (L * Vector3d(normal(rng), normal(rng), normal(rng))).norm();
  std::sort(norms.begin(), norms.end());
  for (const double q : {0.05, 0.5, 0.95}) {
    const double r = norms[static_cast<std::size_t>(q * norms.size())];
    EXPECT_NEAR(gaussian_norm_cdf(C, r), q, 4.0 * std::sqrt(q * (1 - q) / norms.size()));
  }
  EXPECT_NEAR(gaussian_norm_mixture_quantile({C}, 0.5), norms[norms.size() / 2], 0.01 * norms[norms.size() / 2]);
  // A mixture of two scales: the quantile solves the mean of the two CDFs.
  const std::vector<Matrix3d> two{0.01 * Matrix3d::Identity(), 0.09 * Matrix3d::Identity()};
  const double r = gaussian_norm_mixture_quantile(two, 0.7);
  EXPECT_NEAR(0.5 * (gaussian_norm_cdf(two[0], r) + gaussian_norm_cdf(two[1], r)), 0.7, 1e-9);
}

TEST(ErrorHistogram, QuantilesAgreeWithTheSortedValuesToTheBinWidth) {
  std::mt19937_64 rng(test::kSeed);
  std::lognormal_distribution<double> d(std::log(1e-4), 1.0);
  ErrorHistogram h;
  std::vector<double> v(100'000);
  for (double& x : v) h.add(x = d(rng));
  std::sort(v.begin(), v.end());
  for (const double q : {0.05, 0.5, 0.95, 0.999}) {
    const double exact = v[static_cast<std::size_t>(q * v.size())];
    EXPECT_NEAR(h.quantile(q) / exact, 1.0, 0.012);  // 200 bins a decade: 1.16 % wide
  }
  EXPECT_EQ(h.total(), v.size());
  ErrorHistogram zero;
  zero.add(0.0);
  EXPECT_EQ(zero.quantile(0.5), 0.0);
  EXPECT_TRUE(std::isnan(ErrorHistogram{}.quantile(0.5)));
}

}  // namespace
}  // namespace hexatwist
