// SPDX-License-Identifier: BSD-3-Clause
// Internal: the workspace searches' common step, a march along a one-parameter family of poses with
// every change between accepted and refused bisected (docs/theory/design.md §16).
#pragma once

#include <cmath>
#include <vector>

#include "hexatwist/design/workspace_volume.hpp"

namespace hexatwist::detail {

/// True when the options can march: step and tolerance finite and > 0.
inline bool search_options_valid(const WorkspaceOptions& o) noexcept {
  return o.step > 0.0 && std::isfinite(o.step) && o.tolerance > 0.0 && std::isfinite(o.tolerance);
}

/// Whether motor_commands accepts `pose` for `strategy`; `report` names the limit when it does not.
inline bool accepts(const Model& model, const Pose& pose, Strategy strategy, LimitReport& report) noexcept {
  Vector6d command;
  return motor_commands(model, pose, strategy, command, report) == Status::Ok;
}

/// Poses at one orientation along a line of positions: origin + t direction [m, B].
struct PositionProbe {
  const Model& model;
  const Vector3d& rpy;
  Vector3d origin;
  Vector3d direction;
  Strategy strategy;
  bool operator()(double t, LimitReport& report) const noexcept {
    Pose pose;
    pose.position = origin + t * direction;
    pose.rpy = rpy;
    return accepts(model, pose, strategy, report);
  }
};

/// Bisects [in, out] (in accepted, out refused) to `tolerance`; `limit` ends as what the last
/// refused point breaks.
template <class Probe>
Crossing bisect(const Probe& probe, double in, double out, double tolerance, LimitReport limit) {
  LimitReport report;
  while (std::abs(out - in) > tolerance) {
    const double mid = 0.5 * (in + out);
    if (mid == in || mid == out) break;  // the bracket is one ulp wide
    if (probe(mid, report)) {
      in = mid;
    } else {
      out = mid;
      limit = report;
    }
  }
  Crossing c;
  c.inside = in;
  c.outside = out;
  c.limit = limit;
  return c;
}

/// The accepted stretches of t in [t0, t1]: samples at most options.step apart (both ends
/// included), each change bisected. An end of the range that is accepted closes its stretch with
/// a crossing whose limit status is Ok and inside == outside == the end.
template <class Probe>
void march(const Probe& probe, double t0, double t1, const WorkspaceOptions& options, std::vector<LineInterval>& out) {
  out.clear();
  const double span = t1 - t0;
  const long n = span > 0.0 ? std::max(1L, static_cast<long>(std::ceil(span / options.step))) : 0L;
  LimitReport report, previous_report;
  double previous_t = t0;
  bool previous_in = probe(t0, previous_report);
  LineInterval current;
  if (previous_in) current.lower = Crossing{t0, t0, LimitReport{}};
  for (long k = 1; k <= n; ++k) {
    const double t = k == n ? t1 : t0 + span * static_cast<double>(k) / static_cast<double>(n);
    const bool in = probe(t, report);
    if (in && !previous_in) {
      // Entering: bisect from the accepted t back towards the refused previous sample.
      current = LineInterval{};
      current.lower = bisect(probe, t, previous_t, options.tolerance, previous_report);
    } else if (!in && previous_in) {
      current.upper = bisect(probe, previous_t, t, options.tolerance, report);
      out.push_back(current);
    }
    previous_in = in;
    previous_t = t;
    previous_report = report;
  }
  if (previous_in) {
    current.upper = Crossing{t1, t1, LimitReport{}};
    out.push_back(current);
  }
}

/// From t0 (which the caller knows is accepted) towards t1: the first change to refused, bisected
/// (a Crossing with limit status Ok and inside == outside == t1 when none is met).
template <class Probe>
Crossing first_exit(const Probe& probe, double t0, double t1, double step, double tolerance) {
  const double span = t1 - t0;
  const long n = std::max(1L, static_cast<long>(std::ceil(std::abs(span) / step)));
  LimitReport report;
  double previous = t0;
  for (long k = 1; k <= n; ++k) {
    const double t = k == n ? t1 : t0 + span * static_cast<double>(k) / static_cast<double>(n);
    if (!probe(t, report)) return bisect(probe, previous, t, tolerance, report);
    previous = t;
  }
  return Crossing{t1, t1, LimitReport{}};
}

}  // namespace hexatwist::detail
