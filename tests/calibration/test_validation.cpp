// SPDX-License-Identifier: BSD-3-Clause
// Checking a calibration (validation.hpp): the differences leg by leg against what was changed, and
// the accuracy of one platform's commands on another against cases with a known answer: the same
// platform (nothing), a base moved as a whole (every point off by the move in the gauge frames,
// nothing after the re-alignment), and a platform with joint errors (the re-alignment helps, the
// points' order does not matter).
#include "support.hpp"

namespace hexatwist::test {
namespace {

std::vector<Vector6d> stations(const Model& model, int count, std::uint64_t seed) {
  StationsSpec spec;
  spec.count = count;
  spec.seed = seed;
  return random_stations(model, Strategy::Compensated, spec);
}

TEST(Validation, TheDifferencesAreWhatWasChanged) {
  ModelSpec spec = seed_model().spec();
  spec.legs[2].base_B += Vector3d(1e-3, -2e-3, 0.5e-3);
  spec.legs[4].platform_P += Vector3d(0.0, 3e-3, 0.0);
  spec.legs[1].length_offset += 0.25e-3;
  spec.legs[5].lead *= 1.02;
  spec.legs[0].play = 40e-6;
  spec.observation_P += Vector3d(2e-3, 0.0, 0.0);
  const Model changed(spec);
  const PlatformDifference same = compare_platforms(seed_model(), seed_model());
  EXPECT_EQ(same.largest_joint, 0.0);
  EXPECT_EQ(same.observation, Vector3d::Zero());
  const PlatformDifference d = compare_platforms(seed_model(), changed);
  EXPECT_NEAR((d.legs[2].base - Vector3d(1e-3, -2e-3, 0.5e-3)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((d.legs[4].platform - Vector3d(0.0, 3e-3, 0.0)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(d.legs[1].length_offset, 0.25e-3, 1e-15);
  EXPECT_NEAR(d.legs[5].lead, 0.02 * seed_model().leg(5).lead, 1e-15);
  EXPECT_EQ(d.legs[0].play, 40e-6);
  EXPECT_NEAR(d.observation.x(), 2e-3, 1e-15);
  EXPECT_EQ(d.largest_joint_leg, 4);
  EXPECT_TRUE(d.largest_on_platform);
  EXPECT_NEAR(d.largest_joint, 3e-3, 1e-15);
  for (int i : {0, 1, 3}) EXPECT_EQ(d.legs[static_cast<std::size_t>(i)].base, Vector3d::Zero()) << i;
}

TEST(Validation, APlatformCommandsItselfExactly) {
  CommandAccuracy a;
  ASSERT_EQ(command_accuracy(seed_model(), seed_model(), stations(seed_model(), 30, 5), a), Status::Ok);
  ASSERT_EQ(a.gauge.size(), 30u);
  report("self, largest [m]", a.gauge_max);
  EXPECT_LT(a.gauge_max, 1e-14);
  EXPECT_LT(a.aligned_max, 1e-14);
}

TEST(Validation, ABaseMovedAsAWholeMissesByTheMoveUntilReAligned) {
  // The whole platform raised by v, its base joints and its home with it (the legs' lengths,
  // twists and the drives' references unchanged): its point A stands v away at every pose, which
  // the rigid re-alignment takes out. (Moving the base joints alone would move the home the
  // drives' and twists' references are taken at.)
  const Vector3d v(0.0, 0.0, 0.8e-3);
  ModelSpec spec = seed_model().spec();
  for (LegSpec& leg : spec.legs) leg.base_B += v;
  spec.home_height += v.z();
  const Model moved(spec);
  CommandAccuracy a;
  ASSERT_EQ(command_accuracy(seed_model(), moved, stations(seed_model(), 40, 6), a), Status::Ok);
  report("moved base: gauge spread [m]", a.gauge_max - a.gauge.front());
  report("moved base: aligned, largest [m]", a.aligned_max);
  EXPECT_NEAR(a.gauge.front(), v.norm(), 1e-14);
  EXPECT_NEAR(a.gauge_max, v.norm(), 1e-14);
  EXPECT_LT(a.aligned_max, 1e-14);
  EXPECT_NEAR((a.alignment.t - v).norm(), 0.0, 1e-13) << "the re-alignment is the move";
}

TEST(Validation, JointErrorsMissInBothFramesAndTheOrderOfThePosesDoesNotMatter) {
  std::mt19937_64 rng(kSeed + 71);
  ModelSpec spec = seed_model().spec();
  for (LegSpec& leg : spec.legs) {
    leg.base_B += Vector3d(uniform(rng, -1e-3, 1e-3), uniform(rng, -1e-3, 1e-3), uniform(rng, -1e-3, 1e-3));
    leg.platform_P += Vector3d(uniform(rng, -1e-3, 1e-3), uniform(rng, -1e-3, 1e-3), uniform(rng, -1e-3, 1e-3));
  }
  const Model real(spec);
  std::vector<Vector6d> poses = stations(seed_model(), 40, 8);
  CommandAccuracy a, b;
  ASSERT_EQ(command_accuracy(seed_model(), real, poses, a), Status::Ok);
  std::reverse(poses.begin(), poses.end());
  ASSERT_EQ(command_accuracy(seed_model(), real, poses, b), Status::Ok);
  EXPECT_GT(a.gauge_median, 0.1e-3);
  EXPECT_LT(a.aligned_median, a.gauge_median);
  EXPECT_LE(a.gauge_median, a.gauge_max);
  for (std::size_t k = 0; k < a.gauge.size(); ++k) {
    EXPECT_NEAR(a.gauge[k], b.gauge[k], 1e-15);
    EXPECT_NEAR(a.aligned[k], b.aligned[k], 1e-12);
  }
  EXPECT_EQ(command_accuracy(seed_model(), real, std::span(poses).first(3), a), Status::InvalidArgument);
}

}  // namespace
}  // namespace hexatwist::test
