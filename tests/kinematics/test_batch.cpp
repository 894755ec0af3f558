// SPDX-License-Identifier: BSD-3-Clause
// Batches of poses across the lanes (batch.hpp): every pose's status, report and commands are the
// single-pose motor_commands' bit for bit, and the lengths inverse_kinematics', on the seed and on
// random asymmetric platforms, inside, far outside and on every limit (poses within a few ulp of
// the boundary), through a drive scale, at any batch size and with bad rows.
#include "support.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <vector>

namespace hexatwist::test {
namespace {

std::vector<double> rows_of(const std::vector<Pose>& poses) {
  std::vector<double> rows;
  for (const Pose& p : poses) {
    const Vector6d q = p.to_vector();
    rows.insert(rows.end(), q.data(), q.data() + 6);
  }
  return rows;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

// Compares the batch with motor_commands pose by pose: status, leg, value and bound, and the
// commands to the bit (NaN rows where refused). Returns the number of poses accepted.
long expect_batch_equals_single(const Model& model, const std::vector<Pose>& poses, Strategy strategy,
                                const char* what) {
  const std::vector<double> rows = rows_of(poses);
  std::vector<double> commands(rows.size(), -7.0);
  std::vector<LimitReport> reports(poses.size());
  EXPECT_EQ(motor_commands_batch(model, rows, strategy, commands, reports), Status::Ok);
  long ok = 0;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    Vector6d single = Vector6d::Constant(-7.0);
    LimitReport r;
    const Status s = motor_commands(model, poses[i], strategy, single, r);
    const LimitReport& b = reports[i];
    const auto where = [&] { return std::string(what) + " pose " + std::to_string(i) + " " + str(poses[i]); };
    EXPECT_EQ(b.status, s) << where();
    EXPECT_EQ(b.leg, r.leg) << where();
    EXPECT_TRUE(same_bits(b.value, r.value)) << where() << ": " << b.value << " against " << r.value;
    EXPECT_TRUE(same_bits(b.bound, r.bound)) << where();
    for (int k = 0; k < kLegs; ++k) {
      const double c = commands[6 * i + static_cast<std::size_t>(k)];
      if (s == Status::Ok)
        EXPECT_TRUE(same_bits(c, single[k])) << where() << " leg " << k + 1 << ": " << c << " against " << single[k];
      else
        EXPECT_TRUE(std::isnan(c)) << where() << " leg " << k + 1;
    }
    if (::testing::Test::HasFailure()) return ok;  // one failing pose says it all
    ok += s == Status::Ok;
  }
  return ok;
}

// Poses within a few ulp of the boundary of what motor_commands accepts: from a pose inside, a
// bisection along a random direction to the first limit met, then the poses at the last parameters
// on either side and their neighbours.
std::vector<Pose> poses_on_limits(const Model& model, std::mt19937_64& rng, int count, double dpos, double drot) {
  std::vector<Pose> out;
  const auto at = [](const Pose& p0, const Vector6d& d, double t) { return Pose::from_vector(p0.to_vector() + t * d); };
  const auto accepted = [&](const Pose& p) {
    Vector6d c;
    LimitReport r;
    return motor_commands(model, p, Strategy::Compensated, c, r) == Status::Ok;
  };
  while (static_cast<int>(out.size()) < count) {
    const Pose p0 = random_valid_pose(model, rng, dpos, drot);
    Vector6d d;
    for (int k = 0; k < 6; ++k) d[k] = uniform(rng, -1, 1) * (k < 3 ? 1.0 : 1.5);
    double in = 0.0, outside = 4.0;
    if (accepted(at(p0, d, outside))) continue;
    for (int it = 0; it < 200 && std::nextafter(in, outside) < outside; ++it) {
      const double mid = 0.5 * (in + outside);
      (accepted(at(p0, d, mid)) ? in : outside) = mid;
    }
    double t = in;
    for (int k = 0; k < 2; ++k) t = std::nextafter(t, 0.0);
    for (int k = 0; k < 6; ++k, t = std::nextafter(t, 10.0)) out.push_back(at(p0, d, t));
  }
  return out;
}

std::vector<Pose> random_poses(std::mt19937_64& rng, int count, double dpos, double drot) {
  std::vector<Pose> out;
  for (int i = 0; i < count; ++i) out.push_back(random_pose(rng, dpos, drot));
  return out;
}

std::vector<Pose> poses_around_yaw_90(std::mt19937_64& rng, int count) {
  std::vector<Pose> out;
  for (int i = 0; i < count; ++i) {
    Pose p = random_pose(rng, 0.05, deg2rad(3));
    p.rpy[2] = (uniform(rng, -1, 1) < 0 ? -1 : 1) * deg2rad(90 + 15 * uniform(rng, -1, 1));
    out.push_back(p);
  }
  return out;
}

TEST(Batch, CommandsEqualTheSinglePosePathBitForBitOnTheSeed) {
  std::mt19937_64 rng(kSeed + 501);
  const Model wide = seed_with_wide_limits();
  long ok = 0, n = 0;
  for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional}) {
    const std::vector<Pose> inside = random_poses(rng, stress(10000), 0.5, deg2rad(30));
    const std::vector<Pose> far = random_poses(rng, stress(5000), 1.5, kPi);
    const std::vector<Pose> edge = poses_on_limits(seed_model(), rng, stress(4000), 0.4, deg2rad(25));
    const std::vector<Pose> yaw90 = poses_around_yaw_90(rng, stress(6000));
    const std::vector<Pose> yaw90_edge = poses_on_limits(wide, rng, stress(2000), 0.05, deg2rad(3));
    ok += expect_batch_equals_single(seed_model(), inside, strategy, "inside");
    ok += expect_batch_equals_single(seed_model(), far, strategy, "far");
    ok += expect_batch_equals_single(seed_model(), edge, strategy, "on a limit");
    ok += expect_batch_equals_single(wide, yaw90, strategy, "near yaw 90");
    ok += expect_batch_equals_single(wide, yaw90_edge, strategy, "on a limit, wide");
    n += static_cast<long>(inside.size() + far.size() + edge.size() + yaw90.size() + yaw90_edge.size());
  }
  std::printf("  %ld poses, %ld accepted\n", n, ok);
  EXPECT_GT(ok, n / 4);
  EXPECT_LT(ok, 3 * n / 4);
}

TEST(Batch, CommandsEqualTheSinglePosePathOnRandomAsymmetricPlatforms) {
  // Tilted axes, either thread hand and driven side, leads up to 0.2 m (the twist's share of the
  // condition proof matters), a leg without axes, the condition limit near the home condition so
  // that it refuses many poses, and length offsets.
  std::mt19937_64 rng(kSeed + 502);
  long ok = 0, n = 0, singular = 0;
  for (int m = 0; m < 24; ++m) {
    ModelSpec spec = random_platform(rng).spec();
    if (m % 2 == 1)
      for (LegSpec& leg : spec.legs) leg.lead *= 10.0;
    if (m % 3 == 2) {
      spec.legs[4].axis_base_B.setZero();
      spec.legs[4].axis_platform_P.setZero();
      spec.legs[4].lead = 0.0;
    }
    for (LegSpec& leg : spec.legs) leg.length_offset = uniform(rng, -2e-3, 2e-3);
    LegState home;
    double home_condition = 0.0;
    {
      const Model plain(spec);
      ASSERT_EQ(inverse_kinematics(plain, Placement{}, home), Status::Ok);
      ASSERT_EQ(jacobian_condition(plain, home, home_condition), Status::Ok);
    }
    spec.limits.jacobian_condition_max = 1.3 * home_condition;
    const Model model(spec);
    std::vector<Pose> poses = random_poses(rng, stress(1000), 0.3, deg2rad(25));
    const std::vector<Pose> edge = poses_on_limits(model, rng, stress(300), 0.2, deg2rad(15));
    poses.insert(poses.end(), edge.begin(), edge.end());
    for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional}) {
      ok += expect_batch_equals_single(model, poses, strategy, ("platform " + std::to_string(m)).c_str());
      n += static_cast<long>(poses.size());
      if (HasFailure()) return;
    }
    std::vector<double> c(6 * poses.size());
    std::vector<LimitReport> r(poses.size());
    ASSERT_EQ(motor_commands_batch(model, rows_of(poses), Strategy::Compensated, c, r), Status::Ok);
    for (const LimitReport& x : r) singular += x.status == Status::PlatformSingularity;
  }
  std::printf("  %ld poses on 24 platforms, %ld accepted, %ld refused for the platform singularity\n", n, ok, singular);
  EXPECT_GT(ok, n / 5);
  EXPECT_GT(singular, n / 40);
}

TEST(Batch, CommandsThroughADriveScaleEqualTheSinglePosePath) {
  // Drives with a lead 2.5 % off the real one and their own homing reference (theory §4): the
  // batch applies Model::motor_from_travel as motor_commands does.
  std::mt19937_64 rng(kSeed + 503);
  ModelSpec spec = seed_model().spec();
  const Model plain(spec);
  for (int i = 0; i < kLegs; ++i) {
    LegSpec& leg = spec.legs[static_cast<std::size_t>(i)];
    leg.drive_lead = leg.lead / 1.025;
    leg.home_command = plain.length_home()[i] + 1e-3 * (i - 2.5);
  }
  const Model driven(spec);
  ASSERT_TRUE(driven.has_drive_scale());
  std::vector<Pose> poses = random_poses(rng, stress(4000), 0.3, deg2rad(20));
  const std::vector<Pose> edge = poses_on_limits(driven, rng, stress(600), 0.4, deg2rad(25));
  poses.insert(poses.end(), edge.begin(), edge.end());
  long ok = 0;
  for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional})
    ok += expect_batch_equals_single(driven, poses, strategy, "drive scale");
  EXPECT_GT(ok, static_cast<long>(poses.size()) / 2);
  // The scale is applied: the same poses without it give other commands.
  std::vector<double> with(6 * poses.size()), without(6 * poses.size());
  std::vector<LimitReport> r(poses.size());
  ASSERT_EQ(motor_commands_batch(driven, rows_of(poses), Strategy::Compensated, with, r), Status::Ok);
  ASSERT_EQ(motor_commands_batch(plain, rows_of(poses), Strategy::Compensated, without, r), Status::Ok);
  ASSERT_EQ(r[0].status, Status::Ok);
  EXPECT_GT(std::abs(with[0] - without[0]), 1e-5);
}

TEST(Batch, CommandsOfLegsWithEffectsEqualTheSinglePosePathAndCarryThem) {
  // Stiff legs under the seed's load and play: the compensated batch is motor_commands pose by pose
  // (the static load's deflection at the pose, the play of the approach from home), not the rigid
  // legs' commands; the conventional one knows no effect.
  const Config config = load_config(
      std::string(seed_config_yaml()) + "\nleg_effects:\n  stiffness: 2.0e8\n  play: 50.0e-6\n", "effects.yaml");
  const Model& model = config.rig.model();
  ASSERT_TRUE(model.has_leg_effects());
  std::mt19937_64 rng(kSeed + 505);
  const std::vector<Pose> poses = random_poses(rng, stress(800), 0.3, deg2rad(20));
  long ok = 0;
  for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional})
    ok += expect_batch_equals_single(model, poses, strategy, "leg effects");
  EXPECT_GT(ok, static_cast<long>(poses.size()) / 2);
  std::vector<double> with(6 * poses.size()), rigid(6 * poses.size());
  std::vector<LimitReport> r(poses.size());
  ASSERT_EQ(motor_commands_batch(model, rows_of(poses), Strategy::Compensated, with, r), Status::Ok);
  ASSERT_EQ(motor_commands_batch(seed_model(), rows_of(poses), Strategy::Compensated, rigid, r), Status::Ok);
  double largest = 0.0;
  for (std::size_t k = 0; k < with.size(); ++k)
    if (std::isfinite(with[k]) && std::isfinite(rigid[k])) largest = std::max(largest, std::abs(with[k] - rigid[k]));
  report("largest difference to the rigid legs' commands [m]", largest);
  EXPECT_GT(largest, 1e-5);  // tens of micrometres of deflection and play
}

TEST(Batch, AnyBatchSizeAndBadRowsGiveThePosesOwnResults) {
  // Sizes around the packet width, rows of NaN and inf, angles beyond 1e5 rad (where sin and cos
  // fall back to libm) and a zero-length leg's neighbourhood are each the single pose's result.
  std::mt19937_64 rng(kSeed + 504);
  for (const std::size_t n : {0, 1, 2, 3, 5, 7, 8, 9, 15, 16, 17, 31}) {
    std::vector<Pose> poses = random_poses(rng, static_cast<int>(n), 0.3, deg2rad(20));
    if (n > 3) {
      poses[1].position.y() = NAN;
      poses[2].rpy.x() = INFINITY;
      poses[3].rpy.z() = 3e5;  // a valid yaw, reduced by libm in the single pose
    }
    for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional})
      expect_batch_equals_single(seed_model(), poses, strategy, ("batch of " + std::to_string(n)).c_str());
  }
  std::vector<double> rows(12, 0.0), commands(12);
  std::vector<LimitReport> two(2), three(3);
  EXPECT_EQ(motor_commands_batch(seed_model(), rows, Strategy::Compensated, commands, three), Status::MalformedInput);
  EXPECT_EQ(
      motor_commands_batch(seed_model(), std::span<const double>(rows).first(11), Strategy::Compensated, commands, two),
      Status::MalformedInput);
  std::vector<Status> s(3);
  EXPECT_EQ(leg_lengths_batch(seed_model(), rows, commands, s), Status::MalformedInput);
}

// A pose that puts leg 1's platform joint exactly on its base joint (a zero length): a
// translation t from home with (arm - base) + (pivot + t) = 0 in floating point (on the seed; a
// platform whose pivot height and joint heights differ in their last bits may have no such t).
Pose zero_length_pose(const Model& model) {
  Pose p;
  const Vector3d arm_minus_base = model.leg(0).arm_P - model.leg(0).base_B;  // R = I at home
  for (int c = 0; c < 3; ++c) {
    const double pivot = model.pivot_home_B()[c];
    double t = -arm_minus_base[c] - pivot;
    for (int k = 0; k < 8 && arm_minus_base[c] + (pivot + t) != 0.0; ++k)
      t = std::nextafter(t, arm_minus_base[c] + (pivot + t) > 0.0 ? -INFINITY : INFINITY);
    p.position[c] = t;
  }
  return p;
}

TEST(Batch, LengthsEqualInverseKinematicsBitForBit) {
  std::mt19937_64 rng(kSeed + 505);
  std::vector<std::unique_ptr<Model>> models;
  models.push_back(std::make_unique<Model>(seed_model().spec()));
  for (int m = 0; m < 6; ++m) models.push_back(std::make_unique<Model>(random_platform(rng).spec()));
  for (const auto& model : models) {
    std::vector<Pose> poses = random_poses(rng, stress(20000), 1.0, kPi);
    poses[5].position.x() = NAN;
    poses[6].rpy.y() = -2e5;
    poses[7] = zero_length_pose(*model);
    const std::vector<double> rows = rows_of(poses);
    std::vector<double> lengths(rows.size(), -7.0);
    std::vector<Status> status(poses.size());
    ASSERT_EQ(leg_lengths_batch(*model, rows, lengths, status), Status::Ok);
    for (std::size_t i = 0; i < poses.size(); ++i) {
      LegState legs;
      const Status s = inverse_kinematics(*model, poses[i], legs);
      ASSERT_EQ(status[i], s) << i << " " << str(poses[i]);
      for (int k = 0; k < kLegs; ++k) {
        const double l = lengths[6 * i + static_cast<std::size_t>(k)];
        if (s == Status::NonFiniteInput) {
          ASSERT_TRUE(std::isnan(l)) << i;
        } else {
          ASSERT_TRUE(same_bits(l, legs.length[k])) << i << " leg " << k + 1 << " " << l << " " << legs.length[k];
        }
      }
    }
    EXPECT_EQ(status[5], Status::NonFiniteInput);
    if (model == models.front()) {
      EXPECT_EQ(status[7], Status::StrokeBelowMin);
    }
  }
}

}  // namespace
}  // namespace hexatwist::test
