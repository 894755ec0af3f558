// SPDX-License-Identifier: BSD-3-Clause
// The tracker's clock against the run's: a tracker log starts whenever the operator pressed record,
// on a clock of its own. The rests of the run (the commanded pose unchanged) and the rests in the
// log (the target still) are the same events; matched in order, their middles give the offset and
// the rate difference of the two clocks (docs/theory/calibration.md §12b).
#pragma once

#include <string>

#include "hexatwist/calibration/point_log.hpp"
#include "hexatwist/motion/trajectory.hpp"
#include "hexatwist/status.hpp"

namespace hexatwist {

/// How rests are found and matched.
struct ClockFitOptions {
  double min_rest = 0.5;  ///< shortest rest counted, in the run and in the log [s]
  /// The target counts as still while it moves less than this between two samples [m]; 0 = from
  /// the log: 8 times its smallest decile of sample-to-sample steps (the tracker's noise at rest).
  double still = 0.0;
  double max_residual = 0.1;  ///< largest misfit of a rest's middle after the fit [s]
  double max_rate = 0.01;     ///< largest clock-rate difference believed, |scale - 1| [-]
};

/// The log's clock: its time = offset + scale * the run's time.
struct ClockFit {
  double offset = 0.0;     ///< the log's time at the run's t = 0 [s]
  double scale = 1.0;      ///< the log's seconds per second of the run [-]
  double offset_sd = 0.0;  ///< standard deviation of the offset, from the fit's scatter [s]
  double scale_sd = 0.0;   ///< standard deviation of the scale [-]
  double worst = 0.0;      ///< largest misfit of a matched rest's middle [s]
  int matched = 0;         ///< rests matched (the log's first and last, possibly cut short, left out)
  int run_rests = 0;       ///< rests of the run
  int log_rests = 0;       ///< rests found in the log
  int first = 0;           ///< the run's rest matched to the log's second (0-based)
  std::string reason;      ///< why no fit was found (status not Ok)

  /// The alignment of the log's stamps to the run's time; `rate` as the stamps' (an indexed log's).
  TimeAlignment alignment(double rate = 0.0) const noexcept { return {offset, rate, scale}; }
};

/// Finds the log's clock from the rests of the observation point (target 0) and of the commanded
/// run. The log's first and last rests may be cut short by where the recording starts and ends, so
/// the interior ones are matched, in order, to consecutive rests of the run at every shift; the
/// shift whose least-squares line (middles, log against run) fits best is taken. Returns Ok and
/// fills `fit`; InvalidArgument with `fit.reason` when the log has fewer than 3 interior rests,
/// when no shift fits within `max_residual` and `max_rate` (the log is of another run, or the
/// platform did not rest where the run does), or when two shifts fit (the rests are too regular to
/// tell them apart). Throws hexatwist::Error for an indexed log without a rate, as trajectory_times.
Status fit_log_clock(const TimedPoses& commanded, const PointLog& log, const TimeAlignment& stamps,
                     const ClockFitOptions& options, ClockFit& fit);

}  // namespace hexatwist
