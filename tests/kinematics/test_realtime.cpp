// SPDX-License-Identifier: BSD-3-Clause
// The real-time functions never allocate (a counting global operator new) and are noexcept.
#include <atomic>
#include <cstdlib>
#include <new>

#include "hexatwist/dynamics/mechanism.hpp"
#include "hexatwist/io/config.hpp"
#include "support.hpp"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace hexatwist::test {
namespace {

static_assert(noexcept(inverse_kinematics(std::declval<const Model&>(), std::declval<const Pose&>(),
                                          std::declval<LegState&>())));
static_assert(noexcept(twist(std::declval<const Model&>(), std::declval<const LegState&>(),
                             std::declval<Vector6d&>())));
static_assert(noexcept(motor_commands(std::declval<const Model&>(), std::declval<const Pose&>(), Strategy::Compensated,
                                      std::declval<Vector6d&>(), std::declval<LimitReport&>())));
static_assert(noexcept(forward_kinematics(std::declval<const Model&>(), std::declval<const Vector6d&>(),
                                          LengthKind::Motor, std::declval<const Placement&>(),
                                          std::declval<FkResult&>())));
static_assert(noexcept(forward_kinematics_tracked(std::declval<const Model&>(), std::declval<const Vector6d&>(),
                                                  LengthKind::Motor, std::declval<FkTracker&>(),
                                                  std::declval<FkResult&>())));
static_assert(noexcept(jacobian_condition(std::declval<const Model&>(), std::declval<const LegState&>(),
                                          std::declval<double&>())));
static_assert(noexcept(check_limits(std::declval<const Model&>(), std::declval<const LegState&>(),
                                    std::declval<LimitReport&>())));

static_assert(noexcept(stream_line(std::declval<const Model&>(), std::declval<const StreamSettings&>(),
                                   std::string_view(), AngleUnit::Degrees, std::declval<StreamState&>(),
                                   std::declval<StreamOutput&>())));
static_assert(noexcept(inverse_dynamics(std::declval<const Rig&>(), std::declval<const PlatformMotion&>(),
                                        std::declval<InverseDynamics&>())));
static_assert(noexcept(forward_dynamics(std::declval<const Rig&>(), std::declval<const Placement&>(),
                                        std::declval<const Vector6d&>(), std::declval<const Vector6d&>(),
                                        std::declval<Vector6d&>())));
static_assert(noexcept(mechanism_mass_matrix(std::declval<const Rig&>(), std::declval<const Placement&>(),
                                             std::declval<Matrix6d&>())));
static_assert(noexcept(format_stream_output(std::declval<const StreamOutput&>(), StreamFormat::Json,
                                            std::span<char>())));

TEST(RealTime, CountingAllocatorSeesAllocations) {
  // The probe works: a heap allocation is counted (so the zero counts below mean something).
  const long before = g_allocations.load();
  auto* v = new std::vector<double>(100);
  delete v;
  EXPECT_GE(g_allocations.load() - before, 2);
}

TEST(RealTime, CommandsTwistLimitsConditionFkAndBatchesDoNotAllocate) {
  const Model& model = seed_model();
  std::mt19937_64 rng(kSeed + 60);
  std::vector<Pose> poses;
  for (int n = 0; n < 100; ++n) poses.push_back(random_valid_pose(model, rng, 0.5, deg2rad(30)));
  for (int n = 0; n < 100; ++n) poses.push_back(random_pose(rng, 0.8, deg2rad(40)));  // mostly outside limits
  LegState st;
  Vector6d v, cmd;
  Matrix6d J;
  LimitReport lim;
  CommandReport rep;
  FkResult fk;
  Placement previous;
  Vector6d bb, bp;
  FkTracker tracker;
  double condition;

  std::vector<double> rows, batch(6 * poses.size());
  for (const Pose& p : poses) {
    const Vector6d q = p.to_vector();
    rows.insert(rows.end(), q.data(), q.data() + 6);
  }
  std::vector<LimitReport> reports(poses.size());
  std::vector<Status> statuses(poses.size());

  const long before = g_allocations.load();
  for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional})
    EXPECT_EQ(motor_commands_batch(model, rows, strategy, batch, reports), Status::Ok);
  EXPECT_EQ(leg_lengths_batch(model, rows, batch, statuses), Status::Ok);
  int ok = 0;
  for (const Pose& p : poses) {
    (void)inverse_kinematics(model, p, st);
    (void)twist(model, st, v);
    (void)twist_continued(model, st, v, v);
    (void)twist_jacobian(model, st, J);
    length_jacobian(st, J);
    (void)check_limits(model, st, lim);
    (void)jacobian_condition(model, st, condition);
    bend_angles(model, st, bb, bp);
    (void)compute_commands(model, p, rep);
    ok += motor_commands(model, p, Strategy::Conventional, cmd, lim) == Status::Ok;
    if (motor_commands(model, p, Strategy::Compensated, cmd, lim) == Status::Ok) {
      (void)forward_kinematics(model, cmd, LengthKind::Motor, previous, fk);         // warm-ish
      (void)forward_kinematics(model, cmd, LengthKind::Geometric, Placement{}, fk);  // cold
      (void)forward_kinematics_tracked(model, cmd, LengthKind::Motor, tracker, fk);
      previous = fk.placement;
    }
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GE(ok, 100);  // the loop exercised the success path too
}

}  // namespace
}  // namespace hexatwist::test

namespace hexatwist::test {
namespace {

// The mechanism's dynamics: inverse dynamics for a drive's feed-forward, forward dynamics for a
// plant model in a real-time loop.
TEST(RealTime, DynamicsDoNotAllocate) {
  const Config config = default_config();
  const Rig& rig = config.rig;
  std::mt19937_64 rng(kSeed + 60);
  std::vector<PlatformMotion> motions;
  for (int k = 0; k < 200; ++k) {
    Vector6d rate, acc;
    for (int j = 0; j < 6; ++j) rate[j] = uniform(rng, -0.5, 0.5), acc[j] = uniform(rng, -3.0, 3.0);
    motions.push_back(platform_motion(random_valid_pose(rig.model(), rng, 0.3, deg2rad(20)), rate, acc));
  }
  InverseDynamics id;
  Vector6d acc;
  Matrix6d M;
  const long before = g_allocations.load();
  int ok = 0;
  for (const PlatformMotion& m : motions) {
    ok += inverse_dynamics(rig, m, id) == Status::Ok;
    ok += forward_dynamics(rig, m.placement, m.velocity, id.torque, acc) == Status::Ok;
    ok += mechanism_mass_matrix(rig, m.placement, M) == Status::Ok;
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_EQ(ok, 600);
}

// The whole per-line path of `hexatwist stream`: parse, check, rate-limit (with its forward
// kinematics), hold or skip, format.
TEST(RealTime, StreamLinesDoNotAllocate) {
  const Model& model = seed_model();
  std::mt19937_64 rng(kSeed + 61);
  std::vector<std::string> lines = {"garbage", "", "1,2,3", "nan,0,0,0,0,0", "0,0,0,0,0,0,0"};
  for (int n = 0; n < 200; ++n) {
    const Pose p = random_pose(rng, n % 2 ? 0.3 : 0.8, deg2rad(n % 2 ? 20 : 40));
    lines.push_back(std::to_string(p.position.x()) + "," + std::to_string(p.position.y()) + "," +
                    std::to_string(p.position.z()) + "," + std::to_string(rad2deg(p.rpy.x())) + "," +
                    std::to_string(rad2deg(p.rpy.y())) + "," + std::to_string(rad2deg(p.rpy.z())));
  }
  StreamSettings hold_limited;
  hold_limited.max_velocity = 0.2;
  hold_limited.max_acceleration = 2.0;
  StreamSettings skip;
  skip.on_reject = RejectPolicy::Skip;
  skip.strategy = Strategy::Conventional;
  StreamState a, b;
  StreamOutput out;
  std::array<char, kMaxOutputLength> buf{};
  std::size_t written = 0;
  int limited = 0;
  const long before = g_allocations.load();
  for (const std::string& line : lines) {
    (void)stream_line(model, hold_limited, line, AngleUnit::Degrees, a, out);
    limited += out.rate_limited;
    written += format_stream_output(out, StreamFormat::Json, buf);
    (void)stream_line(model, skip, line, AngleUnit::Degrees, b, out);
    written += format_stream_output(out, StreamFormat::Csv, buf);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(written, lines.size() * 2 * 40);
  EXPECT_GT(limited, 50);  // the rate-limited steps (with forward kinematics) were exercised
}

}  // namespace
}  // namespace hexatwist::test
