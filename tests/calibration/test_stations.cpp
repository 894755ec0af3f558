// SPDX-License-Identifier: BSD-3-Clause
// The runs a calibration records (stations.hpp): random stations inside the limits, and how a run
// visits them: each from both sides (every leg's command coming down to the station from above
// and up from below, for identify's play), home again as a repeated reference (identify's heat),
// the plain run unchanged without them, and the values refused.
#include "support.hpp"

namespace hexatwist::test {
namespace {

StationsSpec spec_of(int count, double approach, int reference_every) {
  StationsSpec spec;
  spec.count = count;
  spec.seed = 7;
  spec.approach = approach;
  spec.reference_every = reference_every;
  return spec;
}

Vector6d command_at(const Vector6d& q) {
  Vector6d command;
  LimitReport limit;
  EXPECT_EQ(motor_commands(seed_model(), Pose::from_vector(q), Strategy::Compensated, command, limit), Status::Ok);
  return command;
}

TEST(Stations, WithoutApproachOrReferenceTheRunIsHomeTheStationsHome) {
  const StationsSpec spec = spec_of(12, 0.0, 0);
  const std::vector<Vector6d> stations = random_stations(seed_model(), Strategy::Compensated, spec);
  const std::vector<Vector6d> w = station_waypoints(seed_model(), Strategy::Compensated, stations, spec);
  ASSERT_EQ(w.size(), stations.size() + 2);
  EXPECT_EQ(w.front(), Vector6d::Zero());
  EXPECT_EQ(w.back(), Vector6d::Zero());
  for (std::size_t i = 0; i < stations.size(); ++i) EXPECT_EQ(w[i + 1], stations[i]);
}

TEST(Stations, EachStationIsApproachedByEveryLegFromBothSides) {
  // From 5 mm above (z), every leg's command comes down to the station; from 5 mm below, up. The
  // two visits follow each other; a side outside the limits is left out (few on the seed).
  const StationsSpec spec = spec_of(30, 5e-3, 0);
  const std::vector<Vector6d> stations = random_stations(seed_model(), Strategy::Compensated, spec);
  const std::vector<Vector6d> w = station_waypoints(seed_model(), Strategy::Compensated, stations, spec);
  std::size_t k = 1, both = 0;
  for (const Vector6d& station : stations) {
    int sides = 0;
    // A start pose: the station moved along z alone, by the approach.
    const auto start_of_station = [&](const Vector6d& q) {
      const Vector6d offset = q - station;
      return offset.cwiseAbs().sum() == std::abs(offset[2]) && std::abs(std::abs(offset[2]) - 5e-3) < 1e-15;
    };
    while (k + 1 < w.size() && sides < 2 && start_of_station(w[k])) {
      ASSERT_EQ(w[k + 1], station) << "a start pose is followed by its station";
      const Vector6d offset = w[k] - station;
      const Vector6d change = command_at(station) - command_at(w[k]);
      if (offset[2] > 0.0) {
        EXPECT_TRUE((change.array() < 0.0).all()) << "from above, every leg shortens: " << change.transpose();
        EXPECT_EQ(sides, 0) << "above first";
      } else {
        EXPECT_TRUE((change.array() > 0.0).all()) << "from below, every leg lengthens: " << change.transpose();
      }
      ++sides;
      k += 2;
    }
    if (sides == 0) {
      ASSERT_EQ(w[k], station);
      ++k;
    }
    both += sides == 2;
  }
  EXPECT_EQ(w[k], Vector6d::Zero());
  EXPECT_EQ(k + 1, w.size());
  std::printf("  %zu of %zu stations from both sides\n", both, stations.size());
  EXPECT_GE(both, stations.size() * 8 / 10);
  // The run through them: longer than the plain one, at each waypoint at rest.
  const Trajectory run = station_run(seed_model(), Strategy::Compensated, stations, spec, 0.01);
  const Trajectory plain = station_run(seed_model(), Strategy::Compensated, stations, spec_of(30, 0.0, 0), 0.01);
  EXPECT_GT(run.poses.size(), plain.poses.size() + 2 * 100 * both);
}

TEST(Stations, HomeIsVisitedAgainAfterEveryNStations) {
  const StationsSpec spec = spec_of(12, 0.0, 4);
  const std::vector<Vector6d> stations = random_stations(seed_model(), Strategy::Compensated, spec);
  const std::vector<Vector6d> w = station_waypoints(seed_model(), Strategy::Compensated, stations, spec);
  std::vector<std::size_t> homes;  // stations before each interior home
  std::size_t seen = 0;
  for (std::size_t k = 1; k + 1 < w.size(); ++k) {
    if (w[k] == Vector6d::Zero())
      homes.push_back(seen);
    else
      EXPECT_EQ(w[k], stations[seen++]);
  }
  EXPECT_EQ(seen, stations.size());
  for (const std::size_t h : homes) EXPECT_EQ(h % 4, 0u) << "home after a multiple of 4 stations";
  EXPECT_GE(homes.size(), 1u);
  EXPECT_LE(homes.size(), 2u);  // after 4 and 8; not after the last
}

TEST(Stations, AnApproachOrReferenceOutsideItsRangeIsRefusedNamingIt) {
  const std::vector<Vector6d> stations = random_stations(seed_model(), Strategy::Compensated, spec_of(3, 0.0, 0));
  for (const double a : {-1e-3, 0.051, std::numeric_limits<double>::quiet_NaN()}) {
    try {
      (void)station_waypoints(seed_model(), Strategy::Compensated, stations, spec_of(3, a, 0));
      ADD_FAILURE() << a << " accepted";
    } catch (const ParameterError& e) {
      EXPECT_EQ(e.parameter(), "approach") << e.what();
    }
  }
  try {
    (void)station_waypoints(seed_model(), Strategy::Compensated, stations, spec_of(3, 0.0, -1));
    ADD_FAILURE() << "reference_every -1 accepted";
  } catch (const ParameterError& e) {
    EXPECT_EQ(e.parameter(), "reference_every") << e.what();
  }
}

}  // namespace
}  // namespace hexatwist::test
