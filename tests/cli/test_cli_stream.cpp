// SPDX-License-Identifier: BSD-3-Clause
// hexatwist stream: answers on standard output and over UDP.
#include <fcntl.h>
#include <signal.h>

#include <chrono>
#include <thread>

#include "cli_support.hpp"

using namespace hexatwist::cli_test;

namespace {

// ----- hexatwist stream -----

TEST(CliStream, AnswersEveryLineInOrderWithTheCommandsOfIk) {
  const std::vector<std::string> poses = {"0,0,0.1,0,0,10", "0.1,-0.05,0,5,-3,20", "0,0,0,0,0,0"};
  std::string input;
  for (const auto& p : poses) input += p + "\n";
  for (const std::string strategy : {"compensated", "conventional"}) {
    const Outcome r = run({"stream", "--strategy", strategy}, &input);
    SCOPED_TRACE(r.command + "\n" + r.err);
    EXPECT_EQ(r.code, 0);
    const auto rows = csv_rows(r.out);
    ASSERT_EQ(rows.size(), poses.size());
    for (std::size_t k = 0; k < poses.size(); ++k) {
      ASSERT_EQ(rows[k].size(), 13u);
      EXPECT_EQ(rows[k][0], std::to_string(k + 1));
      EXPECT_EQ(rows[k][1], "ok");
      EXPECT_EQ(rows[k][2], "new");
      const auto ik = leg_values(json(run({"ik", "--pose=" + poses[k], "--json"})), ("command_" + strategy).c_str());
      const auto m = commands_of(rows[k]);
      for (int i = 0; i < 6; ++i) EXPECT_EQ(m[static_cast<std::size_t>(i)], ik[static_cast<std::size_t>(i)]);
    }
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1);  // the summary
    EXPECT_NE(r.err.find("3 inputs"), std::string::npos);
  }
}

TEST(CliStream, RejectedLinesNameTheirProblemAndLineAndTheStreamGoesOn) {
  const std::string input = "0,0,0.1,0,0,10\n0,0,3,0,0,0\n0,0,x,0,0,0\nnan,0,0,0,0,0\n1,2,3\n" +
                            std::string(100000, '7') + "\n0,0,0.1,0,0,10";  // no final newline
  const Outcome hold = run({"stream"}, &input);
  SCOPED_TRACE(hold.out + hold.err);
  EXPECT_EQ(hold.code, 3);
  const auto rows = csv_rows(hold.out);
  ASSERT_EQ(rows.size(), 7u);
  const std::vector<std::string> status = {
      "ok", "stroke_above_max", "malformed_input", "non_finite_input", "malformed_input", "malformed_input", "ok"};
  for (std::size_t k = 0; k < rows.size(); ++k) {
    EXPECT_EQ(rows[k][0], std::to_string(k + 1));
    EXPECT_EQ(rows[k][1], status[k]);
    EXPECT_EQ(rows[k][2], k == 0 || k == 6 ? "new" : "held");
    EXPECT_EQ(commands_of(rows[k]), commands_of(rows[0]));  // held = the last valid command
  }
  EXPECT_EQ(rows[1][9], "1");                                 // leg 1 ...
  EXPECT_GT(std::stod(rows[1][10]), std::stod(rows[1][11]));  // ... above its bound
  EXPECT_EQ(rows[2][12], "field 3 (z) at column 5: not a number");
  EXPECT_EQ(rows[4][12], "field 4 (roll) at column 6: missing (a pose has six fields: x y z roll pitch yaw)");
  EXPECT_EQ(rows[5][12], "line longer than 1024 characters");
  EXPECT_NE(hold.err.find("5 rejected"), std::string::npos);

  const Outcome skip = run({"stream", "--on-reject=skip", "--format=json"}, &input);
  std::istringstream lines(skip.out);
  int n = 0;
  for (std::string line; std::getline(lines, line); ++n) {
    const YAML::Node j = YAML::Load(line);
    EXPECT_EQ(j["input"].as<int>(), n + 1);
    EXPECT_EQ(j["status"].as<std::string>(), status[static_cast<std::size_t>(n)]);
    EXPECT_EQ(j["m"].IsNull(), status[static_cast<std::size_t>(n)] != "ok");
  }
  EXPECT_EQ(n, 7);
}

TEST(CliStream, RadiansWithSiEqualDegreesAndHeaderComesFirst) {
  const std::string deg = "0,0,0.05,3,-4,25\n",
                    rad = "0,0,0.05," + numbers({deg2rad(3), deg2rad(-4), deg2rad(25)}) + "\n";
  const auto a = csv_rows(run({"stream", "--header"}, &deg).out);
  const auto b = csv_rows(run({"stream", "--si"}, &rad).out);
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_EQ(a[0][0], "input");
  EXPECT_EQ(a[0].size(), 13u);
  const auto ma = commands_of(a[1]), mb = commands_of(b[0]);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(ma[static_cast<std::size_t>(i)], mb[static_cast<std::size_t>(i)], 1e-14);
}

TEST(CliStream, RateLimitsBoundEveryAnswerFromHome) {
  std::string input;
  for (int k = 0; k < 1500; ++k) input += "0,0,0.2,0,0,0\n";  // a 0.2 m step, held for 3 s
  const double vmax = 0.1, amax = 2.0, rate = 500;
  const Outcome r = run({"stream", "--max-velocity=0.1", "--max-acceleration=2", "--rate=500"}, &input);
  EXPECT_EQ(r.code, 0) << r.err;
  const auto rows = csv_rows(r.out);
  ASSERT_EQ(rows.size(), 1500u);
  const auto home = leg_values(json(run({"ik", "--pose=0,0,0,0,0,0", "--json"})), "command_compensated");
  std::vector<double> prev = home, prev_v(6, 0.0);
  int limited = 0;
  for (const auto& row : rows) {
    const auto m = commands_of(row);
    limited += row[12] == "rate limited";
    for (std::size_t i = 0; i < 6; ++i) {
      const double v = (m[i] - prev[i]) * rate;
      EXPECT_LE(std::abs(v), vmax * (1 + 1e-9));
      EXPECT_LE(std::abs(v - prev_v[i]), amax / rate * (1 + 1e-9));
      prev_v[i] = v;
    }
    prev = m;
  }
  EXPECT_GT(limited, 100);
  EXPECT_EQ(rows.back()[12], "");  // arrived
}

TEST(CliStream, BadOptionsAreOneLineErrors) {
  const std::string none;
  expect_error(run({"stream", "--input=file.txt"}, &none), 2, {"--input", "file.txt"});
  expect_error(run({"stream", "--input=udp://127.0.0.1"}, &none), 2, {"--input", "PORT"});
  expect_error(run({"stream", "--input=udp://127.0.0.1:99999"}, &none), 2, {"--input", "0..65535"});
  expect_error(run({"stream", "--output=udp://no.such.host.invalid:9000"}, &none), 2, {"--output", "resolve"});
  expect_error(run({"stream", "--format=xml"}, &none), 2, {"--format", "csv, json"});
  expect_error(run({"stream", "--on-reject=retry"}, &none), 2, {"--on-reject", "hold, skip"});
  expect_error(run({"stream", "--max-velocity=-1"}, &none), 2, {"--max-velocity"});
  expect_error(run({"stream", "--rate=0"}, &none), 2, {"--rate"});
  expect_error(run({"stream", "--start=0,0,3,0,0,0"}, &none), 3, {"--start", "stroke_above_max"});
  expect_error(run({"stream", "--start=0,0,0,0,0"}, &none), 2, {"--start", "6"});
  expect_error(run({"stream", "--busy-poll"}, &none), 2, {"--busy-poll", "udp://"});
  expect_error(run({"stream", "--cpu=100000"}, &none), 2, {"--cpu 100000", "CPUs"});
  expect_error(run({"stream", "--cpu=-3"}, &none), 2, {"--cpu -3", ">= 0"});
  // A skipped input would leave the drive stopping within one tick: refused with the rate limits.
  expect_error(run({"stream", "--on-reject=skip", "--max-velocity=0.5", "--max-acceleration=5"}, &none), 2,
               {"--on-reject skip", "--max-velocity", "hold"});
  expect_error(run({"stream", "--accept-from=udp://127.0.0.1:0"}, &none), 2, {"--accept-from", "udp://"});
  // Answers sent where the poses arrive, however the address is spelled (IPv4 written as IPv6).
  for (const auto& [in, out] :
       std::vector<std::pair<std::string, std::string>>{{"udp://[::ffff:127.0.0.1]:9541", "udp://127.0.0.1:9541"},
                                                        {"udp://127.0.0.1:9542", "udp://[::ffff:127.0.0.1]:9542"},
                                                        {"udp://0.0.0.0:9543", "udp://[::ffff:127.0.0.1]:9543"}})
    expect_error(run({"stream", "--input=" + in, "--output=" + out}, &none), 2, {"--output", "its own answers"});
}

// A stop signal while a slow reader holds the stream up: the answer in progress is finished (no
// line cut mid-number), the summary printed, and the exit code the stream's own.
TEST(CliStream, AStopSignalFinishesTheAnswerInProgressAndPrintsTheSummary) {
  std::string poses;
  for (int k = 0; k < 200000; ++k) poses += "0.001,0,0.05,0,0," + std::to_string(k % 10) + "\n";
  const std::string in_path = write_file("stop-poses.txt", poses);
  const std::string err_path = (temp_dir() / "stop-stderr.txt").string();
  int out[2];
  ASSERT_EQ(::pipe(out), 0);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int in = ::open(in_path.c_str(), O_RDONLY);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(in, STDIN_FILENO);
    ::dup2(out[1], STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    ::close(out[0]);
    ::execl(HEXATWIST_CLI, HEXATWIST_CLI, "stream", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(out[1]);
  // A slow reader: small reads with pauses, then SIGTERM while the stream waits on the full pipe.
  std::string got;
  std::array<char, 512> buf{};
  for (int k = 0; k < 50; ++k) {
    const ssize_t n = ::read(out[0], buf.data(), buf.size());
    if (n > 0) got.append(buf.data(), static_cast<std::size_t>(n));
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(pid, SIGTERM);
  for (ssize_t n; (n = ::read(out[0], buf.data(), buf.size())) > 0;)
    got.append(buf.data(), static_cast<std::size_t>(n));
  ::close(out[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "ended by a signal";
  EXPECT_EQ(WEXITSTATUS(status), 0) << read_file(err_path);
  ASSERT_FALSE(got.empty());
  EXPECT_EQ(got.back(), '\n') << "the last answer is cut: "
                              << got.substr(got.size() - std::min<std::size_t>(got.size(), 80));
  const auto rows = csv_rows(got);
  for (const auto& row : rows) ASSERT_EQ(row.size(), 13u);
  const std::string err = read_file(err_path);
  EXPECT_NE(err.find("hexatwist stream: SIGTERM; " + std::to_string(rows.size()) + " inputs"), std::string::npos)
      << err;
  EXPECT_LT(rows.size(), 200000u);  // stopped, not at the end of input
}

// A UDP socket of the test, bound to an ephemeral loopback port.
struct TestSocket {
  int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  explicit TestSocket(int port = 0) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }
  ~TestSocket() { ::close(fd); }
  int port() const {
    sockaddr_in a{};
    socklen_t len = sizeof a;
    ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
    return ntohs(a.sin_port);
  }
  void send_to(int port, const std::string& data) const {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    ::sendto(fd, data.data(), data.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a);
  }
  std::string receive(int timeout_ms) const {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) <= 0) return "(timeout)";
    std::array<char, 2048> buf{};
    const ssize_t n = ::recv(fd, buf.data(), buf.size(), 0);
    return n < 0 ? "(error)" : std::string(buf.data(), static_cast<std::size_t>(n));
  }
};

// Parameter: the stream's extra options (none; busy polling pinned to the first CPU).
class CliStreamUdp : public ::testing::TestWithParam<const char*> {};

TEST_P(CliStreamUdp, AnswersOneDatagramPerDatagramInOrder) {
  TestSocket answers;
  const std::string command =
      shell_quote(HEXATWIST_CLI) +
      " stream --input=udp://127.0.0.1:0 --output=udp://127.0.0.1:" + std::to_string(answers.port()) +
      " --count=4 --idle-timeout=20 " + GetParam() + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::array<char, 512> line{};
  ASSERT_NE(std::fgets(line.data(), line.size(), pipe), nullptr);
  const std::string listening = line.data();  // "hexatwist stream: listening on udp://127.0.0.1:PORT, ..."
  const auto colon = listening.find("127.0.0.1:");
  ASSERT_NE(colon, std::string::npos) << listening;
  const int port = std::stoi(listening.substr(colon + 10));
  TestSocket poses;
  const std::vector<std::string> sent = {"0,0,0.1,0,0,10", "0,0,3,0,0,0\n", "garbage", "0,0,0.1,0,0,10\r\n"};
  std::vector<std::string> got;
  for (const auto& s : sent) {
    poses.send_to(port, s);
    got.push_back(answers.receive(10000));
  }
  std::string rest;
  while (std::fgets(line.data(), line.size(), pipe) != nullptr) rest += line.data();
  const int status = pclose(pipe);
  EXPECT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 3) << rest;
  EXPECT_NE(rest.find("--count 4; 4 inputs"), std::string::npos) << rest;
  ASSERT_EQ(got.size(), 4u);
  const std::vector<std::string> status_of = {"1,ok,new,", "2,stroke_above_max,held,", "3,malformed_input,held,",
                                              "4,ok,new,"};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(got[k].rfind(status_of[k], 0), 0u) << got[k];
    EXPECT_EQ(got[k].find('\n'), std::string::npos);  // one answer, no newline
  }
  EXPECT_EQ(commands_of(csv_rows(got[0])[0]), commands_of(csv_rows(got[3])[0]));
}
INSTANTIATE_TEST_SUITE_P(Receive, CliStreamUdp, ::testing::Values("", "--busy-poll --cpu=0"));

// A stream listening on UDP, started with `options`; its stderr read line by line.
struct UdpStream {
  FILE* pipe = nullptr;
  int port = -1;
  std::string first_line;
  explicit UdpStream(const std::string& options) {
    const std::string command = shell_quote(HEXATWIST_CLI) + " stream --input=udp://127.0.0.1:0 " + options + " 2>&1";
    pipe = popen(command.c_str(), "r");
    std::array<char, 1024> line{};
    while (pipe != nullptr && std::fgets(line.data(), line.size(), pipe) != nullptr) {
      first_line = line.data();
      if (first_line.find("listening on") != std::string::npos) break;
    }
    const auto at = first_line.find("127.0.0.1:");
    if (at != std::string::npos) port = std::stoi(first_line.substr(at + 10));
  }
  // The rest of its stderr and its exit code, once it ended.
  std::pair<std::string, int> finish() {
    std::string rest;
    std::array<char, 1024> line{};
    while (std::fgets(line.data(), line.size(), pipe) != nullptr) rest += line.data();
    const int status = pclose(pipe);
    return {rest, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
  }
};

TEST(CliStreamUdpInput, AcceptFromTakesPosesFromOneSenderOnlyAndCountsTheOthers) {
  TestSocket allowed, other, answers;
  UdpStream stream("--output=udp://127.0.0.1:" + std::to_string(answers.port()) +
                   " --accept-from=udp://127.0.0.1:" + std::to_string(allowed.port()) + " --count=2 --idle-timeout=20");
  ASSERT_GT(stream.port, 0) << stream.first_line;
  EXPECT_NE(stream.first_line.find("taking poses from udp://127.0.0.1:" + std::to_string(allowed.port())),
            std::string::npos)
      << stream.first_line;
  EXPECT_NE(stream.first_line.find("granted by the kernel"), std::string::npos) << stream.first_line;
  other.send_to(stream.port, "0,0,0.1,0,0,10");
  EXPECT_EQ(answers.receive(300), "(timeout)");  // not answered
  allowed.send_to(stream.port, "0,0,0.1,0,0,10");
  EXPECT_EQ(answers.receive(10000).rfind("1,ok,new,", 0), 0u);
  other.send_to(stream.port, "0,0,0.1,0,0,10");
  allowed.send_to(stream.port, "0,0,0.1,0,0,10");
  EXPECT_EQ(answers.receive(10000).rfind("2,ok,new,", 0), 0u);
  const auto [rest, code] = stream.finish();
  EXPECT_EQ(code, 0) << rest;
  EXPECT_NE(rest.find("2 datagrams from other senders were ignored"), std::string::npos) << rest;
}

TEST(CliStreamUdpInput, EveryDatagramIsAnsweredOrCountedAsDroppedByTheKernel) {
  TestSocket poses;
  UdpStream stream("--receive-buffer=4096 --idle-timeout=1");
  ASSERT_GT(stream.port, 0) << stream.first_line;
  constexpr int kSent = 20000;
  for (int k = 0; k < kSent; ++k) poses.send_to(stream.port, "0,0,0.1,0,0,10");
  const auto [rest, code] = stream.finish();
  EXPECT_EQ(code, 0) << rest;
  unsigned long long inputs = 0, dropped = 0;
  const auto summary = rest.find("(--idle-timeout); ");
  ASSERT_NE(summary, std::string::npos) << rest;
  ASSERT_EQ(std::sscanf(rest.c_str() + summary, "(--idle-timeout); %llu inputs", &inputs), 1) << rest;
  if (const auto at = rest.find(" datagrams were dropped by the kernel"); at != std::string::npos)
    dropped = std::stoull(rest.substr(rest.rfind("hexatwist stream: ", at) + 18));
  EXPECT_EQ(inputs + dropped, static_cast<unsigned long long>(kSent)) << rest;
}

TEST(CliStreamUdpInput, ARefusalFromBeforeTheReaderListenedLosesNoLaterAnswer) {
  int port = 0;
  {
    const TestSocket probe;  // a free port, closed again: nobody listens there yet
    port = probe.port();
  }
  TestSocket poses;
  UdpStream stream("--output=udp://127.0.0.1:" + std::to_string(port) + " --count=2 --idle-timeout=20");
  ASSERT_GT(stream.port, 0) << stream.first_line;
  poses.send_to(stream.port, "0,0,0.1,0,0,10");  // answered into a closed port: refused (ICMP)
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const TestSocket answers(port);  // the reader starts
  poses.send_to(stream.port, "0,0,0.1,0,0,10");
  EXPECT_EQ(answers.receive(10000).rfind("2,ok,new,", 0), 0u);
  const auto [rest, code] = stream.finish();
  EXPECT_EQ(code, 0) << rest;
  EXPECT_NE(rest.find("1 answers were refused"), std::string::npos) << rest;
}

}  // namespace
