// hexatwist stream: answers on standard output and over UDP.
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
}

// A UDP socket of the test, bound to an ephemeral loopback port.
struct TestSocket {
  int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  TestSocket() {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
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

}  // namespace
