// SPDX-License-Identifier: BSD-3-Clause
// How every command ends on a signal. SIGINT, SIGTERM and SIGHUP end a run as a failure does:
// what the run was writing is rolled back (the OutputFiles transaction, a figure's scratch folder),
// its children (gnuplot, a Dask client) are stopped, one line says so on stderr, and the exit code
// is kExitInterrupted (6). SIGPIPE is a failed write: the write returns EPIPE and the run ends with
// kExitOutputFailed (4), rolled back. `stream` instead stops at an input boundary: it asks for
// stop_on_request(), finishes the answer in progress and prints its summary.
//
// The roll back runs in the signal handler, so what it undoes is registered beforehand and undone
// with system calls only (async-signal-safe). Registered data change only inside a Critical section:
// a signal arriving then is acted on when the section ends, never while the data are half changed.
#pragma once

#include <sys/types.h>

namespace hexatwist::cli::signals {

/// Installs the handlers (main(), before any command runs).
void install();

/// From now on a stop signal only sets stop_requested() and interrupts a blocking read (EINTR):
/// the caller stops at its next boundary (`stream`).
void stop_on_request();
/// True once SIGINT, SIGTERM or SIGHUP arrived in stop_on_request() mode.
bool stop_requested();
/// The signal's name ("SIGTERM"), or "" if none arrived.
const char* stop_signal_name();

/// An undo action run by the handler: it may only use async-signal-safe calls on data that are not
/// changed outside a Critical section.
using Undo = void (*)(void* context) noexcept;

/// While a Critical lives (in any thread), a signal's roll back waits; it runs when the last one
/// ends. Registered undo data are changed only inside one.
class Critical {
 public:
  Critical() noexcept;
  ~Critical();
  Critical(const Critical&) = delete;
  Critical& operator=(const Critical&) = delete;
};

/// Registers `undo(context)` to run, newest first, if a signal ends the run. Call inside a Critical.
void add_undo(Undo undo, void* context) noexcept;
/// Removes a registration (the object is gone or its work final). Call inside a Critical.
void remove_undo(Undo undo, void* context) noexcept;

/// A child process stopped (SIGTERM) if a signal ends the run. Call inside a Critical.
void add_child(pid_t pid) noexcept;
void remove_child(pid_t pid) noexcept;

/// Whether a progress line (progress.hpp) is on the terminal without its newline: a signal's
/// message then starts on a line of its own.
void set_progress_line(bool shown) noexcept;

/// Removes the files in `dir` and then `dir` (one level), with system calls only: for the undo of
/// a scratch folder.
void remove_flat_dir(const char* dir) noexcept;

}  // namespace hexatwist::cli::signals
