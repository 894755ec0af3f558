#include "figures.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <sstream>
#include <string_view>
#include <system_error>

#include "cli_common.hpp"

extern char** environ;

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

bool is_executable_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(path.c_str(), X_OK) == 0;
}

// Fails with the output path if figures cannot be written into the directory of `stem`, before
// gnuplot runs.
void check_output_directory(const std::string& stem) {
  if (stem.empty()) throw ExitError(kExitOutputFailed, "cannot write a figure: its output path is empty");
  fs::path dir = fs::path(stem).parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  const auto status = fs::status(dir, ec);
  const std::string target = printable(stem + ".png");
  if (!fs::exists(status))
    throw ExitError(kExitOutputFailed, fmt::format("cannot write figure '{}': directory '{}' does not exist", target,
                                                   printable(dir.string())));
  if (!fs::is_directory(status))
    throw ExitError(kExitOutputFailed,
                    fmt::format("cannot write figure '{}': '{}' is not a directory", target, printable(dir.string())));
  if (::access(dir.c_str(), W_OK) != 0)
    throw ExitError(kExitOutputFailed, fmt::format("cannot write figure '{}': directory '{}': {}", target,
                                                   printable(dir.string()), std::strerror(errno)));
}

// A private directory for the script, gnuplot's messages and the figures while they are drawn;
// removed with everything in it when the write ends, however it ends.
class ScratchDir {
 public:
  ScratchDir() {
    std::error_code ec;
    fs::path base = fs::temp_directory_path(ec);
    if (ec) base = "/tmp";
    std::string tmpl = (base / "hexatwist_figures_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr)
      throw ExitError(kExitOutputFailed, fmt::format("cannot create a temporary directory in '{}': {}",
                                                     printable(base.string()), std::strerror(errno)));
    path_ = tmpl;
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// gnuplot's script, with the byte offset where each figure's commands start (to name the figure
// that a gnuplot error comes from).
struct Script {
  std::string text;
  std::vector<std::size_t> figure_start;
};

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

// Every panel is placed by hand (margins at screen positions) so that the plot areas of a figure
// line up under each other, whatever their tick labels.
FigureCommands figure_commands(const Figure& fig, std::size_t f, std::vector<PanelRanges> ranges) {
  static const Panel kNoPanel{};
  const std::size_t n_panels = ranges.size();
  const auto panel = [&](std::size_t p) -> const Panel& { return p < fig.panels.size() ? fig.panels[p] : kNoPanel; };
  const auto panel_height = [&](std::size_t p) {
    return static_cast<double>(panel(p).height > 0 ? panel(p).height : kPanelHeight);
  };
  bool maps = false;
  for (const Panel& p : fig.panels) maps = maps || p.map.has_value();

  // Ticks first: the widest y tick label of the figure sets the left margin.
  std::vector<Ticks> xticks, yticks;
  std::size_t ytick_chars = 0, xtick_last = 0;
  for (const PanelRanges& r : ranges) {
    xticks.push_back(ticks_for('x', r.x, 8.0));
    yticks.push_back(ticks_for('y', r.y, 8.0));
    ytick_chars = std::max(ytick_chars, yticks.back().widest);
    xtick_last = std::max(xtick_last, xticks.back().last);
  }
  const double left_px = kLeftLabelSpace + kDigitWidth * static_cast<double>(ytick_chars);

  // The key never covers the data: right of the plot area, as wide as the longest label of the
  // figure (so every panel has the same plot width), or, for labels too long for that or beside a
  // colour map's bar, in one column under the x label.
  std::size_t longest = 0;
  for (const Panel& p : fig.panels)
    for (const Series& s : p.series) longest = std::max(longest, s.label.size());
  const double key_px = longest == 0 ? 0.0 : kKeySampleWidth + kCharWidth * static_cast<double>(longest);
  const bool key_below = key_px > kMaxKeyWidth || (maps && longest > 0);
  // Without a key on the right, room for half of the last x tick label, which is centred on the edge.
  const double right_px =
      maps ? kWidth - kColorBoxSpace
           : kWidth - (key_below ? std::max(kRightSpace, 0.5 * kDigitWidth * static_cast<double>(xtick_last) + 10.0)
                                 : kRightSpace + key_px);

  // Vertical layout [px from the top].
  std::vector<double> panel_top(n_panels);
  double height = fig.title.empty() ? 0.0 : kFigureTitleHeight;
  for (std::size_t p = 0; p < n_panels; ++p) {
    panel_top[p] = height;
    height += panel_height(p);
    if (key_below && !panel(p).series.empty())
      height += kKeyLineHeight * static_cast<double>(panel(p).series.size()) + kKeyBelowGap;
  }
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
    const double plot_top = panel_top[p] + (pn.title.empty() ? kPanelTopSpace : kPanelTitleSpace);
    const double plot_bottom = panel_top[p] + panel_height(p) - kPanelBottomSpace;
    if (pn.equal_axes && !ranges[p].x.empty() && !ranges[p].y.empty()) {
      // One unit as long on both axes: the range that is short for its side widened about its centre.
      Range& x = ranges[p].x;
      Range& y = ranges[p].y;
      const double w = right_px - left_px, h = plot_bottom - plot_top;
      const double per_px = std::max((x.hi - x.lo) / w, (y.hi - y.lo) / h) * 1.04;
      const double cx = 0.5 * (x.lo + x.hi), cy = 0.5 * (y.lo + y.hi);
      x = Range{cx - 0.5 * per_px * w, cx + 0.5 * per_px * w};
      y = Range{cy - 0.5 * per_px * h, cy + 0.5 * per_px * h};
      xticks[p] = ticks_for('x', x, 8.0, true);
      yticks[p] = ticks_for('y', y, 8.0 * h / w * 1.6, true);
    }
    out += fmt::format("set tmargin at screen {:.5f}\nset bmargin at screen {:.5f}\n", screen_y(plot_top),
                       screen_y(plot_bottom));
    out += pn.title.empty() ? "unset title\n" : fmt::format("set title {} offset 0,-0.3\n", gp_string(pn.title));
    out += fmt::format("set xlabel {}\nset ylabel {}\n", gp_string(pn.xlabel), gp_string(pn.ylabel));
    if (key_below)
      out += fmt::format("set key at screen {:.5f},{:.5f} left top Left reverse samplen 3 spacing 1.15\n",
                         left_px / kWidth, screen_y(panel_top[p] + panel_height(p)));
    else
      out += fmt::format("set key at screen {:.5f},{:.5f} left top Left reverse samplen 3 spacing 1.15\n",
                         (right_px + kKeyGap) / kWidth, screen_y(plot_top));
    out += xticks[p].commands + yticks[p].commands;
    out += ranges[p].x.empty() ? "set label 1 'no data' at graph 0.5,0.5 center textcolor rgb '#808080'\n"
                               : "unset label 1\n";
    if (pn.map)
      out += map_commands(*pn.map, (right_px + kColorBoxGap) / kWidth, screen_y(plot_bottom),
                          (plot_bottom - plot_top) / height);
    else
      out += "unset colorbox\n";
    if (pn.series.empty() && !pn.map) {
      out += "plot NaN notitle\n";
      continue;
    }
    out += "plot";
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
    out += "\n";
  }
  out += "unset multiplot\n";
  return {out, static_cast<int>(std::lround(height))};
}

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

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// gnuplot's first error from its stderr, as "<message>", and the script line it names (0 if none).
// gnuplot reports an error as `"script" line N: message`, after echoing the command and a caret.
std::pair<std::string, std::size_t> first_error(const std::string& err) {
  std::istringstream in(err);
  std::string first_text;
  for (std::string line; std::getline(in, line);) {
    const auto at = line.find(" line ");
    if (at != std::string::npos) {
      std::size_t n = 0;
      const char* b = line.data() + at + 6;
      const char* e = line.data() + line.size();
      const auto [ptr, ec] = std::from_chars(b, e, n);
      if (ec == std::errc() && ptr + 1 < e && ptr[0] == ':' && ptr[1] == ' ') {
        const std::string message(ptr + 2, e);
        if (message.rfind("warning:", 0) == 0) continue;
        return {message, n};
      }
    }
    const auto text = line.find_first_not_of(" \t^");
    if (first_text.empty() && text != std::string::npos) first_text = line.substr(text);
  }
  return {first_text, 0};
}

// Runs gnuplot on `script`; its stderr goes to `err`. Returns the wait status.
int run_gnuplot(const std::string& gnuplot, const fs::path& script, const fs::path& err) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  // --default-settings: no ~/.gnuplot or system gnuplotrc changes the look.
  std::string arg0 = gnuplot, arg1 = "--default-settings", arg2 = script.string();
  char* argv[] = {arg0.data(), arg1.data(), arg2.data(), nullptr};
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, gnuplot.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw ExitError(kExitOutputFailed,
                    fmt::format("cannot run gnuplot '{}': {}", printable(gnuplot), std::strerror(rc)));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR)
      throw ExitError(kExitOutputFailed, fmt::format("waiting for gnuplot failed: {}", std::strerror(errno)));
  }
  return status;
}

// Moves a drawn file to its place: a rename when on the same file system, else a copy under a
// temporary name beside the target and a rename, so the target is never half written.
void publish(const fs::path& from, const std::string& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (!ec) return;
  if (ec != std::errc::cross_device_link)
    throw ExitError(kExitOutputFailed, fmt::format("cannot write figure '{}': {}", printable(to), ec.message()));
  const std::string partial = fmt::format("{}.partial-{}", to, ::getpid());
  fs::copy_file(from, partial, fs::copy_options::overwrite_existing, ec);
  if (!ec) fs::rename(partial, to, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(partial, ignored);
    throw ExitError(kExitOutputFailed, fmt::format("cannot write figure '{}': {}", printable(to), ec.message()));
  }
}

}  // namespace

std::string find_gnuplot() {
  const char* env = std::getenv("HEXATWIST_GNUPLOT");
  const std::string name = env != nullptr && *env != '\0' ? env : "gnuplot";
  if (name.find('/') != std::string::npos) return is_executable_file(name) ? name : std::string();
  const char* path = std::getenv("PATH");
  std::string_view dirs = path != nullptr ? path : "/usr/local/bin:/usr/bin:/bin";
  for (;;) {
    const auto colon = dirs.find(':');
    std::string dir(dirs.substr(0, colon));
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/" + name;
    if (is_executable_file(candidate)) return candidate;
    if (colon == std::string_view::npos) return {};
    dirs.remove_prefix(colon + 1);
  }
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

void write_figures(const std::vector<Figure>& figures) {
  if (figures.empty()) return;
  const std::string gnuplot = find_gnuplot();
  if (gnuplot.empty()) {
    const char* env = std::getenv("HEXATWIST_GNUPLOT");
    throw ExitError(kExitOutputFailed,
                    env != nullptr && *env != '\0'
                        ? fmt::format("gnuplot not found at HEXATWIST_GNUPLOT='{}'; run scripts/setup.sh or install "
                                      "gnuplot-nox",
                                      printable(env))
                        : std::string("gnuplot not found; run scripts/setup.sh or install gnuplot-nox"));
  }
  std::set<std::string> stems;
  for (const Figure& fig : figures) {
    check_output_directory(fig.stem);
    if (!stems.insert(fig.stem).second)
      throw ExitError(kExitOutputFailed,
                      fmt::format("two figures would both be written to '{}.png'", printable(fig.stem)));
    for (const Panel& panel : fig.panels)
      if (panel.map && (panel.map->u.empty() || panel.map->v.empty() ||
                        panel.map->values.size() != panel.map->u.size() * panel.map->v.size()))
        throw ExitError(kExitOutputFailed,
                        fmt::format("figure '{}': colour map '{}' has {} values for {} x {} cells", printable(fig.stem),
                                    printable(panel.map->label), panel.map->values.size(), panel.map->u.size(),
                                    panel.map->v.size()));
    for (const Panel& panel : fig.panels)
      for (const Series& s : panel.series)
        if (s.x.size() != s.y.size())
          throw ExitError(kExitOutputFailed,
                          fmt::format("figure '{}': series '{}' has {} x values but {} y values", printable(fig.stem),
                                      printable(s.label), s.x.size(), s.y.size()));
  }

  const ScratchDir scratch;
  const Script script = build_script(figures, scratch.path());
  const fs::path script_path = scratch.path() / "figures.gp";
  const fs::path err_path = scratch.path() / "gnuplot.err";
  {
    std::ofstream out(script_path, std::ios::binary);
    out.write(script.text.data(), static_cast<std::streamsize>(script.text.size()));
    out.close();
    if (!out)
      throw ExitError(kExitOutputFailed,
                      fmt::format("cannot write gnuplot script '{}'", printable(script_path.string())));
  }

  const int status = run_gnuplot(gnuplot, script_path, err_path);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const auto [message, line] = first_error(read_text(err_path));
    // The figure whose commands hold the failing line.
    std::string where;
    if (line > 0) {
      std::size_t offset = 0;
      for (std::size_t l = 1; l < line && offset != std::string::npos; ++l) {
        offset = script.text.find('\n', offset);
        if (offset != std::string::npos) ++offset;
      }
      const auto it = std::upper_bound(script.figure_start.begin(), script.figure_start.end(), offset);
      if (it != script.figure_start.begin())
        where = fmt::format(" drawing '{}'",
                            printable(figures[static_cast<std::size_t>(it - script.figure_start.begin() - 1)].stem));
    }
    const std::string how = WIFEXITED(status) ? fmt::format("exit status {}", WEXITSTATUS(status))
                                              : fmt::format("signal {}", WIFSIGNALED(status) ? WTERMSIG(status) : 0);
    throw ExitError(kExitOutputFailed, fmt::format("gnuplot failed{} ({}){}{}", where, how, message.empty() ? "" : ": ",
                                                   printable(message)));
  }

  // Every file drawn before any is put in place.
  for (std::size_t f = 0; f < figures.size(); ++f) {
    for (const char* ext : {"png", "svg"}) {
      const fs::path drawn = scratch.path() / fmt::format("f{}.{}", f, ext);
      std::error_code ec;
      const auto size = fs::file_size(drawn, ec);
      if (ec || size == 0)
        throw ExitError(kExitOutputFailed,
                        fmt::format("gnuplot did not write figure '{}.{}'", printable(figures[f].stem), ext));
    }
  }
  // A failure half way removes the figures already put in place: all of them or none.
  std::vector<std::string> published;
  try {
    for (std::size_t f = 0; f < figures.size(); ++f)
      for (const char* ext : {"png", "svg"}) {
        const std::string to = fmt::format("{}.{}", figures[f].stem, ext);
        publish(scratch.path() / fmt::format("f{}.{}", f, ext), to);
        published.push_back(to);
      }
  } catch (...) {
    std::error_code ignored;
    for (const std::string& p : published) fs::remove(p, ignored);
    throw;
  }
}

}  // namespace hexatwist::cli
