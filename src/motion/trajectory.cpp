// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/motion/trajectory.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>

#include "hexatwist/error.hpp"
#include "motion/csv.hpp"

namespace hexatwist {
namespace {

// Largest number of poses a sweep or a resampling may produce (48 bytes each).
constexpr double kMaxSamples = static_cast<double>(kMaxTrajectorySamples);

void check_limit(double value, const char* name) {
  if (!std::isfinite(value)) throw Error(fmt::format("motion limits: {} must be finite, got {}", name, value));
  if (value <= 0.0) throw Error(fmt::format("motion limits: {} must be > 0, got {}", name, value));
}

}  // namespace

// ---- jerk-limited move ----------------------------------------------------------------------

JerkLimitedMove::JerkLimitedMove(double distance, const MotionLimits& limits) : distance_(distance), limits_(limits) {
  if (!std::isfinite(distance))
    throw Error(fmt::format("jerk-limited move: distance must be finite, got {}", distance));
  check_limit(limits.velocity, "velocity");
  check_limit(limits.acceleration, "acceleration");
  check_limit(limits.jerk, "jerk");
  sign_ = distance < 0.0 ? -1.0 : 1.0;
  length_ = std::abs(distance);
  if (length_ == 0.0) return;  // no motion: every segment has zero length

  const double V = limits.velocity, A = limits.acceleration, J = limits.jerk, D = length_;
  // The acceleration phase that reaches a peak velocity v (rest to v) covers v * (its duration)/2
  // and the deceleration phase the same, so the move covers D(v) = v * T_acc(v) without cruise;
  // D grows with v. Pick the largest peak velocity allowed: V if D(V) <= D (then cruise), else
  // the v with D(v) = D, with the acceleration limit reached (v >= A^2/J) or not.
  const double a_full = A * A / J;  // peak velocity at which the acceleration just reaches A
  if (V >= a_full) {
    t_jerk_ = A / J;
    t_accel_ = V / A - t_jerk_;
  } else {
    t_jerk_ = std::sqrt(V / J);
    t_accel_ = 0.0;
  }
  const bool cruise = V * (2.0 * t_jerk_ + t_accel_) <= D;
  if (!cruise) {
    if (D >= 2.0 * A * A * A / (J * J)) {
      // A reached, V not: v^2 + v A^2/J - A D = 0, the positive root in a cancellation-free form.
      t_jerk_ = A / J;
      const double v_peak = 2.0 * A * D / (a_full + std::sqrt(a_full * a_full + 4.0 * A * D));
      t_accel_ = std::max(0.0, v_peak / A - t_jerk_);
    } else {
      // Neither reached: D = 2 J t_jerk^3.
      t_jerk_ = std::cbrt(D / (2.0 * J));
      t_accel_ = 0.0;
    }
  }

  // Exact integration of the first three segments (jerk +J, 0, -J) from rest.
  const double tj = t_jerk_, ta = t_accel_;
  peak_accel_ = J * tj;
  v_[0] = 0.5 * J * tj * tj;
  p_[0] = J * tj * tj * tj / 6.0;
  v_[1] = v_[0] + peak_accel_ * ta;
  p_[1] = p_[0] + v_[0] * ta + 0.5 * peak_accel_ * ta * ta;
  v_[2] = v_[1] + peak_accel_ * tj - 0.5 * J * tj * tj;
  p_[2] = p_[1] + v_[1] * tj + 0.5 * peak_accel_ * tj * tj - J * tj * tj * tj / 6.0;
  // Cruise covers what the two ramps leave; none when V is not reached (the ramps meet).
  t_cruise_ = cruise ? std::max(0.0, (D - 2.0 * p_[2]) / v_[2]) : 0.0;
  duration_ = 2.0 * (2.0 * tj + ta) + t_cruise_;
  if (!std::isfinite(duration_) || !std::isfinite(p_[2]) || !std::isfinite(v_[2]) || !(v_[2] > 0.0))
    throw Error(
        fmt::format("jerk-limited move: distance {} with limits velocity {}, acceleration {}, jerk {} is out of the "
                    "range of a double",
                    distance, V, A, J));
}

MotionSample JerkLimitedMove::first_half(double t) const noexcept {
  const double J = limits_.jerk, tj = t_jerk_;
  const double t1 = tj, t2 = tj + t_accel_, t3 = 2.0 * tj + t_accel_;
  MotionSample s;
  if (t < t1) {
    s.jerk = J;
    s.acceleration = J * t;
    s.velocity = 0.5 * J * t * t;
    s.position = J * t * t * t / 6.0;
  } else if (t < t2) {
    const double u = t - t1;
    s.acceleration = peak_accel_;
    s.velocity = v_[0] + peak_accel_ * u;
    s.position = p_[0] + v_[0] * u + 0.5 * peak_accel_ * u * u;
  } else if (t <= t3) {  // a zero-length cruise: the midpoint belongs to a jerk segment
    const double u = t - t2;
    s.jerk = -J;
    s.acceleration = peak_accel_ - J * u;
    s.velocity = v_[1] + peak_accel_ * u - 0.5 * J * u * u;
    s.position = p_[1] + v_[1] * u + 0.5 * peak_accel_ * u * u - J * u * u * u / 6.0;
  } else {
    s.velocity = v_[2];
    s.position = p_[2] + v_[2] * (t - t3);
  }
  return s;
}

MotionSample JerkLimitedMove::sample(double t) const noexcept {
  if (length_ == 0.0) return {};
  if (std::isnan(t)) {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan, nan};
  }
  t = std::min(std::max(t, 0.0), duration_);
  MotionSample s;
  if (t <= 0.5 * duration_) {
    s = first_half(t);
  } else {
    // The deceleration mirrors the acceleration: p(T - u) = D - p(u), v even, a odd, j even.
    s = first_half(duration_ - t);
    s.position = length_ - s.position;
    s.acceleration = -s.acceleration;
  }
  s.position *= sign_;
  s.velocity *= sign_;
  s.acceleration *= sign_;
  s.jerk *= sign_;
  return s;
}

std::array<double, 8> JerkLimitedMove::switch_times() const noexcept {
  const double t3 = 2.0 * t_jerk_ + t_accel_;
  const double T = duration_;
  return {0.0, t_jerk_, t_jerk_ + t_accel_, t3, T - t3, T - t_jerk_ - t_accel_, T - t_jerk_, T};
}

// ---- fixed-period trajectories --------------------------------------------------------------

double Trajectory::duration() const noexcept {
  return poses.size() < 2 ? 0.0 : dt * static_cast<double>(poses.size() - 1);
}

namespace {

// Straight-line jerk-limited moves through `waypoints` with `dwell` before, between and after
// them (see waypoint_trajectory). Messages name no routine: the caller names its option or field.
Trajectory through_waypoints(std::span<const Vector6d> waypoints, const MotionLimits& limits, double dwell, double dt) {
  struct Stage {
    JerkLimitedMove move;
    double start_time;  // [s]
    Vector6d start;     // pose at the start of the move
    Vector6d unit;      // direction of the move (zero for a move of zero length)
  };
  std::vector<Stage> stages;
  double t = dwell;
  for (std::size_t k = 0; k + 1 < waypoints.size(); ++k) {
    const Vector6d delta = waypoints[k + 1] - waypoints[k];
    const double distance = delta.norm();
    Stage& s = stages.emplace_back(Stage{JerkLimitedMove(distance, limits), t, waypoints[k], Vector6d::Zero()});
    if (distance > 0.0) s.unit = delta / distance;
    t += s.move.duration() + dwell;
  }
  const double total = t;

  // Rounded up, but a total that is a whole number of dt up to rounding is not pushed one further.
  const double steps = std::ceil(total / dt - 1e-9);
  if (!(steps + 1.0 <= kMaxSamples))
    throw Error(
        fmt::format("the motion takes {:g} s: at a period of {:g} s that is more than {:.0f} samples (the "
                    "bound of one trajectory)",
                    total, dt, kMaxSamples));
  const auto n = static_cast<std::size_t>(std::max(steps, 1.0));

  Trajectory traj;
  traj.dt = dt;
  traj.poses.resize(n + 1);
  for (std::size_t k = 0; k < n; ++k) {
    const double tk = traj.time(k);
    // The move under way (or the last one begun): before it starts and after it ends the
    // clamped sample holds its start or end.
    const Stage* stage = &stages[0];
    for (const Stage& s : stages)
      if (tk >= s.start_time) stage = &s;
    traj.poses[k] = Pose::from_vector(stage->start + stage->unit * stage->move.sample(tk - stage->start_time).position);
  }
  traj.poses[n] = Pose::from_vector(waypoints.back());  // the end, exactly
  return traj;
}

void check_dwell_and_period(double dwell, double dt) {
  if (!std::isfinite(dwell) || dwell < 0.0)
    throw Error(fmt::format("dwell: expected a finite time >= 0 s, got {}", dwell));
  if (!std::isfinite(dt) || dt <= 0.0) throw Error(fmt::format("dt: expected a finite period > 0 s, got {}", dt));
}

}  // namespace

Trajectory sweep_trajectory(int coordinate, double amplitude, const MotionLimits& limits, double dwell, double dt) {
  if (coordinate < 0 || coordinate > 5)
    throw Error(fmt::format("coordinate: expected 0..5 (x, y, z, roll, pitch, yaw), got {}", coordinate));
  if (!std::isfinite(amplitude) || amplitude <= 0.0)
    throw Error(fmt::format("amplitude: expected a finite number > 0, got {}", amplitude));
  check_dwell_and_period(dwell, dt);
  // Three moves: 0 -> +a, +a -> -a, -a -> 0.
  std::array<Vector6d, 4> waypoints{Vector6d::Zero(), Vector6d::Zero(), Vector6d::Zero(), Vector6d::Zero()};
  waypoints[1][coordinate] = amplitude;
  waypoints[2][coordinate] = -amplitude;
  return through_waypoints(waypoints, limits, dwell, dt);
}

Trajectory waypoint_trajectory(std::span<const Vector6d> waypoints, const MotionLimits& limits, double dwell,
                               double dt) {
  if (waypoints.size() < 2) throw Error(fmt::format("expected at least 2 waypoints, got {}", waypoints.size()));
  for (std::size_t k = 0; k < waypoints.size(); ++k)
    if (!waypoints[k].allFinite()) throw Error(fmt::format("waypoint {} is not finite", k + 1));
  check_dwell_and_period(dwell, dt);
  return through_waypoints(waypoints, limits, dwell, dt);
}

// ---- CSV ------------------------------------------------------------------------------------

namespace {

// A header name and the factor from its unit to SI.
struct Unit {
  const char* header;
  double to_si;
};
struct ColumnSpec {
  const char* name;
  std::array<Unit, 3> units;  // {nullptr, 0} pads a column with fewer units
};

// Degrees to radians, as the factor of a unit suffix.
constexpr double kDeg = kPi / 180.0;

constexpr ColumnSpec kColumns[7] = {
    {"t", {{{"t", 1.0}, {"t_s", 1.0}, {nullptr, 0.0}}}},
    {"x", {{{"x", 1.0}, {"x_m", 1.0}, {"x_mm", 1e-3}}}},
    {"y", {{{"y", 1.0}, {"y_m", 1.0}, {"y_mm", 1e-3}}}},
    {"z", {{{"z", 1.0}, {"z_m", 1.0}, {"z_mm", 1e-3}}}},
    {"roll", {{{"roll", kDeg}, {"roll_deg", kDeg}, {"roll_rad", 1.0}}}},
    {"pitch", {{{"pitch", kDeg}, {"pitch_deg", kDeg}, {"pitch_rad", 1.0}}}},
    {"yaw", {{{"yaw", kDeg}, {"yaw_deg", kDeg}, {"yaw_rad", 1.0}}}},
};
constexpr const char* kHeaderWhat =
    "the header row t, x, y, z, roll, pitch, yaw (unit suffixes: t_s; _m or _mm; _deg or _rad)";

// The factor to SI of each column, from the header row.
std::array<double, 7> read_header(const detail::CsvReader& r, const detail::CsvLine& line) {
  const std::vector<detail::CsvCell> cells = detail::split_csv(line.text);
  std::array<double, 7> factor{};
  for (std::size_t c = 0; c < 7; ++c) {
    const ColumnSpec& spec = kColumns[c];
    // "'x', 'x_m' or 'x_mm'"
    std::string names;
    for (std::size_t k = 0; k < spec.units.size() && spec.units[k].header != nullptr; ++k) {
      const bool last = k + 1 == spec.units.size() || spec.units[k + 1].header == nullptr;
      names += fmt::format("{}'{}'", k == 0 ? "" : last ? " or " : ", ", spec.units[k].header);
    }
    if (c >= cells.size())
      r.fail(line.number, line.text, line.text.size(), spec.name,
             fmt::format("missing from the header; expected {} as column {} of {}", names, c + 1, kHeaderWhat));
    const detail::CsvCell& cell = cells[c];
    bool found = false;
    for (const Unit& u : spec.units)
      if (u.header != nullptr && cell.text == u.header) factor[c] = u.to_si, found = true;
    if (!found) {
      const char* hint = cell.text.find(';') != std::string_view::npos ? " (cells are separated by commas)" : "";
      r.fail(line.number, line.text, cell.offset, spec.name,
             fmt::format("expected {} as column {} of {}, got '{}'{}", names, c + 1, kHeaderWhat,
                         detail::printable(cell.text, 40), hint));
    }
  }
  if (cells.size() > 7)
    r.fail(line.number, line.text, cells[7].offset, "yaw",
           fmt::format("extra column '{}' after 'yaw'; expected exactly 7 columns t, x, y, z, roll, pitch, yaw",
                       detail::printable(cells[7].text, 40)));
  return factor;
}

// The pose of a data row in SI units; its time in `t`.
Vector6d read_row(const detail::CsvReader& r, const detail::CsvLine& line, const std::array<double, 7>& factor,
                  double& t) {
  const std::vector<detail::CsvCell> cells = detail::split_csv(line.text);
  if (cells.size() < 7)
    r.fail(line.number, line.text, line.text.size(), kColumns[cells.size()].name,
           fmt::format("missing; the row has {} cells, expected 7 (t, x, y, z, roll, pitch, yaw)", cells.size()));
  if (cells.size() > 7)
    r.fail(line.number, line.text, cells[7].offset, "yaw",
           fmt::format("extra cell '{}' after 'yaw'; the row has {} cells, expected 7 (t, x, y, z, roll, pitch, yaw)",
                       detail::printable(cells[7].text, 40), cells.size()));
  t = r.number(line, cells[0], kColumns[0].name, factor[0]);
  Vector6d q;
  for (std::size_t c = 1; c < 7; ++c)
    q[static_cast<int>(c) - 1] = r.number(line, cells[c], kColumns[c].name, factor[c]);
  return q;
}

}  // namespace

TimedPoses parse_trajectory_csv(std::string_view text, std::string_view source) {
  const detail::CsvReader r(source);
  text = detail::without_bom(text);
  const std::vector<detail::CsvLine> lines = detail::csv_lines(text);
  if (lines.empty())
    r.fail(1, {}, 0, "t",
           fmt::format("{}; expected {} and at least 2 data rows",
                       text.empty() ? "empty text" : "no header row (only blank or comment lines)", kHeaderWhat));
  const std::array<double, 7> factor = read_header(r, lines[0]);

  TimedPoses out;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const detail::CsvLine& line = lines[k];
    double t = 0.0;
    const Vector6d q = read_row(r, line, factor, t);
    if (!out.t.empty() && !(t > out.t.back()))
      r.fail(line.number, line.text, detail::split_csv(line.text)[0].offset, "t",
             fmt::format("time {} s is not after {} s on line {}; times must be strictly increasing", t, out.t.back(),
                         out.lines.back()));
    out.t.push_back(t);
    out.poses.push_back(Pose::from_vector(q));
    out.lines.push_back(line.number);
  }
  if (out.t.size() < 2)
    r.fail(lines.back().number, lines.back().text, 0, "t",
           fmt::format("{} data row{}; a trajectory needs at least 2 rows (times)", out.t.size(),
                       out.t.size() == 1 ? "" : "s"));
  return out;
}

// ---- resampling -----------------------------------------------------------------------------

namespace {

// The monotone piecewise-cubic Hermite interpolant of Fritsch and Carlson ("PCHIP") through
// the samples, per coordinate. Messages name the sample (line), not this routine: the caller
// names the option or file (resample, interpolate).
class Pchip {
 public:
  explicit Pchip(const TimedPoses& samples) : samples_(samples), t_(samples.t) {
    const std::size_t m = t_.size();
    if (m != samples.poses.size()) throw Error(fmt::format("{} times but {} poses", m, samples.poses.size()));
    if (m < 2) throw Error(fmt::format("need at least 2 samples, got {}", m));
    const auto at = [&](std::size_t i) { return where(i); };
    q_.resize(m);
    for (std::size_t i = 0; i < m; ++i) {
      if (!std::isfinite(t_[i])) throw Error(fmt::format("{}: time is not finite ({})", at(i), t_[i]));
      if (i > 0 && !(t_[i] > t_[i - 1]))
        throw Error(fmt::format("{}: time {} s is not after {} s", at(i), t_[i], t_[i - 1]));
      if (!samples.poses[i].is_finite()) throw Error(fmt::format("{}: pose is not finite", at(i)));
      q_[i] = samples.poses[i].to_vector();
    }

    // Slopes: a weighted harmonic mean of the two neighbouring secants where they agree in sign,
    // else 0; at the ends, the three-point one-sided slope, limited the same way. The curve then
    // never overshoots the samples: a hold stays a hold and a move does not swing past its end
    // (waypoint files are common input). Lines are reproduced exactly.
    slope_.resize(m);
    const auto secant = [&](std::size_t i) -> Vector6d { return (q_[i + 1] - q_[i]) / (t_[i + 1] - t_[i]); };
    if (m == 2) {
      slope_[0] = slope_[1] = secant(0);
      return;
    }
    for (std::size_t i = 1; i + 1 < m; ++i) {
      const double h0 = t_[i] - t_[i - 1], h1 = t_[i + 1] - t_[i];
      const Vector6d d0 = secant(i - 1), d1 = secant(i);
      const double w0 = 2.0 * h1 + h0, w1 = h1 + 2.0 * h0;
      for (int c = 0; c < 6; ++c) slope_[i][c] = d0[c] * d1[c] > 0.0 ? (w0 + w1) / (w0 / d0[c] + w1 / d1[c]) : 0.0;
    }
    const auto end_slope = [](double h0, double h1, double d0, double d1) {
      double e = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
      if (e * d0 <= 0.0) return 0.0;
      if (d0 * d1 <= 0.0 && std::abs(e) > 3.0 * std::abs(d0)) e = 3.0 * d0;
      return e;
    };
    const Vector6d a0 = secant(0), a1 = secant(1), z0 = secant(m - 2), z1 = secant(m - 3);
    for (int c = 0; c < 6; ++c) {
      slope_[0][c] = end_slope(t_[1] - t_[0], t_[2] - t_[1], a0[c], a1[c]);
      slope_[m - 1][c] = end_slope(t_[m - 1] - t_[m - 2], t_[m - 2] - t_[m - 3], z0[c], z1[c]);
    }
  }

  // The pose at `tk` in [t.front(), t.back()]; within `snap` of a sample time, that sample's pose.
  // `i` is a hint: the interval [t[i], t[i+1]] searched from (advanced as tk grows).
  Pose at(double tk, double snap, std::size_t& i) const {
    const std::size_t m = t_.size();
    if (i + 1 >= m || t_[i] > tk + snap) i = 0;
    while (i + 2 < m && t_[i + 1] <= tk + snap) ++i;
    if (std::abs(tk - t_[i]) <= snap) return samples_.poses[i];
    if (std::abs(tk - t_[i + 1]) <= snap) return samples_.poses[i + 1];
    // Cubic Hermite on [t[i], t[i+1]] in s = (t - t[i]) / h.
    const double h = t_[i + 1] - t_[i];
    const double s = std::clamp((tk - t_[i]) / h, 0.0, 1.0);
    const double s2 = s * s, s3 = s2 * s;
    const double h00 = 2.0 * s3 - 3.0 * s2 + 1.0, h10 = s3 - 2.0 * s2 + s;
    const double h01 = -2.0 * s3 + 3.0 * s2, h11 = s3 - s2;
    const Vector6d q = h00 * q_[i] + h10 * h * slope_[i] + h01 * q_[i + 1] + h11 * h * slope_[i + 1];
    // Finite samples whose differences or rates overflow a double (1e308 m next to 0 m) give an
    // infinite slope: no pose can be interpolated there.
    if (!q.allFinite())
      throw Error(
          fmt::format("between {} and {}: the interpolation overflows a double (a value or its rate of "
                      "change beyond 1e308)",
                      where(i), where(i + 1)));
    return Pose::from_vector(q);
  }

 private:
  // Where a sample came from, for messages.
  std::string where(std::size_t i) const {
    return i < samples_.lines.size() ? fmt::format("sample {} (line {})", i, samples_.lines[i])
                                     : fmt::format("sample {}", i);
  }

  const TimedPoses& samples_;
  const std::vector<double>& t_;
  std::vector<Vector6d> q_, slope_;
};

}  // namespace

std::string_view check_trajectory_samples(double t0, double dt, std::size_t samples) noexcept {
  // Beyond 1e9 s (31 years) a start time leaves no sub-microsecond resolution to the samples' times.
  if (!(std::abs(t0) <= 1e9)) return "t0: expected a start time within +-1e9 s";
  if (!(dt > 0.0 && std::isfinite(dt))) return "dt: expected a finite sample period > 0 [s]";
  if (samples < 2) return "poses: expected at least 2 poses";
  if (samples > kMaxTrajectorySamples)
    return "poses: more than 1,000,000 samples in one trajectory (kMaxTrajectorySamples)";
  return {};
}

Trajectory resample(const TimedPoses& samples, double dt) {
  if (!std::isfinite(dt) || dt <= 0.0) throw Error(fmt::format("dt: expected a finite period > 0 s, got {}", dt));
  const Pchip curve(samples);
  const std::vector<double>& t = samples.t;
  const double span = t.back() - t.front();
  // The grid covers the whole span: a last time between two ticks is reached on the next tick
  // (which holds the last pose) instead of being dropped.
  const double steps = std::ceil(span / dt - 1e-9);
  if (!(steps + 1.0 <= kMaxSamples))
    throw Error(
        fmt::format("its {:g} s at a period of {:g} s are more than {:.0f} samples (the bound of one "
                    "trajectory)",
                    span, dt, kMaxSamples));
  const auto n = static_cast<std::size_t>(steps);

  Trajectory traj;
  traj.t0 = t.front();
  traj.dt = dt;
  traj.poses.resize(n + 1);
  const double snap = 1e-9 * dt;  // a grid time this close to an input time is that time
  std::size_t i = 0;              // interval [t[i], t[i+1]] of the current grid time
  for (std::size_t k = 0; k <= n; ++k) traj.poses[k] = curve.at(std::min(traj.time(k), t.back()), snap, i);
  return traj;
}

std::vector<Pose> interpolate(const TimedPoses& samples, std::span<const double> times) {
  const Pchip curve(samples);
  std::vector<Pose> poses;
  poses.reserve(times.size());
  std::size_t i = 0;
  for (std::size_t k = 0; k < times.size(); ++k) {
    const double tk = times[k];
    if (!(tk >= samples.t.front() && tk <= samples.t.back()))
      throw Error(fmt::format("time {} s (number {}) is outside the samples' span [{}, {}] s", tk, k + 1,
                              samples.t.front(), samples.t.back()));
    poses.push_back(curve.at(tk, 0.0, i));
  }
  return poses;
}

std::string format_trajectory_csv(const Trajectory& trajectory, std::size_t every) {
  fmt::memory_buffer b;
  fmt::format_to(std::back_inserter(b), "t_s,x_m,y_m,z_m,roll_rad,pitch_rad,yaw_rad\n");
  if (trajectory.poses.empty()) return fmt::to_string(b);
  const std::size_t last = trajectory.poses.size() - 1;
  const std::size_t step = std::max<std::size_t>(every, 1);
  for (std::size_t k = 0;; k = std::min(k + step, last)) {
    const Vector6d q = trajectory.poses[k].to_vector();
    fmt::format_to(std::back_inserter(b), "{},{},{},{},{},{},{}\n", trajectory.time(k), q[0], q[1], q[2], q[3], q[4],
                   q[5]);
    if (k == last) break;
  }
  return fmt::to_string(b);
}

TimedPoses timed_poses(const Trajectory& trajectory) {
  TimedPoses out;
  out.poses = trajectory.poses;
  out.t.resize(trajectory.poses.size());
  for (std::size_t k = 0; k < out.t.size(); ++k) out.t[k] = trajectory.time(k);
  return out;
}

}  // namespace hexatwist
