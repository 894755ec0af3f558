// SPDX-License-Identifier: BSD-3-Clause
// The progress line of the long runs (apps/hexatwist/progress.hpp): drawn on a terminal only, with an
// estimate of the time left, erased at the end; the tolerance study's parts give the one-call result.
#include <fcntl.h>
#include <poll.h>
#include <pty.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>

#include "cli_support.hpp"
#include "progress.hpp"

using namespace hexatwist::cli_test;

namespace {

struct TerminalOutcome {
  int code = -1;
  std::string terminal;  // what the command wrote to stderr, a pseudo-terminal
  std::string out;       // its stdout, a file
};

// Runs the tool with stderr on a pseudo-terminal (stdout to a file), bounded to 120 s; with
// `interrupt` it gets SIGINT once the progress line has shown 5 % (then "%" and a line).
TerminalOutcome run_on_terminal(const std::vector<std::string>& args, bool interrupt = false) {
  TerminalOutcome r;
  const std::string out_path = (temp_dir() / "terminal-stdout.txt").string();
  std::vector<std::string> argv_text{HEXATWIST_CLI};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  int master = -1;
  const pid_t pid = forkpty(&master, nullptr, nullptr, nullptr);
  if (pid < 0) return r;
  if (pid == 0) {
    const int fd = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    if (fd < 0 || dup2(fd, STDOUT_FILENO) < 0) _exit(127);
    execv(argv[0], argv.data());
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  char buf[4096];
  for (;;) {
    pollfd p{master, POLLIN, 0};
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      ADD_FAILURE() << "timed out";
      break;
    }
    if (poll(&p, 1, 200) <= 0) continue;
    const ssize_t n = read(master, buf, sizeof buf);
    if (n <= 0) break;  // EIO: the child closed the terminal
    r.terminal.append(buf, static_cast<std::size_t>(n));
    if (interrupt && r.terminal.find("  5%") != std::string::npos) {
      kill(pid, SIGINT);
      interrupt = false;
    }
  }
  close(master);
  int status = 0;
  waitpid(pid, &status, 0);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = read_file(out_path);
  return r;
}

TEST(CliProgress, ToleranceDrawsItsProgressOnATerminalOnlyAndInPartsGetsTheSameResult) {
  const std::string on_tty = (temp_dir() / "progress-tty").string();
  const std::string piped = (temp_dir() / "progress-piped").string();
  // 20 stations calibrate every platform (14 would leave them all not identifiable).
  const std::vector<std::string> study{"tolerance",     "--platforms", "20",
                                       "--calibration", "stations:20", "--no-figures"};
  std::vector<std::string> args = study;
  args.insert(args.end(), {"--out", on_tty});
  const TerminalOutcome t = run_on_terminal(args);
  ASSERT_EQ(t.code, 0) << t.terminal;
  // The bar, its share and the platforms done; the line erased at the end (its last write a '\r').
  EXPECT_NE(t.terminal.find("] 100%  20 of 20 platforms"), std::string::npos) << t.terminal;
  EXPECT_NE(t.terminal.find("%  1 of 20 platforms"), std::string::npos) << t.terminal;
  EXPECT_EQ(t.terminal.back(), '\r');
  EXPECT_NE(t.out.find("20 platforms (seed 1)"), std::string::npos) << t.out;
  EXPECT_EQ(t.out.find("calibration failed"), std::string::npos) << t.out;
  // Piped: no line at all, and the Monte Carlo in one call gives every platform's errors bit for bit.
  args = study;
  args.insert(args.end(), {"--out", piped});
  const Outcome p = run(args);
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_EQ(p.err, "");
  EXPECT_EQ(read_file(std::filesystem::path(on_tty) / "platforms.csv"),
            read_file(std::filesystem::path(piped) / "platforms.csv"));
  // --json on a terminal: the summary alone, no progress.
  args = study;
  args.insert(args.end(), {"--out", (temp_dir() / "progress-json").string(), "--json"});
  const TerminalOutcome j = run_on_terminal(args);
  ASSERT_EQ(j.code, 0) << j.terminal;
  EXPECT_EQ(j.terminal, "");
  EXPECT_EQ(j.out.front(), '{');
}

TEST(CliProgress, AnInterruptedRunsMessageStartsOnALineOfItsOwn) {
  // SIGINT while the line is drawn: the roll-back message after a newline, not appended to the bar.
  const TerminalOutcome t = run_on_terminal({"tolerance", "--platforms", "400", "--calibration", "stations:20",
                                             "--no-figures", "--out", (temp_dir() / "progress-stopped").string()},
                                            true);
  EXPECT_EQ(t.code, 6) << t.terminal;
  const std::size_t at = t.terminal.find("hexatwist: stopped by SIGINT");
  ASSERT_NE(at, std::string::npos) << t.terminal;
  ASSERT_GT(at, 0u);
  EXPECT_EQ(t.terminal[at - 1], '\n') << t.terminal.substr(at > 80 ? at - 80 : 0);
  EXPECT_FALSE(std::filesystem::exists(temp_dir() / "progress-stopped"));
}

TEST(CliProgress, StudyDrawsItsTestsOnATerminal) {
  const TerminalOutcome t = run_on_terminal(
      {"study", "--tests", "Lz", "--no-figures", "--no-csv", "--out", (temp_dir() / "progress-study").string()});
  ASSERT_EQ(t.code, 0) << t.terminal;
  EXPECT_NE(t.terminal.find("%  Lz"), std::string::npos) << t.terminal;
  EXPECT_EQ(t.terminal.back(), '\r');
}

TEST(CliProgress, WorkspaceDrawsItsVolumeAndItsMapOnATerminalOnly) {
  const std::vector<std::string> args{"workspace", "--heights",    "0",        "--yaws", "0", "--cell",
                                      "0.05",      "--no-figures", "--no-csv", "--out"};
  std::vector<std::string> tty = args, piped = args;
  tty.push_back((temp_dir() / "progress-workspace").string());
  piped.push_back((temp_dir() / "progress-workspace-piped").string());
  const TerminalOutcome t = run_on_terminal(tty);
  ASSERT_EQ(t.code, 0) << t.terminal;
  // Each part's share as its rows of cells and of nodes finish, erased at the end.
  EXPECT_NE(t.terminal.find("] 100%  volume "), std::string::npos) << t.terminal;
  EXPECT_NE(t.terminal.find(" cells"), std::string::npos) << t.terminal;
  EXPECT_NE(t.terminal.find("] 100%  map "), std::string::npos) << t.terminal;
  EXPECT_EQ(t.terminal.back(), '\r');
  const Outcome p = run(piped);
  ASSERT_EQ(p.code, 0) << p.err;
  EXPECT_EQ(p.err, "");
  // The same numbers either way.
  EXPECT_EQ(read_file(std::filesystem::path(tty.back()) / "summary.json").size(),
            read_file(std::filesystem::path(piped.back()) / "summary.json").size());
}

TEST(CliProgress, DesignDrawsEachLegAloneThenTheDesign) {
  const TerminalOutcome t =
      run_on_terminal({"design", "--workspace", "random=200", "--out", (temp_dir() / "progress-design.yaml").string()});
  ASSERT_EQ(t.code, 0) << t.terminal;
  EXPECT_NE(t.terminal.find("%  each leg alone (1 of 6)"), std::string::npos) << t.terminal;
  EXPECT_NE(t.terminal.find("] 100%  the design"), std::string::npos) << t.terminal;
  EXPECT_EQ(t.terminal.back(), '\r');
  EXPECT_NE(t.out.find("optimum: no axes in the joint planes do better than"), std::string::npos) << t.out;
}

TEST(CliProgress, TheTimeLeftReadsAsAPersonSaysIt) {
  using hexatwist::cli::remaining_text;
  EXPECT_EQ(remaining_text(0.4), "0 s");
  EXPECT_EQ(remaining_text(59.4), "59 s");
  EXPECT_EQ(remaining_text(59.6), "1 min 00 s");
  EXPECT_EQ(remaining_text(245), "4 min 05 s");
  EXPECT_EQ(remaining_text(3725), "1 h 02 min");
  EXPECT_EQ(remaining_text(-3), "0 s");
}

}  // namespace
