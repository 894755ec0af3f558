// SPDX-License-Identifier: BSD-3-Clause
// The gnuplot script of a set of figures (figures.cpp), run by write_figures (figure_files.cpp).
// Internal to the CLI.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "figures.hpp"

namespace hexatwist::cli {

// gnuplot's script, with the byte offset where each figure's commands start (to name the figure
// that a gnuplot error comes from).
struct Script {
  std::string text;
  std::vector<std::size_t> figure_start;
};

/// The script that draws every figure as PNG then SVG into `dir` (f<i>.png, f<i>.svg).
Script build_script(const std::vector<Figure>& figures, const std::filesystem::path& dir);

}  // namespace hexatwist::cli
