// SPDX-License-Identifier: BSD-3-Clause
#include "figures.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iterator>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>

#include "cli_common.hpp"
#include "figure_script.hpp"

namespace hexatwist::cli {

namespace fs = std::filesystem;

namespace {

// Page geometry [px]; the character widths were measured on the PNG at the 11 pt font.
constexpr int kWidth = 1000;
constexpr int kPanelHeight = 380;
constexpr int kFigureTitleHeight = 40;
constexpr double kPanelTitleSpace = 36;   // above the plot area when the panel has a title
constexpr double kPanelTopSpace = 16;     // above the plot area otherwise
constexpr double kPanelBottomSpace = 64;  // tick labels and the x label
constexpr double kLeftLabelSpace = 52;    // the y label, the tick marks and the gaps between them
constexpr double kDigitWidth = 7.3;       // of a tick label character
constexpr double kRightSpace = 16;        // right of the key (or of the plot area without a key)
constexpr double kKeySampleWidth = 64;    // line sample and gaps of a key entry
constexpr double kCharWidth =
    8.0;  // width of a character of a key label (generous: lower-case text of the study measured 7.5)
constexpr double kMaxKeyWidth = 340;     // a wider key goes under the plot
constexpr double kKeyGap = 12;           // between the plot area and a key right of it
constexpr double kKeyLineHeight = 19.5;  // of a key entry
constexpr double kKeyBelowGap = 8;       // under a key below the plot
constexpr double kColorBoxSpace = 150;   // right of a plot with a colour map: the bar, its ticks and its label
constexpr double kColorBoxGap = 14;
constexpr double kColorBoxWidth = 18;
constexpr const char* kFont = "sans,11";
constexpr const char* kTitleFont = "sans,13";
constexpr double kLineWidth = 1.5;

// Six colours that differ in hue and, in this order, alternately much in lightness (CIE L* 0, 49,
// 24, 74, 37, 60; luma 0, 42, 17, 69, 28, 58 %), so that any two stay apart in greyscale print.
constexpr std::array<const char*, 6> kPalette{"#000000", "#306fe8", "#730d0d", "#ff9f2e", "#1b6619", "#d968ba"};

// A gnuplot single-quoted string: no escapes are processed inside except '' for a quote; control
// characters (a newline would end the command) become spaces.
std::string gp_string(std::string_view text) {
  std::string out = "'";
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\'')
      out += "''";
    else if (u < 0x20 || u == 0x7f)
      out += ' ';
    else
      out += c;
  }
  return out + "'";
}

void append_number(std::string& out, double v) {
  // 10 significant digits: a small variation on a large offset still draws smoothly.
  fmt::format_to(std::back_inserter(out), "{:.10g}", v);
}

std::string block_name(std::size_t f, std::size_t p, std::size_t s) { return fmt::format("$f{}p{}s{}", f, p, s); }

// The span of the drawn finite values on one axis.
struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return lo > hi; }
};

// Writes the drawn points of one series as a datablock and widens the ranges by them.
void append_datablock(std::string& out, const std::string& name, const Series& s, Range& xr, Range& yr) {
  out += name + " << EOD\n";
  bool any = false;
  for (const std::size_t i : drawn_points(s.x, s.y)) {
    if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) {
      append_number(out, s.x[i]);
      out += ' ';
      append_number(out, s.y[i]);
      out += '\n';
      xr.add(s.x[i]);
      yr.add(s.y[i]);
      any = true;
    } else {
      out += "NaN NaN\n";
    }
  }
  if (!any) out += "NaN NaN\n";  // gnuplot rejects an empty datablock
  out += "EOD\n";
}

// Range and tick marks of one axis, chosen here rather than by gnuplot so that every tick label
// has the same number of decimals ("2.10, 2.15, 2.20", not "2.1, 2.15, 2.2") and so that the
// margins can be sized for the labels.
struct Ticks {
  std::string commands;    // set {x,y}range and {x,y}tics
  std::size_t widest = 0;  // characters of the longest tick label
  std::size_t last = 0;    // characters of the label at the upper end
};

Ticks ticks_for(char axis, Range r, double target_count, bool exact = false) {
  Ticks t;
  if (r.empty()) {
    // No finite point: gnuplot cannot autoscale, so an empty frame without tick labels.
    t.commands = fmt::format("set {0}range [0:1]\nset {0}tics 0.2 format ''\n", axis);
    return t;
  }
  double magnitude = std::max(std::abs(r.lo), std::abs(r.hi));
  if (!(r.hi - r.lo > 1e-12 * magnitude)) {
    // A flat line: widened by 1% of its value (or by 1), as gnuplot would.
    const double d = magnitude > 0.0 ? 0.01 * magnitude : 1.0;
    r.lo -= d;
    r.hi += d;
    magnitude += d;
  }
  // The smallest step of 1, 2 or 5 times a power of ten that gives at most target_count steps;
  // the range extends to whole steps.
  const double raw = (r.hi - r.lo) / target_count;
  if (!std::isfinite(raw) || !(raw > 0.0)) {
    // A span beyond double range (values near 1e308): left to gnuplot.
    t.commands = fmt::format("set autoscale {0}\nset {0}tics autofreq format '%g'\n", axis);
    t.widest = t.last = 9;
    return t;
  }
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10.0 * decade;
  for (const double m : {1.0, 2.0, 5.0})
    if (m * decade >= raw * (1.0 - 1e-9)) {
      step = m * decade;
      break;
    }
  const double first = std::floor(r.lo / step + 1e-9), last = std::ceil(r.hi / step - 1e-9);

  // Plain decimals, or for very large or small numbers a mantissa and a power of ten ("25e-6").
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  const bool plain = magnitude >= 1e-4 && magnitude < 1e6 && decimals <= 9;
  // Engineering notation (a power of ten that is a multiple of 3) for the largest tick value.
  const double largest = std::max(std::abs(first), std::abs(last)) * step;
  const int exponent = 3 * static_cast<int>(std::floor(std::log10(largest) / 3.0 + 1e-9));
  const double scale = std::pow(10.0, exponent);
  const int mantissa_decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step / scale) + 1e-9)));
  const auto label = [&](double v) {
    if (std::abs(v) < 1e-9 * step) return std::string("0");
    return plain ? fmt::format("{:.{}f}", v, decimals)
                 : fmt::format("{:.{}f}e{}", v / scale, mantissa_decimals, exponent);
  };

  // An exact range (equal axes) keeps its ends and takes the ticks inside them.
  const double lo_tick = exact ? std::ceil(r.lo / step - 1e-9) : first,
               hi_tick = exact ? std::floor(r.hi / step + 1e-9) : last;
  t.commands = fmt::format("set {}range [{:.17g}:{:.17g}]\nset {}tics (", axis, exact ? r.lo : first * step,
                           exact ? r.hi : last * step, axis);
  for (double k = lo_tick; k <= hi_tick + 0.5; k += 1.0) {
    const std::string text = label(k * step);
    t.commands += fmt::format("{}'{}' {:.17g}", k == lo_tick ? "" : ", ", text, k * step);
    t.widest = std::max(t.widest, text.size());
    t.last = text.size();
  }
  t.commands += ")\n";
  return t;
}

const char* dash(Series::Style style) {
  switch (style) {
    case Series::Style::Dashed:
      return "2";
    case Series::Style::Dotted:
      return "3";
    case Series::Style::Solid:
    case Series::Style::Points:
      break;
  }
  return "1";
}

// The drawn extent of one panel's data.
struct PanelRanges {
  Range x, y;
};

// gnuplot commands that draw one figure on a terminal of `height` px (output set by the caller).
struct FigureCommands {
  std::string text;
  int height = 0;
};

std::string map_block_name(std::size_t f, std::size_t p) { return fmt::format("$f{}p{}map", f, p); }

// Writes a heat map as a datablock (one scan line of u per v, blank lines between) and widens the
// ranges by its cells.
void append_map_block(std::string& out, const std::string& name, const HeatMap& m, Range& xr, Range& yr) {
  out += name + " << EOD\n";
  const std::size_t nu = m.u.size(), nv = m.v.size();
  for (std::size_t j = 0; j < nv; ++j) {
    for (std::size_t i = 0; i < nu; ++i) {
      append_number(out, m.u[i]);
      out += ' ';
      append_number(out, m.v[j]);
      out += ' ';
      const double value = m.values[j * nu + i];
      if (std::isfinite(value))
        append_number(out, value);
      else
        out += "NaN";
      out += '\n';
    }
    out += '\n';
  }
  out += "EOD\n";
  // The cells reach half a step beyond the outer centres.
  const double du = nu > 1 ? 0.5 * (m.u[nu - 1] - m.u[0]) / static_cast<double>(nu - 1) : 0.5;
  const double dv = nv > 1 ? 0.5 * (m.v[nv - 1] - m.v[0]) / static_cast<double>(nv - 1) : 0.5;
  if (nu > 0 && nv > 0) {
    xr.add(m.u.front() - du), xr.add(m.u.back() + du);
    yr.add(m.v.front() - dv), yr.add(m.v.back() + dv);
  }
}

// The colour map's palette, range and bar for one panel (continuous: a perceptually even blue-green-
// yellow scale; categories: one palette colour each).
std::string map_commands(const HeatMap& m, double bar_left, double bar_bottom, double bar_height) {
  std::string out;
  if (!m.categories.empty()) {
    const std::size_t n = m.categories.size();
    out += fmt::format("set palette maxcolors {}\nset palette defined (", n);
    for (std::size_t k = 0; k < n; ++k)
      out += fmt::format("{}{} '{}'", k ? ", " : "", k, kPalette[k % kPalette.size()]);
    out += fmt::format(")\nset cbrange [0.5:{}.5]\nset cbtics (", n);
    for (std::size_t k = 0; k < n; ++k) out += fmt::format("{}{} {}", k ? ", " : "", gp_string(m.categories[k]), k + 1);
    out += ") scale 0\n";
  } else {
    out +=
        "set palette defined (0 '#440154', 0.125 '#472d7b', 0.25 '#3b528b', 0.375 '#2c728e', 0.5 '#21918c', "
        "0.625 '#28ae80', 0.75 '#5ec962', 0.875 '#addc30', 1 '#fde725')\nset palette maxcolors 0\n";
    Range r;
    for (const double v : m.values)
      if (std::isfinite(v)) r.add(v);
    if (r.empty()) r.add(0.0), r.add(1.0);
    if (!(r.hi > r.lo)) r.hi = r.lo + (r.lo != 0.0 ? 0.01 * std::abs(r.lo) : 1.0);
    const Ticks t = ticks_for('x', r, 8.0, true);
    // The same ticks on the bar: the range and tick list of ticks_for, renamed to the cb axis.
    std::string cb = t.commands;
    for (std::size_t at = cb.find("set xrange"); at != std::string::npos; at = cb.find("set xrange"))
      cb.replace(at, 10, "set cbrange");
    for (std::size_t at = cb.find("set xtics"); at != std::string::npos; at = cb.find("set xtics"))
      cb.replace(at, 9, "set cbtics");
    out += cb;
  }
  out += fmt::format("set colorbox user origin screen {:.5f},{:.5f} size screen {:.5f},{:.5f} border\n", bar_left,
                     bar_bottom, kColorBoxWidth / kWidth, bar_height);
  out += fmt::format("set cblabel {} offset 1,0\n", gp_string(m.label));
  return out;
}

// The plot command of panel p of figure f: its map, then its series.
std::string plot_command(const Panel& pn, std::size_t f, std::size_t p) {
  if (pn.series.empty() && !pn.map) return "plot NaN notitle\n";
  std::string out = "plot";
  const char* sep = "";  // a std::string here meets GCC 12's false -Wrestrict on its assignment
  if (pn.map) {
    out += fmt::format(" {} using 1:2:3 with image notitle", map_block_name(f, p));
    sep = ",";
  }
  for (std::size_t s = 0; s < pn.series.size(); ++s) {
    const Series& series = pn.series[s];
    if (series.style == Series::Style::Points)
      out += fmt::format("{} {} using 1:2 with points pt 7 ps 0.4 lc rgb '{}' title {}", sep, block_name(f, p, s),
                         kPalette[s % kPalette.size()], gp_string(series.label));
    else
      out += fmt::format("{} {} using 1:2 with lines lw {} lc rgb '{}' dt {} title {}", sep, block_name(f, p, s),
                         kLineWidth, kPalette[s % kPalette.size()], dash(series.style), gp_string(series.label));
    sep = ",";
    if (s + 1 < pn.series.size()) out += " \\\n ";
  }
  return out + "\n";
}

// Where a figure's parts go [px]: the plot areas' left and right edges (the same for every panel),
// the key's place, each panel's top and the page's height.
struct FigureLayout {
  std::vector<Ticks> xticks, yticks;
  double left_px = 0.0, right_px = 0.0;
  bool key_below = false;
  std::vector<double> panel_top;
  double height = 0.0;
};

FigureLayout figure_layout(const Figure& fig, const std::vector<PanelRanges>& ranges,
                           const std::function<const Panel&(std::size_t)>& panel,
                           const std::function<double(std::size_t)>& panel_height) {
  FigureLayout l;
  bool maps = false;
  for (const Panel& p : fig.panels) maps = maps || p.map.has_value();
  // Ticks first: the widest y tick label of the figure sets the left margin.
  std::size_t ytick_chars = 0, xtick_last = 0;
  for (const PanelRanges& r : ranges) {
    l.xticks.push_back(ticks_for('x', r.x, 8.0));
    l.yticks.push_back(ticks_for('y', r.y, 8.0));
    ytick_chars = std::max(ytick_chars, l.yticks.back().widest);
    xtick_last = std::max(xtick_last, l.xticks.back().last);
  }
  l.left_px = kLeftLabelSpace + kDigitWidth * static_cast<double>(ytick_chars);

  // The key never covers the data: right of the plot area, as wide as the longest label of the
  // figure (so every panel has the same plot width), or, for labels too long for that or beside a
  // colour map's bar, in one column under the x label.
  std::size_t longest = 0;
  for (const Panel& p : fig.panels)
    for (const Series& s : p.series) longest = std::max(longest, s.label.size());
  const double key_px = longest == 0 ? 0.0 : kKeySampleWidth + kCharWidth * static_cast<double>(longest);
  l.key_below = key_px > kMaxKeyWidth || (maps && longest > 0);
  // Without a key on the right, room for half of the last x tick label, which is centred on the edge.
  l.right_px =
      maps ? kWidth - kColorBoxSpace
           : kWidth - (l.key_below ? std::max(kRightSpace, 0.5 * kDigitWidth * static_cast<double>(xtick_last) + 10.0)
                                   : kRightSpace + key_px);

  // Vertical layout [px from the top].
  l.panel_top.resize(ranges.size());
  l.height = fig.title.empty() ? 0.0 : kFigureTitleHeight;
  for (std::size_t p = 0; p < ranges.size(); ++p) {
    l.panel_top[p] = l.height;
    l.height += panel_height(p);
    if (l.key_below && !panel(p).series.empty())
      l.height += kKeyLineHeight * static_cast<double>(panel(p).series.size()) + kKeyBelowGap;
  }
  return l;
}

// Every panel is placed by hand (margins at screen positions) so that the plot areas of a figure
// line up under each other, whatever their tick labels.
FigureCommands figure_commands(const Figure& fig, std::size_t f, std::vector<PanelRanges> ranges) {
  static const Panel kNoPanel{};
  const std::size_t n_panels = ranges.size();
  const std::function<const Panel&(std::size_t)> panel = [&](std::size_t p) -> const Panel& {
    return p < fig.panels.size() ? fig.panels[p] : kNoPanel;
  };
  const std::function<double(std::size_t)> panel_height = [&](std::size_t p) {
    return static_cast<double>(panel(p).height > 0 ? panel(p).height : kPanelHeight);
  };
  FigureLayout l = figure_layout(fig, ranges, panel, panel_height);
  const double left_px = l.left_px, right_px = l.right_px, height = l.height;
  const auto screen_y = [&](double px) { return 1.0 - px / height; };

  std::string out;
  out += "reset\n";
  out += "set encoding utf8\n";
  out += "set border 3 lw 1 lc rgb '#404040'\n";
  out += "set tics nomirror out scale 0.6 textcolor rgb '#202020'\nunset mxtics\nunset mytics\n";
  out += "set grid back lt 1 lw 1 lc rgb '#dcdcdc'\n";
  out += "set xlabel offset 0,0.3\nset ylabel offset 0.3,0\n";
  out +=
      fmt::format("set lmargin at screen {:.5f}\nset rmargin at screen {:.5f}\n", left_px / kWidth, right_px / kWidth);
  out += fmt::format("set multiplot{}\n",
                     fig.title.empty() ? "" : fmt::format(" title {} font '{}'", gp_string(fig.title), kTitleFont));
  for (std::size_t p = 0; p < n_panels; ++p) {
    const Panel& pn = panel(p);
    const double plot_top = l.panel_top[p] + (pn.title.empty() ? kPanelTopSpace : kPanelTitleSpace);
    const double plot_bottom = l.panel_top[p] + panel_height(p) - kPanelBottomSpace;
    if (pn.equal_axes && !ranges[p].x.empty() && !ranges[p].y.empty()) {
      // One unit as long on both axes: the range that is short for its side widened about its centre.
      Range& x = ranges[p].x;
      Range& y = ranges[p].y;
      const double w = right_px - left_px, h = plot_bottom - plot_top;
      const double per_px = std::max((x.hi - x.lo) / w, (y.hi - y.lo) / h) * 1.04;
      const double cx = 0.5 * (x.lo + x.hi), cy = 0.5 * (y.lo + y.hi);
      x = Range{cx - 0.5 * per_px * w, cx + 0.5 * per_px * w};
      y = Range{cy - 0.5 * per_px * h, cy + 0.5 * per_px * h};
      l.xticks[p] = ticks_for('x', x, 8.0, true);
      l.yticks[p] = ticks_for('y', y, 8.0 * h / w * 1.6, true);
    }
    out += fmt::format("set tmargin at screen {:.5f}\nset bmargin at screen {:.5f}\n", screen_y(plot_top),
                       screen_y(plot_bottom));
    out += pn.title.empty() ? "unset title\n" : fmt::format("set title {} offset 0,-0.3\n", gp_string(pn.title));
    out += fmt::format("set xlabel {}\nset ylabel {}\n", gp_string(pn.xlabel), gp_string(pn.ylabel));
    if (l.key_below)
      out += fmt::format("set key at screen {:.5f},{:.5f} left top Left reverse samplen 3 spacing 1.15\n",
                         left_px / kWidth, screen_y(l.panel_top[p] + panel_height(p)));
    else
      out += fmt::format("set key at screen {:.5f},{:.5f} left top Left reverse samplen 3 spacing 1.15\n",
                         (right_px + kKeyGap) / kWidth, screen_y(plot_top));
    out += l.xticks[p].commands + l.yticks[p].commands;
    out += ranges[p].x.empty() ? "set label 1 'no data' at graph 0.5,0.5 center textcolor rgb '#808080'\n"
                               : "unset label 1\n";
    if (pn.map)
      out += map_commands(*pn.map, (right_px + kColorBoxGap) / kWidth, screen_y(plot_bottom),
                          (plot_bottom - plot_top) / height);
    else
      out += "unset colorbox\n";
    out += plot_command(pn, f, p);
  }
  out += "unset multiplot\n";
  return {out, static_cast<int>(std::lround(height))};
}

}  // namespace

Script build_script(const std::vector<Figure>& figures, const fs::path& dir) {
  Script script;
  std::string& out = script.text;
  out += "# Written by hexatwist: every figure as PNG, then as SVG.\n";
  for (std::size_t f = 0; f < figures.size(); ++f) {
    const Figure& fig = figures[f];
    script.figure_start.push_back(out.size());
    // A figure without panels is drawn as one empty panel.
    std::vector<PanelRanges> ranges(std::max<std::size_t>(fig.panels.size(), 1));
    for (std::size_t p = 0; p < fig.panels.size(); ++p) {
      if (fig.panels[p].map) append_map_block(out, map_block_name(f, p), *fig.panels[p].map, ranges[p].x, ranges[p].y);
      for (std::size_t s = 0; s < fig.panels[p].series.size(); ++s)
        append_datablock(out, block_name(f, p, s), fig.panels[p].series[s], ranges[p].x, ranges[p].y);
    }
    const FigureCommands commands = figure_commands(fig, f, ranges);
    const std::string common = fmt::format("size {},{} font '{}' noenhanced", kWidth, commands.height, kFont);
    out += fmt::format("set terminal pngcairo {} background rgb 'white'\n", common);
    out += fmt::format("set output {}\n", gp_string((dir / fmt::format("f{}.png", f)).string()));
    out += commands.text;
    out += fmt::format("set terminal svg {} background rgb 'white'\n", common);
    out += fmt::format("set output {}\n", gp_string((dir / fmt::format("f{}.svg", f)).string()));
    out += commands.text;
    out += "set output\n";
    // Free the data of this figure before the next is read.
    for (std::size_t p = 0; p < fig.panels.size(); ++p) {
      if (fig.panels[p].map) out += "undefine " + map_block_name(f, p) + "\n";
      for (std::size_t s = 0; s < fig.panels[p].series.size(); ++s) out += "undefine " + block_name(f, p, s) + "\n";
    }
  }
  return script;
}

std::vector<std::size_t> drawn_points(std::span<const double> x, std::span<const double> y) {
  const std::size_t n = std::min(x.size(), y.size());
  std::vector<std::size_t> keep;
  if (n <= kMaxDrawnPoints) {
    keep.resize(n);
    for (std::size_t i = 0; i < n; ++i) keep[i] = i;
    return keep;
  }
  // Buckets of consecutive points (not of x: a hysteresis loop goes back in x). A smooth curve
  // keeps about 2-4 points per bucket, so this many buckets draw about kMaxDrawnPoints points.
  const std::size_t buckets = kMaxDrawnPoints / 4;
  keep.reserve(kMaxDrawnPoints + 64);
  constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  bool previous_finite = true;
  for (std::size_t b = 0; b < buckets; ++b) {
    const std::size_t begin = b * n / buckets, end = (b + 1) * n / buckets;
    std::array<std::size_t, 6> pick;  // first, last, min x, max x, min y, max y
    pick.fill(kNone);
    const std::size_t before = keep.size();
    for (std::size_t i = begin; i < end; ++i) {
      const bool finite = std::isfinite(x[i]) && std::isfinite(y[i]);
      if (!finite) {
        // A gap starts here: close the points so far, keep the break, and start afresh.
        if (previous_finite) {
          for (const std::size_t k : pick)
            if (k != kNone) keep.push_back(k);
          keep.push_back(i);
          pick.fill(kNone);
        }
        previous_finite = false;
        continue;
      }
      previous_finite = true;
      if (pick[0] == kNone) pick.fill(i);
      pick[1] = i;
      if (x[i] < x[pick[2]]) pick[2] = i;
      if (x[i] > x[pick[3]]) pick[3] = i;
      if (y[i] < y[pick[4]]) pick[4] = i;
      if (y[i] > y[pick[5]]) pick[5] = i;
    }
    for (const std::size_t k : pick)
      if (k != kNone) keep.push_back(k);
    std::sort(keep.begin() + static_cast<std::ptrdiff_t>(before), keep.end());
    keep.erase(std::unique(keep.begin() + static_cast<std::ptrdiff_t>(before), keep.end()), keep.end());
  }
  return keep;
}

}  // namespace hexatwist::cli
