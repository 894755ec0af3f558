// SPDX-License-Identifier: BSD-3-Clause
// Maps over a slice (workspace_map.hpp, docs/theory/design.md §16): each node's numbers against the
// library's functions called directly, NaN and the limit outside, and the rows' independence.
#include "hexatwist/design/workspace_map.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "support.hpp"

namespace hexatwist {
namespace {

TEST(WorkspaceMap, EachNodeHoldsTheLargestTwistLengthErrorConditionAndMarginOfItsPose) {
  const Model& model = test::seed_model();
  const Vector3d rpy(0.0, deg2rad(5), deg2rad(15));
  SliceSpec spec;
  spec.spacing = 0.05;
  WorkspaceSlice slice;
  ASSERT_EQ(workspace_slice(model, rpy, spec, WorkspaceOptions{}, slice), Status::Ok);
  const MapGrid grid = map_grid_around(slice, 0.05);
  WorkspaceMap map;
  ASSERT_EQ(workspace_map(model, rpy, grid, Strategy::Compensated, map, 2), Status::Ok);
  ASSERT_EQ(map.points.size(), grid.size());
  int inside = 0, outside = 0;
  for (int j = 0; j < grid.nv; ++j)
    for (int i = 0; i < grid.nu; ++i) {
      const MapPoint& m = map.points[static_cast<std::size_t>(j * grid.nu + i)];
      Pose pose;
      pose.position = Vector3d(grid.u(i), grid.v(j), 0.0);
      pose.rpy = rpy;
      Vector6d command;
      LimitReport r;
      const Status s = motor_commands(model, pose, Strategy::Compensated, command, r);
      ASSERT_EQ(m.status, s);
      if (s != Status::Ok) {
        ++outside;
        EXPECT_TRUE(std::isnan(m.max_twist));
        EXPECT_EQ(m.limit.status, r.status);
        EXPECT_EQ(m.limit.leg, r.leg);
        continue;
      }
      ++inside;
      LegState legs;
      ASSERT_EQ(inverse_kinematics(model, pose, legs), Status::Ok);
      Vector6d twist, error;
      ASSERT_EQ(hexatwist::twist(model, legs, twist), Status::Ok);
      length_error(model, twist, error);
      EXPECT_EQ(m.max_twist, twist.cwiseAbs().maxCoeff());
      EXPECT_EQ(std::abs(twist[m.twist_leg]), m.max_twist);
      EXPECT_EQ(m.max_length_error, error.cwiseAbs().maxCoeff());
      double condition;
      ASSERT_EQ(jacobian_condition(model, legs, condition), Status::Ok);
      EXPECT_EQ(m.condition, condition);
      LimitReport nearest;
      double margin;
      nearest_limit(model, legs, condition, nearest, margin);
      EXPECT_EQ(m.margin, margin);
      EXPECT_GT(m.margin, 0.0);  // inside every limit
    }
  EXPECT_GT(inside, 100);
  EXPECT_GT(outside, 20);
}

TEST(WorkspaceMap, RowsComputedApartEqualTheWholeMap) {
  const Model& model = test::seed_model();
  MapGrid grid;
  grid.plane = SlicePlane::XZ;
  grid.u0 = -0.6, grid.u1 = 0.7, grid.v0 = -0.6, grid.v1 = 0.5;
  grid.nu = 27, grid.nv = 23;
  WorkspaceMap whole;
  ASSERT_EQ(workspace_map(model, Vector3d::Zero(), grid, Strategy::Compensated, whole, 1), Status::Ok);
  std::vector<MapPoint> rows(grid.size());
  for (int first = 0; first < grid.nv; first += 5) {
    const int count = std::min(5, grid.nv - first);
    workspace_map_rows(model, Vector3d::Zero(), grid, Strategy::Compensated, first, count,
                       rows.data() + static_cast<std::size_t>(first * grid.nu));
  }
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(rows[k].status, whole.points[k].status);
    if (rows[k].status == Status::Ok) {
      EXPECT_EQ(rows[k].max_twist, whole.points[k].max_twist);
      EXPECT_EQ(rows[k].margin, whole.points[k].margin);
    }
  }
  // Its own grid and orientation passed back in: the same map.
  WorkspaceMap again = whole;
  ASSERT_EQ(workspace_map(model, again.rpy, again.grid, Strategy::Compensated, again), Status::Ok);
  ASSERT_EQ(again.points.size(), whole.points.size());
  for (std::size_t k = 0; k < again.points.size(); ++k) {
    EXPECT_EQ(again.points[k].status, whole.points[k].status);
    if (whole.points[k].status == Status::Ok) {
      EXPECT_EQ(again.points[k].margin, whole.points[k].margin);
    }
  }
  grid.nu = 1;
  EXPECT_EQ(workspace_map(model, Vector3d::Zero(), grid, Strategy::Compensated, whole), Status::NonFiniteInput);
}

TEST(WorkspaceMap, SummaryHoldsTheExtremesOfTheInsideNodesAtTheirOwnPoses) {
  const Model& model = test::seed_model();
  const Vector3d rpy(deg2rad(3), 0.0, deg2rad(-10));
  MapGrid grid;
  grid.plane = SlicePlane::XZ;
  grid.offset = 0.1;
  grid.u0 = -0.9, grid.u1 = 0.8, grid.v0 = -0.7, grid.v1 = 0.6;
  grid.nu = 18, grid.nv = 14;
  WorkspaceMap map;
  std::vector<std::size_t> rows_told;
  ASSERT_EQ(workspace_map(model, rpy, grid, Strategy::Compensated, map, 2,
                          [&](std::size_t done, std::size_t total) {
                            EXPECT_EQ(total, 14u);
                            rows_told.push_back(done);
                          }),
            Status::Ok);
  ASSERT_EQ(rows_told.size(), 14u);
  EXPECT_EQ(rows_told.back(), 14u);
  const MapSummary s = summarize_map(map);
  std::size_t inside = 0;
  double twist = -1.0, error = -1.0, cmin = INFINITY, cmax = -1.0, margin = INFINITY;
  for (std::size_t k = 0; k < map.points.size(); ++k) {
    const MapPoint& p = map.points[k];
    // Each node's position is the pose its numbers were computed at.
    Pose pose;
    pose.position = map_node_position(grid, k);
    pose.rpy = rpy;
    MapPoint again;
    (void)map_point(model, pose, Strategy::Compensated, again);
    ASSERT_EQ(again.status, p.status) << k;
    if (p.status != Status::Ok) continue;
    ASSERT_EQ(again.max_twist, p.max_twist) << k;
    ++inside;
    twist = std::max(twist, p.max_twist), error = std::max(error, p.max_length_error);
    cmin = std::min(cmin, p.condition), cmax = std::max(cmax, p.condition), margin = std::min(margin, p.margin);
  }
  ASSERT_GT(inside, 20u);
  ASSERT_LT(inside, map.points.size());
  EXPECT_EQ(s.inside, inside);
  EXPECT_EQ(s.max_twist, twist);
  EXPECT_EQ(s.max_length_error, error);
  EXPECT_EQ(s.condition_min, cmin);
  EXPECT_EQ(s.condition_max, cmax);
  EXPECT_EQ(s.margin_min, margin);
  // The nodes named hold them, with their leg and limit.
  EXPECT_EQ(map.points[s.max_twist_node].max_twist, twist);
  EXPECT_EQ(map.points[s.max_twist_node].twist_leg, s.max_twist_leg);
  EXPECT_EQ(map.points[s.max_length_error_node].max_length_error, error);
  EXPECT_EQ(map.points[s.margin_min_node].margin, margin);
  EXPECT_EQ(map.points[s.margin_min_node].nearest.status, s.margin_min_limit.status);
  // Nothing inside: NaN, not a number from outside the workspace.
  for (MapPoint& p : map.points) p.status = Status::StrokeAboveMax;
  const MapSummary none = summarize_map(map);
  EXPECT_EQ(none.inside, 0u);
  EXPECT_TRUE(std::isnan(none.max_twist) && std::isnan(none.condition_min) && std::isnan(none.margin_min));
}

TEST(WorkspaceMap, GridAroundASliceCoversEveryBoundaryPoint) {
  SliceSpec spec;
  spec.plane = SlicePlane::YZ;
  spec.spacing = 0.04;
  WorkspaceSlice slice;
  ASSERT_EQ(workspace_slice(test::seed_model(), Vector3d::Zero(), spec, WorkspaceOptions{}, slice), Status::Ok);
  const MapGrid g = map_grid_around(slice, 0.03);
  EXPECT_EQ(g.plane, SlicePlane::YZ);
  for (const BoundaryPoint& p : slice.boundary) {
    EXPECT_GE(p.u, g.u0);
    EXPECT_LE(p.u, g.u1);
    EXPECT_GE(p.v, g.v0);
    EXPECT_LE(p.v, g.v1);
  }
  EXPECT_NEAR((g.u1 - g.u0) / (g.nu - 1), 0.03, 0.003);
}

}  // namespace
}  // namespace hexatwist
