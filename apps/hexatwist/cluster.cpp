// SPDX-License-Identifier: BSD-3-Clause
#include "cluster.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_common.hpp"
#include "signals.hpp"

extern char** environ;

namespace hexatwist::cli {
namespace {

namespace fs = std::filesystem;

#ifndef HEXATWIST_PYTHON_DEFAULT
#define HEXATWIST_PYTHON_DEFAULT "python3"
#endif

std::string python_program() {
  const char* env = std::getenv("HEXATWIST_PYTHON");
  if (env != nullptr && *env != '\0') return env;
  return HEXATWIST_PYTHON_DEFAULT;
}

// The last non-empty line of a text (Python's traceback ends with the exception).
std::string last_line(const std::string& text) {
  std::istringstream in(text);
  std::string last;
  for (std::string line; std::getline(in, line);)
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  return last;
}

void write_all(int fd, std::string_view data) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd, data.data(), data.size());
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;  // Python ended early: its exit status says why
    data.remove_prefix(static_cast<std::size_t>(n));
  }
}

std::string read_all(int fd) {
  std::string out;
  char buf[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    out.append(buf, static_cast<std::size_t>(n));
  }
  return out;
}

ClusterArrays parse(const std::string& text) {
  ClusterArrays arrays;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string name;
    std::size_t count = 0;
    if (!(fields >> name >> count)) continue;
    std::vector<double> values;
    values.reserve(count);
    for (std::string item; values.size() < count && fields >> item;) {
      char* end = nullptr;
      const double v = std::strtod(item.c_str(), &end);  // hexadecimal floats, inf and nan included
      if (end == item.c_str() || *end != '\0')
        throw ExitError(kExitOutOfLimit, fmt::format("--scheduler: the cluster's answer has '{}' in {}",
                                                     printable(item), printable(name)));
      values.push_back(v);
    }
    if (values.size() != count)
      throw ExitError(kExitOutOfLimit, fmt::format("--scheduler: the cluster's answer has {} of the {} values of {}",
                                                   values.size(), count, printable(name)));
    arrays[name] = std::move(values);
  }
  return arrays;
}

}  // namespace

ClusterArrays run_cluster_job(const std::string& scheduler, const std::string& request) {
  const std::string python = python_program();
  int in_pipe[2], out_pipe[2];
  if (::pipe(in_pipe) != 0 || ::pipe(out_pipe) != 0)
    throw ExitError(kExitBadInput, fmt::format("--scheduler: cannot create a pipe: {}", std::strerror(errno)));
  char tmpl[] = "/tmp/hexatwist_cluster_XXXXXX";
  const int err_fd = ::mkstemp(tmpl);
  if (err_fd < 0)
    throw ExitError(kExitBadInput,
                    fmt::format("--scheduler: cannot create a temporary file: {}", std::strerror(errno)));
  ::close(err_fd);
  const std::string err_path = tmpl;

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, in_pipe[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, out_pipe[1], STDOUT_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_path.c_str(), O_WRONLY | O_TRUNC, 0600);
  for (const int fd : {in_pipe[0], in_pipe[1], out_pipe[0], out_pipe[1]})
    posix_spawn_file_actions_addclose(&actions, fd);
  std::string arg0 = python, arg1 = "-m", arg2 = "hexatwist.cluster";
  char* argv[] = {arg0.data(), arg1.data(), arg2.data(), nullptr};
  pid_t pid = 0;
  int rc = 0;
  // A signal stops the client with the run and removes its message file.
  const signals::Undo remove_err = [](void* path) noexcept { ::unlink(static_cast<const char*>(path)); };
  void* const err_context = const_cast<char*>(err_path.c_str());
  {
    const signals::Critical critical;
    signals::add_undo(remove_err, err_context);
    rc = python.find('/') != std::string::npos ? posix_spawn(&pid, python.c_str(), &actions, nullptr, argv, environ)
                                               : posix_spawnp(&pid, python.c_str(), &actions, nullptr, argv, environ);
    if (rc == 0) signals::add_child(pid);
  }
  posix_spawn_file_actions_destroy(&actions);
  ::close(in_pipe[0]);
  ::close(out_pipe[1]);
  if (rc != 0) {
    ::close(in_pipe[1]);
    ::close(out_pipe[0]);
    const signals::Critical critical;
    signals::remove_undo(remove_err, err_context);
    std::error_code ec;
    fs::remove(err_path, ec);
    throw ExitError(kExitBadInput, fmt::format("--scheduler: cannot run Python '{}' (HEXATWIST_PYTHON): {}",
                                               printable(python), std::strerror(rc)));
  }
  {
    // Python may end before it reads the request (a failed import): no SIGPIPE for that, its exit
    // status says what happened.
    struct sigaction ignore {
    }, previous{};
    ignore.sa_handler = SIG_IGN;
    ::sigaction(SIGPIPE, &ignore, &previous);
    write_all(in_pipe[1], request);
    ::close(in_pipe[1]);
    ::sigaction(SIGPIPE, &previous, nullptr);
  }
  const std::string out = read_all(out_pipe[0]);
  ::close(out_pipe[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  {
    const signals::Critical critical;
    signals::remove_child(pid);
  }
  std::string err;
  {
    std::ifstream e(err_path, std::ios::binary);
    std::ostringstream s;
    s << e.rdbuf();
    err = s.str();
  }
  {
    const signals::Critical critical;
    signals::remove_undo(remove_err, err_context);
    std::error_code ec;
    fs::remove(err_path, ec);
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 0) return parse(out);
  const std::string why = printable(last_line(err));
  if (err.find("No module named 'hexatwist'") != std::string::npos ||
      err.find("No module named 'dask'") != std::string::npos ||
      err.find("No module named 'distributed'") != std::string::npos)
    throw ExitError(kExitBadInput,
                    fmt::format("--scheduler needs the hexatwist Python package and dask.distributed importable by "
                                "'{}' (set PYTHONPATH, e.g. build/python, or HEXATWIST_PYTHON): {}",
                                printable(python), why));
  if (code == 2) throw ExitError(kExitBadInput, fmt::format("--scheduler {}: {}", printable(scheduler), why));
  throw ExitError(kExitOutOfLimit,
                  fmt::format("--scheduler {}: the cluster job failed: {}", printable(scheduler), why));
}

const std::vector<double>& cluster_array(const ClusterArrays& arrays, const std::string& name, std::size_t size) {
  const auto it = arrays.find(name);
  if (it == arrays.end())
    throw ExitError(kExitOutOfLimit, fmt::format("--scheduler: the cluster's answer has no {}", name));
  if (size != 0 && it->second.size() != size)
    throw ExitError(kExitOutOfLimit, fmt::format("--scheduler: the cluster's answer has {} values of {}, not {}",
                                                 it->second.size(), name, size));
  return it->second;
}

}  // namespace hexatwist::cli
