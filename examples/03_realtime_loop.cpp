// SPDX-License-Identifier: BSD-3-Clause
// A fixed-rate servo loop (1 kHz) that calls the real-time API: every period it takes the pose the
// motion cue asks for, gets six checked, rate-limited motor commands from hexatwist, hands them
// to the drives, and checks its deadline. Nothing inside the loop allocates, locks or prints.
//
//   example_03_realtime_loop [SECONDS]      (default 2 s; as root it runs under SCHED_FIFO)
#include <sched.h>
#include <sys/mman.h>
#include <time.h>
#include <hexatwist/hexatwist.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace {

using namespace hexatwist;

constexpr long kPeriodNs = 1'000'000;  // 1 kHz

long ns_between(const timespec& a, const timespec& b) {
  return (b.tv_sec - a.tv_sec) * 1'000'000'000L + (b.tv_nsec - a.tv_nsec);
}

void add_ns(timespec& t, long ns) {
  t.tv_nsec += ns;
  while (t.tv_nsec >= 1'000'000'000L) {
    t.tv_nsec -= 1'000'000'000L;
    ++t.tv_sec;
  }
}

// The motion cue: heave and yaw sines, with one corrupted sample (as a lost packet might give).
Pose cue(long tick) {
  const double t = 1e-3 * static_cast<double>(tick);
  Pose p;
  p.position.z() = 0.08 * std::sin(2 * kPi * 0.5 * t);
  p.rpy.z() = deg2rad(10) * std::sin(2 * kPi * 0.3 * t);
  if (tick == 700) p.position.x() = std::nan("");
  return p;
}

// Stands in for the fieldbus write to the six drives.
void send_to_drives(const Vector6d& command) { asm volatile("" : : "g"(&command) : "memory"); }

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 2.0;
  const long ticks = static_cast<long>(seconds * 1000.0);
  if (!(ticks > 0)) {
    std::fprintf(stderr, "usage: example_03_realtime_loop [SECONDS > 0]\n");
    return 2;
  }

  // ----- set-up: may allocate, throw, print -----
  const Model model = default_model();
  StreamSettings settings;
  settings.strategy = Strategy::Compensated;
  settings.on_reject = RejectPolicy::Hold;
  settings.period = kPeriodNs * 1e-9;
  settings.max_velocity = 0.3;      // m/s per leg
  settings.max_acceleration = 3.0;  // m/s^2 per leg
  if (const auto why = check_stream_settings(settings); !why.empty()) {
    std::fprintf(stderr, "settings: %.*s\n", static_cast<int>(why.size()), why.data());
    return 2;
  }
  StreamState stream;
  if (start_stream(model, settings, Pose{}, stream) != Status::Ok) return 1;  // the platform is parked at home
  std::vector<long> compute_ns(static_cast<std::size_t>(ticks)), late_ns(static_cast<std::size_t>(ticks));
  sched_param prio{};
  prio.sched_priority = 80;
  const bool realtime = sched_setscheduler(0, SCHED_FIFO, &prio) == 0 && mlockall(MCL_CURRENT | MCL_FUTURE) == 0;

  // ----- the loop: no allocation, no lock, no I/O -----
  long overruns = 0, held = 0, rejected = 0, bad = 0, limited = 0;
  StreamOutput out;
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (long k = 0; k < ticks; ++k) {
    add_ns(next, kPeriodNs);
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    timespec woke{}, done{};
    clock_gettime(CLOCK_MONOTONIC, &woke);

    const Status st = stream_pose(model, settings, cue(k), stream, out);
    if (out.action != CommandAction::None) send_to_drives(out.command);
    rejected += st != Status::Ok;
    held += out.action == CommandAction::Held;
    limited += out.rate_limited;
    bad += out.action != CommandAction::None && !out.command.allFinite();

    clock_gettime(CLOCK_MONOTONIC, &done);
    compute_ns[static_cast<std::size_t>(k)] = ns_between(woke, done);
    late_ns[static_cast<std::size_t>(k)] = ns_between(next, woke);
    // Deadline: the commands must be out before the next period starts.
    if (ns_between(next, done) > kPeriodNs) ++overruns;
  }

  // ----- report -----
  const auto percentile = [](std::vector<long> v, double q) {
    std::sort(v.begin(), v.end());
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
  };
  std::printf("%ld ticks at 1 kHz (%s)\n", ticks, realtime ? "SCHED_FIFO, memory locked" : "normal scheduling");
  std::printf("compute per tick: median %.1f us, p99.9 %.1f us, max %.1f us\n", 1e-3 * percentile(compute_ns, 0.5),
              1e-3 * percentile(compute_ns, 0.999), 1e-3 * percentile(compute_ns, 1.0));
  std::printf("wake-up lateness: median %.1f us, p99.9 %.1f us, max %.1f us\n", 1e-3 * percentile(late_ns, 0.5),
              1e-3 * percentile(late_ns, 0.999), 1e-3 * percentile(late_ns, 1.0));
  std::printf("deadline overruns: %ld; rejected cues: %ld (held: %ld); rate-limited ticks: %ld; leg 1 ends at %.6f m\n",
              overruns, rejected, held, limited, stream.command[0]);
  // The corrupted cue must have been rejected and held; no command may be non-finite. Overruns are
  // reported, not failed: on a shared machine they say more about the machine than the code.
  return bad == 0 && rejected == 1 && held == 1 ? 0 : 1;
}
