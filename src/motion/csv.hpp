// SPDX-License-Identifier: BSD-3-Clause
// Internal: the CSV reading shared by the trajectory and the point-log parsers (trajectory.cpp,
// measurement.cpp): data lines, cells, numbers, and the one-line error
// "source:line:column: column 'name': message".
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace hexatwist::detail {

/// Text from the input as it may appear inside a one-line message: control characters escaped,
/// and (if `max` is set) cut at a character boundary after `max` bytes.
std::string printable(std::string_view s, std::size_t max = std::string_view::npos);

/// One cell of a line: its text without the surrounding whitespace, and where that text starts.
struct CsvCell {
  std::string_view text;
  std::size_t offset;  ///< byte offset in the line of `text` (of the cell's start if `text` is empty)
};

/// Splits a line at commas (no quoting) and trims blanks around each cell.
std::vector<CsvCell> split_csv(std::string_view line);

/// A line that carries a header or data.
struct CsvLine {
  int number;             ///< 1-based line number in the text
  std::string_view text;  ///< without its line end (LF or CRLF)
};

/// The text without a leading UTF-8 byte-order mark (spreadsheets write one).
std::string_view without_bom(std::string_view text);

/// The lines of `text` that carry a header or data: blank lines and lines whose first non-blank
/// character is '#' are skipped.
std::vector<CsvLine> csv_lines(std::string_view text);

/// Errors located in one source.
class CsvReader {
 public:
  explicit CsvReader(std::string_view source) : source_(printable(source)) {}

  /// Throws Error "source:line:column: column 'name': message"; `offset` is a byte offset into
  /// `line`, shown as a 1-based character column (UTF-8 continuation bytes do not count).
  [[noreturn]] void fail(int line_no, std::string_view line, std::size_t offset, std::string_view column,
                         const std::string& message) const;

  /// The cell as a finite number times `factor` (a unit's factor to SI); fails naming `column`
  /// for an empty cell, a non-number, a non-finite number or one out of range.
  double number(const CsvLine& line, const CsvCell& cell, std::string_view column, double factor) const;

  /// The source as shown in messages.
  const std::string& source() const noexcept { return source_; }

 private:
  std::string source_;
};

}  // namespace hexatwist::detail
