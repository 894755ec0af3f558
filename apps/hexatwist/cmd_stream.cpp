// SPDX-License-Identifier: BSD-3-Clause
// hexatwist stream: one pose per line (stdin) or datagram (UDP) in, one answer per input out,
// in order: six checked motor commands and a status (include/hexatwist/kinematics/stream.hpp does the work;
// this file only moves bytes).
#include <fmt/format.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <optional>

#include "cli_common.hpp"
#include "signals.hpp"
#include "udp.hpp"

namespace hexatwist::cli {
namespace {

struct StreamOptions {
  ModelOptions model;
  std::string input = "stdin";
  std::string output = "stdout";
  std::string strategy = "compensated";
  std::string format = "csv";
  std::string on_reject = "hold";
  bool header = false;
  bool si = false;
  double max_velocity = 0;      // 0 = no limit
  double max_acceleration = 0;  // 0 = no limit
  double rate = 1000;
  std::string start;
  std::string temperature_c;
  std::uint64_t count = 0;
  double idle_timeout = 0;
  int rt_priority = 0;
  int cpu = -1;                  // -1 = any
  int receive_buffer = 4 << 20;  // bytes
  std::string accept_from = "any";
  bool busy_poll = false;
  bool quiet = false;
};

// Lines of a file descriptor, without allocation: a line longer than the parser accepts is
// passed on as its first kMaxLineLength + 1 characters, which the parser rejects as too long.
class LineReader {
 public:
  enum class Result { Line, End, Interrupted };

  explicit LineReader(int fd) : fd_(fd) {}

  bool has_complete_line() const { return std::memchr(buf_.data() + begin_, '\n', end_ - begin_) != nullptr; }

  Result next(std::string_view& line) {
    for (;;) {
      if (const void* nl = std::memchr(buf_.data() + begin_, '\n', end_ - begin_)) {
        const std::size_t stop = static_cast<std::size_t>(static_cast<const char*>(nl) - buf_.data());
        line = overlong_ ? std::string_view(prefix_.data(), prefix_.size())
                         : std::string_view(buf_.data() + begin_, stop - begin_);
        overlong_ = false;
        begin_ = stop + 1;
        return Result::Line;
      }
      if (end_ - begin_ > kMaxLineLength && !overlong_) {  // keep the start, drop the rest of the line
        std::memcpy(prefix_.data(), buf_.data() + begin_, prefix_.size());
        overlong_ = true;
      }
      if (overlong_) begin_ = end_;
      if (eof_) {
        if (begin_ == end_ && !overlong_) return Result::End;
        line = overlong_ ? std::string_view(prefix_.data(), prefix_.size())
                         : std::string_view(buf_.data() + begin_, end_ - begin_);
        overlong_ = false;
        begin_ = end_;
        return Result::Line;  // the last line, without its newline
      }
      if (begin_ > 0) {
        std::memmove(buf_.data(), buf_.data() + begin_, end_ - begin_);
        end_ -= begin_;
        begin_ = 0;
      }
      const ssize_t n = ::read(fd_, buf_.data() + end_, buf_.size() - end_);
      if (n < 0) {
        if (errno == EINTR) {
          if (signals::stop_requested()) return Result::Interrupted;
          continue;
        }
        throw ExitError(kExitBadInput, fmt::format("--input: reading stdin: {}", std::strerror(errno)));
      }
      if (n == 0) eof_ = true;
      end_ += static_cast<std::size_t>(n);
    }
  }

 private:
  int fd_;
  std::array<char, 1 << 16> buf_{};
  std::array<char, kMaxLineLength + 1> prefix_{};
  std::size_t begin_ = 0, end_ = 0;
  bool eof_ = false, overlong_ = false;
};

template <class E>
E parse_choice(const std::string& text, const std::string& option,
               std::initializer_list<std::pair<const char*, E>> choices) {
  std::string names;
  for (const auto& [name, value] : choices) {
    if (text == name) return value;
    names += names.empty() ? name : std::string(", ") + name;
  }
  throw ExitError(kExitBadInput, fmt::format("{}: '{}' is not one of {}", option, printable(text), names));
}

StreamSettings settings_from(const StreamOptions& o) {
  StreamSettings s;
  s.strategy = strategy_option(o.strategy);
  s.on_reject = parse_choice<RejectPolicy>(o.on_reject, "--on-reject",
                                           {{"hold", RejectPolicy::Hold}, {"skip", RejectPolicy::Skip}});
  s.period = 1.0 / o.rate;
  if (o.max_velocity > 0) s.max_velocity = o.max_velocity;
  if (o.max_acceleration > 0) s.max_acceleration = o.max_acceleration;
  return s;
}

// The library's check of the settings on the model, its fields named as the options that set them.
void check_settings(const Model& model, const StreamSettings& s, const StreamOptions& o) {
  const std::string_view why = check_stream_settings(model, s);
  if (why.empty()) return;
  if (why.starts_with("max_velocity: "))
    throw ExitError(kExitBadInput,
                    fmt::format("--max-velocity {:g} with --rate {:g}: {}", o.max_velocity, o.rate, why.substr(14)));
  if (why.starts_with("max_acceleration: "))
    throw ExitError(kExitBadInput, fmt::format("--max-acceleration {:g} with --rate {:g}: {}", o.max_acceleration,
                                               o.rate, why.substr(18)));
  if (why.starts_with("on_reject: "))
    throw ExitError(kExitBadInput, fmt::format("--on-reject {} with --max-velocity or --max-acceleration: {}",
                                               o.on_reject, why.substr(11)));
  throw ExitError(kExitBadInput, fmt::format("stream settings: {}", why));
}

// Where answers go: stdout (whole answers in a buffer of its own, written out whenever no further
// input is waiting; a write interrupted by a signal is resumed, so an answer is never cut) or one
// datagram each.
class AnswerSink {
 public:
  explicit AnswerSink(std::optional<UdpSocket> udp) : udp_(std::move(udp)) {}

  void write(std::string_view line) {
    if (!udp_) {
      if (used_ + line.size() > buffer_.size()) flush();
      std::memcpy(buffer_.data() + used_, line.data(), line.size());  // an answer fits: kMaxOutputLength
      used_ += line.size();
      return;
    }
    if (!line.empty() && line.back() == '\n') line.remove_suffix(1);  // a datagram is one answer
    (void)udp_->send(line);                                           // a refusal is counted by the socket
  }
  void flush() {
    for (std::size_t done = 0; done < used_;) {
      const ssize_t n = ::write(STDOUT_FILENO, buffer_.data() + done, used_ - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0)
        throw ExitError(kExitOutputFailed,
                        fmt::format("--output: writing stdout: {}", n < 0 ? std::strerror(errno) : "nothing written"));
      done += static_cast<std::size_t>(n);
    }
    used_ = 0;
  }
  std::uint64_t refused() const { return udp_ ? udp_->refused() : 0; }

 private:
  std::optional<UdpSocket> udp_;
  std::array<char, 1 << 16> buffer_{};
  std::size_t used_ = 0;
};

// True unless the kernel lets real-time tasks run without limit (sched_rt_runtime_us = -1).
bool rt_throttled() {
  std::FILE* f = std::fopen("/proc/sys/kernel/sched_rt_runtime_us", "r");
  if (f == nullptr) return true;
  long runtime = 0;
  const bool read = std::fscanf(f, "%ld", &runtime) == 1;
  std::fclose(f);
  return !read || runtime != -1;
}

// Pins the process to one CPU (a real-time loop does not migrate).
void pin_to_cpu(int cpu) {
  if (cpu < 0) return;
  cpu_set_t set;
  CPU_ZERO(&set);
  if (cpu >= CPU_SETSIZE)
    throw ExitError(kExitBadInput, fmt::format("--cpu {}: no such CPU (this machine has {} CPUs online)", cpu,
                                               sysconf(_SC_NPROCESSORS_ONLN)));
  CPU_SET(cpu, &set);
  if (sched_setaffinity(0, sizeof set, &set) != 0)
    throw ExitError(kExitBadInput, fmt::format("--cpu {}: cannot pin to it: {} (this machine has {} CPUs online)", cpu,
                                               std::strerror(errno), sysconf(_SC_NPROCESSORS_ONLN)));
}

void enter_realtime(int priority) {
  if (priority <= 0) return;
  sched_param p{};
  p.sched_priority = priority;
  if (sched_setscheduler(0, SCHED_FIFO, &p) != 0)
    throw ExitError(kExitBadInput,
                    fmt::format("--rt-priority {}: cannot use SCHED_FIFO: {} (needs root or CAP_SYS_NICE)", priority,
                                std::strerror(errno)));
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    throw ExitError(kExitBadInput,
                    fmt::format("--rt-priority {}: cannot lock memory: {}", priority, std::strerror(errno)));
}

// Default UDP endpoints: loopback, poses to port 9000, answers to port 9001.
constexpr const char* kDefaultUdpInput = "udp://127.0.0.1:9000";
constexpr const char* kDefaultUdpOutput = "udp://127.0.0.1:9001";

// The stream's ends: stdin or a bound UDP socket in, stdout or a connected one out.
struct Endpoints {
  std::optional<UdpSocket> in, out;
  std::string in_text = "stdin", out_text = "stdout";
  std::optional<UdpAddress> sender;  // --accept-from: the one sender taken
  int receive_buffer = 0;            // granted by the kernel [bytes]
  bool open_to_network = false;      // bound beyond loopback and taking any sender
};

Endpoints open_endpoints(const StreamOptions& o) {
  Endpoints e;
  if (is_udp(o.input)) {
    const UdpAddress local = parse_udp_address(o.input, "--input");
    e.in = UdpSocket::bound(local, "--input");
    e.receive_buffer = e.in->set_receive_buffer(o.receive_buffer, "--receive-buffer");
    e.in_text = udp_text(local.host, e.in->local_port());  // the port it got, also for port 0
    if (o.accept_from != "any") e.sender = parse_udp_address(o.accept_from, "--accept-from");
    e.open_to_network = !is_loopback(local) && !e.sender;
  } else if (o.input != "stdin" && o.input != "-") {
    throw ExitError(kExitBadInput,
                    fmt::format("--input: '{}' is neither stdin nor udp://HOST:PORT", printable(o.input)));
  }
  if (is_udp(o.output)) {
    const UdpAddress peer = parse_udp_address(o.output, "--output");
    if (udp_port(peer) == 0)
      throw ExitError(kExitBadInput, fmt::format("--output {}: port 0 is no address to send to (it picks a free port "
                                                 "only where the stream listens, --input)",
                                                 printable(o.output)));
    // Answers sent to where the poses arrive would be read back as poses, forever.
    if (e.in && reaches(peer, parse_udp_address(o.input, "--input"), e.in->local_port()))
      throw ExitError(kExitBadInput,
                      fmt::format("--output {}: is where --input listens ({}): the stream would read its own answers "
                                  "as poses, forever; give another port",
                                  printable(o.output), e.in_text));
    e.out = UdpSocket::connected(peer, "--output");
    e.out_text = peer.text;
  } else if (o.output != "stdout" && o.output != "-") {
    throw ExitError(kExitBadInput,
                    fmt::format("--output: '{}' is neither stdout nor udp://HOST:PORT", printable(o.output)));
  }
  return e;
}

// The summary on stderr: why the stream ended, what it answered, what was refused.
void print_summary(const StreamState& state, const std::array<std::uint64_t, 64>& by_status,
                   const std::array<std::uint64_t, 3>& by_action, const std::string& stop_reason, std::uint64_t refused,
                   const std::string& out_text) {
  const std::uint64_t rejected = state.inputs - by_status[0];
  std::string reasons;
  for (std::size_t k = 1; k < by_status.size(); ++k)
    if (by_status[k] > 0)
      reasons += fmt::format("{}{} {}", reasons.empty() ? "" : ", ", by_status[k], to_string(static_cast<Status>(k)));
  std::fprintf(stderr,
               "hexatwist stream: %s; %llu inputs; commands: %llu new, %llu held, %llu none; %llu rejected%s%s%s\n",
               stop_reason.c_str(), static_cast<unsigned long long>(state.inputs),
               static_cast<unsigned long long>(by_action[0]), static_cast<unsigned long long>(by_action[1]),
               static_cast<unsigned long long>(by_action[2]), static_cast<unsigned long long>(rejected),
               reasons.empty() ? "" : " (", reasons.c_str(), reasons.empty() ? "" : ")");
  if (refused > 0)
    std::fprintf(stderr, "hexatwist stream: %llu answers were refused by %s (nobody listening)\n",
                 static_cast<unsigned long long>(refused), out_text.c_str());
}

// The next datagram as a line: waiting in the kernel, or spinning on a non-blocking receive
// (--busy-poll: no sleep and wake-up between datagrams; the idle timeout kept by the clock).
UdpSocket::Received receive_datagram(UdpSocket& in, const StreamOptions& o, std::array<char, 2048>& datagram,
                                     std::string_view& line) {
  std::size_t size = 0;
  bool truncated = false;
  auto r = UdpSocket::Received::Timeout;
  if (o.busy_poll) {
    const auto since = std::chrono::steady_clock::now();
    const auto idle = std::chrono::duration<double>(o.idle_timeout > 0 ? o.idle_timeout : 1e300);
    while (!signals::stop_requested() &&
           (r = in.try_receive(datagram, size, truncated)) == UdpSocket::Received::Timeout &&
           std::chrono::steady_clock::now() - since < idle) {
    }
    if (signals::stop_requested()) r = UdpSocket::Received::Interrupted;
  } else {
    r = in.receive(datagram, size, truncated);
  }
  // A datagram longer than the buffer cannot be a pose; the parser says so (too long).
  line = std::string_view(datagram.data(), truncated ? datagram.size() : size);
  return r;
}

int run_stream(const StreamOptions& o) {
  const Model model = load_model_from(o.model);
  StreamSettings settings = settings_from(o);
  settings.inputs.temperature = temperature_option(o.temperature_c, model);
  check_settings(model, settings, o);
  const StreamFormat format =
      parse_choice<StreamFormat>(o.format, "--format", {{"csv", StreamFormat::Csv}, {"json", StreamFormat::Json}});
  const AngleUnit unit = o.si ? AngleUnit::Radians : AngleUnit::Degrees;

  auto state = std::make_unique<StreamState>();
  // Rate limits need a place to start from: home, unless --start says otherwise.
  const std::string start = o.start.empty() ? (settings.rate_limited() ? "home" : "none") : o.start;
  if (start != "none") {
    const Pose pose = start == "home" ? Pose{} : parse_pose_m_deg(start, "--start");
    if (const Status s = start_stream(model, settings, pose, *state); s != Status::Ok)
      throw ExitError(kExitOutOfLimit, fmt::format("--start: {} ({})", to_string(s), describe(s)));
  }

  Endpoints ends = open_endpoints(o);
  std::optional<UdpSocket>& in_udp = ends.in;
  const std::string& in_text = ends.in_text;
  const std::string& out_text = ends.out_text;
  if (o.busy_poll && o.rt_priority > 0 && rt_throttled())
    throw ExitError(kExitBadInput,
                    "--busy-poll with --rt-priority: the kernel throttles a SCHED_FIFO task that never sleeps (for "
                    "50 ms each second, /proc/sys/kernel/sched_rt_runtime_us) and datagrams are lost then; use one "
                    "of them, or set sched_rt_runtime_us to -1");
  if (o.cpu < -1) throw ExitError(kExitBadInput, fmt::format("--cpu {}: expected a CPU number >= 0", o.cpu));
  pin_to_cpu(o.cpu);
  enter_realtime(o.rt_priority);
  if (ends.open_to_network)  // warned even with --quiet
    std::fprintf(stderr,
                 "hexatwist stream: warning: --input %s takes poses from every host that reaches this machine; "
                 "--accept-from udp://HOST:PORT takes them from one sender only\n",
                 in_text.c_str());
  if (in_udp && !o.quiet) {
    std::fprintf(stderr,
                 "hexatwist stream: listening on %s (receive buffer: %d bytes asked, %d granted by the kernel), "
                 "taking poses from %s, answering to %s\n",
                 in_text.c_str(), o.receive_buffer, ends.receive_buffer,
                 ends.sender ? ends.sender->text.c_str() : "any sender", out_text.c_str());
    std::fflush(stderr);
  }
  AnswerSink sink(std::move(ends.out));
  signals::stop_on_request();  // a stop ends the stream at an input boundary, with its summary

  if (o.header && format == StreamFormat::Csv) sink.write(kStreamCsvHeader);
  std::array<char, kMaxOutputLength> answer{};
  std::array<char, 2048> datagram{};
  std::array<std::uint64_t, 64> by_status{};
  std::array<std::uint64_t, 3> by_action{};
  StreamOutput out;
  LineReader reader(STDIN_FILENO);
  if (in_udp && o.idle_timeout > 0 && !o.busy_poll)  // at most about 23 days, the range of the timeout in ms
    in_udp->set_receive_timeout(std::max(1, static_cast<int>(std::min(o.idle_timeout, 2e6) * 1000.0)));
  std::string stop_reason = "end of input";
  std::uint64_t ignored = 0;

  while (!signals::stop_requested() && (o.count == 0 || state->inputs < o.count)) {
    std::string_view line;
    if (in_udp) {
      const auto r = receive_datagram(*in_udp, o, datagram, line);
      if (r == UdpSocket::Received::Timeout) {
        stop_reason = fmt::format("no datagram for {} s (--idle-timeout)", o.idle_timeout);
        break;
      }
      if (r == UdpSocket::Received::Interrupted) break;
      if (ends.sender && !same_sender(*ends.sender, in_udp->sender())) {
        ++ignored;  // not the one sender taken: no input, no answer
        continue;
      }
    } else {
      if (!reader.has_complete_line()) sink.flush();  // about to wait: what was answered goes out now
      const auto r = reader.next(line);
      if (r != LineReader::Result::Line) break;
    }
    (void)stream_line(model, settings, line, unit, *state, out);
    const std::size_t n = format_stream_output(out, format, answer);
    sink.write(std::string_view(answer.data(), n));
    ++by_status[static_cast<std::size_t>(out.status)];
    ++by_action[static_cast<std::size_t>(out.action)];
  }
  sink.flush();
  if (signals::stop_requested()) stop_reason = signals::stop_signal_name();
  if (o.count != 0 && state->inputs >= o.count) stop_reason = fmt::format("--count {}", o.count);

  if (!o.quiet) {
    print_summary(*state, by_status, by_action, stop_reason, sink.refused(), out_text);
    if (in_udp && in_udp->dropped() > 0)
      std::fprintf(stderr,
                   "hexatwist stream: %llu datagrams were dropped by the kernel before they were read (its receive "
                   "buffer was full: --receive-buffer, net.core.rmem_max)\n",
                   static_cast<unsigned long long>(in_udp->dropped()));
    if (ignored > 0)
      std::fprintf(stderr, "hexatwist stream: %llu datagrams from other senders were ignored (--accept-from %s)\n",
                   static_cast<unsigned long long>(ignored), ends.sender->text.c_str());
  }
  const std::uint64_t rejected = state->inputs - by_status[0];
  return rejected == 0 ? kExitOk : kExitOutOfLimit;
}

}  // namespace

// The options' meaning in the mode chosen: the shorthands resolved, and an option that would
// have no effect refused, not ignored; number options in their ranges.
void check_mode(StreamOptions& o, const CLI::App& app) {
  // The documented shorthand first, so that the checks below see the address it means.
  if (o.input == "udp") o.input = kDefaultUdpInput;
  if (o.output == "udp") o.output = kDefaultUdpOutput;
  // An option that has no effect in the chosen mode is refused, not ignored.
  if (app.count("--header") > 0 && o.format != "csv")
    throw ExitError(kExitBadInput, "--header: only with --format csv (JSON answers carry their field names)");
  if (app.count("--cpu") > 0 && o.cpu < 0)
    throw ExitError(kExitBadInput, fmt::format("--cpu {}: expected a CPU number >= 0", o.cpu));
  if (!is_udp(o.input))
    for (const char* udp_only : {"--idle-timeout", "--receive-buffer", "--busy-poll", "--accept-from"})
      if (app.count(udp_only) > 0)
        throw ExitError(kExitBadInput, fmt::format("{}: only with --input udp://HOST:PORT", udp_only));
  if (app.count("--rate") > 0 && o.max_velocity == 0 && o.max_acceleration == 0)
    throw ExitError(kExitBadInput,
                    "--rate: only with --max-velocity or --max-acceleration (the input rate "
                    "their limits assume)");
  if (!(o.rate > 0) || !std::isfinite(o.rate)) throw ExitError(kExitBadInput, "--rate: expected a positive rate [Hz]");
  // Finite but absurd: no input arrives (or is parsed) faster than every microsecond.
  if (o.rate > 1e6)
    throw ExitError(kExitBadInput, fmt::format("--rate {:g}: expected at most 1e6 Hz (one input per "
                                               "microsecond) [Hz]",
                                               o.rate));
  if (o.rt_priority < 0 || o.rt_priority > sched_get_priority_max(SCHED_FIFO))
    throw ExitError(kExitBadInput,
                    fmt::format("--rt-priority {}: expected a SCHED_FIFO priority {}..{}, or 0 "
                                "for none",
                                o.rt_priority, sched_get_priority_min(SCHED_FIFO), sched_get_priority_max(SCHED_FIFO)));
  if (o.max_velocity < 0 || o.max_acceleration < 0 || !std::isfinite(o.max_velocity) ||
      !std::isfinite(o.max_acceleration))
    throw ExitError(kExitBadInput, "--max-velocity, --max-acceleration: expected a positive limit, or 0 for none");
  if (o.idle_timeout < 0 || !std::isfinite(o.idle_timeout))
    throw ExitError(kExitBadInput, "--idle-timeout: expected seconds >= 0");
}

Command make_stream_command(CLI::App& root) {
  auto o = std::make_shared<StreamOptions>();
  CLI::App* app = root.add_subcommand(
      "stream",
      "Motor commands for a stream of poses: one pose per line (stdin) or datagram (UDP) in, one answer per input "
      "out, in order. A pose is x,y,z [m], roll,pitch,yaw [deg] (--si: rad). An answer is "
      "input,status,command,m1..m6,leg,value,bound,detail (CSV) or the same as a JSON object: command is new, held "
      "or none, m1..m6 are the motor-side commands [m]. A command outside a limit is never sent; a rejected pose "
      "(outside a limit, non-finite, malformed) is answered with its status and the input's number. Ends at end of "
      "input, --count, --idle-timeout or SIGINT/SIGTERM/SIGHUP (the answer in progress is finished), with a summary on "
      "stderr; exit 0 if every input was "
      "accepted, 3 if any was rejected.");
  add_model_options(*app, o->model);
  app->add_option("--input", o->input,
                  "stdin, or udp://HOST:PORT to listen on (HOST defaults to 127.0.0.1; port 0 picks one; udp alone: "
                  "udp://127.0.0.1:9000)")
      ->capture_default_str();
  app->add_option("--output", o->output,
                  "stdout, or udp://HOST:PORT to send each answer to (HOST defaults to 127.0.0.1; udp alone: "
                  "udp://127.0.0.1:9001)")
      ->capture_default_str();
  app->add_option("--strategy", o->strategy, "compensated (Eq. 12, twist included) or conventional (twist ignored)")
      ->capture_default_str();
  app->add_option("--format", o->format, "csv or json (one object per line)")->capture_default_str();
  app->add_flag("--header", o->header, "write the CSV header line first");
  app->add_flag("--si", o->si, "angles of the input poses in rad instead of degrees");
  app->add_option("--on-reject", o->on_reject,
                  "hold: answer a rejected pose with the last valid command; skip: with no command")
      ->capture_default_str();
  app->add_option("--max-velocity", o->max_velocity, "rate limit of each leg's command [m/s] (0: none)");
  app->add_option("--max-acceleration", o->max_acceleration,
                  "acceleration limit of each leg's command [m/s^2] (0: none)");
  app->add_option(
         "--rate", o->rate,
         "input rate the limits assume [Hz]: one input every 1/rate s; only with --max-velocity or --max-acceleration")
      ->capture_default_str();
  app->add_option("--temperature-c", o->temperature_c, kTemperatureHelp);
  app->add_option("--start", o->start,
                  "pose the platform stands at when the stream starts (x,y,z [m],roll,pitch,yaw [deg]), home or none; "
                  "default: home with rate limits, none without");
  app->add_option("--count", o->count, "stop after this many inputs (0: no limit)");
  app->add_option("--idle-timeout", o->idle_timeout,
                  "UDP: stop after this many seconds without a datagram (0: wait); refused on stdin");
  app->add_option("--rt-priority", o->rt_priority,
                  "run under SCHED_FIFO at this priority with memory locked (needs root)");
  app->add_option("--cpu", o->cpu, "pin the process to this CPU (0-based; default: any)");
  app->add_option("--receive-buffer", o->receive_buffer,
                  "UDP: socket receive buffer [bytes] (the kernel caps it at net.core.rmem_max): poses that arrive "
                  "while the stream is held up wait here instead of being dropped")
      ->check(CLI::Range(4096, 1 << 30))
      ->capture_default_str();
  app->add_flag("--busy-poll", o->busy_poll,
                "UDP: spin on a non-blocking receive instead of sleeping between datagrams (lower latency; one CPU "
                "at 100 %)");
  app->add_option("--accept-from", o->accept_from,
                  "UDP: take poses only from this sender, udp://HOST:PORT (port 0: any of its ports); datagrams of "
                  "others are counted and not answered. Default any: every sender that reaches --input (with the "
                  "default loopback --input, the processes of this machine; another --input address is warned about)")
      ->capture_default_str();
  app->add_flag("--quiet", o->quiet, "no summary on stderr");
  return {app, [o, app] {
            check_mode(*o, *app);
            return run_stream(*o);
          }};
}

}  // namespace hexatwist::cli
