// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/workspace.hpp"

#include <cmath>

namespace hexatwist {
namespace {

// Commands for the pose with coordinate k at value v and the others at home.
Status accepts(const Model& model, int k, double v, Strategy strategy, LimitReport& report) noexcept {
  Vector6d q = Vector6d::Zero();
  q[k] = v;
  Vector6d command;
  return motor_commands(model, Pose::from_vector(q), strategy, command, report);
}

// Reach from 0 in direction `sign`: the last accepted value and the limit met just beyond it.
double reach(const Model& model, int k, double sign, double step, double bound, double tolerance, Strategy strategy,
             LimitReport& limit) noexcept {
  limit = LimitReport{};
  double inside = 0.0;
  double outside = NAN;
  LimitReport report;
  for (double v = step; v <= bound + 0.5 * step; v += step) {
    const double value = std::min(v, bound);
    if (accepts(model, k, sign * value, strategy, report) != Status::Ok) {
      outside = value;
      limit = report;
      break;
    }
    inside = value;
  }
  if (std::isnan(outside)) return sign * inside;  // the search bound: no limit met
  while (outside - inside > tolerance) {
    const double mid = 0.5 * (inside + outside);
    if (accepts(model, k, sign * mid, strategy, report) == Status::Ok) {
      inside = mid;
    } else {
      outside = mid;
      limit = report;
    }
  }
  return sign * inside;
}

}  // namespace

Status axis_range(const Model& model, int coordinate, Strategy strategy, AxisRange& out,
                  const AxisRangeOptions& o) noexcept {
  out = AxisRange{};
  const bool linear = coordinate < 3;
  const double step = linear ? o.linear_step : o.angular_step;
  const double bound = linear ? o.linear_bound : o.angular_bound;
  if (coordinate < 0 || coordinate > 5 || !(step > 0.0) || !(bound >= step) || !(o.tolerance > 0.0) ||
      !std::isfinite(bound))
    return Status::NonFiniteInput;
  LimitReport home;
  if (const Status s = accepts(model, coordinate, 0.0, strategy, home); s != Status::Ok) {
    out.lower_limit = out.upper_limit = home;
    return s;
  }
  out.upper = reach(model, coordinate, 1.0, step, bound, o.tolerance, strategy, out.upper_limit);
  out.lower = reach(model, coordinate, -1.0, step, bound, o.tolerance, strategy, out.lower_limit);
  return Status::Ok;
}

}  // namespace hexatwist
