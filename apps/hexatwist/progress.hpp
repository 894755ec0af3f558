// SPDX-License-Identifier: BSD-3-Clause
// A progress line on stderr for the long runs (study, simulate, tolerance): the share done, what is
// running and an estimate of the time left. Drawn only when stderr is a terminal and the command
// prints a text report (never when piped, redirected or with --json), and erased when the run ends.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>
#include <string_view>

namespace hexatwist::cli {

class Progress {
 public:
  /// `total` units of work; `wanted` false (e.g. --json) draws nothing.
  explicit Progress(std::size_t total, bool wanted = true);
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  ~Progress();

  /// Whether the line is drawn (stderr a terminal, wanted, some work).
  [[nodiscard]] bool drawn() const noexcept { return drawn_; }

  /// `done` of the total units finished, `what` running now (a test's name; may be empty).
  void update(std::size_t done, std::string_view what = {});

  /// Erases the line (also done by the destructor, so that a failure's message starts clean).
  void finish() noexcept;

 private:
  std::size_t total_;
  bool drawn_;
  int last_percent_ = -1;
  long last_seconds_ = -1;
  bool shown_ = false;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

/// The time left as a person reads it: "12 s", "4 min 05 s", "1 h 02 min".
std::string remaining_text(double seconds);

}  // namespace hexatwist::cli
