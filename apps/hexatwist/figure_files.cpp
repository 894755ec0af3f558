// SPDX-License-Identifier: BSD-3-Clause
// Writing figures: gnuplot found and run on the script (figure_script.hpp) in a private scratch
// directory, its first error named by figure, and each drawn file moved to its place whole.
#include "figures.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>
#include <system_error>

#include "cli_common.hpp"
#include "figure_script.hpp"
#include "signals.hpp"

extern char** environ;

namespace hexatwist::cli {

namespace fs = std::filesystem;

namespace {

bool is_executable_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(path.c_str(), X_OK) == 0;
}

// Fails with the output path if figures cannot be written into the directory of `stem`, before
// gnuplot runs.
void check_output_directory(const std::string& stem) {
  if (stem.empty()) throw ExitError(kExitOutputFailed, "cannot write a figure: its output path is empty");
  fs::path dir = fs::path(stem).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  const auto status = fs::status(dir, ec);
  const std::string target = printable(stem + ".png");
  if (!fs::exists(status))
    throw ExitError(kExitOutputFailed, fmt::format("cannot write figure '{}': directory '{}' does not exist", target,
                                                   printable(dir.string())));
  if (!fs::is_directory(status))
    throw ExitError(kExitOutputFailed,
                    fmt::format("cannot write figure '{}': '{}' is not a directory", target, printable(dir.string())));
  if (::access(dir.c_str(), W_OK) != 0)
    throw ExitError(kExitOutputFailed, fmt::format("cannot write figure '{}': directory '{}': {}", target,
                                                   printable(dir.string()), std::strerror(errno)));
}

// A private directory for the script, gnuplot's messages and the figures while they are drawn;
// removed with everything in it when the write ends, however it ends.
class ScratchDir {
 public:
  ScratchDir() {
    std::error_code ec;
    fs::path base = fs::temp_directory_path(ec);
    if (ec) base = "/tmp";
    std::string tmpl = (base / "hexatwist_figures_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr)
      throw ExitError(kExitOutputFailed, fmt::format("cannot create a temporary directory in '{}': {}",
                                                     printable(base.string()), std::strerror(errno)));
    const signals::Critical critical;
    path_ = tmpl;
    signals::add_undo(&ScratchDir::undo, this);
  }
  ~ScratchDir() {
    const signals::Critical critical;
    signals::remove_undo(&ScratchDir::undo, this);
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  static void undo(void* self) noexcept { signals::remove_flat_dir(static_cast<ScratchDir*>(self)->path_.c_str()); }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// gnuplot's first error from its stderr, as "<message>", and the script line it names (0 if none).
// gnuplot reports an error as `"script" line N: message`, after echoing the command and a caret.
std::pair<std::string, std::size_t> first_error(const std::string& err) {
  std::istringstream in(err);
  std::string first_text;
  for (std::string line; std::getline(in, line);) {
    const auto at = line.find(" line ");
    if (at != std::string::npos) {
      std::size_t n = 0;
      const char* b = line.data() + at + 6;
      const char* e = line.data() + line.size();
      const auto [ptr, ec] = std::from_chars(b, e, n);
      if (ec == std::errc() && ptr + 1 < e && ptr[0] == ':' && ptr[1] == ' ') {
        const std::string message(ptr + 2, e);
        if (message.rfind("warning:", 0) == 0) continue;
        return {message, n};
      }
    }
    const auto text = line.find_first_not_of(" \t^");
    if (first_text.empty() && text != std::string::npos) first_text = line.substr(text);
  }
  return {first_text, 0};
}

// Runs gnuplot on `script`; its stderr goes to `err`. Returns the wait status.
int run_gnuplot(const std::string& gnuplot, const fs::path& script, const fs::path& err) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  // --default-settings: no ~/.gnuplot or system gnuplotrc changes the look.
  std::string arg0 = gnuplot, arg1 = "--default-settings", arg2 = script.string();
  char* argv[] = {arg0.data(), arg1.data(), arg2.data(), nullptr};
  pid_t pid = 0;
  int rc = 0;
  {
    const signals::Critical critical;  // a signal now stops gnuplot with the run
    rc = posix_spawn(&pid, gnuplot.c_str(), &actions, nullptr, argv, environ);
    if (rc == 0) signals::add_child(pid);
  }
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw ExitError(kExitOutputFailed,
                    fmt::format("cannot run gnuplot '{}': {}", printable(gnuplot), std::strerror(rc)));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) {
      const signals::Critical critical;
      signals::remove_child(pid);
      throw ExitError(kExitOutputFailed, fmt::format("waiting for gnuplot failed: {}", std::strerror(errno)));
    }
  }
  const signals::Critical critical;
  signals::remove_child(pid);
  return status;
}

// Moves a drawn file to its place: a rename when on the same file system, else a copy under a
// temporary name beside the target and a rename, so the target is never half written.
void publish(const fs::path& from, const std::string& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (!ec) return;
  if (ec != std::errc::cross_device_link)
    throw ExitError(kExitOutputFailed, fmt::format("cannot write figure '{}': {}", printable(to), ec.message()));
  const std::string partial = fmt::format("{}.partial-{}", to, ::getpid());
  fs::copy_file(from, partial, fs::copy_options::overwrite_existing, ec);
  if (!ec) fs::rename(partial, to, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(partial, ignored);
    throw ExitError(kExitOutputFailed, fmt::format("cannot write figure '{}': {}", printable(to), ec.message()));
  }
}

}  // namespace

std::string find_gnuplot() {
  const char* env = std::getenv("HEXATWIST_GNUPLOT");
  const std::string name = env != nullptr && *env != '\0' ? env : "gnuplot";
  if (name.find('/') != std::string::npos) return is_executable_file(name) ? name : std::string();
  const char* path = std::getenv("PATH");
  std::string_view dirs = path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin";
  for (;;) {
    const auto colon = dirs.find(':');
    std::string dir(dirs.substr(0, colon));
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/" + name;
    if (is_executable_file(candidate)) return candidate;
    if (colon == std::string_view::npos) return {};
    dirs.remove_prefix(colon + 1);
  }
}

namespace {

// Every figure writable and consistent before gnuplot runs: its directory, one stem each, maps
// and series whose sizes agree.
void check_figures(const std::vector<Figure>& figures) {
  std::set<std::string> stems;
  for (const Figure& fig : figures) {
    check_output_directory(fig.stem);
    if (!stems.insert(fig.stem).second)
      throw ExitError(kExitOutputFailed,
                      fmt::format("two figures would both be written to '{}.png'", printable(fig.stem)));
    for (const Panel& panel : fig.panels)
      if (panel.map && (panel.map->u.empty() || panel.map->v.empty() ||
                        panel.map->values.size() != panel.map->u.size() * panel.map->v.size()))
        throw ExitError(kExitOutputFailed,
                        fmt::format("figure '{}': colour map '{}' has {} values for {} x {} cells", printable(fig.stem),
                                    printable(panel.map->label), panel.map->values.size(), panel.map->u.size(),
                                    panel.map->v.size()));
    for (const Panel& panel : fig.panels)
      for (const Series& s : panel.series)
        if (s.x.size() != s.y.size())
          throw ExitError(kExitOutputFailed,
                          fmt::format("figure '{}': series '{}' has {} x values but {} y values", printable(fig.stem),
                                      printable(s.label), s.x.size(), s.y.size()));
  }
}

// gnuplot's failure in one line: the figure whose commands hold the failing line, how it ended,
// its first message.
ExitError gnuplot_failure(const std::vector<Figure>& figures, const Script& script, int status,
                          const fs::path& err_path) {
  const auto [message, line] = first_error(read_text(err_path));
  std::string where;
  if (line > 0) {
    std::size_t offset = 0;
    for (std::size_t l = 1; l < line && offset != std::string::npos; ++l) {
      offset = script.text.find('\n', offset);
      if (offset != std::string::npos) ++offset;
    }
    const auto it = std::upper_bound(script.figure_start.begin(), script.figure_start.end(), offset);
    if (it != script.figure_start.begin())
      where = fmt::format(" drawing '{}'",
                          printable(figures[static_cast<std::size_t>(it - script.figure_start.begin() - 1)].stem));
  }
  const std::string how = WIFEXITED(status) ? fmt::format("exit status {}", WEXITSTATUS(status))
                                            : fmt::format("signal {}", WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  return ExitError(kExitOutputFailed, fmt::format("gnuplot failed{} ({}){}{}", where, how, message.empty() ? "" : ": ",
                                                  printable(message)));
}

// Every drawn file checked, then all put in place, or none (a failure half way removes those
// already placed).
void publish_all(const std::vector<Figure>& figures, const fs::path& scratch) {
  for (std::size_t f = 0; f < figures.size(); ++f) {
    for (const char* ext : {"png", "svg"}) {
      const fs::path drawn = scratch / fmt::format("f{}.{}", f, ext);
      std::error_code ec;
      const auto size = fs::file_size(drawn, ec);
      if (ec || size == 0)
        throw ExitError(kExitOutputFailed,
                        fmt::format("gnuplot did not write figure '{}.{}'", printable(figures[f].stem), ext));
    }
  }
  std::vector<std::string> published;
  try {
    for (std::size_t f = 0; f < figures.size(); ++f)
      for (const char* ext : {"png", "svg"}) {
        const std::string to = fmt::format("{}.{}", figures[f].stem, ext);
        publish(scratch / fmt::format("f{}.{}", f, ext), to);
        published.push_back(to);
      }
  } catch (...) {
    std::error_code ignored;
    for (const std::string& p : published) fs::remove(p, ignored);
    throw;
  }
}

}  // namespace

void write_figures(const std::vector<Figure>& figures) {
  if (figures.empty()) return;
  const std::string gnuplot = find_gnuplot();
  if (gnuplot.empty()) {
    const char* env = std::getenv("HEXATWIST_GNUPLOT");
    throw ExitError(kExitOutputFailed,
                    env != nullptr && *env != '\0'
                        ? fmt::format("gnuplot not found at HEXATWIST_GNUPLOT='{}'; run scripts/setup.sh or install "
                                      "gnuplot-nox",
                                      printable(env))
                        : std::string("gnuplot not found; run scripts/setup.sh or install gnuplot-nox"));
  }
  check_figures(figures);

  const ScratchDir scratch;
  const Script script = build_script(figures, scratch.path());
  const fs::path script_path = scratch.path() / "figures.gp";
  const fs::path err_path = scratch.path() / "gnuplot.err";
  {
    std::ofstream out(script_path, std::ios::binary);
    out.write(script.text.data(), static_cast<std::streamsize>(script.text.size()));
    out.close();
    if (!out)
      throw ExitError(kExitOutputFailed,
                      fmt::format("cannot write gnuplot script '{}'", printable(script_path.string())));
  }
  const int status = run_gnuplot(gnuplot, script_path, err_path);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw gnuplot_failure(figures, script, status, err_path);
  publish_all(figures, scratch.path());
}

}  // namespace hexatwist::cli
