// SPDX-License-Identifier: BSD-3-Clause
// The real-time command stream: one pose in, one checked set of six motor commands out, with a
// policy for rejected poses and optional per-leg rate limits; and the text protocol of
// `hexatwist stream` (a pose line in, a CSV or JSON line out).
//
// Every function here is noexcept, allocates nothing, takes no lock and does no I/O: call it from
// your own servo thread (examples/03_realtime_loop.cpp). The guarantee it gives: a command it
// emits lies inside every limit of the model (stroke, U-joint bend and singularity), whatever the
// input; a rejected input is answered with its reason, never with a new command.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string_view>

#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/kinematics/forward.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"

namespace hexatwist {

// ---------------------------------------------------------------------------------------------
// Reading a pose line
// ---------------------------------------------------------------------------------------------

/// Units of the angles of a pose line; positions are always metres.
enum class AngleUnit {
  Degrees,  ///< x,y,z [m], roll,pitch,yaw [deg] (what a person types)
  Radians,  ///< x,y,z [m], roll,pitch,yaw [rad] (SI)
};

/// What is wrong with a pose line that could not be read.
enum class LineError {
  None = 0,
  Empty,          ///< the line holds nothing but blanks
  TooLong,        ///< longer than kMaxLineLength
  MissingFields,  ///< fewer than six comma-separated fields
  ExtraFields,    ///< more than six fields
  EmptyField,     ///< a field holds nothing but blanks
  NotANumber,     ///< a field is not a number
  OutOfRange,     ///< a number too large for a double
};

/// Stable snake_case name of a line error (`"not_a_number"`).
std::string_view to_string(LineError e) noexcept;

/// Where and why a pose line failed to parse.
struct LineParse {
  LineError error = LineError::None;
  int field = -1;  ///< offending field, 0-based (0 = x ... 5 = yaw); -1 for the whole line
  int column = 0;  ///< 1-based character position of the offending field (0 for the whole line)
};

/// Longest pose line accepted [characters].
inline constexpr std::size_t kMaxLineLength = 1024;

/// Reads "x,y,z,roll,pitch,yaw": six comma-separated numbers, blanks around fields allowed, a
/// trailing carriage return and/or line feed ignored, a leading '+' accepted. "nan" and "inf" are read as numbers:
/// the command check rejects them (Status::NonFiniteInput), so that the status says what is wrong.
/// Returns false and fills `where` on a malformed line; `pose` is written only on success.
[[nodiscard]] bool parse_pose_line(std::string_view line, AngleUnit unit, Pose& pose, LineParse& where) noexcept;

// ---------------------------------------------------------------------------------------------
// The command stream
// ---------------------------------------------------------------------------------------------

/// What to answer a rejected input with.
enum class RejectPolicy {
  Hold,  ///< repeat the last valid command (moving on towards the last valid target when rate-limited)
  Skip,  ///< answer with the status and no command
};

/// Settings of a stream (validate once with `check_stream_settings`, outside the real-time loop).
struct StreamSettings {
  Strategy strategy = Strategy::Compensated;
  RejectPolicy on_reject = RejectPolicy::Hold;
  double period = 1e-3;  ///< time between two inputs, used by the rate limits [s]
  double max_velocity = std::numeric_limits<double>::infinity();      ///< per-leg command rate [m/s]
  double max_acceleration = std::numeric_limits<double>::infinity();  ///< per-leg command acceleration [m/s^2]
  FkOptions fk;  ///< forward kinematics that checks a rate-limited command
  /// The legs' conditions for the compensated commands of a model with leg effects (theory §4b):
  /// each leg's temperature [degC] (NaN = the reference) and force [N] (NaN = the static force of
  /// the configuration's load at the pose); the play's directions are the stream's own.
  LegInputs inputs;

  /// True if either rate limit is finite.
  bool rate_limited() const noexcept;
};

/// Empty if the settings are usable, else a one-sentence reason naming the field
/// ("max_velocity must be positive"; the FK options as check_fk_options). Not real-time (may be called anywhere).
std::string_view check_stream_settings(const StreamSettings& settings) noexcept;

/// The same, and that a finite rate limit can bind on `model`: one period's step at max_velocity
/// (or max_acceleration times the period squared) shorter than the stroke. start_stream and
/// stream_pose do not check it; the CLI and Python call this before streaming.
std::string_view check_stream_settings(const Model& model, const StreamSettings& settings) noexcept;

/// State of one stream (caller-owned workspace; one per stream, no sharing between threads).
struct StreamState {
  bool has_command = false;              ///< a valid command was emitted (or the stream was started)
  Vector6d command = Vector6d::Zero();   ///< last emitted command [m]
  Vector6d velocity = Vector6d::Zero();  ///< its rate of change [m/s]
  Vector6d target = Vector6d::Zero();    ///< command of the last accepted pose [m]
  Placement placement;                   ///< pose the last emitted command means (warm start for FK)
  Placement target_placement;            ///< the last accepted pose
  std::uint64_t inputs = 0;              ///< inputs processed
  PlayState play;                        ///< each leg's direction of motion (start_stream: homing's)
  FkResult fk;                           ///< scratch
};

/// What was done with the command this time.
enum class CommandAction {
  New,   ///< a new command (for this pose, or a rate-limited step towards it)
  Held,  ///< the last valid command, repeated (or a rate-limited step towards the last valid target)
  None,  ///< no command (Skip policy, or no valid command yet)
};

/// Stable name of an action (`"new"`, `"held"`, `"none"`).
std::string_view to_string(CommandAction a) noexcept;

/// Answer to one input.
struct StreamOutput {
  std::uint64_t input = 0;     ///< 1-based number of the input (its line or datagram)
  Status status = Status::Ok;  ///< Ok, or why the input was rejected
  CommandAction action = CommandAction::None;
  bool rate_limited = false;            ///< the command was slowed down by the rate limits
  Vector6d command = Vector6d::Zero();  ///< the command to send [m]; meaningful unless action is None
  LimitReport limit;                    ///< which leg broke which limit, when status is a limit
  LineParse parse;                      ///< where the line is malformed, when status is MalformedInput
};

/// Starts (or restarts) a stream at a pose the platform stands at, e.g. home: its command becomes
/// the last valid command, the velocity zero. Returns the pose's status; on failure the stream is
/// left empty (no command to hold).
[[nodiscard]] Status start_stream(const Model& model, const StreamSettings& settings, const Pose& pose,
                                  StreamState& state) noexcept;

/// One input pose: checks it, forms its command for the strategy (Eq. 11-12), applies the rate
/// limits (a limited step is checked again through forward kinematics) and fills `out`.
/// Returns `out.status`.
[[nodiscard]] Status stream_pose(const Model& model, const StreamSettings& settings, const Pose& pose,
                                 StreamState& state, StreamOutput& out) noexcept;

/// One input line: parse_pose_line, then stream_pose; a malformed line is rejected with
/// Status::MalformedInput and `out.parse` says where.
[[nodiscard]] Status stream_line(const Model& model, const StreamSettings& settings, std::string_view line,
                                 AngleUnit unit, StreamState& state, StreamOutput& out) noexcept;

// ---------------------------------------------------------------------------------------------
// Writing an answer line
// ---------------------------------------------------------------------------------------------

/// Output line format.
enum class StreamFormat { Csv, Json };

/// Header of the CSV format, with its newline.
inline constexpr std::string_view kStreamCsvHeader = "input,status,command,m1,m2,m3,m4,m5,m6,leg,value,bound,detail\n";

/// Longest line `format_stream_output` writes [characters].
inline constexpr std::size_t kMaxOutputLength = 640;

/// Writes one answer line (with its newline) into `buffer` and returns its length, or 0 if the
/// buffer is shorter than kMaxOutputLength. Numbers are written in the shortest form that reads
/// back to the same double.
///
/// CSV: `input,status,command,m1..m6,leg,value,bound,detail`, where command is new|held|none,
/// m1..m6 are empty when it is none, leg (1-based), value and bound are set for a limit, and
/// detail is a short comma-free text ("rate limited", "field 4 (roll): not_a_number at column 17").
/// JSON: one object per line with the same fields (`"m"` is an array of six or null).
std::size_t format_stream_output(const StreamOutput& out, StreamFormat format, std::span<char> buffer) noexcept;

}  // namespace hexatwist
