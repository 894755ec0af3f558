// Line-plot figures for reports, drawn by gnuplot (PNG and SVG); the only plotting code of the project.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace hexatwist::cli {

/// One curve: y against x, drawn as a line (or as dots, Style::Points: a scatter of operating
/// points). Non-finite points are left out (the line breaks there).
struct Series {
  std::string label;         ///< legend text, drawn literally (no markup)
  std::vector<double> x, y;  ///< same length [caller's units]
  enum class Style { Solid, Dashed, Dotted, Points } style = Style::Solid;
};

/// One plot with its own axes; colours follow the order of `series` (a fixed palette of six).
struct Panel {
  std::string title;   ///< may be empty
  std::string xlabel;  ///< axis label with its unit, e.g. "time [s]"
  std::string ylabel;  ///< axis label with its unit
  std::vector<Series> series;
};

/// One figure: panels stacked vertically, each with its own axes (they share nothing).
struct Figure {
  std::string stem;   ///< output path without extension: writes stem + ".png" and stem + ".svg"
  std::string title;  ///< may be empty
  std::vector<Panel> panels;
};

/// Series longer than this are thinned for drawing (see drawn_points).
inline constexpr std::size_t kMaxDrawnPoints = 2000;

/// Path of the gnuplot program: the HEXATWIST_GNUPLOT environment variable if set, else "gnuplot"
/// on PATH; empty if that is not an executable file.
std::string find_gnuplot();

/// Writes every figure as PNG (1000 px wide, 380 px per panel, sans 11 pt) and as SVG of the same
/// size, with one gnuplot run for all of them: grid, lines 1.5 px, the key right of the plot (under
/// it for labels over ~40 characters), tick labels with equal decimals. gnuplot draws into a
/// temporary directory (under TMPDIR), removed afterwards; the files are moved into place only
/// once all are drawn, so none is left half written.
/// Throws ExitError(kExitOutputFailed) with a one-line message if gnuplot is missing or fails
/// (with its first error line), or a file cannot be written (naming it).
void write_figures(const std::vector<Figure>& figures);

/// Indices, increasing, of the points of a series that are drawn: all of them up to kMaxDrawnPoints;
/// beyond that, the points are split into kMaxDrawnPoints / 4 runs of consecutive points and each
/// run keeps its first, its last and its extremes in x and in y (M4 aggregation, Jugel et al.,
/// VLDB 2014, extended to curves that go back in x), so the series keeps its first, last, minimum
/// and maximum points and its shape. Where non-finite points start, one of them is kept so that the
/// drawn line breaks there too.
std::vector<std::size_t> drawn_points(std::span<const double> x, std::span<const double> y);

}  // namespace hexatwist::cli
