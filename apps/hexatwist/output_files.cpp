// SPDX-License-Identifier: BSD-3-Clause
#include "output_files.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>
#include <tuple>

#include "cli_common.hpp"
#include "signals.hpp"

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

// 64-bit FNV-1a: the fingerprint of a file in the manifest (shows a file is still what we wrote).
struct Fingerprint {
  std::uint64_t bytes = 0, hash = 14695981039346656037ull;
  void add(std::string_view data) {
    for (const char c : data) hash = (hash ^ static_cast<unsigned char>(c)) * 1099511628211ull;
    bytes += data.size();
  }
};

// The fingerprint of a regular file (not through a link); nullopt if it is not one or unreadable.
std::optional<Fingerprint> fingerprint_of(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  struct stat st {};
  std::optional<Fingerprint> f;
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode)) {
    f.emplace();
    char buffer[1 << 16];
    for (;;) {
      const ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) f.reset();
      if (n <= 0) break;
      f->add(std::string_view(buffer, static_cast<std::size_t>(n)));
    }
  }
  ::close(fd);
  return f;
}

// A manifest is small (a line per file); a larger file of that name is not ours.
constexpr std::size_t kMaxManifestBytes = 1 << 20;

// Reads the manifest of an earlier run (our own writer's line format, read without a parser, with
// a bound, never through a link). Anything else: not ours, nothing listed.
struct Manifest {
  bool ours = false;
  std::string command;
  std::vector<std::tuple<std::string, std::uint64_t, std::uint64_t>> files;  // name, bytes, hash
};

Manifest read_manifest(const fs::path& file) {
  Manifest m;
  const int fd = ::open(file.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return m;
  struct stat st {};
  std::string text;
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && static_cast<std::size_t>(st.st_size) <= kMaxManifestBytes) {
    char buffer[1 << 16];
    for (;;) {
      const ssize_t n = ::read(fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0 || text.size() + static_cast<std::size_t>(n) > kMaxManifestBytes) break;
      text.append(buffer, static_cast<std::size_t>(n));
    }
  }
  ::close(fd);
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line != "{") return m;
  if (!std::getline(in, line) || line != fmt::format("  \"schema\": \"{}\",", kRunManifestSchema)) return m;
  if (!std::getline(in, line) || !line.starts_with("  \"command\": \"") || !line.ends_with("\",")) return m;
  const std::string command = line.substr(14, line.size() - 16);
  if (!std::getline(in, line) || line != "  \"files\": [") return m;
  while (std::getline(in, line) && line.starts_with("    {\"name\": \"")) {
    const std::size_t close = line.find('"', 14);
    if (close == std::string::npos) return m;
    const std::string name = line.substr(14, close - 14);
    unsigned long long bytes = 0, hash = 0;
    if (std::sscanf(line.c_str() + close, "\", \"bytes\": %llu, \"fnv1a64\": \"%16llx\"}", &bytes, &hash) != 2)
      return m;
    if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..") return m;
    m.files.emplace_back(name, bytes, hash);
  }
  if (line != "  ]" && line != "  ],") return m;
  m.ours = true;
  m.command = command;
  return m;
}

// A name the manifest can carry in its line format (others are never listed, so never removed).
bool plain_name(std::string_view name) {
  return std::all_of(name.begin(), name.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u >= 0x20 && u != 0x7f && c != '"' && c != '\\' && c != '/';
  });
}

std::string why(int err) { return err != 0 ? std::strerror(err) : "write error"; }

// Writes `content` whole to a new file `path` (which must not exist); false with errno on failure.
bool write_new_file(const std::string& path, std::string_view content, bool& created) {
  int fd = -1;
  {
    const signals::Critical critical;  // the temporary and its flag together (the handler removes it)
    fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    created = fd >= 0;
  }
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

OutputFiles::OutputFiles(std::string command) : command_(std::move(command)) {
  const signals::Critical critical;
  signals::add_undo(&OutputFiles::undo, this);
}

OutputFiles::~OutputFiles() {
  {
    const signals::Critical critical;
    if (!finished_) roll_back();
    signals::remove_undo(&OutputFiles::undo, this);
  }
  if (lock_ >= 0) ::close(lock_);
}

void OutputFiles::undo(void* self) noexcept { static_cast<OutputFiles*>(self)->roll_back(); }

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

void OutputFiles::check_not_link(std::string_view what, const std::string& path) const {
  std::error_code ec;
  if (fs::is_symlink(fs::symlink_status(path, ec)))
    throw ExitError(kExitBadInput, fmt::format("{} '{}' is a symbolic link: hexatwist never writes through a link "
                                               "(name the file it points to, or remove the link); nothing was written",
                                               what, printable(path)));
}

void OutputFiles::output(std::string_view option, const std::string& path) {
  if (path.empty()) return;
  std::error_code ec;
  if (fs::is_directory(fs::symlink_status(path, ec)))
    throw ExitError(kExitBadInput,
                    fmt::format("{} '{}': is a folder; expected a file to write", option, printable(path)));
  check_not_input(option, path);
  check_not_link(option, path);
  for (const Named& o : outputs_)
    if (same_file(o.path, path))
      throw ExitError(kExitBadInput, fmt::format("{} and {} both name '{}': one run's outputs never overwrite each "
                                                 "other; nothing was written",
                                                 o.option, option, printable(path)));
  // Its folder must be there before the run computes anything (a file's folder is never created).
  const fs::path parent = fs::path(path).parent_path();
  const fs::path dir = parent.empty() ? fs::path(".") : parent;
  if (const fs::file_status st = fs::status(dir, ec); !fs::is_directory(st))
    throw ExitError(kExitOutputFailed,
                    fmt::format("{} '{}': the folder '{}' {}; nothing was written", option, printable(path),
                                printable(dir.string()), fs::exists(st) ? "is not a folder" : "does not exist"));
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
  {
    const signals::Critical critical;
    created_.reserve(missing.size());
    for (const fs::path& p : missing) {
      if (::mkdir(p.c_str(), 0777) != 0) {
        if (errno != EEXIST) ec.assign(errno, std::generic_category());
        break;
      }
      created_.push_back(p);
    }
  }
  if (ec || !fs::is_directory(path, ec))
    throw ExitError(kExitOutputFailed,
                    fmt::format("{}: cannot create the output folder '{}'{}", option, printable(dir),
                                ec ? ": " + ec.message() : std::string(": a file of that name is in the way")));
  // One run at a time in a folder: another run's lock refuses this one before anything is written.
  lock_ = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (lock_ < 0 || ::flock(lock_, LOCK_EX | LOCK_NB) != 0) {
    const int err = errno;
    if (err == EWOULDBLOCK) {
      const signals::Critical critical;
      created_.clear();  // the folder is the other run's now
      throw ExitError(kExitBadInput, fmt::format("{} '{}': another hexatwist run is writing into this folder; wait "
                                                 "for it to end or choose another folder; nothing was written",
                                                 option, printable(dir)));
    }
    throw ExitError(kExitOutputFailed,
                    fmt::format("{}: cannot open the output folder '{}': {}", option, printable(dir), why(err)));
  }
  folder_ = path;
  for (fs::directory_iterator it(path, ec), end; !ec && it != end; it.increment(ec))
    earlier_.entries.push_back(it->path().filename().string());
  std::sort(earlier_.entries.begin(), earlier_.entries.end());
  if (const Manifest m = read_manifest(path / kRunManifest); m.ours) {
    earlier_.command = m.command;
    for (const auto& [name, bytes, hash] : m.files) earlier_.listed.push_back({name, bytes, hash});
  }
}

std::string OutputFiles::temporary_beside(const std::string& path, std::string_view kind) {
  // A short name of its own (not the final name's): it fits wherever the final name fits.
  std::error_code ec;
  const fs::path dir = fs::path(path).parent_path();
  for (int n = 0;; ++n) {
    const fs::path candidate = dir / fmt::format(".hexatwist-{}-{}.{}", ::getpid(), n, kind);
    if (!fs::exists(fs::symlink_status(candidate, ec))) {
      bool taken = false;
      for (const Pending& p : pending_)
        taken = taken || p.tmp == candidate.string() || p.tmp.starts_with(candidate.string() + ".");
      for (const Moved& m : moved_) taken = taken || m.backup == candidate.string();
      if (!taken) return candidate.string();
    }
  }
}

// In a report folder, a file this run writes replaces only a file of ours: one the folder's
// manifest lists with the size and hash it still has.
void OutputFiles::check_replaceable(const std::string& path) const {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(path, ec);
  if (folder_.empty() || !fs::exists(st) || fs::is_directory(st)) return;  // (a folder in the way: stage())
  if (!fs::equivalent(fs::path(path).parent_path(), folder_, ec)) return;
  const std::string name = fs::path(path).filename().string();
  const std::optional<Fingerprint> f = fingerprint_of(path);
  for (const Written& w : earlier_.listed)
    if (w.name == name && f && f->bytes == w.bytes && f->hash == w.hash) return;
  throw ExitError(kExitBadInput,
                  fmt::format("{} '{}': holds '{}', which hexatwist did not write (or which changed since): a run "
                              "never replaces a file it cannot show it made; move it away or choose another folder; "
                              "nothing was written",
                              folder_option_, printable(folder_.string()), printable(name)));
}

void OutputFiles::add(const std::string& path, std::string content) {
  check_not_input("the output", path);
  check_not_link("the output", path);
  check_replaceable(path);
  for (const Pending& p : pending_)
    if (same_file(p.path, path))
      throw ExitError(kExitBadInput,
                      fmt::format("'{}' would be written twice by one run; nothing was written", printable(path)));
  add_pending(path, std::move(content));
  paths_.push_back(path);
}

std::string OutputFiles::external(const std::string& final_stem, const std::vector<std::string>& extensions) {
  const std::string stem = temporary_beside(final_stem, "part");
  for (const std::string& ext : extensions) {
    const std::string path = final_stem + ext;
    check_not_input("the output", path);
    check_not_link("the output", path);
    check_replaceable(path);
    const signals::Critical critical;
    pending_.push_back({path, stem + ext, std::string(), path, true, true});
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
    if (fs::is_directory(fs::symlink_status(p.path, ec))) {
      const signals::Critical critical;
      roll_back();
      throw ExitError(kExitOutputFailed,
                      fmt::format("cannot write '{}': it is a directory; nothing was written", printable(p.shown)));
    }
    {
      std::string tmp = temporary_beside(p.path, "tmp");
      const signals::Critical critical;
      p.tmp = std::move(tmp);
    }
    const bool ok = write_new_file(p.tmp, p.content, p.staged);  // staged: the temporary is ours to remove
    const int err = errno;
    if (!ok) {
      const signals::Critical critical;
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
  const signals::Critical critical;
  moved_.reserve(moved_.size() + 1);  // the record cannot fail once the file has moved
  if (::rename(path.c_str(), backup.c_str()) != 0)
    throw ExitError(kExitOutputFailed,
                    fmt::format("cannot replace '{}': {}; nothing was written", printable(path), why(errno)));
  moved_.push_back({path, backup});
}

// The folder's manifest: each file this run put there, with the size and hash it was written with.
void OutputFiles::add_manifest() {
  if (folder_.empty()) return;
  std::string text = fmt::format("{{\n  \"schema\": \"{}\",\n  \"command\": \"{}\",\n  \"files\": [\n",
                                 kRunManifestSchema, plain_name(command_) ? command_ : "");
  bool first = true;
  for (Pending& p : pending_) {
    const fs::path file(p.path);
    if (p.external) {  // drawn by another program: fingerprinted as drawn
      const std::optional<Fingerprint> f = fingerprint_of(p.tmp);
      if (!f) continue;
      p.bytes = f->bytes;
      p.hash = f->hash;
    }
    std::error_code ec;
    if (!fs::equivalent(file.parent_path(), folder_, ec) || !plain_name(file.filename().string())) continue;
    text += fmt::format("{}    {{\"name\": \"{}\", \"bytes\": {}, \"fnv1a64\": \"{:016x}\"}}", first ? "" : ",\n",
                        file.filename().string(), p.bytes, p.hash);
    first = false;
  }
  text += "\n  ]\n}\n";
  const std::string path = (folder_ / kRunManifest).string();
  check_not_link("the run's manifest", path);  // (an earlier manifest is ours by its name and format)
  add_pending(path, std::move(text));
}

// A file of the set with its content and fingerprint (the manifest's), recorded for the handler.
void OutputFiles::add_pending(const std::string& path, std::string content) {
  Fingerprint f;
  f.add(content);
  const signals::Critical critical;
  pending_.push_back({path, std::string(), std::move(content), path});
  pending_.back().bytes = f.bytes;
  pending_.back().hash = f.hash;
}

void OutputFiles::commit() {
  try {
    add_manifest();
    stage();
    for (Pending& p : pending_) {
      std::error_code ec;
      if (p.external && !fs::is_regular_file(fs::symlink_status(p.tmp, ec)))
        throw ExitError(kExitOutputFailed, fmt::format("'{}' was not drawn; nothing was written", printable(p.shown)));
      const fs::file_status st = fs::symlink_status(p.path, ec);
      if (fs::is_directory(st))
        throw ExitError(kExitOutputFailed,
                        fmt::format("cannot write '{}': it is a directory; nothing was written", printable(p.shown)));
      if (fs::exists(st)) move_aside(p.path);
      const signals::Critical critical;
      placed_.reserve(placed_.size() + 1);
      if (::rename(p.tmp.c_str(), p.path.c_str()) != 0)
        throw ExitError(kExitOutputFailed,
                        fmt::format("cannot write '{}': {}; nothing was written", printable(p.shown), why(errno)));
      p.staged = false;
      placed_.push_back(p.path);
    }
    clear_earlier_run();
  } catch (...) {
    const signals::Critical critical;
    roll_back();
    finished_ = true;
    throw;
  }
}

// A reused folder holds one run's files: the earlier run's files that this run does not write, and
// that are still byte for byte what that run wrote (its manifest), are moved aside with the replaced
// ones; any other file is left and named.
void OutputFiles::clear_earlier_run() {
  if (folder_.empty()) return;
  const std::vector<std::string> ours = names();
  const auto has = [](const std::vector<std::string>& v, const std::string& n) {
    return std::find(v.begin(), v.end(), n) != v.end();
  };
  for (const std::string& n : earlier_.entries) {
    if (n == kRunManifest) continue;
    const fs::path p = folder_ / n;
    bool input = false;
    for (const Named& i : inputs_) input = input || same_file(i.path, p.string());
    if (has(ours, n)) {
      ++replaced_;
      continue;
    }
    bool written_by_us = false;
    for (const Written& w : earlier_.listed)
      if (w.name == n && !input) {
        const std::optional<Fingerprint> f = fingerprint_of(p.string());
        written_by_us = f && f->bytes == w.bytes && f->hash == w.hash;
      }
    if (written_by_us) {
      move_aside(p.string());
      ++removed_;
    } else {
      others_.push_back(n);
    }
  }
}

std::string OutputFiles::folder_note() const {
  if (folder_.empty() || earlier_.entries.empty()) return {};
  if (earlier_.entries.size() == 1 && earlier_.entries[0] == kRunManifest) return {};
  std::string note = fmt::format(
      "hexatwist {}: note: {} '{}' was not empty: {} replaced, {} of an earlier run "
      "removed",
      command_, folder_option_, printable(folder_.string()), counted(replaced_, "file"), removed_);
  if (!others_.empty()) {
    note +=
        fmt::format("; {} left (not written by hexatwist, or changed since):", counted(others_.size(), "other file"));
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
    const signals::Critical critical;
    roll_back();
    finished_ = true;
    throw;
  }
  {
    const signals::Critical critical;  // the run is final: a signal now changes nothing
    signals::stop_on_request();
    finished_ = true;
    for (const Moved& m : moved_) ::unlink(m.backup.c_str());
    moved_.clear();
    placed_.clear();
    signals::remove_undo(&OutputFiles::undo, this);
  }
  if (const std::string note = folder_note(); !note.empty()) std::fprintf(stderr, "%s\n", note.c_str());
}

// System calls only, on data changed inside Critical sections: the signal handler runs this too.
void OutputFiles::roll_back() noexcept {
  for (auto it = placed_.rbegin(); it != placed_.rend(); ++it) ::unlink(it->c_str());
  placed_.clear();
  for (auto it = moved_.rbegin(); it != moved_.rend(); ++it) ::rename(it->backup.c_str(), it->path.c_str());
  moved_.clear();
  for (Pending& p : pending_)
    if (p.staged) {
      ::unlink(p.tmp.c_str());
      p.staged = false;
    }
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) ::rmdir(it->c_str());  // only if empty
  created_.clear();
}

}  // namespace hexatwist::cli
