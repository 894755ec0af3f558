// SPDX-License-Identifier: BSD-3-Clause
#include "signals.hpp"

#include <dirent.h>
#include <fcntl.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <csignal>
#include <cstring>
#include <ctime>

#include "cli_common.hpp"

namespace hexatwist::cli::signals {
namespace {

constexpr int kStopSignals[] = {SIGINT, SIGTERM, SIGHUP};

struct Registration {
  Undo undo = nullptr;
  void* context = nullptr;
};

// Fixed storage: the handler reads it without allocating. Changed only inside a Critical section.
std::array<Registration, 32> g_undo{};
std::array<pid_t, 16> g_children{};

std::atomic<int> g_critical{0};       // live Critical sections, all threads
std::atomic<bool> g_aborting{false};  // a thread is rolling back and exiting
std::atomic<int> g_pending{0};        // the stop signal received, 0 if none
std::atomic<bool> g_on_request{false};
std::atomic<bool> g_progress_line{false};  // a progress line is drawn, not ended

void say(const char* text) noexcept {
  std::size_t left = std::strlen(text);
  while (left > 0) {
    const ssize_t n = ::write(STDERR_FILENO, text, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    text += n;
    left -= static_cast<std::size_t>(n);
  }
}

const char* name_of(int sig) noexcept {
  switch (sig) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    default:
      return "a signal";
  }
}

// Stops each child: SIGTERM, up to a second to end, then SIGKILL; reaped either way.
void stop_children() noexcept {
  for (const pid_t pid : g_children)
    if (pid > 0) ::kill(pid, SIGTERM);
  for (pid_t& pid : g_children) {
    if (pid <= 0) continue;
    int status = 0;
    bool ended = false;
    for (int k = 0; k < 100 && !ended; ++k) {
      ended = ::waitpid(pid, &status, WNOHANG) == pid;
      if (!ended) {
        const timespec ten_ms{0, 10'000'000};
        ::nanosleep(&ten_ms, nullptr);
      }
    }
    if (!ended) {
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
    }
    pid = 0;
  }
}

// Rolls the run back and exits, unless a Critical section is live (it does this when it ends).
void abort_run(int sig) noexcept {
  if (g_aborting.exchange(true)) return;  // another thread is at it
  if (g_critical.load() > 0) {
    g_aborting.store(false);
    return;
  }
  stop_children();
  bool undone = false;
  for (auto it = g_undo.rbegin(); it != g_undo.rend(); ++it)
    if (it->undo != nullptr) {
      it->undo(it->context);
      undone = true;
    }
  if (g_progress_line.load()) say("\n");
  say("hexatwist: stopped by ");
  say(name_of(sig));
  say(undone ? "; the run was rolled back: every file is as it was before it, nothing was written\n" : "\n");
  ::_exit(kExitInterrupted);
}

extern "C" void on_stop_signal(int sig) {
  const int saved = errno;
  g_pending.store(sig);
  if (!g_on_request.load()) abort_run(sig);
  errno = saved;
}

// SIGPIPE: nothing; the write that met a closed pipe returns EPIPE and fails as any write does.
// (A handler, not SIG_IGN, so that children do not inherit an ignored SIGPIPE.)
extern "C" void on_broken_pipe(int) {}

void set_handlers(bool restart) {
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  for (const int s : kStopSignals) sigaddset(&sa.sa_mask, s);
  sa.sa_flags = restart ? SA_RESTART : 0;  // without: a blocking read returns EINTR
  for (const int s : kStopSignals) ::sigaction(s, &sa, nullptr);
}

}  // namespace

void install() {
  set_handlers(true);
  struct sigaction pipe {};
  pipe.sa_handler = on_broken_pipe;
  sigemptyset(&pipe.sa_mask);
  pipe.sa_flags = SA_RESTART;
  ::sigaction(SIGPIPE, &pipe, nullptr);
}

void set_progress_line(bool shown) noexcept { g_progress_line.store(shown); }

void stop_on_request() {
  g_on_request.store(true);
  set_handlers(false);
}

bool stop_requested() { return g_on_request.load() && g_pending.load() != 0; }

const char* stop_signal_name() {
  const int sig = g_pending.load();
  return sig == 0 ? "" : name_of(sig);
}

Critical::Critical() noexcept {
  for (;;) {
    g_critical.fetch_add(1);
    if (!g_aborting.load()) return;
    g_critical.fetch_sub(1);  // a roll back is under way: it ends the process
    while (g_aborting.load()) ::sched_yield();
  }
}

Critical::~Critical() {
  if (g_critical.fetch_sub(1) == 1 && !g_on_request.load())
    if (const int sig = g_pending.load(); sig != 0) abort_run(sig);
}

void add_undo(Undo undo, void* context) noexcept {
  for (Registration& r : g_undo)
    if (r.undo == nullptr) {
      r = {undo, context};
      return;
    }
}

void remove_undo(Undo undo, void* context) noexcept {
  for (Registration& r : g_undo)
    if (r.undo == undo && r.context == context) r = {};
}

void add_child(pid_t pid) noexcept {
  for (pid_t& p : g_children)
    if (p == 0) {
      p = pid;
      return;
    }
}

void remove_child(pid_t pid) noexcept {
  for (pid_t& p : g_children)
    if (p == pid) p = 0;
}

void remove_flat_dir(const char* dir) noexcept {
  const int fd = ::open(dir, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd >= 0) {
    alignas(8) char buffer[4096];
    for (;;) {
      const long n = ::syscall(SYS_getdents64, fd, buffer, sizeof buffer);
      if (n <= 0) break;
      for (long at = 0; at < n;) {
        struct Entry {
          ino64_t ino;
          off64_t off;
          unsigned short reclen;
          unsigned char type;
          char name[1];
        };
        const auto* e = reinterpret_cast<const Entry*>(buffer + at);
        if (std::strcmp(e->name, ".") != 0 && std::strcmp(e->name, "..") != 0) ::unlinkat(fd, e->name, 0);
        at += e->reclen;
      }
    }
    ::close(fd);
  }
  ::rmdir(dir);
}

}  // namespace hexatwist::cli::signals
