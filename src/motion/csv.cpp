// SPDX-License-Identifier: BSD-3-Clause
#include "motion/csv.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>

#include "hexatwist/error.hpp"

namespace hexatwist::detail {
namespace {

bool blank(char c) { return c == ' ' || c == '\t'; }

}  // namespace

std::string printable(std::string_view s, std::size_t max) {
  std::size_t n = std::min(s.size(), max);
  while (n < s.size() && n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0) == 0x80) --n;  // UTF-8 continuation
  std::string out;
  for (const char c : s.substr(0, n)) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\t')
      out += "\\t";
    else if (c == '\r')
      out += "\\r";
    else if (c == '\n')
      out += "\\n";
    else if (u < 0x20 || u == 0x7f)
      out += fmt::format("\\x{:02x}", u);
    else
      out += c;
  }
  if (n < s.size()) out += "...";
  return out;
}

std::vector<CsvCell> split_csv(std::string_view line) {
  std::vector<CsvCell> cells;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t comma = line.find(',', begin);
    const std::size_t end = comma == std::string_view::npos ? line.size() : comma;
    std::size_t b = begin, e = end;
    while (b < e && blank(line[b])) ++b;
    while (e > b && blank(line[e - 1])) --e;
    cells.push_back({line.substr(b, e - b), b < e ? b : begin});
    if (comma == std::string_view::npos) return cells;
    begin = comma + 1;
  }
}

std::string_view without_bom(std::string_view text) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  return text;
}

std::vector<CsvLine> csv_lines(std::string_view text) {
  std::vector<CsvLine> lines;
  int line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string_view line = text.substr(pos, nl - pos);
    pos = nl + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    std::size_t first = 0;
    while (first < line.size() && blank(line[first])) ++first;
    if (first == line.size() || line[first] == '#') continue;
    lines.push_back({line_no, line});
  }
  return lines;
}

void CsvReader::fail(int line_no, std::string_view line, std::size_t offset, std::string_view column,
                     const std::string& message) const {
  int col = 1;
  for (std::size_t i = 0; i < offset && i < line.size(); ++i)
    if ((static_cast<unsigned char>(line[i]) & 0xC0) != 0x80) ++col;
  throw Error(fmt::format("{}:{}:{}: column '{}': {}", source_, line_no, col, column, message));
}

double CsvReader::number(const CsvLine& line, const CsvCell& cell, std::string_view column, double factor) const {
  std::string_view text = cell.text;
  if (text.empty()) fail(line.number, line.text, cell.offset, column, "empty cell; expected a number");
  // from_chars takes no leading '+', a person may type one.
  if (text.size() > 1 && text[0] == '+' && text[1] != '-' && text[1] != '+') text.remove_prefix(1);
  double x = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), x);
  const std::string shown = printable(cell.text, 40);
  if (ec == std::errc::result_out_of_range && end == text.data() + text.size())
    fail(line.number, line.text, cell.offset, column, fmt::format("number out of range, got '{}'", shown));
  if (ec != std::errc() || end != text.data() + text.size())
    fail(line.number, line.text, cell.offset, column, fmt::format("expected a number, got '{}'", shown));
  if (!std::isfinite(x))
    fail(line.number, line.text, cell.offset, column, fmt::format("expected a finite number, got '{}'", shown));
  const double v = x * factor;
  if (!std::isfinite(v))
    fail(line.number, line.text, cell.offset, column,
         fmt::format("number out of range after unit conversion, got '{}'", shown));
  return v;
}

}  // namespace hexatwist::detail
