// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/measurement.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <span>

#include <Eigen/Eigenvalues>

#include "calibration/log_alignment.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/kinematics/forward.hpp"

namespace hexatwist {
namespace {

// Model points whose spread is below this are at one place [m].
constexpr double kCoincident = 1e-6;

// The rms distance of points from their mean [m].
template <class Get, class Range>
double rms_spread(const Range& range, Get get) {
  Vector3d mean = Vector3d::Zero();
  double n = 0.0;
  for (const auto& x : range) mean += get(x), n += 1.0;
  if (n == 0.0) return 0.0;
  mean /= n;
  double sum = 0.0;
  for (const auto& x : range) sum += (get(x) - mean).squaredNorm();
  return std::sqrt(sum / n);
}

// A registration that cannot bring the log's points onto the model's is of another shape: the
// log is in other units than its header says, or of another run.
void check_registration_fit(const std::string& src, const std::string& lines_text, const std::vector<PointPair>& pairs,
                            const Registration& reg, const MeasurementOptions& options) {
  if (const std::string why = shape_misfit(pairs, reg, options.max_registration_misfit); !why.empty())
    throw Error(fmt::format("{}: {}: {}", src, lines_text, why));
}

// Evaluated errors the platform cannot have: a point farther off than a leg is long (a typing or
// export error), or errors comparable to the motion itself (the log of another motion).
void check_errors_plausible(const Model& model, const PointLog& log, const Measurement& m,
                            const MeasurementOptions& options) {
  const double absurd = model.spec().limits.length_max;
  double sum = 0.0;
  for (std::size_t k = m.window; k < m.points.size(); ++k) {
    const double e = m.points[k].error_B.norm();
    if (!(e <= absurd))
      throw Error(
          fmt::format("{}:{}: the point is more than a leg's maximum length ({} m) from where the run puts it "
                      "({:.4g} m): not a point of this run",
                      log.source, m.points[k].line, absurd, e));
    sum += e * e;
  }
  const std::size_t evaluated = m.points.size() - m.window;
  const double rms = std::sqrt(sum / static_cast<double>(evaluated));
  const auto tail = std::span(m.points).subspan(m.window);
  const double motion = rms_spread(tail, [](const MeasuredPoint& p) { return p.desired_B; });
  const double bound = std::max(options.max_error_fraction * motion, options.max_error_floor);
  if (rms <= bound) return;
  throw Error(fmt::format(
      "{}: lines {}-{}: the platform misses the run by {:.4g} mm rms where the observation point moves {:.4g} mm rms "
      "(at most {:g} % of it, or {:g} mm): the log is of another motion than the run's (another test or trajectory?)",
      log.source, m.points[m.window].line, m.points.back().line, 1e3 * rms, 1e3 * motion,
      100.0 * options.max_error_fraction, 1e3 * options.max_error_floor));
}

}  // namespace

using detail::aligned_times;
using detail::at_rest;
using detail::check_settle;
using detail::kTimeTolerance;
using detail::point_location;

Measurement measure_points(const Model& model, const TimedPoses& commanded, const PointLog& log,
                           const MeasurementOptions& options) {
  const std::string& src = log.source;
  const std::size_t n = log.points_T.size();
  const std::vector<double> times = aligned_times(commanded, log, options.time);
  detail::check_within_reach(model, log);
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
  const char* window_parameter = w.first > 0 ? "register_first" : "register_until";
  if (m.window == 0)
    throw ParameterError(fmt::format("{}: no point in the registration window ({}); the first point is at t = {} s",
                                     src, window_text, times[0]),
                         window_parameter);
  const std::string lines_text = fmt::format("lines {}-{}", log.lines[0], log.lines[m.window - 1]);
  if (m.window == n)
    throw ParameterError(fmt::format("{}: {} ({}) hold every point: no point is left after the registration to "
                                     "evaluate",
                                     src, lines_text, window_text),
                         window_parameter);
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
    throw ParameterError(
        fmt::format("{}: {}: only {} of the {} points in {} {}{}; registering the tracker frame needs at least "
                    "3 (widen the window, or lower the settle time)",
                    src, lines_text, used.size(), m.window, window_text, used.size() == 1 ? "is" : "are",
                    rest_text.empty() ? std::string(" usable") : rest_text),
        window_parameter);

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
  check_registration_fit(src, lines_text, pairs, m.registration, options);

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
  check_errors_plausible(model, log, m, options);
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

}  // namespace hexatwist
