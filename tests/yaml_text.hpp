// SPDX-License-Identifier: BSD-3-Clause
// Test support for configuration files: the seed platform as YAML text with one key per line
// (tests break it one line at a time and check the reported line), and line editing helpers.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace hexatwist::test {

/// The seed platform in the symmetric form; the comments give the line numbers.
inline const std::string kSymmetricYaml =
    "name: test platform\n"           //  1
    "symmetric:\n"                    //  2
    "  Ra: 1.2\n"                     //  3
    "  Rb: 1.5\n"                     //  4
    "  da: 0.2\n"                     //  5
    "  db: 0.3\n"                     //  6
    "  H: 1.511\n"                    //  7
    "screw:\n"                        //  8
    "  lead: 0.010\n"                 //  9
    "  thread: right\n"               // 10
    "  driven_side: base\n"           // 11
    "limits:\n"                       // 12
    "  length_min: 1.40\n"            // 13
    "  length_max: 2.45\n"            // 14
    "  bend_max_deg: 40\n"            // 15
    "  singularity_margin_deg: 5\n";  // 16

inline std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  return lines;
}

inline std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += l + "\n";
  return out;
}

/// Line `n` (1-based) of `text`.
inline std::string line_of(const std::string& text, int n) {
  return split_lines(text).at(static_cast<std::size_t>(n - 1));
}

/// `text` with line `n` (1-based) replaced by `with` (which may hold several lines).
inline std::string replace_line(const std::string& text, int n, const std::string& with) {
  std::vector<std::string> lines = split_lines(text);
  lines.at(static_cast<std::size_t>(n - 1)) = with;
  return join_lines(lines);
}

/// `text` without lines first..last (1-based, inclusive).
inline std::string erase_lines(const std::string& text, int first, int last) {
  std::vector<std::string> lines = split_lines(text);
  lines.erase(lines.begin() + (first - 1), lines.begin() + last);
  return join_lines(lines);
}

}  // namespace hexatwist::test
