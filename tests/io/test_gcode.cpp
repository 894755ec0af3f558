// SPDX-License-Identifier: BSD-3-Clause
// The LinuxCNC program of a run of straight moves (gcode.hpp): read back by a small G-code reader
// here, its targets are the waypoints (LinuxCNC units converted back to SI), its times those of
// waypoint_trajectory, the same run the CSV holds; its comments are comments LinuxCNC reads.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "hexatwist/error.hpp"
#include "hexatwist/io/config.hpp"
#include "hexatwist/io/gcode.hpp"

namespace hexatwist {
namespace {

// What a program does, as a controller reads it: the target of each G1 (SI, from home) with its
// duration (G93: F is moves per minute), and each dwell.
struct Step {
  bool move = false;
  Vector6d target = Vector6d::Zero();
  double seconds = 0.0;
};

double word(const std::string& line, char letter) {
  const auto at = line.find(std::string(" ") + letter);
  return at == std::string::npos ? std::nan("") : std::stod(line.substr(at + 2));
}

std::vector<Step> read_program(const std::string& program, double home_height, bool& inverse_time, bool& ended) {
  std::vector<Step> steps;
  std::istringstream in(program);
  inverse_time = ended = false;
  for (std::string line; std::getline(in, line);) {
    if (line.starts_with("(")) {
      EXPECT_TRUE(line.ends_with(")")) << line;
      EXPECT_EQ(line.find('(', 1), std::string::npos) << line;  // one comment, nothing nested
      EXPECT_EQ(line.find(')'), line.size() - 1) << line;
      continue;
    }
    if (line == "G93") inverse_time = true;
    if (line == "G94") inverse_time = false;
    if (line == "M2") ended = true;
    if (line.starts_with("G1 ")) {
      EXPECT_TRUE(inverse_time) << "a timed move outside G93: " << line;
      Step s;
      s.move = true;
      s.target << 1e-3 * word(line, 'X'), 1e-3 * word(line, 'Y'), 1e-3 * word(line, 'Z') - home_height,
          deg2rad(word(line, 'A')), deg2rad(word(line, 'B')), deg2rad(word(line, 'C'));
      s.seconds = 60.0 / word(line, 'F');
      steps.push_back(s);
    } else if (line.starts_with("G4 P")) {
      steps.push_back({false, Vector6d::Zero(), std::stod(line.substr(4))});
    }
  }
  return steps;
}

TEST(Gcode, AProgramDrivesTheWaypointsWithTheTimesOfTheirTrajectory) {
  const Model model = default_model();
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vector6d> waypoints{Vector6d::Zero()};
  for (int k = 0; k < 8; ++k) {
    Vector6d w;
    w << 0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng), deg2rad(5 * u(rng)), deg2rad(5 * u(rng)), deg2rad(5 * u(rng));
    waypoints.push_back(w);
  }
  waypoints.push_back(Vector6d::Zero());
  const MotionLimits limits{0.2, 0.5, 2.5};
  const double dwell = 0.75, dt = 1e-3;
  const std::string program = waypoint_program(model, waypoints, limits, dwell, "a test (with parentheses)");
  bool inverse_time = true, ended = false;
  const std::vector<Step> steps = read_program(program, model.spec().home_height, inverse_time, ended);
  EXPECT_FALSE(inverse_time) << "the program leaves G93 before it ends";
  EXPECT_TRUE(ended);
  // Every waypoint after the first is a move's target, each followed by a dwell; the first dwell is at home.
  ASSERT_EQ(steps.size(), 2 * waypoints.size() - 1);
  const Trajectory run = waypoint_trajectory(waypoints, limits, dwell, dt);
  double t = 0.0;
  std::size_t next = 1;
  for (const Step& s : steps) {
    if (!s.move) {
      EXPECT_DOUBLE_EQ(s.seconds, dwell);
      t += s.seconds;
      continue;
    }
    // The target reads back to 1 nm and 1 urad; the move takes the planned time.
    EXPECT_LT((s.target.head<3>() - waypoints[next].head<3>()).cwiseAbs().maxCoeff(), 1e-9);
    EXPECT_LT((s.target.tail<3>() - waypoints[next].tail<3>()).cwiseAbs().maxCoeff(), 1e-7);
    const double planned = JerkLimitedMove((waypoints[next] - waypoints[next - 1]).norm(), limits).duration();
    EXPECT_NEAR(s.seconds, planned, 1e-8 * planned);
    t += s.seconds;
    // The trajectory stands at the waypoint from the program's arrival time on, not before.
    const auto k = static_cast<std::size_t>(std::ceil((t - run.t0) / dt - 1e-6));
    ASSERT_LT(k, run.poses.size());
    EXPECT_LT((run.poses[k].to_vector() - waypoints[next]).cwiseAbs().maxCoeff(), 1e-9) << "station " << next;
    const std::size_t before = k - static_cast<std::size_t>(0.05 / dt);
    EXPECT_GT((run.poses[before].to_vector() - waypoints[next]).cwiseAbs().maxCoeff(), 1e-6) << "station " << next;
    ++next;
  }
  // The program's length is the trajectory's (rounded up to a sample there).
  EXPECT_NEAR(t, run.duration(), dt);
  EXPECT_NE(program.find("(hexatwist: a test [with parentheses])"), std::string::npos);
  EXPECT_NE(program.find("(station 8 of 8: arrive at t = "), std::string::npos);
}

TEST(Gcode, BadWaypointsOrDwellAreRefused) {
  const Model model = default_model();
  const MotionLimits limits{0.2, 0.5, 2.5};
  const std::vector<Vector6d> one{Vector6d::Zero()};
  EXPECT_THROW((void)waypoint_program(model, one, limits, 1.0, ""), Error);
  std::vector<Vector6d> bad{Vector6d::Zero(), Vector6d::Constant(std::nan(""))};
  EXPECT_THROW((void)waypoint_program(model, bad, limits, 1.0, ""), Error);
  const std::vector<Vector6d> two{Vector6d::Zero(), Vector6d::Constant(0.01)};
  EXPECT_THROW((void)waypoint_program(model, two, limits, -1.0, ""), Error);
  EXPECT_THROW((void)waypoint_program(model, two, MotionLimits{0.2, 0.0, 2.5}, 1.0, ""), Error);
  EXPECT_NO_THROW((void)waypoint_program(model, two, limits, 0.0, ""));
}

}  // namespace
}  // namespace hexatwist
