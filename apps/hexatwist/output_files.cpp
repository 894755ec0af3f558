#include "output_files.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "cli_common.hpp"

namespace hexatwist::cli {
namespace {

namespace fs = std::filesystem;

// The file a path names once symbolic links at its end are followed (a link to a file that does
// not exist yet names that file), made absolute and free of "." and "..", with the links of its
// folders resolved.
fs::path resolved(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec) p = path;
  for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(p, ec)); ++hops) {
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) break;
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  const fs::path canonical = fs::weakly_canonical(p, ec);
  return ec ? p.lexically_normal() : canonical;
}

// The earlier run of our own in a report folder: every entry, the command and files its
// summary.json names (one JSON array of plain file names, our own writer's: read without a parser).
struct Summary {
  std::string command;
  std::vector<std::string> files;
  bool ours = false;
};

Summary read_summary(const fs::path& file) {
  Summary s;
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const std::string t = text.str();
  const std::size_t key = t.rfind("\"files\": [");
  if (key == std::string::npos) return s;
  s.ours = true;
  const std::size_t close = t.find(']', key);
  for (std::size_t q = t.find('"', key + 9); q < close; q = t.find('"', q + 1)) {
    const std::size_t r = t.find('"', q + 1);
    if (r == std::string::npos || r > close) break;
    const std::string name = t.substr(q + 1, r - q - 1);
    if (!name.empty() && name.find('/') == std::string::npos && name.find('\\') == std::string::npos)
      s.files.push_back(name);
    q = r;
  }
  if (const std::size_t c = t.find("\"command\": \""); c != std::string::npos) {
    const std::size_t begin = c + 12, end = t.find('"', begin);
    if (end != std::string::npos && end - begin < 64) s.command = t.substr(begin, end - begin);
  }
  return s;
}

std::string why(int err) { return err != 0 ? std::strerror(err) : "write error"; }

// Writes `content` whole to a new file `path` (which must not exist); false with errno on failure.
bool write_new_file(const std::string& path, std::string_view content, bool& created) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  created = fd >= 0;
  if (fd < 0) return false;
  std::size_t done = 0;
  while (done < content.size()) {
    const ssize_t n = ::write(fd, content.data() + done, content.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : ENOSPC;
      ::close(fd);
      errno = err;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) return false;
  return true;
}

}  // namespace

bool same_file(const std::string& a, const std::string& b) {
  const fs::path ra = resolved(a), rb = resolved(b);
  if (ra == rb) return true;
  std::error_code ec;
  return fs::exists(ra, ec) && fs::exists(rb, ec) && fs::equivalent(ra, rb, ec) && !ec;
}

OutputFiles::OutputFiles(std::string command) : command_(std::move(command)) {}

OutputFiles::~OutputFiles() {
  if (!finished_) roll_back();
}

void OutputFiles::input(std::string_view option, const std::string& path) {
  if (path.empty()) return;
  for (const Named& o : outputs_)
    if (same_file(o.path, path))
      throw ExitError(kExitBadInput,
                      fmt::format("{} '{}' is the input {}: an output never replaces an input; nothing was written",
                                  o.option, printable(o.path), option));
  inputs_.push_back({std::string(option), path});
}

void OutputFiles::check_not_input(std::string_view what, const std::string& path) const {
  for (const Named& i : inputs_)
    if (same_file(i.path, path))
      throw ExitError(kExitBadInput,
                      fmt::format("{} '{}' is the input {}: an output never replaces an input; nothing was written",
                                  what, printable(path), i.option));
}

void OutputFiles::output(std::string_view option, const std::string& path) {
  if (path.empty()) return;
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw ExitError(kExitBadInput,
                    fmt::format("{} '{}': is a folder; expected a file to write", option, printable(path)));
  check_not_input(option, path);
  for (const Named& o : outputs_)
    if (same_file(o.path, path))
      throw ExitError(kExitBadInput, fmt::format("{} and {} both name '{}': one run's outputs never overwrite each "
                                                 "other; nothing was written",
                                                 o.option, option, printable(path)));
  outputs_.push_back({std::string(option), path});
}

void OutputFiles::folder(std::string_view option, const std::string& dir) {
  folder_option_ = option;
  if (dir.empty()) throw ExitError(kExitBadInput, fmt::format("{}: expected a folder to write to, got ''", option));
  for (const Named& i : inputs_)
    if (same_file(i.path, dir))
      throw ExitError(kExitBadInput, fmt::format("{} '{}' is the input {}: an output never replaces an input", option,
                                                 printable(dir), i.option));
  std::error_code ec;
  const fs::path path = fs::absolute(dir, ec);
  // The folders this run makes, outermost first: removed again if the run fails.
  std::vector<fs::path> missing;
  for (fs::path p = path; !p.empty() && !fs::exists(fs::symlink_status(p, ec)); p = p.parent_path()) {
    missing.insert(missing.begin(), p);
    if (p == p.parent_path()) break;
  }
  for (const fs::path& p : missing) {
    if (!fs::create_directory(p, ec) && ec) break;
    created_.push_back(p);
  }
  if (ec || !fs::is_directory(path, ec))
    throw ExitError(kExitOutputFailed,
                    fmt::format("{}: cannot create the output folder '{}'{}", option, printable(dir),
                                ec ? ": " + ec.message() : std::string(": a file of that name is in the way")));
  folder_ = path;
  for (fs::directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec))
    earlier_.entries.push_back(it->path().filename().string());
  std::sort(earlier_.entries.begin(), earlier_.entries.end());
  if (fs::is_regular_file(path / "summary.json", ec)) {
    const Summary s = read_summary(path / "summary.json");
    if (s.ours) {
      earlier_.command = s.command;
      earlier_.listed = s.files;
      // The summaries themselves belong to that run, listed or not.
      for (const char* own : {"summary.json", "summary.md"}) earlier_.listed.emplace_back(own);
    }
  }
}

std::string OutputFiles::temporary_beside(const std::string& path, std::string_view kind) {
  std::error_code ec;
  const fs::path p(path);
  for (int n = 0;; ++n) {
    const fs::path candidate =
        p.parent_path() / fmt::format(".{}.{}-{}.{}", p.filename().string(), ::getpid(), n, kind);
    if (!fs::exists(fs::symlink_status(candidate, ec))) return candidate.string();
  }
}

void OutputFiles::add(const std::string& path, std::string content) {
  check_not_input("the output", path);
  for (const Pending& p : pending_)
    if (same_file(p.path, path))
      throw ExitError(kExitBadInput,
                      fmt::format("'{}' would be written twice by one run; nothing was written", printable(path)));
  // Through a symbolic link the file it names is replaced, and the link kept.
  const std::string target = resolved(path).string();
  pending_.push_back({target, std::string(), std::move(content), path});
  paths_.push_back(path);
}

std::string OutputFiles::external(const std::string& final_stem, const std::vector<std::string>& extensions) {
  const std::string stem = temporary_beside(final_stem, "part");
  for (const std::string& ext : extensions) {
    const std::string path = final_stem + ext;
    check_not_input("the output", path);
    pending_.push_back({resolved(path).string(), stem + ext, std::string(), path, true, true});
    paths_.push_back(path);
  }
  return stem;
}

std::vector<std::string> OutputFiles::names() const {
  std::vector<std::string> out;
  for (const std::string& p : paths_) out.push_back(fs::path(p).filename().string());
  return out;
}

void OutputFiles::stage() {
  for (Pending& p : pending_) {
    if (p.staged) continue;
    std::error_code ec;
    if (fs::is_directory(p.path, ec)) {
      roll_back();
      throw ExitError(kExitOutputFailed,
                      fmt::format("cannot write '{}': it is a directory; nothing was written", printable(p.shown)));
    }
    p.tmp = temporary_beside(p.path, "tmp");
    bool created = false;
    const bool ok = write_new_file(p.tmp, p.content, created);
    const int err = errno;
    p.staged = created;  // from here on, the temporary is ours to remove
    if (!ok) {
      roll_back();
      throw ExitError(kExitOutputFailed,
                      fmt::format("cannot write '{}': {}; nothing was written", printable(p.shown), why(err)));
    }
    p.content.clear();
    p.content.shrink_to_fit();
  }
}

void OutputFiles::move_aside(const std::string& path) {
  const std::string backup = temporary_beside(path, "bak");
  std::error_code ec;
  fs::rename(path, backup, ec);
  if (ec)
    throw ExitError(kExitOutputFailed,
                    fmt::format("cannot replace '{}': {}; nothing was written", printable(path), ec.message()));
  moved_.push_back({path, backup});
}

void OutputFiles::commit() {
  stage();
  try {
    for (Pending& p : pending_) {
      std::error_code ec;
      if (p.external && !fs::is_regular_file(p.tmp, ec))
        throw ExitError(kExitOutputFailed, fmt::format("'{}' was not drawn; nothing was written", printable(p.shown)));
      const fs::file_status st = fs::symlink_status(p.path, ec);
      if (fs::is_directory(st))
        throw ExitError(kExitOutputFailed,
                        fmt::format("cannot write '{}': it is a directory; nothing was written", printable(p.shown)));
      if (fs::exists(st)) move_aside(p.path);
      fs::rename(p.tmp, p.path, ec);
      if (ec)
        throw ExitError(kExitOutputFailed,
                        fmt::format("cannot write '{}': {}; nothing was written", printable(p.shown), ec.message()));
      p.staged = false;
      placed_.push_back(p.path);
    }
    clear_earlier_run();
  } catch (...) {
    roll_back();
    finished_ = true;
    throw;
  }
}

// A reused folder holds one run's files: the earlier run's files (as its summary listed them) that
// this run does not write are moved aside with the replaced ones; other files are left and named.
void OutputFiles::clear_earlier_run() {
  if (folder_.empty()) return;
  const std::vector<std::string> ours = names();
  const auto has = [](const std::vector<std::string>& v, const std::string& n) {
    return std::find(v.begin(), v.end(), n) != v.end();
  };
  for (const std::string& n : earlier_.entries) {
    const fs::path p = folder_ / n;
    bool input = false;
    for (const Named& i : inputs_) input = input || same_file(i.path, p.string());
    std::error_code ec;
    if (has(ours, n)) {
      ++replaced_;
    } else if (has(earlier_.listed, n) && !input && !fs::is_directory(fs::symlink_status(p, ec))) {
      move_aside(p.string());
      ++removed_;
    } else {
      others_.push_back(n);
    }
  }
}

std::string OutputFiles::folder_note() const {
  if (folder_.empty() || earlier_.entries.empty()) return {};
  std::string note = fmt::format(
      "hexatwist {}: note: {} '{}' was not empty: {} files replaced, {} of an earlier run "
      "removed",
      command_, folder_option_, printable(folder_.string()), replaced_, removed_);
  if (!others_.empty()) {
    note += fmt::format("; {} other files left, not described by the summary:", others_.size());
    for (std::size_t k = 0; k < others_.size() && k < 5; ++k) note += " " + printable(others_[k]);
    if (others_.size() > 5) note += " ...";
  }
  if (!earlier_.command.empty() && earlier_.command != command_)
    note += fmt::format("; the earlier run was {}", printable(earlier_.command));
  return note;
}

void OutputFiles::finish(std::string_view stdout_text) {
  if (placed_.empty() && !pending_.empty()) commit();
  try {
    write_stdout(stdout_text);
  } catch (const ExitError&) {
    roll_back();
    finished_ = true;
    throw;
  }
  finished_ = true;
  std::error_code ec;
  for (const Moved& m : moved_) fs::remove(m.backup, ec);
  if (const std::string note = folder_note(); !note.empty()) std::fprintf(stderr, "%s\n", note.c_str());
}

void OutputFiles::roll_back() noexcept {
  std::error_code ec;
  for (auto it = placed_.rbegin(); it != placed_.rend(); ++it) fs::remove(*it, ec);
  placed_.clear();
  for (auto it = moved_.rbegin(); it != moved_.rend(); ++it) fs::rename(it->backup, it->path, ec);
  moved_.clear();
  for (Pending& p : pending_)
    if (p.staged) {
      fs::remove(p.tmp, ec);
      p.staged = false;
    }
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove(*it, ec);  // only if empty
  created_.clear();
}

}  // namespace hexatwist::cli
