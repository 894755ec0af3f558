// SPDX-License-Identifier: BSD-3-Clause
#include "progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "signals.hpp"

namespace hexatwist::cli {

namespace {

constexpr int kBarWidth = 30;
constexpr int kLineWidth = 78;
// The estimate needs some of the run behind it: before this share and this time, none is shown.
constexpr double kEstimateAfterShare = 0.02;
constexpr double kEstimateAfterSeconds = 1.0;

}  // namespace

std::string remaining_text(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  if (s < 60) return fmt::format("{} s", s);
  if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
  return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
}

Progress::Progress(std::size_t total, bool wanted)
    : total_(total), drawn_(wanted && total > 0 && isatty(fileno(stderr)) != 0) {}

Progress::~Progress() { finish(); }

void Progress::update(std::size_t done, std::string_view what) {
  if (!drawn_) return;
  const double share = std::min(1.0, static_cast<double>(done) / static_cast<double>(total_));
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const int percent = static_cast<int>(100.0 * share);
  const bool estimate = share >= kEstimateAfterShare && elapsed >= kEstimateAfterSeconds && share < 1.0;
  const double left = estimate ? elapsed * (1.0 - share) / share : 0.0;
  const long left_seconds = estimate ? std::lround(left) : -1;
  if (percent == last_percent_ && left_seconds == last_seconds_) return;  // redraw only on a change
  last_percent_ = percent;
  last_seconds_ = left_seconds;
  const int filled = percent * kBarWidth / 100;
  std::string line = fmt::format("[{}{}] {:3d}%", std::string(static_cast<std::size_t>(filled), '#'),
                                 std::string(static_cast<std::size_t>(kBarWidth - filled), '.'), percent);
  // The estimate is kept whole; what is running is shortened to fit the line.
  const std::string tail = estimate ? fmt::format("  about {} left", remaining_text(left)) : std::string();
  if (!what.empty() && line.size() + 2 + tail.size() < kLineWidth)
    line += fmt::format("  {}", what.substr(0, kLineWidth - line.size() - 2 - tail.size()));
  line += tail;
  if (line.size() > kLineWidth) line.resize(kLineWidth);
  std::fprintf(stderr, "\r%-*s", kLineWidth, line.c_str());
  std::fflush(stderr);
  shown_ = true;
  signals::set_progress_line(true);
}

void Progress::finish() noexcept {
  if (!shown_) return;
  std::fprintf(stderr, "\r%*s\r", kLineWidth, "");
  std::fflush(stderr);
  shown_ = false;
  signals::set_progress_line(false);
}

}  // namespace hexatwist::cli
