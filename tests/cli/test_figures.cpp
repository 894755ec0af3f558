// SPDX-License-Identifier: BSD-3-Clause
// The figure writer of the command-line tool (apps/hexatwist/figures.cpp): real gnuplot runs that
// write PNG and SVG files, its failures as exit code 4 with one line, and the thinning of long series.
// gnuplot is required (scripts/setup.sh installs gnuplot-nox): without it these tests fail.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "figures.hpp"

namespace {

namespace fs = std::filesystem;
using hexatwist::cli::ExitError;
using hexatwist::cli::Figure;
using hexatwist::cli::Panel;
using hexatwist::cli::Series;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A fresh directory for one test, removed at its end.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "hexatwist_figures_test_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) std::abort();
    path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// Sets an environment variable for the life of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      ::setenv(name_, old_->c_str(), 1);
    else
      ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

std::string read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Width and height of a PNG from its IHDR chunk, or nothing if it is not a PNG.
std::optional<std::array<std::uint32_t, 2>> png_size(const std::string& bytes) {
  static const std::string kSignature("\x89PNG\r\n\x1a\n", 8);
  if (bytes.size() < 24 || bytes.compare(0, 8, kSignature) != 0 || bytes.compare(12, 4, "IHDR") != 0) return {};
  const auto be32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + k]);
    return v;
  };
  return std::array<std::uint32_t, 2>{be32(16), be32(20)};
}

// An executable shell script standing in for gnuplot.
std::string fake_gnuplot(const TempDir& dir, const std::string& body) {
  const std::string path = dir / "fake-gnuplot";
  std::ofstream(path) << "#!/bin/sh\n" << body << "\n";
  ::chmod(path.c_str(), 0755);
  return path;
}

// A leg-like smooth curve y(t) and a hysteresis loop (x goes back and forth) of n points.
Series time_series(const std::string& label, int leg, std::size_t n, Series::Style style = Series::Style::Solid) {
  Series s{label, {}, {}, style};
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 20.0 * static_cast<double>(i) / static_cast<double>(n - 1);
    s.x.push_back(t);
    s.y.push_back(2.2 + 0.05 * std::sin(0.6 * t + leg) + 0.01 * std::sin(3.1 * t));
  }
  return s;
}
Series loop_series(const std::string& label, int leg, std::size_t n) {
  Series s{label, {}, {}, Series::Style::Solid};
  for (std::size_t i = 0; i < n; ++i) {
    const double phase = 0.9 * 20.0 * static_cast<double>(i) / static_cast<double>(n - 1);
    s.x.push_back(2000.0 + 40.0 * std::sin(phase) + 3.0 * leg);
    s.y.push_back(0.5 * leg + 1.5 * std::tanh(3.0 * std::sin(phase)) + 0.6 * std::cos(phase));
  }
  return s;
}

void expect_one_line(const std::string& message) {
  EXPECT_FALSE(message.empty());
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
}

// Labels with the characters that break naive quoting or turn into markup.
const std::string kQuoteLabel = "leg_1 'commanded' \"x\"";
const std::string kTitleLabel = "F_z of the nut's \"twist\"";

TEST(Figures, GnuplotIsInstalled) {
  EXPECT_FALSE(hexatwist::cli::find_gnuplot().empty()) << "install gnuplot-nox (scripts/setup.sh)";
}

TEST(Figures, WritesPngAndSvgOfEveryFigure) {
  const TempDir dir;
  Figure one{dir / "one", kTitleLabel, {}};
  Panel p{"Leg length", "time t [s]", "length l_i [m]", {}};
  p.series.push_back(time_series(kQuoteLabel, 0, 20000));
  p.series.push_back(time_series("leg 2 (dashed)", 1, 20000, Series::Style::Dashed));
  p.series.push_back(time_series("leg 3 (dotted)", 2, 20000, Series::Style::Dotted));
  p.series[0].y[12345] = kNaN;
  one.panels.push_back(p);

  Figure two{dir / "two", "", {}};
  Panel a{"Lengths", "time t [s]", "length [m]", {}}, b{"Hysteresis", "leg length [mm]", "twist angle [deg]", {}};
  for (int leg = 0; leg < 6; ++leg) {
    a.series.push_back(time_series("leg " + std::to_string(leg + 1), leg, 500));
    b.series.push_back(loop_series("leg_" + std::to_string(leg + 1), leg, 15000));
  }
  two.panels = {a, b};

  hexatwist::cli::write_figures({one, two});

  for (const auto& [stem, panels] : {std::pair{one.stem, 1u}, std::pair{two.stem, 2u}}) {
    SCOPED_TRACE(stem);
    const std::string png = read_file(stem + ".png");
    const auto size = png_size(png);
    ASSERT_TRUE(size) << "not a PNG";
    EXPECT_EQ((*size)[0], 1000u);
    EXPECT_GE((*size)[1], 380u * panels);
    EXPECT_LE((*size)[1], 380u * panels + 100u);
    EXPECT_GT(png.size(), 10'000u);
    EXPECT_LT(png.size(), 5'000'000u);

    const std::string svg = read_file(stem + ".svg");
    EXPECT_NE(svg.find("<svg"), std::string::npos);
    EXPECT_NE(svg.find("</svg>"), std::string::npos) << "SVG not finished";
    EXPECT_NE(svg.find("width=\"1000\""), std::string::npos);
  }
  // Every label drawn literally, in one piece (enhanced text mode would split "_1" into a subscript).
  const std::string svg1 = read_file(one.stem + ".svg"), svg2 = read_file(two.stem + ".svg");
  for (const std::string& text : {kTitleLabel, kQuoteLabel, std::string("leg 2 (dashed)"), std::string("Leg length"),
                                  std::string("time t [s]"), std::string("length l_i [m]")})
    EXPECT_NE(svg1.find(">" + text + "<"), std::string::npos) << "missing: " << text;
  for (const std::string& text : {std::string("leg 6"), std::string("leg_6"), std::string("Hysteresis"),
                                  std::string("twist angle [deg]"), std::string("leg length [mm]")})
    EXPECT_NE(svg2.find(">" + text + "<"), std::string::npos) << "missing: " << text;
}

TEST(Figures, LeavesNothingButTheFigures) {
  const TempDir out, tmp;
  const ScopedEnv tmpdir("TMPDIR", tmp.path().string());
  Figure f{out / "fig", "t", {Panel{"", "x [m]", "y [m]", {time_series("a", 0, 3000)}}}};
  hexatwist::cli::write_figures({f});
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(out.path())) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"fig.png", "fig.svg"}));
  EXPECT_TRUE(fs::is_empty(tmp.path())) << "temporary files left in " << tmp.path();
}

TEST(Figures, EmptyAndDegenerateDataStillDraw) {
  const TempDir dir;
  Figure f{dir / "odd", "", {}};
  f.panels.push_back(Panel{"all NaN", "x", "y", {Series{"nan", {1.0, 2.0}, {kNaN, kNaN}, Series::Style::Solid}}});
  f.panels.push_back(Panel{"flat", "x", "y", {Series{"five", {0.0, 1.0, 2.0}, {5.0, 5.0, 5.0}, {}}}});
  f.panels.push_back(Panel{"no series", "x", "y", {}});
  f.panels.push_back(Panel{"tiny", "x", "y", {Series{"t", {0.0, 1e-9}, {1e-12, -3e-12}, {}}}});
  Figure none{dir / "none", "no panels", {}};
  hexatwist::cli::write_figures({f, none});
  EXPECT_TRUE(png_size(read_file(dir / "odd.png")));
  EXPECT_TRUE(png_size(read_file(dir / "none.png")));
}

TEST(Figures, MissingGnuplotThrowsExitCode4) {
  const TempDir dir;
  const ScopedEnv env("HEXATWIST_GNUPLOT", dir / "no-such-gnuplot");
  EXPECT_EQ(hexatwist::cli::find_gnuplot(), "");
  Figure f{dir / "fig", "", {Panel{"", "x", "y", {time_series("a", 0, 10)}}}};
  try {
    hexatwist::cli::write_figures({f});
    FAIL() << "no exception";
  } catch (const ExitError& e) {
    EXPECT_EQ(e.code(), hexatwist::cli::kExitOutputFailed);
    expect_one_line(e.what());
    EXPECT_NE(std::string(e.what()).find("gnuplot not found"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("gnuplot-nox"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "fig.png"));
}

TEST(Figures, UnwritableOutputDirectoryThrowsNamingThePath) {
  const TempDir dir;
  // A path under a regular file cannot be written, not even by root.
  std::ofstream(dir / "plain-file") << "x";
  for (const std::string& stem : {dir / "plain-file/fig", dir / "missing-dir/fig"}) {
    SCOPED_TRACE(stem);
    Figure f{stem, "", {Panel{"", "x", "y", {time_series("a", 0, 10)}}}};
    try {
      hexatwist::cli::write_figures({f});
      FAIL() << "no exception";
    } catch (const ExitError& e) {
      EXPECT_EQ(e.code(), hexatwist::cli::kExitOutputFailed);
      expect_one_line(e.what());
      EXPECT_NE(std::string(e.what()).find(stem), std::string::npos) << e.what();
    }
  }
}

TEST(Figures, GnuplotErrorIsReportedWithItsFirstLine) {
  const TempDir dir;
  const ScopedEnv env("HEXATWIST_GNUPLOT",
                      fake_gnuplot(dir, "echo 'first: the real problem' >&2\necho 'second line' >&2\nexit 3"));
  Figure f{dir / "fig", "", {Panel{"", "x", "y", {time_series("a", 0, 10)}}}};
  try {
    hexatwist::cli::write_figures({f});
    FAIL() << "no exception";
  } catch (const ExitError& e) {
    EXPECT_EQ(e.code(), hexatwist::cli::kExitOutputFailed);
    expect_one_line(e.what());
    EXPECT_NE(std::string(e.what()).find("first: the real problem"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("exit status 3"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "fig.png"));
}

TEST(Figures, GnuplotThatWritesNothingIsAnError) {
  const TempDir dir;
  const ScopedEnv env("HEXATWIST_GNUPLOT", fake_gnuplot(dir, "exit 0"));
  Figure f{dir / "fig", "", {Panel{"", "x", "y", {time_series("a", 0, 10)}}}};
  try {
    hexatwist::cli::write_figures({f});
    FAIL() << "no exception";
  } catch (const ExitError& e) {
    EXPECT_EQ(e.code(), hexatwist::cli::kExitOutputFailed);
    expect_one_line(e.what());
    EXPECT_NE(std::string(e.what()).find(dir / "fig.png"), std::string::npos) << e.what();
  }
}

// gnuplot reports an error in a script as `"<script>" line N: <message>` after echoing the command;
// a fake that prints that format checks that the message keeps the error and names the figure.
TEST(Figures, GnuplotScriptErrorNamesItsMessage) {
  const TempDir dir;
  const ScopedEnv env("HEXATWIST_GNUPLOT",
                      fake_gnuplot(dir,
                                   "echo '' >&2\necho ' plot $x' >&2\necho '      ^' >&2\n"
                                   "echo \"\\\"$2\\\" line 2: undefined variable: x\" >&2\nexit 1"));
  Figure f{dir / "fig", "", {Panel{"", "x", "y", {time_series("a", 0, 10)}}}};
  try {
    hexatwist::cli::write_figures({f});
    FAIL() << "no exception";
  } catch (const ExitError& e) {
    expect_one_line(e.what());
    EXPECT_NE(std::string(e.what()).find("): undefined variable: x"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(dir / "fig"), std::string::npos) << e.what();
  }
}

// Speed is judged from `hexatwist study`'s own timing line and the benchmarks, not here.
TEST(Figures, StudySizedBatchDrawsEveryFigure) {
  const TempDir dir;
  std::vector<Figure> figures;
  for (int k = 0; k < 8; ++k) {
    Figure f{dir / ("study" + std::to_string(k)), "Study figure " + std::to_string(k), {}};
    Panel p{"Legs", "time t [s]", "length [m]", {}};
    for (int leg = 0; leg < 6; ++leg)
      p.series.push_back(k % 2 == 0 ? time_series("leg " + std::to_string(leg + 1), leg, 15000)
                                    : loop_series("leg " + std::to_string(leg + 1), leg, 15000));
    f.panels.push_back(p);
    figures.push_back(f);
  }
  hexatwist::cli::write_figures(figures);
  for (const Figure& f : figures) EXPECT_TRUE(png_size(read_file(f.stem + ".png"))) << f.stem;
}

TEST(Figures, ShortSeriesAreDrawnWhole) {
  std::vector<double> x(hexatwist::cli::kMaxDrawnPoints), y(x.size(), 1.0);
  const auto kept = hexatwist::cli::drawn_points(x, y);
  ASSERT_EQ(kept.size(), x.size());
  for (std::size_t i = 0; i < kept.size(); ++i) EXPECT_EQ(kept[i], i);
}

TEST(Figures, ThinningKeepsEndsExtremesAndOrder) {
  for (const Series& s : {time_series("t", 0, 15000), loop_series("loop", 2, 15000), loop_series("long", 1, 200000)}) {
    SCOPED_TRACE(s.label + " of " + std::to_string(s.x.size()));
    const auto kept = hexatwist::cli::drawn_points(s.x, s.y);
    EXPECT_LE(kept.size(), hexatwist::cli::kMaxDrawnPoints * 3 / 2);
    EXPECT_GE(kept.size(), hexatwist::cli::kMaxDrawnPoints / 4);
    EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end()));
    EXPECT_EQ(std::adjacent_find(kept.begin(), kept.end()), kept.end()) << "an index twice";
    const auto has = [&](std::size_t i) { return std::binary_search(kept.begin(), kept.end(), i); };
    EXPECT_TRUE(has(0));
    EXPECT_TRUE(has(s.x.size() - 1));
    for (const auto* v : {&s.x, &s.y}) {
      EXPECT_TRUE(has(static_cast<std::size_t>(std::min_element(v->begin(), v->end()) - v->begin())));
      EXPECT_TRUE(has(static_cast<std::size_t>(std::max_element(v->begin(), v->end()) - v->begin())));
    }
    // The shape: between two kept neighbours, the dropped points stay within the box of the
    // bucket's extremes, so the drawn curve is off by no more than one bucket's travel.
    double worst = 0.0, range = 0.0;
    const auto [lo, hi] = std::minmax_element(s.y.begin(), s.y.end());
    range = *hi - *lo;
    for (std::size_t k = 0; k + 1 < kept.size(); ++k) {
      const std::size_t a = kept[k], b = kept[k + 1];
      for (std::size_t i = a + 1; i < b; ++i) {
        const double t = static_cast<double>(i - a) / static_cast<double>(b - a);
        worst = std::max(worst, std::abs(s.y[i] - (s.y[a] + t * (s.y[b] - s.y[a]))));
      }
    }
    EXPECT_LT(worst, 0.01 * range) << "drawn curve off by " << worst;
  }
}

TEST(Figures, ThinningKeepsGaps) {
  Series s = time_series("gappy", 0, 15000);
  for (std::size_t i = 5000; i < 5100; ++i) s.y[i] = kNaN;  // a run of NaN
  s.x[9000] = std::numeric_limits<double>::infinity();      // a single bad point
  const auto kept = hexatwist::cli::drawn_points(s.x, s.y);
  const auto has = [&](std::size_t i) { return std::binary_search(kept.begin(), kept.end(), i); };
  EXPECT_TRUE(has(5000));
  EXPECT_TRUE(has(9000));
  EXPECT_TRUE(has(4999)) << "the last point before the gap";
  EXPECT_TRUE(has(5100)) << "the first point after the gap";
  std::size_t non_finite = 0;
  for (const std::size_t i : kept) non_finite += std::isfinite(s.x[i]) && std::isfinite(s.y[i]) ? 0 : 1;
  EXPECT_EQ(non_finite, 2u) << "one break per gap";
}

}  // namespace
