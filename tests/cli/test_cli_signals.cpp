// SPDX-License-Identifier: BSD-3-Clause
// A signal is a failure like any other (apps/hexatwist/signals.hpp), walked across every command of
// the command table: SIGTERM, SIGINT or SIGHUP at moments spread over the run leave the folder byte
// for byte as it was (exit 6, one line) or the run completes (its own exit code); never a half-written
// file, a temporary or a backup left behind. SIGPIPE on standard output is a failed write (exit 4),
// rolled back as one.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <map>
#include <thread>

#include "cli_support.hpp"
#include "command_table.hpp"

using namespace hexatwist::cli_test;

namespace {

// Every entry under `dir` (hidden ones too): its content, or where a link points.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> s;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = fs::relative(it->path(), dir).string();
    if (it->is_symlink())
      s[name] = "link:" + fs::read_symlink(it->path()).string();
    else if (it->is_directory())
      s[name] = "<dir>";
    else
      s[name] = read_file(it->path());
  }
  return s;
}

// The names only (a completed run may write other digits, a time, than the one before it).
std::vector<std::string> names(const std::map<std::string, std::string>& s) {
  std::vector<std::string> out;
  for (const auto& [name, content] : s) out.push_back(name);
  return out;
}

// Starts the tool in `dir` (stdin /dev/null, stdout to `out_fd` or /dev/null, stderr to `err`).
pid_t spawn_in(const fs::path& dir, const std::vector<std::string>& args, const fs::path& err, int out_fd = -1) {
  std::vector<std::string> words{HEXATWIST_CLI};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = out_fd >= 0 ? out_fd : ::open("/dev/null", O_WRONLY);
    const int e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || e < 0 || ::chdir(dir.c_str()) != 0) ::_exit(127);
    ::dup2(in, STDIN_FILENO);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(e, STDERR_FILENO);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  return pid;
}

int wait_code(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// Hidden files of an unfinished write: temporaries, backups, figures being drawn.
bool has_leftovers(const std::map<std::string, std::string>& s) {
  for (const auto& [name, content] : s)
    if (name.find(".hexatwist-") != std::string::npos && !name.ends_with(".hexatwist-run.json")) return true;
  return false;
}

TEST(CliSignals, AStopSignalAtAnyMomentRollsEveryCommandBackOrLetsItComplete) {
  const Inputs& in = inputs();
  const auto base = base_arguments(in);
  const int kSignals[] = {SIGTERM, SIGINT, SIGHUP};
  // Under the sanitizers (about 25 times slower, scripts/test.sh's second stage) three moments.
#ifdef HEXATWIST_SANITIZED
  const double kFractions[] = {0.3, 0.6, 0.9};
#else
  const double kFractions[] = {0.15, 0.35, 0.55, 0.75, 0.9, 0.97};
#endif
  int interrupted_total = 0;
  for (const auto& [command, args] : base) {
    const fs::path dir = in.dir / ("signals-" + command);
    fs::create_directories(dir);
    std::vector<std::string> full{command};
    full.insert(full.end(), args.begin(), args.end());
    // An earlier run's files, which an interrupted run must leave as they are.
    const auto t0 = std::chrono::steady_clock::now();
    const Outcome first = run_in(dir, full);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(first.code == 0 || (command == "identify" && first.code == 5)) << first.command << "\n" << first.err;
    fs::remove(dir / "stderr.txt");
    auto before = snapshot(dir);
    int interrupted = 0;
    for (std::size_t k = 0; k < std::size(kFractions); ++k) {
      const int sig = kSignals[k % std::size(kSignals)];
      const fs::path err = in.dir / ("signals-" + command + ".err");
      const pid_t pid = spawn_in(dir, full, err);
      std::this_thread::sleep_for(std::chrono::duration<double>(kFractions[k] * seconds));
      ::kill(pid, sig);
      const int code = wait_code(pid);
      const auto after = snapshot(dir);
      const std::string what = command + " stopped by signal " + std::to_string(sig) + " after " +
                               std::to_string(kFractions[k] * seconds) + " s: exit " + std::to_string(code);
      const std::string message = read_file(err);
      EXPECT_FALSE(has_leftovers(after)) << what;
      if (code == 6) {
        ++interrupted;
        EXPECT_EQ(after, before) << what << ": the folder changed";
        EXPECT_NE(message.find("stopped by SIG"), std::string::npos) << what << "\n" << message;
        EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << what << "\n" << message;
      } else if (code == 128 + sig) {
        // Before main() installed the handlers (the first milliseconds): nothing was written yet.
        EXPECT_EQ(after, before) << what;
        EXPECT_EQ(message, "") << what;
      } else {
        EXPECT_EQ(code, first.code) << what << "\n" << message;
        EXPECT_EQ(names(after), names(before)) << what;
        before = after;  // the run completed: its files (another time in a summary) are what is there now
      }
    }
    // A run long enough to be caught is caught at least once.
    if (seconds > 0.2) {
      EXPECT_GT(interrupted, 0) << command << " (" << seconds << " s) was never interrupted";
    }
    interrupted_total += interrupted;
  }
  EXPECT_GT(interrupted_total, static_cast<int>(std::size(kFractions)));
}

TEST(CliSignals, AClosedStandardOutputIsAFailedWriteRolledBack) {
  const Inputs& in = inputs();
  const auto base = base_arguments(in);
  for (const auto& [command, args] : base) {
    const fs::path dir = in.dir / ("sigpipe-" + command);
    fs::create_directories(dir);
    std::vector<std::string> full{command};
    full.insert(full.end(), args.begin(), args.end());
    const Outcome first = run_in(dir, full);
    ASSERT_TRUE(first.code == 0 || (command == "identify" && first.code == 5)) << first.err;
    fs::remove(dir / "stderr.txt");
    const auto before = snapshot(dir);
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    ::close(fds[0]);  // nobody reads: `hexatwist ... | true`
    const fs::path err = in.dir / ("sigpipe-" + command + ".err");
    const pid_t pid = spawn_in(dir, full, err, fds[1]);
    ::close(fds[1]);
    const int code = wait_code(pid);
    const std::string message = read_file(err);
    if (first.out.empty()) {
      EXPECT_EQ(code, first.code) << command << " prints nothing: " << message;
      continue;
    }
    EXPECT_EQ(code, 4) << command << "\n" << message;
    EXPECT_NE(message.find("Broken pipe"), std::string::npos) << command << "\n" << message;
    EXPECT_EQ(snapshot(dir), before) << command << ": a failed write changed the folder";
  }
}

}  // namespace
