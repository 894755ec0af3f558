// SPDX-License-Identifier: BSD-3-Clause
// Line-plot figures for reports, drawn by gnuplot (PNG and SVG); the only plotting code of the project.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace hexatwist::cli {

/// One curve: y against x, drawn as a line (or as dots, Style::Points: a scatter of operating
/// points). Non-finite points are left out (the line breaks there).
struct Series {
  std::string label;         ///< legend text, drawn literally (no markup)
  std::vector<double> x, y;  ///< same length [caller's units]
  enum class Style { Solid, Dashed, Dotted, Points } style = Style::Solid;
};

/// A colour map on a regular grid, drawn under a panel's series with its colour bar right of the
/// plot: value j * u.size() + i at (u[i], v[j]); NaN cells are left blank.
struct HeatMap {
  std::vector<double> u, v;             ///< cell centres, evenly spaced and increasing [caller's units]
  std::vector<double> values;           ///< v.size() rows of u.size() values
  std::string label;                    ///< the colour bar's label with its unit
  std::vector<std::string> categories;  ///< when set, values are 1..n drawn in n distinct colours named by these
};

/// One plot with its own axes; colours follow the order of `series` (a fixed palette of six).
struct Panel {
  Panel() = default;
  /// The common case, a plot of lines or points: title, axis labels, series (map, height, axes default).
  Panel(std::string title_, std::string xlabel_, std::string ylabel_, std::vector<Series> series_ = {})
      : title(std::move(title_)), xlabel(std::move(xlabel_)), ylabel(std::move(ylabel_)), series(std::move(series_)) {}

  std::string title;   ///< may be empty
  std::string xlabel;  ///< axis label with its unit, e.g. "time [s]"
  std::string ylabel;  ///< axis label with its unit
  std::vector<Series> series;
  std::optional<HeatMap> map;  ///< a colour map under the series (a figure with one puts its key under the plots)
  int height = 0;              ///< of the panel [px]; 0 = 380
  bool equal_axes = false;     ///< one unit as long on both axes (a ranges widened to fit), for maps of a plane
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
