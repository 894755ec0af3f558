// SPDX-License-Identifier: BSD-3-Clause
// Internal: what the simulation's files share.
#pragma once

#include "hexatwist/simulation/simulation.hpp"

namespace hexatwist::detail {

/// Records a failure at sample `index` of `trajectory` in `issue` (its limit's status the failure's
/// where `limit` names none) and returns `status`.
inline Status fail_at(SimulationIssue& issue, Status status, std::size_t index, const Trajectory& trajectory,
                      const LimitReport& limit = {}) {
  issue.status = status;
  issue.index = index;
  issue.time = trajectory.time(index);
  issue.limit = limit;
  if (issue.limit.status == Status::Ok) issue.limit.status = status;
  return status;
}

}  // namespace hexatwist::detail
