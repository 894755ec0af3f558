// SPDX-License-Identifier: BSD-3-Clause
// Slices of the constant-orientation workspace and the orientation workspace
// (workspace_boundary.hpp, docs/theory/design.md §16): every boundary point accepted just inside
// and refused just outside by the limit it names, the slice's area against a Monte Carlo estimate,
// tilt-and-torsion rotations, and the seed's three-fold symmetry.
#include "hexatwist/design/workspace_boundary.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "support.hpp"

namespace hexatwist {
namespace {

bool accepted(const Model& model, const Pose& pose, LimitReport* report = nullptr) {
  Vector6d command;
  LimitReport r;
  const bool ok = motor_commands(model, pose, Strategy::Compensated, command, r) == Status::Ok;
  if (report) *report = r;
  return ok;
}

Pose at(const Vector3d& p, const Vector3d& rpy) {
  Pose pose;
  pose.position = p;
  pose.rpy = rpy;
  return pose;
}

TEST(WorkspaceSlice, EveryBoundaryPointIsInsideJustInsideAndBreaksItsNamedLimitJustOutside) {
  const Model& model = test::seed_model();
  const Vector3d rpy(0.05, -0.1, 0.2);
  std::set<Status> limits;
  for (const SlicePlane plane : {SlicePlane::XY, SlicePlane::XZ, SlicePlane::YZ}) {
    SliceSpec spec;
    spec.plane = plane;
    spec.offset = plane == SlicePlane::XY ? 0.1 : -0.05;
    spec.spacing = 0.02;
    WorkspaceSlice slice;
    ASSERT_EQ(workspace_slice(model, rpy, spec, WorkspaceOptions{}, slice), Status::Ok);
    ASSERT_GT(slice.boundary.size(), 100u);
    for (const BoundaryPoint& p : slice.boundary) {
      EXPECT_LE((p.outside - p.inside).norm(), 1e-9);
      EXPECT_EQ(slice_point(spec, p.u, p.v), p.inside);
      EXPECT_TRUE(accepted(model, at(p.inside, rpy))) << p.inside.transpose();
      LimitReport r;
      EXPECT_FALSE(accepted(model, at(p.outside, rpy), &r)) << p.outside.transpose();
      EXPECT_EQ(r.status, p.limit.status);
      EXPECT_EQ(r.leg, p.limit.leg);
      limits.insert(p.limit.status);
    }
  }
  // The seed's workspace is bounded by more than one kind of limit.
  EXPECT_GE(limits.size(), 2u);
}

TEST(WorkspaceSlice, AreaAgreesWithAMonteCarloEstimate) {
  const Model& model = test::seed_model();
  SliceSpec spec;
  spec.spacing = 0.005;
  WorkspaceSlice slice;
  ASSERT_EQ(workspace_slice(model, Vector3d::Zero(), spec, WorkspaceOptions{}, slice), Status::Ok);
  std::mt19937_64 rng(test::kSeed);
  const int n = 400'000;
  int in = 0;
  for (int k = 0; k < n; ++k)
    in += accepted(
        model, at(Vector3d(test::uniform(rng, slice.u0, slice.u1), test::uniform(rng, slice.v0, slice.v1), spec.offset),
                  Vector3d::Zero()));
  const double rect = (slice.u1 - slice.u0) * (slice.v1 - slice.v0), share = static_cast<double>(in) / n;
  const double mc = share * rect, sd = rect * std::sqrt(share * (1 - share) / n);
  test::report("slice area [m^2]", slice.area);
  test::report("Monte Carlo [m^2]", mc);
  EXPECT_LT(std::abs(slice.area - mc), 4 * sd + 0.005 * mc);
}

TEST(WorkspaceSlice, IsEmptyOutsideTheBoundsAndRefusesBadSpacing) {
  const Model& model = test::seed_model();
  SliceSpec spec;
  spec.offset = 5.0;
  WorkspaceSlice slice;
  ASSERT_EQ(workspace_slice(model, Vector3d::Zero(), spec, WorkspaceOptions{}, slice), Status::Ok);
  EXPECT_TRUE(slice.boundary.empty());
  EXPECT_EQ(slice.area, 0.0);
  spec.offset = 0.0;
  spec.spacing = 0.0;
  EXPECT_EQ(workspace_slice(model, Vector3d::Zero(), spec, WorkspaceOptions{}, slice), Status::NonFiniteInput);
}

TEST(TiltTorsion, TiltsThePlatformAxisTowardsTheAzimuthAndIsAYawAtZeroTilt) {
  std::mt19937_64 rng(test::kSeed);
  for (int k = 0; k < 200; ++k) {
    const double azimuth = test::uniform(rng, -kPi, kPi), tilt = test::uniform(rng, 0, 1.2),
                 torsion = test::uniform(rng, -1, 1);
    const Matrix3d R = tilt_torsion_rotation(azimuth, tilt, torsion);
    const Vector3d z = R * Vector3d::UnitZ();
    EXPECT_NEAR(z.x(), std::sin(tilt) * std::cos(azimuth), 1e-14);
    EXPECT_NEAR(z.y(), std::sin(tilt) * std::sin(azimuth), 1e-14);
    EXPECT_NEAR(z.z(), std::cos(tilt), 1e-14);
    EXPECT_NEAR((R.transpose() * R - Matrix3d::Identity()).norm(), 0.0, 1e-14);
    const Matrix3d yaw = tilt_torsion_rotation(azimuth, 0.0, torsion);
    EXPECT_NEAR((yaw - rotation_from_rpy(Vector3d(0, 0, torsion))).norm(), 0.0, 1e-14);
  }
}

TEST(OrientationWorkspace, EachLargestTiltIsAcceptedAndTheNextRefusedByTheNamedLimit) {
  const Model& model = test::seed_model();
  OrientationSpec spec;
  spec.position = Vector3d(0.05, -0.1, 0.1);
  spec.torsions = {deg2rad(-20), 0.0, deg2rad(15)};
  spec.directions = 36;
  OrientationWorkspace ow;
  ASSERT_EQ(orientation_workspace(model, spec, Strategy::Compensated, ow), Status::Ok);
  ASSERT_EQ(ow.reach.size(), 3u);
  for (std::size_t t = 0; t < spec.torsions.size(); ++t)
    for (const TiltReach& r : ow.reach[t]) {
      ASSERT_FALSE(std::isnan(r.tilt));
      EXPECT_GT(r.tilt, deg2rad(5));
      const auto pose = [&](double tilt) {
        return at(spec.position, rpy_from_rotation(tilt_torsion_rotation(r.azimuth, tilt, spec.torsions[t])));
      };
      EXPECT_TRUE(accepted(model, pose(r.tilt)));
      EXPECT_TRUE(accepted(model, pose(0.5 * r.tilt)));
      LimitReport lim;
      EXPECT_FALSE(accepted(model, pose(r.tilt + 2e-9), &lim));
      EXPECT_EQ(lim.status, r.limit.status);
    }
}

TEST(OrientationWorkspace, HasTheSeedsThreeFoldSymmetryAtHome) {
  const Model& model = test::seed_model();
  OrientationSpec spec;
  spec.directions = 72;  // 5 deg: 120 deg is 24 directions
  OrientationWorkspace ow;
  ASSERT_EQ(orientation_workspace(model, spec, Strategy::Compensated, ow), Status::Ok);
  double worst = 0.0;
  for (int j = 0; j < 72; ++j) worst = std::max(worst, std::abs(ow.reach[0][j].tilt - ow.reach[0][(j + 24) % 72].tilt));
  test::report("largest difference of the reach 120 deg apart [rad]", worst);
  EXPECT_LT(worst, 1e-8);
}

TEST(OrientationWorkspace, ATorsionOutsideTheWorkspaceHasNoTilt) {
  OrientationSpec spec;
  spec.torsions = {deg2rad(60)};  // pure yaw is refused beyond about 40 deg (theory §6)
  spec.directions = 4;
  OrientationWorkspace ow;
  ASSERT_EQ(orientation_workspace(test::seed_model(), spec, Strategy::Compensated, ow), Status::Ok);
  for (const TiltReach& r : ow.reach[0]) {
    EXPECT_TRUE(std::isnan(r.tilt));
    EXPECT_TRUE(is_limit(r.limit.status));
  }
  const TiltExtremes e = tilt_extremes(ow.reach[0]);
  EXPECT_EQ(e.reached, 0u);
  EXPECT_TRUE(std::isnan(e.smallest) && std::isnan(e.largest) && std::isnan(e.smallest_azimuth));
  EXPECT_EQ(e.smallest_limit.status, ow.reach[0].front().limit.status);  // what refuses the torsion alone
  EXPECT_EQ(e.smallest_limit.leg, ow.reach[0].front().limit.leg);
  spec.directions = 0;
  EXPECT_EQ(orientation_workspace(test::seed_model(), spec, Strategy::Compensated, ow), Status::NonFiniteInput);
}

TEST(OrientationWorkspace, TiltExtremesAreTheRowsSmallestAndLargestReachedTilts) {
  OrientationSpec spec;
  spec.torsions = {deg2rad(-20), deg2rad(10), deg2rad(38)};  // at 38 deg of yaw some azimuths are refused
  spec.directions = 36;
  OrientationWorkspace ow;
  ASSERT_EQ(orientation_workspace(test::seed_model(), spec, Strategy::Compensated, ow), Status::Ok);
  for (std::vector<TiltReach>& row : ow.reach) {
    // A row with an azimuth refused outright, planted: it must not count.
    row[5].tilt = NAN;
    const TiltExtremes e = tilt_extremes(row);
    std::size_t reached = 0;
    for (const TiltReach& r : row) {
      if (std::isnan(r.tilt)) continue;
      ++reached;
      EXPECT_LE(e.smallest, r.tilt);
      EXPECT_GE(e.largest, r.tilt);
    }
    ASSERT_EQ(e.reached, reached);
    ASSERT_GT(reached, 0u);
    // Each extreme is one of the row's own entries, the first of equal ones, with its azimuth and limit.
    const auto first_with = [&](double tilt) {
      return std::find_if(row.begin(), row.end(), [&](const TiltReach& r) { return r.tilt == tilt; });
    };
    const auto lo = first_with(e.smallest), hi = first_with(e.largest);
    ASSERT_NE(lo, row.end());
    ASSERT_NE(hi, row.end());
    EXPECT_EQ(lo->azimuth, e.smallest_azimuth);
    EXPECT_EQ(lo->limit.status, e.smallest_limit.status);
    EXPECT_EQ(lo->limit.leg, e.smallest_limit.leg);
    EXPECT_EQ(hi->azimuth, e.largest_azimuth);
    EXPECT_LT(e.smallest, e.largest);
  }
  EXPECT_EQ(tilt_extremes({}).reached, 0u);
}

}  // namespace
}  // namespace hexatwist
