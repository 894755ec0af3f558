// SPDX-License-Identifier: BSD-3-Clause
// Pose trajectories: jerk-limited rest-to-rest moves, the seed paper's sweep test motion, poses
// read from CSV text and their resampling onto a fixed period. Reading files is the caller's job.
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "hexatwist/kinematics/pose.hpp"

namespace hexatwist {

/// Limits of a jerk-limited move along one coordinate (units of the coordinate per s, s^2, s^3;
/// all > 0).
struct MotionLimits {
  double velocity = 0.0;      ///< largest |velocity| [unit/s]
  double acceleration = 0.0;  ///< largest |acceleration| [unit/s^2]
  double jerk = 0.0;          ///< largest |jerk| [unit/s^3]
};

/// One instant of a 1-D profile.
struct MotionSample {
  double position = 0.0;      ///< [unit]
  double velocity = 0.0;      ///< [unit/s]
  double acceleration = 0.0;  ///< [unit/s^2]
  double jerk = 0.0;          ///< [unit/s^3]; at a switching instant, the value of one adjoining segment
};

/// A rest-to-rest move over `distance` (any sign, 0 allowed) with the seven-segment ("double S")
/// jerk-limited profile: the shortest such move under the limits. Handles the cases where the
/// maximum velocity and/or the maximum acceleration is not reached.
///
/// Segments: jerk +J, 0, -J (acceleration), cruise, jerk -J, 0, +J (deceleration), each possibly of
/// zero length; the deceleration mirrors the acceleration, so position(T - t) = distance -
/// position(t) and the move ends exactly at `distance`.
class JerkLimitedMove {
 public:
  /// The fastest move over `distance` [unit] under `limits`. Throws hexatwist::Error for a
  /// non-finite distance or a non-positive / non-finite limit, naming the field
  /// ("motion limits: jerk must be > 0, got -1"), or if the move's times overflow a double.
  JerkLimitedMove(double distance, const MotionLimits& limits);

  /// Length of the move [s]; 0 for a zero distance.
  double duration() const noexcept { return duration_; }
  /// Signed distance of the move [unit].
  double distance() const noexcept { return distance_; }
  /// The limits the move was planned for.
  const MotionLimits& limits() const noexcept { return limits_; }

  /// Position relative to the start [unit], velocity, acceleration and jerk at time `t` [s], `t`
  /// clamped to [0, duration]; a NaN `t` gives NaN values (zeros for a zero distance). Exact
  /// evaluation of the piecewise polynomial; real-time safe (no allocation).
  MotionSample sample(double t) const noexcept;

  /// The eight segment boundaries [s]: 0, the ends of the seven segments in order (the last is
  /// `duration()`); a segment that is not needed has zero length (two equal boundaries).
  std::array<double, 8> switch_times() const noexcept;

 private:
  // First half of the move (|distance|, positive direction) at 0 <= t <= duration / 2.
  MotionSample first_half(double t) const noexcept;

  double distance_ = 0.0;
  MotionLimits limits_;
  double sign_ = 1.0;        // sign of the distance
  double length_ = 0.0;      // |distance| [unit]
  double t_jerk_ = 0.0;      // each constant-jerk segment [s]
  double t_accel_ = 0.0;     // the constant-acceleration segment [s]
  double t_cruise_ = 0.0;    // the constant-velocity segment [s]
  double duration_ = 0.0;    // [s]
  double peak_accel_ = 0.0;  // [unit/s^2]
  // State at the end of segments 1, 2 and 3 (the first half of the move).
  std::array<double, 3> p_{}, v_{};
};

/// Most samples of one trajectory the library makes or runs (sweep_trajectory, waypoint_trajectory,
/// resample; simulate and size_motors refuse longer ones): 1,000,000, e.g. 1000 s at a 1 kHz control
/// rate. The bound fits a machine of 2 cores and 24 GB: `hexatwist simulate` on a trajectory this
/// long holds about 3 GB (three simulations and their CSVs) for about 2 minutes, `dynamics` about
/// 1.4 GB (measured at 10^5 samples: 300 MB and 11 s, 140 MB and 2 s).
inline constexpr std::size_t kMaxTrajectorySamples = 1'000'000;

/// A pose trajectory sampled at a fixed period: poses[k] is the pose at time t0 + k*dt.
struct Trajectory {
  double t0 = 0.0;          ///< time of the first pose [s]
  double dt = 0.0;          ///< sample period [s]
  std::vector<Pose> poses;  ///< pose relative to home [m, rad]

  /// Time of poses[k] [s].
  double time(std::size_t k) const noexcept { return t0 + dt * static_cast<double>(k); }
  /// dt * (size - 1) [s]; 0 if there are fewer than 2 poses.
  double duration() const noexcept;
};

/// Why a trajectory of `samples` poses from `t0` [s] every `dt` [s] cannot be simulated or sized
/// (empty if it can), as "t0: ...", "dt: ..." or "poses: ...": |t0| <= 1e9 s (the samples' times
/// keep sub-microsecond resolution), dt finite and > 0, at least 2 and at most
/// kMaxTrajectorySamples poses. Checked before the poses take any memory.
[[nodiscard]] std::string_view check_trajectory_samples(double t0, double dt, std::size_t samples) noexcept;

/// The seed paper's test motion along one pose coordinate (0..5 = x, y, z, roll, pitch, yaw):
/// at rest for `dwell` [s], home -> +amplitude, dwell, +amplitude -> -amplitude, dwell,
/// -amplitude -> home, dwell; each move a JerkLimitedMove under `limits` [m or rad per s, s^2, s^3].
/// `amplitude` [m or rad] > 0. Sampled every `dt` [s] from t0 = 0: the total duration is rounded
/// up to a whole number of dt (within 1e-9 dt) and the last pose is exactly home. Throws
/// hexatwist::Error on a bad coordinate index, amplitude <= 0 or non-finite, dwell < 0 or
/// non-finite, dt <= 0 or non-finite, bad limits, or more than kMaxTrajectorySamples samples.
Trajectory sweep_trajectory(int coordinate, double amplitude, const MotionLimits& limits, double dwell, double dt);

/// Straight-line moves through `waypoints` ([x, y, z, roll, pitch, yaw] relative to home [m, rad],
/// at least 2): at rest at the first for `dwell` [s], then to each next one along the straight line
/// between them in pose coordinates, each a JerkLimitedMove over the Euclidean distance between
/// the two poses under `limits` (so give waypoints that differ in translations only, or in
/// rotations only, for limits in one unit), with `dwell` after each. Sampled every `dt` [s] from
/// t0 = 0 as sweep_trajectory is (which is this function through 0, +a, -a, 0 on one coordinate);
/// the last pose is exactly the last waypoint. Throws hexatwist::Error for fewer than 2 or
/// non-finite waypoints, and as sweep_trajectory for the rest.
Trajectory waypoint_trajectory(std::span<const Vector6d> waypoints, const MotionLimits& limits, double dwell,
                               double dt);

/// Poses at arbitrary strictly increasing times, as read from a file.
struct TimedPoses {
  std::vector<double> t;    ///< times [s], strictly increasing
  std::vector<Pose> poses;  ///< pose at each time, relative to home [m, rad]
  std::vector<int> lines;   ///< source line of each row (1-based), for messages; may be empty
};

/// Parses CSV text with a header row naming the columns t, x, y, z, roll, pitch, yaw in this
/// order. Each header name may carry a unit suffix: t or t_s (seconds); x/y/z: no suffix or _m =
/// metres, _mm = millimetres; roll/pitch/yaw: no suffix or _deg = degrees, _rad = radians (no
/// suffix = m and degrees, as a person types them; hexatwist's own CSV output uses _m/_rad so it
/// reads back). Cells are separated by commas, without quoting; whitespace around cells is
/// ignored; blank lines and lines whose first non-blank character is '#' are skipped; CRLF line
/// ends and a leading UTF-8 byte-order mark are accepted; extra columns are an error.
/// Returned values are SI (s, m, rad). `source` names the text in messages (a file name).
/// Throws hexatwist::Error with one line "source:line:column: column 'pitch': expected a number,
/// got 'abc'" (column = 1-based character column of the cell) for: a missing or wrong header,
/// a wrong number of cells, a non-numeric or non-finite cell, a time not strictly increasing,
/// fewer than 2 data rows, empty text.
TimedPoses parse_trajectory_csv(std::string_view text, std::string_view source);

/// The trajectory as CSV text that parse_trajectory_csv reads back to the same doubles: the header
/// `t_s,x_m,y_m,z_m,roll_rad,pitch_rad,yaw_rad` (SI), then one row every `every` samples (>= 1) and
/// the last sample, numbers in their shortest exact form. Rests stay exact (the interpolation is
/// flat between equal samples), so a run written at a tracker's rate keeps its points at rest.
std::string format_trajectory_csv(const Trajectory& trajectory, std::size_t every = 1);

/// Resamples every `dt` [s] from t.front() to t.back() (t0 = t.front(); the last sample at, or
/// within dt after, t.back(), holding the last pose: a last time between two ticks is not lost) with the monotone
/// piecewise-cubic Hermite interpolation of Fritsch and Carlson ("PCHIP") per coordinate: C1, and never beyond the
/// samples (a hold stays flat, a move does not overshoot its end), so waypoint files are safe. Lines are reproduced
/// exactly; the acceleration jumps at the samples, so sparse files show up in the servo's
/// acceleration feed-forward (give samples at the control rate for the smoothest run). A grid
/// time within 1e-9 dt of an input time gives that input pose exactly. Angles are interpolated as
/// given (no wrapping at ±pi). Throws hexatwist::Error if dt <= 0 or non-finite, fewer than 2
/// samples, t and poses differ in size, times are not finite and strictly increasing, a pose is
/// not finite, more than kMaxTrajectorySamples samples would result, or the interpolation overflows a double
/// (finite samples whose difference or rate of change is beyond 1e308): it never returns a
/// non-finite pose.
Trajectory resample(const TimedPoses& samples, double dt);

/// The poses at `times` [s] on the curve that `resample` samples (the same monotone cubic through
/// `samples`), for times off a fixed grid, e.g. a tracker's. Each time must lie within
/// [t.front(), t.back()]; a time equal to a sample's gives that sample's pose exactly. Throws
/// hexatwist::Error as resample does, and for a time outside the span or not finite.
std::vector<Pose> interpolate(const TimedPoses& samples, std::span<const double> times);

/// The samples of a fixed-period trajectory with their times (for `interpolate`; no source lines).
TimedPoses timed_poses(const Trajectory& trajectory);

}  // namespace hexatwist
