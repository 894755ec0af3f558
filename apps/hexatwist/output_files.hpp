// SPDX-License-Identifier: BSD-3-Clause
// The one writer of the tool's files: every command that writes files puts them in place through an
// OutputFiles transaction, so that an output never replaces an input or another output, a report
// folder holds one run's files, and a failed run leaves every file that existed before it byte for
// byte as it was.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace hexatwist::cli {

/// The manifest of a report folder's run: hidden, written by the transaction itself.
inline constexpr const char* kRunManifest = ".hexatwist-run.json";
/// Its schema (docs/schemas/run.schema.json).
inline constexpr const char* kRunManifestSchema = "hexatwist.run/1";

/// True if `a` and `b` name the same file: compared as files, not as strings (relative and
/// absolute paths, `..`, symbolic links, hard links; files that do not exist yet by their resolved
/// path).
bool same_file(const std::string& a, const std::string& b);

/// One run's output files, put in place as a transaction:
///  1. input() and output() declare what the run reads and writes; an output that is an input or
///     another output (as a file, same_file), or a symbolic link, is refused at once,
///     ExitError(2), before any work: hexatwist never writes through a link (someone else's link in
///     a shared folder would make it overwrite that person's file).
///     folder() declares a report folder: created if missing and locked for this run (a second run
///     into it is refused, ExitError(2)); the manifest of an earlier run of ours in it
///     (kRunManifest: each file's name, size and hash, read with a bound) is noted.
///  2. add() gives a file's content, external() a temporary stem for files another program draws
///     (figures); stage() writes every added file whole to a temporary name beside it (short names
///     of their own, so that they fit wherever the final name fits).
///     In a report folder, a file of this run's that is there already must be one of the earlier
///     run's files as it wrote it; any other is refused, ExitError(2), and left as it is.
///  3. commit() moves each file it replaces, and each file of the earlier run that this run does
///     not write and that is still byte for byte what that run wrote, aside to a backup name, then
///     renames every temporary into place and writes the folder's new manifest. A file hexatwist
///     cannot show it wrote is never removed: it is left and named.
///  4. finish() writes the run's standard output; only once that succeeded are the backups deleted
///     (and a note on stderr says what a reused folder held).
/// Any failure (ExitError(4) naming the file, an exception that leaves the transaction unfinished,
/// or SIGINT, SIGTERM or SIGHUP at any moment: signals.hpp) rolls everything back: this run's files
/// and temporaries removed, every backup renamed back, folders this run created removed.
class OutputFiles {
 public:
  /// `command` names the run in notes ("simulate").
  explicit OutputFiles(std::string command);
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;
  ~OutputFiles();

  /// An input file of the run (empty: none), named in messages by `option` ("--trajectory").
  void input(std::string_view option, const std::string& path);
  /// An output file of the run (empty: none). ExitError(2) if it is an input or another output.
  void output(std::string_view option, const std::string& path);
  /// The report folder (option "--out"): created if missing (ExitError(4) if it cannot be, or is
  /// a file); ExitError(2) if it is an input.
  void folder(std::string_view option, const std::string& dir);

  /// Content of a file to write: a declared output, or a file in the folder. ExitError(2) if it is
  /// an input or was added before.
  void add(const std::string& path, std::string content);
  /// A temporary stem for files `final_stem` + each of `extensions` that another writer makes
  /// (gnuplot): it writes them as stem + extension, and commit() puts them in place.
  std::string external(const std::string& final_stem, const std::vector<std::string>& extensions);
  /// Writes every added file to its temporary; ExitError(4) naming the file if one cannot be.
  void stage();
  /// stage(), then puts the whole set in place (replaced files kept as backups until finish()).
  void commit();
  /// Writes `stdout_text` (may be empty) to standard output; on success the run is final, on
  /// failure everything is rolled back and ExitError(4) thrown.
  void finish(std::string_view stdout_text);

  /// Every file of the set in the order added (the externals' final names included).
  const std::vector<std::string>& paths() const { return paths_; }
  /// The file names (in the folder) of the set, in the order added.
  std::vector<std::string> names() const;

 private:
  struct Named {
    std::string option, path;
  };
  struct Pending {
    std::string path, tmp, content;  // path: the file itself, as named (never through a link)
    std::string shown;               // as the user named it, for messages
    bool staged = false, external = false;
    std::uint64_t bytes = 0, hash = 0;  // of the content written (the manifest)
  };
  struct Moved {
    std::string path, backup;
  };
  struct Written {
    std::string name;
    std::uint64_t bytes = 0, hash = 0;
  };
  struct EarlierRun {
    std::string command;          // its manifest's "command"; empty if none
    std::vector<Written> listed;  // its files as it wrote them (names in the folder)
    std::vector<std::string> entries;
  };

  std::string temporary_beside(const std::string& path, std::string_view kind);
  void check_not_input(std::string_view what, const std::string& path) const;
  void check_not_link(std::string_view what, const std::string& path) const;
  void check_replaceable(const std::string& path) const;
  void move_aside(const std::string& path);
  void clear_earlier_run();
  std::string folder_note() const;
  void add_manifest();
  void add_pending(const std::string& path, std::string content);
  void roll_back() noexcept;
  static void undo(void* self) noexcept;  // the signal handler's roll back

  std::string command_;
  std::vector<Named> inputs_, outputs_;
  std::string folder_option_;
  std::filesystem::path folder_;
  std::vector<std::filesystem::path> created_;  // folders this run made, outermost first
  EarlierRun earlier_;
  std::vector<Pending> pending_;
  std::vector<Moved> moved_;         // backups of replaced and earlier-run files
  std::vector<std::string> placed_;  // files put in place by commit()
  std::vector<std::string> paths_;
  std::size_t replaced_ = 0, removed_ = 0;
  std::vector<std::string> others_;  // files in the folder that no run of ours describes
  int lock_ = -1;                    // the folder, locked (flock) for this run
  bool finished_ = false;
};

}  // namespace hexatwist::cli
