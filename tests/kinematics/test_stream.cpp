// SPDX-License-Identifier: BSD-3-Clause
// The real-time command stream (include/hexatwist/kinematics/stream.hpp): pose lines, reject policies, rate
// limits, answer lines.
#include <yaml-cpp/yaml.h>

#include <array>
#include <charconv>
#include <string>
#include <vector>

#include "support.hpp"

namespace hexatwist::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ----- pose lines -----

TEST(PoseLine, ReadsSixNumbersWithBlanksSignsAndLineEnds) {
  Pose p;
  LineParse where;
  ASSERT_TRUE(parse_pose_line(" 0.1, -0.02 ,+3e-1,\t30, -45,+90.5\r\n", AngleUnit::Degrees, p, where));
  EXPECT_EQ(where.error, LineError::None);
  EXPECT_EQ(p.position, Vector3d(0.1, -0.02, 0.3));
  EXPECT_DOUBLE_EQ(p.rpy[0], deg2rad(30));
  EXPECT_DOUBLE_EQ(p.rpy[1], deg2rad(-45));
  EXPECT_DOUBLE_EQ(p.rpy[2], deg2rad(90.5));
  ASSERT_TRUE(parse_pose_line("0,0,0,0.5,-0.25,1", AngleUnit::Radians, p, where));
  EXPECT_EQ(p.rpy, Vector3d(0.5, -0.25, 1.0));
}

TEST(PoseLine, NonFiniteNumbersAreReadAndLeftToTheCommandCheck) {
  Pose p;
  LineParse where;
  ASSERT_TRUE(parse_pose_line("nan,0,0,0,0,inf", AngleUnit::Degrees, p, where));
  EXPECT_TRUE(std::isnan(p.position[0]));
  EXPECT_TRUE(std::isinf(p.rpy[2]));
}

struct BadLine {
  const char* line;
  LineError error;
  int field;
  int column;
};

TEST(PoseLine, EveryMalformedLineSaysWhichFieldAndColumn) {
  const std::string long_line(kMaxLineLength + 1, '1');
  const std::vector<BadLine> cases = {
      {"", LineError::Empty, -1, 0},
      {"  \t\r\n", LineError::Empty, -1, 0},
      {long_line.c_str(), LineError::TooLong, -1, 0},
      {"0,0,0,0,0", LineError::MissingFields, 5, 10},
      {"0.1", LineError::MissingFields, 1, 4},
      {"0,0,0,0,0,0,7", LineError::ExtraFields, 6, 13},
      {"0,0,0,0,0,0,", LineError::ExtraFields, 6, 13},
      {"0,, 0,0,0,0", LineError::EmptyField, 1, 3},
      {"0,0,0,0,0, ", LineError::EmptyField, 5, 11},
      {"0,0,abc,0,0,0", LineError::NotANumber, 2, 5},
      {"0,0,0,0, 1.5x,0", LineError::NotANumber, 4, 10},
      {"0,0,0,0,0,++1", LineError::NotANumber, 5, 11},
      {"0,0,0,0,0,0x10", LineError::NotANumber, 5, 11},
      {"0 0 0 0 0 0", LineError::NotANumber, 0, 1},
      {"0,0,1e999,0,0,0", LineError::OutOfRange, 2, 5},
  };
  for (const BadLine& c : cases) {
    SCOPED_TRACE(c.line);
    Pose p;
    p.position = Vector3d(7, 7, 7);
    LineParse where;
    EXPECT_FALSE(parse_pose_line(c.line, AngleUnit::Degrees, p, where));
    EXPECT_EQ(where.error, c.error) << to_string(where.error);
    EXPECT_EQ(where.field, c.field);
    EXPECT_EQ(where.column, c.column);
    EXPECT_EQ(p.position, Vector3d(7, 7, 7));  // untouched
  }
}

// ----- the stream -----

StreamSettings limited(double vmax, double amax) {
  StreamSettings s;
  s.max_velocity = vmax;
  s.max_acceleration = amax;
  return s;
}

TEST(Stream, SettingsAreValidated) {
  EXPECT_TRUE(check_stream_settings(StreamSettings{}).empty());
  EXPECT_TRUE(check_stream_settings(limited(0.1, 1.0)).empty());
  StreamSettings s;
  s.period = 0;
  EXPECT_NE(check_stream_settings(s).find("period"), std::string_view::npos);
  EXPECT_NE(check_stream_settings(limited(-1, kInf)).find("max_velocity"), std::string_view::npos);
  EXPECT_NE(check_stream_settings(limited(std::nan(""), kInf)).find("max_velocity"), std::string_view::npos);
  EXPECT_NE(check_stream_settings(limited(kInf, 0)).find("max_acceleration"), std::string_view::npos);
  // Skip leaves the drive without a command for a rejected input: no limit could hold then.
  StreamSettings skip = limited(0.5, 5.0);
  skip.on_reject = RejectPolicy::Skip;
  EXPECT_NE(check_stream_settings(skip).find("on_reject"), std::string_view::npos);
  skip.max_velocity = skip.max_acceleration = kInf;
  EXPECT_TRUE(check_stream_settings(skip).empty());
  EXPECT_FALSE(StreamSettings{}.rate_limited());
  EXPECT_TRUE(limited(0.1, kInf).rate_limited());
}

TEST(Stream, AcceptedPoseGivesExactlyTheRealTimeCommandOfItsStrategy) {
  const Model& model = seed_model();
  std::mt19937_64 rng(kSeed + 401);
  for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional}) {
    StreamSettings s;
    s.strategy = strategy;
    StreamState state;
    StreamOutput out;
    for (int n = 0; n < 200; ++n) {
      const Pose p = random_valid_pose(model, rng, 0.4, deg2rad(25));
      Vector6d expected;
      LimitReport rep;
      ASSERT_EQ(motor_commands(model, p, strategy, expected, rep), Status::Ok);
      ASSERT_EQ(stream_pose(model, s, p, state, out), Status::Ok);
      EXPECT_EQ(out.action, CommandAction::New);
      EXPECT_FALSE(out.rate_limited);
      EXPECT_EQ(out.command, expected);
      EXPECT_EQ(out.input, static_cast<std::uint64_t>(n + 1));
    }
  }
}

TEST(Stream, RejectedInputsAreHeldOrSkippedAndNameTheirReason) {
  const Model& model = seed_model();
  Pose good;
  good.position.z() = 0.1;
  Pose far;
  far.position.z() = 2.0;  // beyond the stroke
  Pose nan_pose;
  nan_pose.rpy[1] = std::nan("");
  for (const RejectPolicy policy : {RejectPolicy::Hold, RejectPolicy::Skip}) {
    StreamSettings s;
    s.on_reject = policy;
    StreamState state;
    StreamOutput out;
    // Nothing valid yet: nothing to hold.
    EXPECT_EQ(stream_pose(model, s, far, state, out), Status::StrokeAboveMax);
    EXPECT_EQ(out.action, CommandAction::None);
    ASSERT_EQ(stream_pose(model, s, good, state, out), Status::Ok);
    const Vector6d valid = out.command;

    EXPECT_EQ(stream_pose(model, s, far, state, out), Status::StrokeAboveMax);
    EXPECT_TRUE(is_limit(out.status));
    EXPECT_GE(out.limit.leg, 0);
    EXPECT_GT(out.limit.value, out.limit.bound);
    EXPECT_EQ(out.action, policy == RejectPolicy::Hold ? CommandAction::Held : CommandAction::None);
    if (policy == RejectPolicy::Hold) {
      EXPECT_EQ(out.command, valid);
    }

    EXPECT_EQ(stream_pose(model, s, nan_pose, state, out), Status::NonFiniteInput);
    EXPECT_EQ(stream_line(model, s, "0,0,0.1,0,0", AngleUnit::Degrees, state, out), Status::MalformedInput);
    EXPECT_EQ(out.parse.error, LineError::MissingFields);
    EXPECT_EQ(out.input, 5u);
    if (policy == RejectPolicy::Hold) {
      EXPECT_EQ(out.command, valid);
    }
    EXPECT_EQ(stream_line(model, s, "0,0,0.1,0,0,0", AngleUnit::Degrees, state, out), Status::Ok);
    EXPECT_EQ(out.command, valid);
  }
}

TEST(Stream, StartedStreamHoldsItsStartPose) {
  const Model& model = seed_model();
  StreamSettings s;
  StreamState state;
  ASSERT_EQ(start_stream(model, s, Pose{}, state), Status::Ok);
  StreamOutput out;
  EXPECT_EQ(stream_line(model, s, "garbage", AngleUnit::Degrees, state, out), Status::MalformedInput);
  EXPECT_EQ(out.action, CommandAction::Held);
  Vector6d home;
  LimitReport rep;
  ASSERT_EQ(motor_commands(model, Pose{}, s.strategy, home, rep), Status::Ok);
  EXPECT_EQ(out.command, home);
  Pose far;
  far.position.x() = 3.0;
  StreamState other;
  EXPECT_NE(start_stream(model, s, far, other), Status::Ok);
  EXPECT_FALSE(other.has_command);
}

// Steps towards a far target under both rate limits: every step respects them, every step lies
// inside the limits (forward kinematics of the command), and the target is reached exactly in
// about the time of the trapezoidal profile.
TEST(Stream, RateLimitsBoundEveryStepAndReachTheTargetInTheTrapezoidTime) {
  const Model& model = seed_model();
  const double vmax = 0.05, amax = 0.4;
  for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional}) {
    StreamSettings s = limited(vmax, amax);
    s.strategy = strategy;
    StreamState state;
    ASSERT_EQ(start_stream(model, s, Pose{}, state), Status::Ok);
    Pose target;
    target.position = Vector3d(0.2, -0.1, 0.1);
    target.rpy = Vector3d(deg2rad(10), 0, deg2rad(-20));
    Vector6d goal;
    LimitReport rep;
    ASSERT_EQ(motor_commands(model, target, strategy, goal, rep), Status::Ok);
    const double distance = (goal - state.command).cwiseAbs().maxCoeff();
    const double t_trapezoid = distance / vmax + vmax / amax;

    Vector6d previous = state.command, previous_v = Vector6d::Zero();
    StreamOutput out;
    int steps = 0, limited_steps = 0;
    double overshoot = 0;
    const Vector6d start = state.command;
    for (; steps < 100000; ++steps) {
      ASSERT_EQ(stream_pose(model, s, target, state, out), Status::Ok) << "step " << steps;
      const Vector6d v = (out.command - previous) / s.period;
      EXPECT_LE(v.cwiseAbs().maxCoeff(), vmax * (1 + 1e-9)) << "step " << steps;
      EXPECT_LE((v - previous_v).cwiseAbs().maxCoeff(), amax * s.period * (1 + 1e-9)) << "step " << steps;
      for (int i = 0; i < kLegs; ++i) {
        const double dir = goal[i] > start[i] ? 1 : -1;
        overshoot = std::max(overshoot, dir * (out.command[i] - goal[i]));
      }
      if (out.rate_limited) {
        ++limited_steps;
        // The limited command means a pose inside every limit.
        FkResult fk;
        const LengthKind kind = strategy == Strategy::Compensated ? LengthKind::Motor : LengthKind::Geometric;
        ASSERT_EQ(forward_kinematics(model, out.command, kind, Placement{}, fk), Status::Ok);
        LimitReport lim;
        EXPECT_EQ(check_limits(model, fk.legs, lim), Status::Ok);
      }
      previous_v = v;
      previous = out.command;
      if (!out.rate_limited) break;
    }
    EXPECT_EQ(out.command, goal);
    EXPECT_EQ(limited_steps, steps);
    // The longest leg follows the trapezoid to within a tick (measured: 1 tick in 10.6 s).
    EXPECT_NEAR(steps * s.period, t_trapezoid, 10 * s.period);
    // The discrete braking distance keeps the legs from passing the target (measured: 5e-8 m,
    // where the acceleration limit rounds the last tick).
    EXPECT_LE(overshoot, 5e-7);
  }
}

TEST(Stream, RateLimitedStepsOfAPlatformWithLengthOffsetsMeanPosesOnTheWay) {
  // The check of a limited step must read the command as the platform does: with offsets, a
  // conventional command is the real length minus delta. Steps from home towards a target must
  // mean poses between the two, not a pose delta away.
  ModelSpec spec = seed_model().spec();
  const std::array<double, kLegs> delta{2e-3, -2e-3, 1e-3, -1e-3, 2e-3, -2e-3};
  for (std::size_t i = 0; i < delta.size(); ++i) spec.legs[i].length_offset = delta[i];
  const Model model(spec);
  for (const Strategy strategy : {Strategy::Compensated, Strategy::Conventional}) {
    StreamSettings s = limited(0.05, 0.4);
    s.strategy = strategy;
    StreamState state;
    ASSERT_EQ(start_stream(model, s, Pose{}, state), Status::Ok);
    Pose target;
    target.position.z() = 0.01;
    StreamOutput out;
    ASSERT_EQ(stream_pose(model, s, target, state, out), Status::Ok);
    ASSERT_TRUE(out.rate_limited);
    // The pose of the first limited step: a few micrometres up from home, level.
    const Pose p = pose_from_placement(state.placement);
    EXPECT_GT(p.position.z(), 0.0);
    EXPECT_LT(p.position.z(), 1e-4);
    EXPECT_LT(p.position.head<2>().norm(), 1e-9);
    EXPECT_LT(p.rpy.norm(), 1e-9);
  }
}

TEST(Stream, RateLimitedHoldKeepsMovingTowardsTheLastValidTarget) {
  const Model& model = seed_model();
  StreamSettings s = limited(0.05, kInf);
  StreamState state;
  ASSERT_EQ(start_stream(model, s, Pose{}, state), Status::Ok);
  Pose up;
  up.position.z() = 0.1;
  StreamOutput out;
  ASSERT_EQ(stream_pose(model, s, up, state, out), Status::Ok);
  ASSERT_TRUE(out.rate_limited);
  const Vector6d first = out.command;
  ASSERT_EQ(stream_line(model, s, "not a pose", AngleUnit::Degrees, state, out), Status::MalformedInput);
  EXPECT_EQ(out.action, CommandAction::Held);
  EXPECT_TRUE(out.rate_limited);
  // Every leg moved on by vmax * period.
  EXPECT_NEAR((out.command - first).cwiseAbs().minCoeff(), 0.05 * s.period, 1e-15);
}

TEST(Stream, ALimitedStepThatFailsItsCheckIsHeldWithTheFailure) {
  const Model& model = seed_model();
  StreamSettings s = limited(0.05, kInf);
  s.fk.max_iterations = 1;
  s.fk.tolerance = 1e-300;  // cannot converge: the check of the step fails
  StreamState state;
  ASSERT_EQ(start_stream(model, s, Pose{}, state), Status::Ok);
  const Vector6d home = state.command;
  Pose up;
  up.position.z() = 0.1;
  StreamOutput out;
  EXPECT_EQ(stream_pose(model, s, up, state, out), Status::NoConvergence);
  EXPECT_EQ(out.action, CommandAction::Held);
  EXPECT_TRUE(out.rate_limited);
  EXPECT_EQ(out.command, home);
  EXPECT_EQ(state.velocity, Vector6d::Zero());
}

// ----- answer lines -----

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> cells(1);
  for (const char c : line) {
    if (c == ',')
      cells.emplace_back();
    else if (c != '\n')
      cells.back() += c;
  }
  return cells;
}

TEST(StreamOutputLine, CsvReadsBackToTheSameDoublesAndHasFixedColumns) {
  const Model& model = seed_model();
  std::mt19937_64 rng(kSeed + 402);
  StreamSettings s;
  StreamState state;
  StreamOutput out;
  std::array<char, kMaxOutputLength> buf{};
  const std::size_t header_columns = split_csv(std::string(kStreamCsvHeader)).size();
  for (int n = 0; n < 300; ++n) {
    const Pose p = random_pose(rng, 0.6, deg2rad(35));  // some outside the limits
    (void)stream_pose(model, s, p, state, out);
    const std::size_t len = format_stream_output(out, StreamFormat::Csv, buf);
    ASSERT_GT(len, 0u);
    const std::string line(buf.data(), len);
    ASSERT_EQ(line.back(), '\n');
    const auto cells = split_csv(line);
    ASSERT_EQ(cells.size(), header_columns) << line;
    EXPECT_EQ(cells[0], std::to_string(out.input));
    EXPECT_EQ(cells[1], to_string(out.status));
    EXPECT_EQ(cells[2], to_string(out.action));
    for (int i = 0; i < kLegs; ++i) {
      if (out.action == CommandAction::None) {
        EXPECT_TRUE(cells[3 + i].empty());
        continue;
      }
      double v = 0;
      const std::string& c = cells[3 + static_cast<std::size_t>(i)];
      ASSERT_EQ(std::from_chars(c.data(), c.data() + c.size(), v).ec, std::errc());
      EXPECT_EQ(v, out.command[i]);  // shortest form, exact
    }
    if (is_limit(out.status)) {
      EXPECT_EQ(cells[9], std::to_string(out.limit.leg + 1));
    }
    EXPECT_EQ(cells[12].empty(), out.status == Status::Ok);
  }
}

TEST(StreamOutputLine, JsonIsOneValidObjectWithTheSameFields) {
  const Model& model = seed_model();
  StreamSettings s;
  StreamState state;
  StreamOutput out;
  std::array<char, kMaxOutputLength> buf{};
  const std::vector<std::string> lines = {"0,0,0.1,0,0,10", "0,0,3,0,0,0", "0,0,x,0,0,0", "nan,0,0,0,0,0"};
  const std::vector<std::string> statuses = {"ok", "stroke_above_max", "malformed_input", "non_finite_input"};
  for (std::size_t k = 0; k < lines.size(); ++k) {
    (void)stream_line(model, s, lines[k], AngleUnit::Degrees, state, out);
    const std::size_t len = format_stream_output(out, StreamFormat::Json, buf);
    ASSERT_GT(len, 0u);
    const std::string line(buf.data(), len);
    SCOPED_TRACE(line);
    ASSERT_EQ(std::count(line.begin(), line.end(), '\n'), 1);
    const YAML::Node j = YAML::Load(line);
    EXPECT_EQ(j["input"].as<int>(), static_cast<int>(k + 1));
    EXPECT_EQ(j["status"].as<std::string>(), statuses[k]);
    EXPECT_EQ(j["command"].as<std::string>(), k == 0 ? "new" : "held");
    ASSERT_TRUE(j["m"].IsSequence());
    for (int i = 0; i < kLegs; ++i) EXPECT_EQ(j["m"][i].as<double>(), out.command[i]);
    EXPECT_EQ(j["leg"].IsNull(), k != 1);
    if (k == 2) {
      EXPECT_EQ(j["detail"].as<std::string>(), "field 3 (z) at column 5: not a number");
    }
  }
}

TEST(StreamOutputLine, EveryDetailIsFreeOfCommasAndQuotes) {
  std::array<char, kMaxOutputLength> buf{};
  const std::size_t columns = std::count(kStreamCsvHeader.begin(), kStreamCsvHeader.end(), ',');
  for (int st = 0; to_string(static_cast<Status>(st)) != "unknown"; ++st) {  // every status
    for (int e = 0; e <= static_cast<int>(LineError::OutOfRange); ++e) {
      for (const bool limited : {false, true}) {
        StreamOutput out;
        out.status = static_cast<Status>(st);
        out.parse = {static_cast<LineError>(e), e - 2, e};
        out.rate_limited = limited;
        const std::string line(buf.data(), format_stream_output(out, StreamFormat::Csv, buf));
        SCOPED_TRACE(line);
        EXPECT_EQ(static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')), columns);
        EXPECT_EQ(line.find('"'), std::string::npos);
        EXPECT_EQ(line.find("unknown"), std::string::npos);
      }
    }
  }
}

TEST(StreamOutputLine, LongestAnswerFitsAndShortBuffersAreRefused) {
  StreamOutput out;
  out.input = std::numeric_limits<std::uint64_t>::max();
  out.status = Status::SingularPlatform;  // the longest description
  out.action = CommandAction::Held;
  out.rate_limited = true;
  out.command.setConstant(-1.2345678901234567e-300);
  out.limit = {Status::SingularPlatform, 5, -2.2250738585072014e-308, -1.7976931348623157e308};
  std::array<char, kMaxOutputLength> buf{};
  for (const StreamFormat f : {StreamFormat::Csv, StreamFormat::Json}) {
    const std::size_t len = format_stream_output(out, f, buf);
    ASSERT_GT(len, 0u);
    EXPECT_LT(len, kMaxOutputLength * 3 / 4);  // a margin
    EXPECT_EQ(format_stream_output(out, f, std::span<char>(buf.data(), kMaxOutputLength - 1)), 0u);
  }
  out.status = Status::MalformedInput;
  out.parse = {LineError::MissingFields, 5, 1025};
  const std::size_t len = format_stream_output(out, StreamFormat::Csv, buf);
  EXPECT_NE(std::string(buf.data(), len).find("field 6 (yaw) at column 1025: missing"), std::string::npos);
}

}  // namespace
}  // namespace hexatwist::test
