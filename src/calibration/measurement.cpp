#include "hexatwist/calibration/measurement.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>
#include <span>

#include <Eigen/Eigenvalues>

#include "calibration/random.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/kinematics/forward.hpp"
#include "motion/csv.hpp"

namespace hexatwist {
namespace {

// ---- point log --------------------------------------------------------------------------------

// A unit suffix of a header name and its factor to SI.
struct Suffix {
  const char* text;
  double to_si;
};
constexpr Suffix kTimeSuffixes[] = {{"_s", 1.0}, {"_ms", 1e-3}};
constexpr Suffix kLengthSuffixes[] = {{"_m", 1.0}, {"_mm", 1e-3}};

bool same_ignoring_case(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string unit_name(double to_si) { return to_si == 1.0 ? "m" : to_si == 1e-3 ? "mm" : fmt::format("{} m", to_si); }

// One wanted column: where it is in the header and the factor of its values to SI.
struct Column {
  std::string name;         // as the format names it
  std::size_t index = 0;    // cell index in the row
  double to_si = 1.0;       // factor to SI (0 while unknown)
  std::string_view header;  // the header cell
};

// Finds `name` in the header cells; the suffix found (or none) in `suffix`.
Column find_column(const detail::CsvReader& r, const detail::CsvLine& line, const std::vector<detail::CsvCell>& cells,
                   const std::string& name, std::span<const Suffix> suffixes, std::optional<Suffix>& suffix) {
  std::optional<std::size_t> found;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const std::string_view text = cells[c].text;
    std::optional<Suffix> here;
    bool match = same_ignoring_case(text, name);
    for (const Suffix& s : suffixes) {
      const std::size_t n = std::char_traits<char>::length(s.text);
      if (!match && text.size() == name.size() + n && same_ignoring_case(text.substr(0, name.size()), name) &&
          same_ignoring_case(text.substr(name.size()), s.text)) {
        match = true;
        here = s;
      }
    }
    if (!match) continue;
    if (found)
      r.fail(line.number, line.text, cells[c].offset, name,
             fmt::format("named twice in the header, as '{}' and '{}'", detail::printable(cells[*found].text, 40),
                         detail::printable(text, 40)));
    found = c;
    suffix = here;
  }
  if (!found) {
    std::string names;
    for (const detail::CsvCell& c : cells)
      names += fmt::format("{}'{}'", names.empty() ? "" : ", ", detail::printable(c.text, 40));
    std::string accepted = fmt::format("'{}'", name);
    for (const Suffix& s : suffixes) accepted += fmt::format(" or '{}{}'", name, s.text);
    r.fail(line.number, line.text, 0, name,
           fmt::format("not in the header ({}); expected a column named {} (case ignored)", names, accepted));
  }
  return {name, *found, 1.0, cells[*found].text};
}

}  // namespace

PointLog parse_point_log(std::string_view text, std::string_view source, const PointLogFormat& format) {
  const detail::CsvReader r(source);
  text = detail::without_bom(text);
  const std::vector<detail::CsvLine> lines = detail::csv_lines(text);
  if (lines.empty())
    r.fail(1, {}, 0, format.time_column,
           fmt::format("{}; expected a header row naming the columns {}, {}, {}, {} and at least {} points",
                       text.empty() ? "empty text" : "no header row (only blank or comment lines)", format.time_column,
                       format.x_column, format.y_column, format.z_column, kMinLogPoints));
  const detail::CsvLine& head = lines[0];
  const std::vector<detail::CsvCell> header = detail::split_csv(head.text);

  // The time column: seconds (or ms by suffix), or a bare sample index.
  std::optional<Suffix> suffix;
  Column time = format.indexed ? find_column(r, head, header, format.time_column, {}, suffix)
                               : find_column(r, head, header, format.time_column, kTimeSuffixes, suffix);
  time.to_si = suffix ? suffix->to_si : 1.0;
  // x, y, z: the length unit from the suffix or the format; both given must agree.
  std::array<Column, 3> xyz;
  const std::array<const std::string*, 3> names{&format.x_column, &format.y_column, &format.z_column};
  for (std::size_t a = 0; a < 3; ++a) {
    xyz[a] = find_column(r, head, header, *names[a], kLengthSuffixes, suffix);
    const std::size_t at = header[xyz[a].index].offset;
    if (suffix && format.length_unit > 0.0 && suffix->to_si != format.length_unit)
      r.fail(head.number, head.text, at, xyz[a].name,
             fmt::format("'{}' is in {} but the units were given as {}", detail::printable(xyz[a].header, 40),
                         unit_name(suffix->to_si), unit_name(format.length_unit)));
    if (!suffix && !(format.length_unit > 0.0))
      r.fail(head.number, head.text, at, xyz[a].name,
             fmt::format("units missing: '{}' has no unit suffix (_mm or _m) and no length unit was given (mm or m)",
                         detail::printable(xyz[a].header, 40)));
    xyz[a].to_si = suffix ? suffix->to_si : format.length_unit;
  }

  // A cell's column as messages name it: as the format does for the four read, else the header's.
  const auto column_name = [&](std::size_t c) -> std::string_view {
    if (c == time.index) return time.name;
    for (const Column& a : xyz)
      if (c == a.index) return a.name;
    return header[c].text;
  };

  PointLog log;
  log.source = std::string(source);
  log.indexed = format.indexed;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const detail::CsvLine& line = lines[k];
    const std::vector<detail::CsvCell> cells = detail::split_csv(line.text);
    if (cells.size() != header.size()) {
      const bool more = cells.size() > header.size();
      r.fail(line.number, line.text, more ? cells[header.size()].offset : line.text.size(),
             column_name(more ? header.size() - 1 : cells.size()),
             fmt::format("{}; the row has {} cells, the header on line {} has {}",
                         more ? fmt::format("extra cell '{}'", detail::printable(cells[header.size()].text, 40))
                              : std::string("missing"),
                         cells.size(), head.number, header.size()));
    }
    const detail::CsvCell& tc = cells[time.index];
    const double stamp = r.number(line, tc, time.name, time.to_si);
    if (format.indexed && stamp != std::floor(stamp))
      r.fail(line.number, line.text, tc.offset, time.name,
             fmt::format("expected a whole sample index, got '{}'", detail::printable(tc.text, 40)));
    Vector3d p;
    for (std::size_t a = 0; a < 3; ++a)
      p[static_cast<int>(a)] = r.number(line, cells[xyz[a].index], xyz[a].name, xyz[a].to_si);
    if (!log.stamps.empty() && !(stamp > log.stamps.back()))
      r.fail(line.number, line.text, tc.offset, time.name,
             format.indexed ? fmt::format("index {} is not after {} on line {}; indices must be strictly increasing",
                                          stamp, log.stamps.back(), log.lines.back())
                            : fmt::format("time {} s is not after {} s on line {}; times must be strictly increasing",
                                          stamp, log.stamps.back(), log.lines.back()));
    log.stamps.push_back(stamp);
    log.points_T.push_back(p);
    log.lines.push_back(line.number);
    int col = 1;
    for (std::size_t i = 0; i < tc.offset; ++i)
      if ((static_cast<unsigned char>(line.text[i]) & 0xC0) != 0x80) ++col;
    log.stamp_columns.push_back(col);
  }
  if (log.stamps.size() < kMinLogPoints)
    r.fail(lines.back().number, lines.back().text, 0, format.time_column,
           fmt::format("{} point{}; registering the tracker frame needs at least {}", log.stamps.size(),
                       log.stamps.size() == 1 ? "" : "s", kMinLogPoints));
  return log;
}

std::vector<double> trajectory_times(const PointLog& log, const TimeAlignment& alignment) {
  if (!std::isfinite(alignment.offset))
    throw Error(
        fmt::format("{}: time offset: expected a finite number of seconds, got {}", log.source, alignment.offset));
  if (log.indexed && !(std::isfinite(alignment.rate) && alignment.rate > 0.0))
    throw Error(fmt::format("{}: sample rate: expected > 0 Hz for a log of sample indices, got {}", log.source,
                            alignment.rate));
  std::vector<double> t(log.stamps.size());
  for (std::size_t k = 0; k < t.size(); ++k)
    t[k] = (log.indexed ? log.stamps[k] / alignment.rate : log.stamps[k]) - alignment.offset;
  return t;
}

// ---- calibration moves ------------------------------------------------------------------------

Trajectory measured_test_trajectory(const StudySpec& study, const StudyTest& test, const CalibrationSpec& calibration,
                                    double dt, double& calibration_end) {
  // Home, +step along x, y and z, home: four points that span a volume (theory §12).
  std::array<Vector6d, 5> stations{};
  for (Vector6d& s : stations) s.setZero();
  for (int a = 0; a < 3; ++a) stations[static_cast<std::size_t>(a) + 1][a] = calibration.step;
  Trajectory traj = waypoint_trajectory(stations, calibration.limits, calibration.dwell, dt);
  calibration_end = traj.time(traj.poses.size() - 1);
  const Trajectory sweep = test_trajectory(study, test, dt);
  // Both are at home where they meet: the sweep's first sample is the calibration's last.
  traj.poses.insert(traj.poses.end(), sweep.poses.begin() + 1, sweep.poses.end());
  return traj;
}

namespace {

// True if `pose` and the poses every 5 mm (5 mrad) on the straight line from `from` to it are
// inside every limit for the commands of `strategy`.
bool reachable_from(const Model& model, Strategy strategy, const Vector6d& from, const Vector6d& pose) {
  constexpr double kCheckStep = 5e-3;  // [m or rad]
  // A line of more than 10^6 checks (5 km or 5,000 rad) is no station move: not reachable. The
  // count is checked in double before the conversion, which would overflow an int.
  const double checks = std::ceil((pose - from).norm() / kCheckStep);
  if (!(checks <= 1e6)) return false;
  const int steps = std::max(1, static_cast<int>(checks));
  Vector6d command;
  LimitReport limit;
  for (int j = 1; j <= steps; ++j) {
    const Vector6d q = from + (pose - from) * (static_cast<double>(j) / steps);
    if (motor_commands(model, Pose::from_vector(q), strategy, command, limit) != Status::Ok) return false;
  }
  return true;
}

}  // namespace

Trajectory stations_trajectory(const Model& model, Strategy strategy, const StationsSpec& spec, double dt) {
  constexpr int kMaxStations = 10000, kMaxDraws = 1000;
  if (spec.count < 1 || spec.count > kMaxStations)
    throw Error(fmt::format("stations: expected 1 to {} stations, got {}", kMaxStations, spec.count));
  if (!(std::isfinite(spec.translation) && spec.translation >= 0.0 && std::isfinite(spec.rotation) &&
        spec.rotation >= 0.0))
    throw Error(
        fmt::format("stations: expected finite ranges >= 0, got ±{} m and ±{} rad", spec.translation, spec.rotation));
  detail::Random rng(spec.seed);
  std::vector<Vector6d> waypoints{Vector6d::Zero()};
  for (int i = 0; i < spec.count; ++i) {
    for (int draw = 0;; ++draw) {
      if (draw == kMaxDraws)
        throw Error(
            fmt::format("station {}: no pose within ±{} m and ±{} rad drawn in {} tries is "
                        "reachable inside the limits; give smaller ranges",
                        i + 1, spec.translation, spec.rotation, kMaxDraws));
      Vector6d q;
      for (int c = 0; c < 6; ++c) q[c] = (c < 3 ? spec.translation : spec.rotation) * rng.symmetric();
      // The way home from the last station is checked with it.
      if (reachable_from(model, strategy, waypoints.back(), q) &&
          (i + 1 < spec.count || reachable_from(model, strategy, q, Vector6d::Zero()))) {
        waypoints.push_back(q);
        break;
      }
    }
  }
  waypoints.push_back(Vector6d::Zero());
  return waypoint_trajectory(waypoints, spec.limits, spec.dwell, dt);
}

// ---- registration and errors ------------------------------------------------------------------

namespace {

// Times this close to the trajectory's ends count as on them (stamps are printed with finite
// decimals) [s].
constexpr double kTimeTolerance = 1e-9;
// Model points whose spread is below this are at one place [m].
constexpr double kCoincident = 1e-6;
// Two commanded poses closer than this in every coordinate are the same pose [m, rad].
constexpr double kSamePose = 1e-12;

// True if the commanded pose is the same over [t - settle, t] (before the trajectory starts, the
// platform stood at its first pose). The interpolant is flat between two equal samples, so it is
// enough that every sample from the last one at or before t - settle up to t equals the pose.
bool at_rest(const TimedPoses& commanded, double t, const Vector6d& pose, double settle) {
  if (settle <= 0.0) return true;
  const std::vector<double>& ts = commanded.t;
  auto begin = std::upper_bound(ts.begin(), ts.end(), t - settle);
  if (begin != ts.begin()) --begin;
  const auto end = std::upper_bound(ts.begin(), ts.end(), t);
  for (auto it = begin; it != end; ++it) {
    const Vector6d q = commanded.poses[static_cast<std::size_t>(it - ts.begin())].to_vector();
    if ((q - pose).cwiseAbs().maxCoeff() > kSamePose) return false;
  }
  return true;
}

// "log:line:column" of point k, for messages.
std::string point_location(const PointLog& log, std::size_t k) {
  return fmt::format("{}:{}:{}", log.source, log.lines[k], k < log.stamp_columns.size() ? log.stamp_columns[k] : 1);
}

// The trajectory time of every point, each checked to lie in the commanded trajectory's span.
std::vector<double> aligned_times(const TimedPoses& commanded, const PointLog& log, const TimeAlignment& alignment) {
  if (commanded.t.size() < 2)
    throw Error(fmt::format("{}: the commanded trajectory has fewer than 2 poses", log.source));
  std::vector<double> times = trajectory_times(log, alignment);
  const double front = commanded.t.front(), back = commanded.t.back();
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (!(times[k] >= front - kTimeTolerance && times[k] <= back + kTimeTolerance))
      throw Error(fmt::format(
          "{}: point at t = {} s{} is outside the commanded trajectory's time span [{}, {}] s (check the "
          "time offset{})",
          point_location(log, k), times[k], log.indexed ? fmt::format(" (index {})", log.stamps[k]) : std::string(),
          front, back, log.indexed ? " and the sample rate" : ""));
    times[k] = std::clamp(times[k], front, back);
  }
  return times;
}

void check_settle(const std::string& source, double settle) {
  if (!(std::isfinite(settle) && settle >= 0.0))
    throw Error(fmt::format("{}: settle time: expected a finite number >= 0 s, got {}", source, settle));
}

}  // namespace

Measurement measure_points(const Model& model, const TimedPoses& commanded, const PointLog& log,
                           const MeasurementOptions& options) {
  const std::string& src = log.source;
  const std::size_t n = log.points_T.size();
  const std::vector<double> times = aligned_times(commanded, log, options.time);
  const auto where = [&](std::size_t k) { return point_location(log, k); };
  const std::vector<Pose> desired = interpolate(commanded, times);
  const Vector3d& obs = model.spec().observation_P;

  Measurement m;
  m.points.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    MeasuredPoint& p = m.points[k];
    p.time = times[k];
    p.line = log.lines[k];
    p.p_T = log.points_T[k];
    p.desired = desired[k].to_vector();
    p.desired_B = platform_point_B(model, placement_from_pose(desired[k]), obs);
  }

  // The registration window and its points at rest.
  const RegistrationWindow& w = options.window;
  std::string window_text;
  if (w.first > 0) {
    m.window = std::min(w.first, n);
    window_text = fmt::format("the first {} points", w.first);
  } else {
    if (!std::isfinite(w.until)) throw Error(fmt::format("{}: the registration window is not given", src));
    while (m.window < n && times[m.window] <= w.until) ++m.window;
    window_text = fmt::format("the window t <= {} s", w.until);
  }
  if (m.window == 0)
    throw Error(fmt::format("{}: no point in the registration window ({}); the first point is at t = {} s", src,
                            window_text, times[0]));
  const std::string lines_text = fmt::format("lines {}-{}", log.lines[0], log.lines[m.window - 1]);
  if (m.window == n)
    throw Error(fmt::format("{}: {} ({}) hold every point: no point is left after the registration to evaluate", src,
                            lines_text, window_text));
  m.window_end = times[m.window - 1];
  check_settle(src, w.settle);
  std::vector<PointPair> pairs;
  std::vector<std::size_t>& used = m.registered;
  for (std::size_t k = 0; k < m.window; ++k) {
    MeasuredPoint& p = m.points[k];
    p.in_window = true;
    if (!at_rest(commanded, p.time, p.desired, w.settle)) continue;
    p.registered = true;
    used.push_back(k);
  }
  const std::string rest_text =
      w.settle > 0.0 ? fmt::format(" at rest (commanded pose unchanged for {} s)", w.settle) : std::string();
  if (used.size() < 3)
    throw Error(
        fmt::format("{}: {}: only {} of the {} points in {} {}{}; registering the tracker frame needs at least "
                    "3 (widen the window, or lower the settle time)",
                    src, lines_text, used.size(), m.window, window_text, used.size() == 1 ? "is" : "are",
                    rest_text.empty() ? std::string(" usable") : rest_text));

  // Each registration point's model position: where the nominal model puts the observation point
  // for the commands the platform ran (exactly the commanded position with compensation).
  FkResult fk;
  for (const std::size_t k : used) {
    MeasuredPoint& p = m.points[k];
    const Pose pose = Pose::from_vector(p.desired);
    Vector6d command;
    LimitReport limit;
    if (const Status s = motor_commands(model, pose, options.strategy, command, limit); s != Status::Ok)
      throw Error(fmt::format("{}: the commanded pose at t = {} s is outside a limit ({}); it cannot register",
                              where(k), p.time, describe(s)));
    if (const Status s = forward_kinematics(model, command, LengthKind::Motor, placement_from_pose(pose), fk);
        s != Status::Ok)
      throw Error(
          fmt::format("{}: forward kinematics of the command at t = {} s failed ({})", where(k), p.time, describe(s)));
    p.model_B = platform_point_B(model, fk.placement, obs);
    pairs.push_back({p.p_T, p.model_B});
  }
  const Status s = register_points(pairs, m.registration, options.registration);
  if (s == Status::DegenerateRegistration) {
    // How far the model points spread along their principal axes says what is wrong.
    Vector3d mean = Vector3d::Zero();
    for (const PointPair& pair : pairs) mean += pair.p_B;
    mean /= static_cast<double>(pairs.size());
    Matrix3d cov = Matrix3d::Zero();
    for (const PointPair& pair : pairs) cov += (pair.p_B - mean) * (pair.p_B - mean).transpose();
    const Vector3d spread = (cov / static_cast<double>(pairs.size()))
                                .selfadjointView<Eigen::Lower>()
                                .eigenvalues()
                                .cwiseMax(0.0)
                                .cwiseSqrt();
    throw Error(fmt::format(
        "{}: {}: the {} registration points{} in {} are {} (rms spread {:.3g} m, {:.3g} m and {:.3g} m along their "
        "principal axes; condition {:.3g}, at most {:.3g}); they cannot fix the tracker frame (register on stations "
        "that span a plane, such as the calibration moves)",
        src, lines_text, used.size(), rest_text, window_text,
        spread[2] < kCoincident ? "all at one place" : "on a line or nearly", spread[2], spread[1], spread[0],
        m.registration.condition, options.registration.max_condition));
  }
  if (s != Status::Ok) throw Error(fmt::format("{}: {}: registration failed: {}", src, lines_text, describe(s)));

  // Errors: every point registered; the statistics over the points after the window.
  std::vector<double> norm, axis[3];
  for (std::size_t k = 0; k < n; ++k) {
    MeasuredPoint& p = m.points[k];
    p.p_B = apply(m.registration.X_BT, p.p_T);
    p.error_B = p.p_B - p.desired_B;
    if (k < m.window) continue;
    norm.push_back(p.error_B.norm());
    for (int a = 0; a < 3; ++a) axis[a].push_back(std::abs(p.error_B[a]));
  }
  m.error = error_stats(norm);
  for (int a = 0; a < 3; ++a) m.axes[static_cast<std::size_t>(a)] = error_stats(axis[a]);
  return m;
}

std::vector<double> simulated_errors(const std::vector<SimulationSample>& samples, const Measurement& measurement) {
  std::vector<double> out;
  out.reserve(measurement.points.size() - std::min(measurement.window, measurement.points.size()));
  const auto before = [](const SimulationSample& s, double t) { return s.time < t; };
  for (std::size_t k = measurement.window; k < measurement.points.size(); ++k) {
    const double t = measurement.points[k].time;
    const auto it = std::lower_bound(samples.begin(), samples.end(), t - kTimeTolerance, before);
    if (it != samples.end() && std::abs(it->time - t) <= kTimeTolerance) {
      out.push_back(it->error);
    } else if (it == samples.end() || it == samples.begin()) {
      out.push_back(std::nan(""));
    } else {
      const SimulationSample& a = *(it - 1);
      const double s = (t - a.time) / (it->time - a.time);
      out.push_back(a.error + s * (it->error - a.error));
    }
  }
  return out;
}

// ---- observations for identification ----------------------------------------------------------

ObservationSet observations_at_rest(const Model& model, const TimedPoses& commanded, const PointLog& log,
                                    const TimeAlignment& time, Strategy strategy, double settle) {
  check_settle(log.source, settle);
  const std::vector<double> times = aligned_times(commanded, log, time);
  const std::vector<Pose> desired = interpolate(commanded, times);
  ObservationSet set;
  set.settle = settle;
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (!at_rest(commanded, times[k], desired[k].to_vector(), settle)) continue;
    Observation o;
    LimitReport limit;
    if (const Status s = motor_commands(model, desired[k], strategy, o.motor, limit); s != Status::Ok)
      throw Error(fmt::format("{}: the commanded pose at t = {} s is outside a limit ({}); no command reached it",
                              point_location(log, k), times[k], describe(s)));
    o.p_T = log.points_T[k];
    if (set.points.empty() ||
        (desired[k].to_vector() - desired[set.points.back()].to_vector()).cwiseAbs().maxCoeff() > kSamePose)
      ++set.poses;
    set.observations.push_back(o);
    set.points.push_back(k);
  }
  if (set.observations.size() < static_cast<std::size_t>(kMinObservations))
    throw Error(fmt::format(
        "{}: only {} of the {} points {}; an identification needs at least {} (lower the settle time, or record "
        "a run that stops at more poses: a stations run)",
        log.source, set.observations.size(), times.size(),
        settle > 0.0 ? fmt::format("are at rest (commanded pose unchanged for {} s)", settle)
                     : std::string("are usable"),
        kMinObservations));
  return set;
}

}  // namespace hexatwist
