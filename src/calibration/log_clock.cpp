// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/log_clock.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "calibration/log_alignment.hpp"

namespace hexatwist {
namespace {

struct Rest {
  double begin = 0.0, end = 0.0;
  double middle() const { return 0.5 * (begin + end); }
};

// The run's rests: the commanded pose unchanged for at least `shortest` s.
std::vector<Rest> run_rests(const TimedPoses& c, double shortest) {
  std::vector<Rest> rests;
  std::size_t first = 0;
  for (std::size_t k = 1; k <= c.t.size(); ++k) {
    const bool same = k < c.t.size() &&
                      (c.poses[k].to_vector() - c.poses[first].to_vector()).cwiseAbs().maxCoeff() <= detail::kSamePose;
    if (same) continue;
    if (c.t[k - 1] - c.t[first] >= shortest) rests.push_back({c.t[first], c.t[k - 1]});
    first = k;
  }
  return rests;
}

// The log's rests: consecutive points of the observation point (target 0) each within `still` of
// the one before, for at least `shortest` s of the log's time.
std::vector<Rest> log_rests(const std::vector<double>& t, const std::vector<Vector3d>& p, double still,
                            double shortest) {
  std::vector<Rest> rests;
  std::size_t first = 0;
  for (std::size_t k = 1; k <= t.size(); ++k) {
    if (k < t.size() && (p[k] - p[k - 1]).norm() <= still) continue;
    if (t[k - 1] - t[first] >= shortest) rests.push_back({t[first], t[k - 1]});
    first = k;
  }
  return rests;
}

struct Line {
  double offset = 0.0, scale = 1.0, offset_sd = 0.0, scale_sd = 0.0, worst = 0.0;
};

// Least squares y = offset + scale x, with the standard deviations from the residuals' scatter.
Line fit_line(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i] / n, my += y[i] / n;
  double sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) sxx += (x[i] - mx) * (x[i] - mx), sxy += (x[i] - mx) * (y[i] - my);
  Line l;
  l.scale = sxx > 0.0 ? sxy / sxx : 1.0;
  l.offset = my - l.scale * mx;
  double ss = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double r = y[i] - l.offset - l.scale * x[i];
    ss += r * r;
    l.worst = std::max(l.worst, std::abs(r));
  }
  const double s2 = x.size() > 2 ? ss / (n - 2.0) : 0.0;
  l.scale_sd = sxx > 0.0 ? std::sqrt(s2 / sxx) : 0.0;
  l.offset_sd = sxx > 0.0 ? std::sqrt(s2 * (1.0 / n + mx * mx / sxx)) : 0.0;
  return l;
}

}  // namespace

Status fit_log_clock(const TimedPoses& commanded, const PointLog& log, const TimeAlignment& stamps,
                     const ClockFitOptions& options, ClockFit& fit) {
  fit = ClockFit{};
  // The observation point's samples, on the log's own clock (an indexed log through its rate).
  TimeAlignment own = stamps;
  own.offset = 0.0;
  own.scale = 1.0;
  const std::vector<double> all = trajectory_times(log, own);
  std::vector<double> t;
  std::vector<Vector3d> p;
  for (std::size_t k = 0; k < all.size(); ++k)
    if (log.targets.empty() || log.targets[k] == 0) {
      t.push_back(all[k]);
      p.push_back(log.points_T[k]);
    }
  double still = options.still;
  if (!(still > 0.0) && p.size() > 10) {
    std::vector<double> steps;
    for (std::size_t k = 1; k < p.size(); ++k) steps.push_back((p[k] - p[k - 1]).norm());
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 10), steps.end());
    still = std::max(8.0 * steps[steps.size() / 10], 1e-9);
  }
  const std::vector<Rest> in_run = run_rests(commanded, options.min_rest);
  const std::vector<Rest> in_log = log_rests(t, p, still, options.min_rest);
  fit.run_rests = static_cast<int>(in_run.size());
  fit.log_rests = static_cast<int>(in_log.size());
  // The interior rests of the log (its first and last may be cut short by the recording).
  const std::size_t interior = in_log.size() >= 2 ? in_log.size() - 2 : 0;
  if (interior < 3) {
    fit.reason = fmt::format(
        "{}: {} rests of at least {:g} s found in the log (the target still to {:.3g} mm between "
        "samples), the run has {}: at least 5 are needed to find the log's clock",
        log.source, in_log.size(), options.min_rest, 1e3 * still, in_run.size());
    return Status::InvalidArgument;
  }
  Line best;
  best.worst = std::numeric_limits<double>::infinity();
  int best_shift = -1, fitting = 0;
  for (std::size_t shift = 0; shift + interior <= in_run.size(); ++shift) {
    std::vector<double> x, y;
    bool durations_agree = true;
    for (std::size_t i = 0; i < interior; ++i) {
      const Rest& r = in_run[shift + i];
      const Rest& l = in_log[1 + i];
      x.push_back(r.middle());
      y.push_back(l.middle());
      // A rest of the log lasts as long as the run's (the still target is found within a few samples).
      durations_agree = durations_agree && std::abs((l.end - l.begin) - (r.end - r.begin)) <=
                                               3.0 * options.max_residual + options.max_rate * (r.end - r.begin);
    }
    const Line line = fit_line(x, y);
    const bool fits =
        durations_agree && line.worst <= options.max_residual && std::abs(line.scale - 1.0) <= options.max_rate;
    fitting += fits ? 1 : 0;
    if (durations_agree && line.worst < best.worst) {
      best = line;
      best_shift = static_cast<int>(shift);
    }
  }
  if (fitting == 0) {
    fit.reason = best_shift < 0
                     ? fmt::format(
                           "{}: the log's {} rests do not last as the run's {} do: a log of another run, or one in "
                           "which the platform did not rest where the run does",
                           log.source, in_log.size(), in_run.size())
                     : fmt::format(
                           "{}: the log's rests do not match the run's: the best match of its {} rests to the run's {} "
                           "leaves {:.3g} s between their middles (at most {:g} s) with the log's clock {:.6f} times "
                           "the run's: a log of another run, or one in which the platform did not rest where the run "
                           "does",
                           log.source, in_log.size(), in_run.size(), best.worst, options.max_residual, best.scale);
    return Status::InvalidArgument;
  }
  if (fitting > 1) {
    fit.reason = fmt::format(
        "{}: the log's {} rests match the run's {} at {} places: the rests are too regular to tell "
        "where the log starts; give --time-offset",
        log.source, in_log.size(), in_run.size(), fitting);
    return Status::InvalidArgument;
  }
  fit.offset = best.offset;
  fit.scale = best.scale;
  fit.offset_sd = best.offset_sd;
  fit.scale_sd = best.scale_sd;
  fit.worst = best.worst;
  fit.matched = static_cast<int>(interior);
  fit.first = best_shift;
  return Status::Ok;
}

}  // namespace hexatwist
