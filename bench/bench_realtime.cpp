// SPDX-License-Identifier: BSD-3-Clause
// Worst-case timing of the real-time path: every call timed on its own, reported as percentiles
// (p50, p99, p99.9, max, in ns) for the compensated command, the warm twist-aware FK and the
// stream's per-line processing (parse, check, rate-limit, format); and a loopback UDP round trip
// through the real `hexatwist stream` process at a fixed pose rate.
// Run in Release: build/bench/bench_realtime.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <charconv>
#include <cstdio>
#include <string>
#include <thread>

#include "bench_support.hpp"

extern char** environ;

namespace {

using namespace hexatwist;
using namespace hexatwist::bench;

// Times `command(pose, cmd, lim)` call by call over the motion's poses.
template <class Command>
void time_each_command(benchmark::State& state, Command&& command) {
  const Motion& m = motion();
  Latencies lat(1 << 22);
  Vector6d cmd;
  LimitReport lim;
  std::size_t k = 0;
  for (auto _ : state) {
    const Pose p = pose_from_placement(m.poses[k]);
    const std::uint64_t t0 = Latencies::now();
    const Status s = command(p, cmd, lim);
    const std::uint64_t t1 = Latencies::now();
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(cmd);
    lat.add(t0, t1);
    if (++k == m.poses.size()) k = 0;
  }
  lat.report(state);
}

void BM_CompensatedCommandPerCall(benchmark::State& state) {
  time_each_command(state, [](const Pose& p, Vector6d& cmd, LimitReport& lim) {
    return motor_commands(model(), p, Strategy::Compensated, cmd, lim);
  });
}
BENCHMARK(BM_CompensatedCommandPerCall)->MinTime(2.0);

// The seed with every leg effect (README's leg_effects block: 200 N/um legs under the load, 50 um
// of play, 11.5 ppm/K on the length and the lead).
const Model& effects_model() {
  static const Model m = load_model(std::string(seed_config_yaml()) +
                                        "\nleg_effects:\n  stiffness: 2.0e8\n  play: 50.0e-6\n  home_direction: 1\n"
                                        "  length_expansion: 11.5e-6\n  lead_expansion: 11.5e-6\n"
                                        "  reference_temperature: 20\n",
                                    "seed with leg effects");
  return m;
}

// The command of a real machine (issue 27): the static load's deflection at the pose, each leg's
// temperature and the play's direction kept from call to call. Same run and poses as
// BM_CompensatedCommandPerCall; the budget is twice its time.
void BM_CompensatedCommandWithLegEffectsPerCall(benchmark::State& state) {
  const Model& em = effects_model();
  LegInputs inputs;
  inputs.temperature = Vector6d::Constant(23.5);
  PlayState play;
  start_play(em, em.geometry().home_command, play);
  time_each_command(state, [&](const Pose& p, Vector6d& cmd, LimitReport& lim) {
    return motor_commands(em, p, Strategy::Compensated, inputs, &play, cmd, lim);
  });
}
BENCHMARK(BM_CompensatedCommandWithLegEffectsPerCall)->MinTime(2.0);

// Each effect alone, to see where the time of the command above goes.
const Model& one_effect_model(int which) {
  static const std::array<Model, 3> models = {
      load_model(std::string(seed_config_yaml()) + "\nleg_effects:\n  stiffness: 2.0e8\n", "load"),
      load_model(std::string(seed_config_yaml()) +
                     "\nleg_effects:\n  length_expansion: 11.5e-6\n  lead_expansion: 11.5e-6\n"
                     "  reference_temperature: 20\n",
                 "heat"),
      load_model(std::string(seed_config_yaml()) + "\nleg_effects:\n  play: 50.0e-6\n  home_direction: 1\n", "play")};
  return models[static_cast<std::size_t>(which)];
}
void BM_CompensatedCommandWithOneLegEffectPerCall(benchmark::State& state) {
  const Model& em = one_effect_model(static_cast<int>(state.range(0)));
  LegInputs inputs;
  if (state.range(0) == 1) inputs.temperature = Vector6d::Constant(23.5);
  PlayState play;
  start_play(em, em.geometry().home_command, play);
  time_each_command(state, [&](const Pose& p, Vector6d& cmd, LimitReport& lim) {
    return motor_commands(em, p, Strategy::Compensated, inputs, &play, cmd, lim);
  });
  state.SetLabel(state.range(0) == 0 ? "load" : state.range(0) == 1 ? "heat" : "play");
}
BENCHMARK(BM_CompensatedCommandWithOneLegEffectPerCall)->DenseRange(0, 2)->MinTime(1.0);

void BM_TwistAwareFkWarmPerCall(benchmark::State& state) {
  // From the pose 1 ms earlier on the motion, as a servo loop at 1 kHz does.
  const Motion& m = motion();
  Latencies lat(1 << 22);
  FkResult r;
  std::size_t k = 1;
  for (auto _ : state) {
    const std::uint64_t t0 = Latencies::now();
    const Status s = forward_kinematics(model(), m.motor[k], LengthKind::Motor, m.poses[k - 1], r);
    const std::uint64_t t1 = Latencies::now();
    benchmark::DoNotOptimize(s);
    lat.add(t0, t1);
    if (++k == m.poses.size()) k = 1;
  }
  lat.report(state);
}
BENCHMARK(BM_TwistAwareFkWarmPerCall)->MinTime(2.0);

// The motion as pose lines (m and degrees, 9 decimals), as a simulator would send them.
const std::vector<std::string>& motion_lines() {
  static const std::vector<std::string> lines = [] {
    std::vector<std::string> out;
    for (const Placement& x : motion().poses) {
      const Pose p = pose_from_placement(x);
      std::array<char, 256> buf{};
      std::snprintf(buf.data(), buf.size(), "%.9f,%.9f,%.9f,%.9f,%.9f,%.9f\n", p.position.x(), p.position.y(),
                    p.position.z(), rad2deg(p.rpy.x()), rad2deg(p.rpy.y()), rad2deg(p.rpy.z()));
      out.emplace_back(buf.data());
    }
    return out;
  }();
  return lines;
}

// Per line: parse, check, command, (rate limit), format. Arg 1: with rate limits, so that every
// tick's step is checked through forward kinematics too (limits below the motion's own speed).
void BM_StreamLinePerCall(benchmark::State& state) {
  const auto& lines = motion_lines();
  StreamSettings settings;
  if (state.range(0) == 1) {
    settings.max_velocity = 0.05;
    settings.max_acceleration = 0.5;
  }
  auto stream = std::make_unique<StreamState>();
  (void)start_stream(model(), settings, pose_from_placement(motion().poses[0]), *stream);
  StreamOutput out;
  std::array<char, kMaxOutputLength> answer{};
  Latencies lat(1 << 22);
  std::size_t k = 0, limited = 0, bytes = 0;
  for (auto _ : state) {
    const std::uint64_t t0 = Latencies::now();
    (void)stream_line(model(), settings, lines[k], AngleUnit::Degrees, *stream, out);
    const std::size_t n = format_stream_output(out, StreamFormat::Csv, answer);
    const std::uint64_t t1 = Latencies::now();
    benchmark::DoNotOptimize(answer.data());
    lat.add(t0, t1);
    limited += out.rate_limited;
    bytes += n;
    if (++k == lines.size()) k = 0;
  }
  lat.report(state);
  state.counters["rate_limited_share"] = static_cast<double>(limited) / static_cast<double>(state.iterations());
  state.SetLabel(state.range(0) == 1 ? "rate-limited (FK check every tick)" : "no rate limits");
}
BENCHMARK(BM_StreamLinePerCall)->Arg(0)->Arg(1)->MinTime(2.0);

// ----- loopback UDP round trip through `hexatwist stream` -----

#ifdef HEXATWIST_CLI
int udp_socket(int port) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  const int size = 1 << 22;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &size, sizeof size);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) return -1;
  return fd;
}

int local_port(int fd) {
  sockaddr_in a{};
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  return ntohs(a.sin_port);
}

// The stream process, started with its stderr on a pipe; its input port is read from the line
// "hexatwist stream: listening on udp://127.0.0.1:PORT, ...".
struct StreamProcess {
  pid_t pid = -1;
  int port = -1;
  std::string error;

  // mode: 0 normal scheduling, 1 --rt-priority, 2 --busy-poll pinned to CPU 1 (normal
  // scheduling: a SCHED_FIFO task that never sleeps is throttled by the kernel).
  StreamProcess(int answer_port, int mode) {
    int err[2];
    if (::pipe(err) != 0) {
      error = "pipe";
      return;
    }
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_adddup2(&fa, err[1], 2);
    posix_spawn_file_actions_addclose(&fa, err[0]);
    const std::string out = "--output=udp://127.0.0.1:" + std::to_string(answer_port);
    const char* argv[] = {HEXATWIST_CLI,
                          "stream",
                          "--input=udp://127.0.0.1:0",
                          out.c_str(),
                          mode == 1 ? "--rt-priority=50" : "--busy-poll",
                          "--cpu=1",
                          nullptr};
    if (mode == 0) argv[4] = nullptr;
    if (posix_spawn(&pid, HEXATWIST_CLI, &fa, nullptr, const_cast<char**>(argv), environ) != 0) pid = -1;
    posix_spawn_file_actions_destroy(&fa);
    ::close(err[1]);
    std::string text;
    std::array<char, 256> buf{};
    pollfd p{err[0], POLLIN, 0};
    while (pid > 0 && text.find('\n') == std::string::npos && ::poll(&p, 1, 10000) > 0) {
      const ssize_t n = ::read(err[0], buf.data(), buf.size());
      if (n <= 0) break;
      text.append(buf.data(), static_cast<std::size_t>(n));
    }
    ::close(err[0]);  // later stderr lines (the summary) go nowhere
    const auto at = text.find("127.0.0.1:");
    if (at == std::string::npos) {
      error = "hexatwist stream did not start: " + text;
      return;
    }
    port = std::stoi(text.substr(at + 10));
  }
  ~StreamProcess() {
    if (pid > 0) {
      ::kill(pid, SIGTERM);
      int status = 0;
      ::waitpid(pid, &status, 0);
    }
  }
};

// SCHED_FIFO for the calling thread (root or CAP_SYS_NICE); false if refused.
bool fifo(int priority) {
  sched_param p{};
  p.sched_priority = priority;
  return pthread_setschedparam(pthread_self(), SCHED_FIFO, &p) == 0;
}

// The calling thread on CPU `cpu` only; false if refused.
bool pin(int cpu) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  return pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
}

// Sends `count` poses at `rate` per second (paced by absolute sleeps) and receives the answers on
// another thread; latency = receive time - send time of the same input number. Bounded: at most
// 30 s of waiting for answers. Third argument: 0 normal scheduling; 1 the stream runs with
// --rt-priority and the sender and receiver under SCHED_FIFO too, as a deployment would (skipped
// without root); 2 the stream busy-polls its socket pinned to CPU 1 (normal scheduling), the
// receiver busy-polls on CPU 0 and the sender runs there under SCHED_FIFO: no CPU in the path
// goes idle, which on a virtual machine makes a wake-up cost up to milliseconds (skipped with
// fewer than 2 CPUs or without root).
void BM_StreamUdpRoundTrip(benchmark::State& state) {
  const double rate = static_cast<double>(state.range(0));
  const std::size_t count = static_cast<std::size_t>(state.range(1));
  const int mode = static_cast<int>(state.range(2));
  const bool realtime = mode >= 1;
  if (mode == 2 && (sysconf(_SC_NPROCESSORS_ONLN) < 2 || !pin(0))) {
    state.SkipWithError("busy polling needs 2 CPUs");
    return;
  }
  ::prctl(PR_SET_TIMERSLACK, 1UL);  // wake on time, not up to 50 us late
  const auto& lines = motion_lines();
  if (realtime && !fifo(40)) {
    state.SkipWithError("SCHED_FIFO refused (needs root or CAP_SYS_NICE)");
    return;
  }
  for (auto _ : state) {
    const int rx = udp_socket(0), tx = udp_socket(0);
    StreamProcess proc(local_port(rx), mode);
    if (!proc.error.empty() || rx < 0 || tx < 0) {
      state.SkipWithError(proc.error.empty() ? "socket" : proc.error.c_str());
      return;
    }
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    to.sin_port = htons(static_cast<std::uint16_t>(proc.port));

    std::vector<std::uint64_t> sent(count, 0), received(count, 0);
    std::atomic<bool> done{false};
    std::size_t got = 0, bad = 0;
    std::thread receiver([&] {
      // Mode 2: the receiver spins too, at normal priority so that the SCHED_FIFO sender on the
      // same CPU preempts it when its time comes (and that CPU never goes idle either).
      if (mode == 2) {
        sched_param other{};  // not the SCHED_FIFO it inherits from the sender
        pthread_setschedparam(pthread_self(), SCHED_OTHER, &other);
        pin(0);
      }
      std::array<char, 2048> buf{};
      pollfd p{rx, POLLIN, 0};
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
      auto last = std::chrono::steady_clock::now();
      while (got < count && std::chrono::steady_clock::now() < deadline) {
        ssize_t n = -1;
        if (mode == 2) {
          n = ::recv(rx, buf.data(), buf.size(), MSG_DONTWAIT);
          if (n < 0) {
            if (done && std::chrono::steady_clock::now() - last > std::chrono::seconds(2)) break;
            continue;
          }
          last = std::chrono::steady_clock::now();
        } else {
          if (::poll(&p, 1, 100) <= 0) {
            if (done && ::poll(&p, 1, 2000) <= 0) break;  // all sent, nothing more for 2 s
            continue;
          }
          n = ::recv(rx, buf.data(), buf.size(), 0);
        }
        const std::uint64_t t = Latencies::now();
        std::size_t input = 0;
        const auto [ptr, ec] = std::from_chars(buf.data(), buf.data() + std::max<ssize_t>(n, 0), input);
        if (n <= 0 || ec != std::errc() || input == 0 || input > count || std::string_view(ptr, 4) != ",ok,") {
          ++bad;
          continue;
        }
        received[input - 1] = t;
        ++got;
      }
    });
    timespec next{};
    clock_gettime(CLOCK_MONOTONIC, &next);
    const long step_ns = static_cast<long>(1e9 / rate);
    const auto wall0 = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < count; ++k) {
      next.tv_nsec += step_ns;
      while (next.tv_nsec >= 1000000000L) {
        next.tv_nsec -= 1000000000L;
        ++next.tv_sec;
      }
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
      const std::string& line = lines[k % lines.size()];
      sent[k] = Latencies::now();
      ::sendto(tx, line.data(), line.size(), 0, reinterpret_cast<sockaddr*>(&to), sizeof to);
    }
    const double send_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    done = true;
    receiver.join();
    ::close(rx);
    ::close(tx);

    Latencies lat(count);
    for (std::size_t k = 0; k < count; ++k)
      if (received[k] != 0) lat.add(sent[k], received[k]);
    lat.report(state);
    state.counters["poses_per_s"] = static_cast<double>(count) / send_s;
    state.counters["answered"] = static_cast<double>(got);
    state.counters["lost"] = static_cast<double>(count - got);
    state.counters["bad_answers"] = static_cast<double>(bad);
    if (got < count) {
      static std::string why;  // SkipWithError keeps the pointer
      why = std::to_string(count - got) + " of " + std::to_string(count) + " poses were not answered (" +
            std::to_string(bad) + " bad answers)";
      state.SkipWithError(why.c_str());
    }
  }
  if (realtime) {
    sched_param p{};
    pthread_setschedparam(pthread_self(), SCHED_OTHER, &p);
  }
  if (mode == 2) {
    cpu_set_t all;
    CPU_ZERO(&all);
    for (int c = 0; c < sysconf(_SC_NPROCESSORS_ONLN) && c < CPU_SETSIZE; ++c) CPU_SET(c, &all);
    pthread_setaffinity_np(pthread_self(), sizeof all, &all);
  }
  state.SetLabel(mode == 2  ? "busy polling: stream on CPU 1, client on CPU 0"
                 : realtime ? "SCHED_FIFO"
                            : "normal scheduling");
}
BENCHMARK(BM_StreamUdpRoundTrip)
    ->Args({10000, 30000, 0})
    ->Args({20000, 40000, 0})
    ->Args({10000, 30000, 1})
    ->Args({20000, 40000, 1})
    ->Args({10000, 30000, 2})
    ->Args({20000, 40000, 2})
    ->Iterations(1)
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);
#endif

}  // namespace

BENCHMARK_MAIN();
