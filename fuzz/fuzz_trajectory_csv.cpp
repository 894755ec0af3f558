// SPDX-License-Identifier: BSD-3-Clause
// Fuzz target: trajectory CSV text (hexatwist::parse_trajectory_csv), then its resampling. Bad text
// must end in hexatwist::Error with a one-line message that starts with the source name; any other
// exception, a crash or a sanitizer finding is a bug. What parses must hold what the header
// promises (at least two rows, finite, strictly increasing times, finite poses), and its PCHIP
// resampling must stay finite and within the range of the samples, or refuse a step that is not
// usable or numbers whose interpolation overflows.
#include <algorithm>
#include <cmath>

#include "fuzz_support.hpp"
#include "hexatwist/motion/trajectory.hpp"

namespace {

using namespace hexatwist;

void check_samples(const TimedPoses& s) {
  fuzz::require(s.t.size() >= 2, "fewer than 2 rows accepted");
  fuzz::require(s.poses.size() == s.t.size() && s.lines.size() == s.t.size(), "times, poses and lines differ in size");
  for (std::size_t k = 0; k < s.t.size(); ++k) {
    fuzz::require(std::isfinite(s.t[k]) && s.poses[k].is_finite(), "non-finite value accepted");
    fuzz::require(k == 0 || s.t[k] > s.t[k - 1], "times not strictly increasing");
    fuzz::require(k == 0 || s.lines[k] > s.lines[k - 1], "line numbers not increasing");
  }
}

// Resampled onto about 256 steps: every coordinate stays between the smallest and the largest
// sample (the interpolation is monotone between samples).
void check_resampled(const TimedPoses& s) {
  const double dt = (s.t.back() - s.t.front()) / 256.0;
  Trajectory tr;
  try {
    tr = resample(s, dt);
  } catch (const Error& e) {
    fuzz::require_message(e);
    const bool overflow = std::string_view(e.what()).find("overflows a double") != std::string_view::npos;
    fuzz::require(overflow || !(std::isfinite(dt) && dt > 0.0), "resample refused a usable step");
    return;
  }
  // The grid t0 + k dt covers the samples' whole span, a last time between two ticks reached on the
  // next tick: ceil(span / dt) + 1 poses. dt is not exactly span / 256 when the span is subnormal
  // (dt rounds to a few ulps), so the count is checked against the dt actually used.
  const double ratio = (s.t.back() - s.t.front()) / tr.dt;
  const auto steps = static_cast<double>(tr.poses.size()) - 1.0;
  fuzz::require(tr.dt == dt && !tr.poses.empty() && steps >= ratio - 1e-6 && steps < ratio + 1.0 + 1e-6,
                "resample gave an unexpected number of poses");
  for (int c = 0; c < 6; ++c) {
    double lo = INFINITY, hi = -INFINITY;
    for (const Pose& p : s.poses) {
      lo = std::min(lo, p.to_vector()[c]);
      hi = std::max(hi, p.to_vector()[c]);
    }
    const double slack = 1e-12 * std::max(std::abs(lo), std::abs(hi));
    for (const Pose& p : tr.poses) {
      const double v = p.to_vector()[c];
      fuzz::require(std::isfinite(v), "resample gave a non-finite pose");
      fuzz::require(v >= lo - slack && v <= hi + slack, "resample overshot the samples");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const TimedPoses samples = parse_trajectory_csv(fuzz::as_text(data, size), "fuzz");
    check_samples(samples);
    check_resampled(samples);
  } catch (const Error& e) {
    fuzz::require_message(e, "fuzz");
  }
  return 0;
}
