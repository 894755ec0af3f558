// SPDX-License-Identifier: BSD-3-Clause
// The constant-orientation workspace's volume (workspace_volume.hpp, docs/theory/design.md §16):
// against an independent Monte Carlo estimate, its stated error, the search's crossings, the
// independence from threads and chunks, and the platform's symmetry.
#include "hexatwist/design/workspace_volume.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <thread>

#include "hexatwist/io/config.hpp"
#include "support.hpp"

namespace hexatwist {
namespace {

bool accepted(const Model& model, const Vector3d& p, const Vector3d& rpy, LimitReport* report = nullptr) {
  Pose pose;
  pose.position = p;
  pose.rpy = rpy;
  Vector6d command;
  LimitReport r;
  const bool ok = motor_commands(model, pose, Strategy::Compensated, command, r) == Status::Ok;
  if (report) *report = r;
  return ok;
}

// Independent estimate: the share of uniform points of the box that are accepted, times the box.
struct MonteCarlo {
  double volume, sd;
};
MonteCarlo monte_carlo(const Model& model, const Vector3d& rpy, const Box& box, int n, std::uint32_t seed) {
  std::mt19937_64 rng(seed);
  int in = 0;
  for (int k = 0; k < n; ++k) {
    Vector3d p;
    for (int c = 0; c < 3; ++c) p[c] = test::uniform(rng, box.lower[c], box.upper[c]);
    in += accepted(model, p, rpy);
  }
  const double box_volume = (box.upper - box.lower).prod();
  const double share = static_cast<double>(in) / n;
  return {share * box_volume, box_volume * std::sqrt(share * (1.0 - share) / n)};
}

TEST(WorkspaceVolume, AgreesWithAnIndependentMonteCarloEstimateToOnePercent) {
  const Model& model = test::seed_model();
  for (const Vector3d& rpy : {Vector3d(0, 0, 0), Vector3d(deg2rad(5), deg2rad(-10), deg2rad(20))}) {
    SCOPED_TRACE(testing::Message() << "rpy " << rpy.transpose());
    WorkspaceVolume v;
    ASSERT_EQ(workspace_volume(model, rpy, VolumeOptions{}, v), Status::Ok);
    const MonteCarlo mc = monte_carlo(model, rpy, v.grid.box, rpy.isZero() ? 1'000'000 : 300'000, test::kSeed);
    test::report("volume [m^3]", v.volume);
    test::report("Monte Carlo [m^3]", mc.volume);
    test::report("its standard error [m^3]", mc.sd);
    test::report("stated error [m^3]", v.error);
    test::report("relative difference", (v.volume - mc.volume) / mc.volume);
    EXPECT_LT(v.error, 0.01 * v.volume);  // the volume to 1 %, as stated
    if (rpy.isZero()) {
      EXPECT_LT(std::abs(v.volume - mc.volume), 0.01 * mc.volume);  // its sd is 0.3 % here
    }
    EXPECT_LT(std::abs(v.volume - mc.volume), v.error + 4.0 * mc.sd);  // within what both state
  }
}

TEST(WorkspaceVolume, StatedErrorBoundsTheErrorAgainstAFinerGrid) {
  const Model& model = test::seed_model();
  VolumeOptions coarse;
  coarse.cell = 0.08;
  coarse.threads = 0;
  VolumeOptions fine = coarse;
  fine.cell = 0.03;
  WorkspaceVolume a, b;
  ASSERT_EQ(workspace_volume(model, Vector3d::Zero(), coarse, a), Status::Ok);
  ASSERT_EQ(workspace_volume(model, Vector3d::Zero(), fine, b), Status::Ok);
  test::report("coarse grid's error against the fine one [m^3]", std::abs(a.volume - b.volume));
  test::report("coarse grid's stated error [m^3]", a.error);
  EXPECT_LE(std::abs(a.volume - b.volume), a.error + b.error);
  EXPECT_LT(b.error, a.error);
}

TEST(WorkspaceVolume, SymmetriesOfTheSeedGiveEqualVolumesWithinTheStatedError) {
  // Turning base and platform by 120 deg about z, or mirroring them in the x-z plane, maps the seed
  // onto itself (legs relabelled): the workspace at R is the one at Q R Q^T moved by Q, on a grid
  // that lies differently across it.
  const Model& model = test::seed_model();
  const Vector3d rpy(deg2rad(6), deg2rad(-9), deg2rad(14));
  const Matrix3d R = rotation_from_rpy(rpy);
  const Matrix3d turn = Eigen::AngleAxisd(deg2rad(120), Vector3d::UnitZ()).toRotationMatrix();
  const Matrix3d mirror = Vector3d(1, -1, 1).asDiagonal();
  WorkspaceVolume a;
  ASSERT_EQ(workspace_volume(model, rpy, VolumeOptions{}, a), Status::Ok);
  for (const Matrix3d& Q : {turn, mirror}) {
    WorkspaceVolume b;
    ASSERT_EQ(workspace_volume(model, rpy_from_rotation(Q * R * Q.transpose()), VolumeOptions{}, b), Status::Ok);
    test::report("difference [m^3]", a.volume - b.volume);
    EXPECT_LT(std::abs(a.volume - b.volume), a.error + b.error);
  }
  EXPECT_GT(a.volume, 0.1);
}

TEST(WorkspaceVolume, DoesNotDependOnThreadsOrOnHowTheCellsAreSplit) {
  const Model& model = test::seed_model();
  VolumeOptions o;
  o.cell = 0.05;
  WorkspaceVolume one, many;
  ASSERT_EQ(workspace_volume(model, Vector3d(0.1, 0, 0), o, one), Status::Ok);
  o.threads = 3;
  ASSERT_EQ(workspace_volume(model, Vector3d(0.1, 0, 0), o, many), Status::Ok);
  EXPECT_EQ(one.volume, many.volume);
  EXPECT_EQ(one.error, many.error);
  // Cells in uneven chunks, as Dask workers would take them.
  const std::size_t n = one.grid.cells();
  std::vector<double> fine(n), coarse(n);
  std::uint64_t columns = 0;
  for (std::size_t first = 0, size = 1; first < n; first += size, size = size * 2 + 1) {
    const std::size_t count = std::min(size, n - first);
    columns += volume_cells(model, one.grid, o.search, first, count, fine.data() + first, coarse.data() + first);
  }
  const WorkspaceVolume split = volume_from_cells(one.grid, fine, coarse, columns);
  EXPECT_EQ(split.volume, one.volume);
  EXPECT_EQ(split.coarse_volume, one.coarse_volume);
}

TEST(WorkspaceVolume, TellsItsProgressOneCallAtATimeUpToEveryCellWithoutChangingTheVolume) {
  const Model& model = test::seed_model();
  VolumeOptions o;
  o.cell = 0.05;
  WorkspaceVolume plain, told;
  ASSERT_EQ(workspace_volume(model, Vector3d::Zero(), o, plain), Status::Ok);
  o.threads = 3;
  std::vector<std::size_t> calls;
  std::atomic<int> inside{0};
  bool overlapped = false;
  o.progress = [&](std::size_t done, std::size_t total) {
    overlapped = overlapped || inside.fetch_add(1) != 0;  // never two calls at once
    EXPECT_EQ(total, plain.grid.cells());
    calls.push_back(done);
    std::this_thread::sleep_for(std::chrono::microseconds(50));
    inside.fetch_sub(1);
  };
  ASSERT_EQ(workspace_volume(model, Vector3d::Zero(), o, told), Status::Ok);
  EXPECT_FALSE(overlapped);
  EXPECT_EQ(told.volume, plain.volume);
  EXPECT_EQ(told.error, plain.error);
  // One call per row of coarse cells, increasing, the last at every cell.
  ASSERT_EQ(calls.size(), static_cast<std::size_t>(plain.grid.ny));
  EXPECT_TRUE(std::is_sorted(calls.begin(), calls.end()));
  EXPECT_EQ(calls.back(), plain.grid.cells());
  // A callback that throws (a user's stop) ends the computation and the exception reaches the caller.
  o.progress = [](std::size_t done, std::size_t) {
    if (done > 0) throw std::runtime_error("stopped");
  };
  EXPECT_THROW((void)workspace_volume(model, Vector3d::Zero(), o, told), std::runtime_error);
}

TEST(WorkspaceVolume, BoundsHoldEveryAcceptedPosition) {
  const Model& model = test::seed_model();
  std::mt19937_64 rng(test::kSeed);
  for (int trial = 0; trial < 20; ++trial) {
    const Vector3d rpy(test::uniform(rng, -0.3, 0.3), test::uniform(rng, -0.3, 0.3), test::uniform(rng, -0.6, 0.6));
    Box box;
    ASSERT_EQ(workspace_bounds(model, rpy, box), Status::Ok);
    for (int k = 0; k < 2000; ++k) {
      // Points around the box, some outside it: none outside may be accepted.
      Vector3d p;
      for (int c = 0; c < 3; ++c)
        p[c] = test::uniform(rng, 1.2 * box.lower[c] - 0.2 * box.upper[c], 1.2 * box.upper[c] - 0.2 * box.lower[c]);
      const bool in_box = (p.array() >= box.lower.array()).all() && (p.array() <= box.upper.array()).all();
      if (!in_box) {
        ASSERT_FALSE(accepted(model, p, rpy)) << p.transpose();
      }
    }
  }
}

TEST(WorkspaceVolume, EveryCrossingIsAcceptedInsideAndRefusedOutsideByTheLimitItNames) {
  const Model& model = test::seed_model();
  std::mt19937_64 rng(test::kSeed + 1);
  WorkspaceOptions o;
  int crossings = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Vector3d rpy(test::uniform(rng, -0.2, 0.2), test::uniform(rng, -0.2, 0.2), test::uniform(rng, -0.5, 0.5));
    Vector3d direction(test::uniform(rng, -1, 1), test::uniform(rng, -1, 1), test::uniform(rng, -1, 1));
    direction.normalize();
    const Vector3d origin(test::uniform(rng, -0.2, 0.2), test::uniform(rng, -0.2, 0.2), test::uniform(rng, -0.2, 0.2));
    std::vector<LineInterval> intervals;
    ASSERT_EQ(line_intervals(model, rpy, origin, direction, -2.0, 2.0, o, intervals), Status::Ok);
    for (const LineInterval& iv : intervals) {
      EXPECT_LE(iv.lower.inside, iv.upper.inside);
      for (const Crossing* c : {&iv.lower, &iv.upper}) {
        if (c->limit.status == Status::Ok) continue;
        ++crossings;
        EXPECT_LE(std::abs(c->outside - c->inside), o.tolerance);
        EXPECT_TRUE(accepted(model, origin + c->inside * direction, rpy));
        LimitReport r;
        EXPECT_FALSE(accepted(model, origin + c->outside * direction, rpy, &r));
        EXPECT_EQ(r.status, c->limit.status);
        EXPECT_EQ(r.leg, c->limit.leg);
      }
      // The middle of a stretch is inside.
      EXPECT_TRUE(accepted(model, origin + 0.5 * (iv.lower.inside + iv.upper.inside) * direction, rpy));
    }
  }
  EXPECT_GT(crossings, 60);
}

TEST(WorkspaceVolume, RefusesOptionsThatCannotMarch) {
  const Model& model = test::seed_model();
  WorkspaceVolume v;
  VolumeOptions o;
  o.search.step = 0.0;
  EXPECT_EQ(workspace_volume(model, Vector3d::Zero(), o, v), Status::NonFiniteInput);
  o = VolumeOptions{};
  o.refine = 9;
  EXPECT_EQ(workspace_volume(model, Vector3d::Zero(), o, v), Status::NonFiniteInput);
  o = VolumeOptions{};
  EXPECT_EQ(workspace_volume(model, Vector3d(NAN, 0, 0), o, v), Status::NonFiniteInput);
  std::vector<LineInterval> iv;
  EXPECT_EQ(
      line_intervals(model, Vector3d::Zero(), Vector3d::Zero(), Vector3d::UnitZ(), 1.0, 0.0, WorkspaceOptions{}, iv),
      Status::NonFiniteInput);
}

}  // namespace
}  // namespace hexatwist
