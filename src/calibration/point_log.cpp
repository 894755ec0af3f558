// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/calibration/point_log.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <optional>
#include <span>

#include "hexatwist/error.hpp"
#include "motion/csv.hpp"

namespace hexatwist {
namespace {

// ---- point log --------------------------------------------------------------------------------

// A unit suffix of a header name and its factor to SI.
struct Suffix {
  const char* text;
  double to_si;
};
constexpr Suffix kTimeSuffixes[] = {{"_s", 1.0}, {"_ms", 1e-3}};
constexpr Suffix kLengthSuffixes[] = {{"_m", 1.0}, {"_mm", 1e-3}};
constexpr Suffix kTemperatureSuffixes[] = {{"_c", 1.0}};  // degrees Celsius

bool same_ignoring_case(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

std::string unit_name(double to_si) { return to_si == 1.0 ? "m" : to_si == 1e-3 ? "mm" : fmt::format("{} m", to_si); }

// One wanted column: where it is in the header and the factor of its values to SI.
struct Column {
  std::string name;         // as the format names it
  std::size_t index = 0;    // cell index in the row
  double to_si = 1.0;       // factor to SI (0 while unknown)
  std::string_view header;  // the header cell
};

// Finds `name` in the header cells; the suffix found (or none) in `suffix`.
Column find_column(const detail::CsvReader& r, const detail::CsvLine& line, const std::vector<detail::CsvCell>& cells,
                   const std::string& name, std::span<const Suffix> suffixes, std::optional<Suffix>& suffix) {
  std::optional<std::size_t> found;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const std::string_view text = cells[c].text;
    std::optional<Suffix> here;
    bool match = same_ignoring_case(text, name);
    // A name that carries a unit suffix itself (`x_mm`) gives the unit by it.
    for (const Suffix& s : suffixes) {
      const std::size_t n = std::char_traits<char>::length(s.text);
      if (match && name.size() > n && same_ignoring_case(std::string_view(name).substr(name.size() - n), s.text))
        here = s;
    }
    for (const Suffix& s : suffixes) {
      const std::size_t n = std::char_traits<char>::length(s.text);
      if (!match && text.size() == name.size() + n && same_ignoring_case(text.substr(0, name.size()), name) &&
          same_ignoring_case(text.substr(name.size()), s.text)) {
        match = true;
        here = s;
      }
    }
    if (!match) continue;
    if (found)
      r.fail(line.number, line.text, cells[c].offset, name,
             fmt::format("named twice in the header, as '{}' and '{}'", detail::printable(cells[*found].text, 40),
                         detail::printable(text, 40)));
    found = c;
    suffix = here;
  }
  if (!found) {
    std::string names;
    for (const detail::CsvCell& c : cells)
      names += fmt::format("{}'{}'", names.empty() ? "" : ", ", detail::printable(c.text, 40));
    std::string accepted = fmt::format("'{}'", name);
    for (const Suffix& s : suffixes) accepted += fmt::format(" or '{}{}'", name, s.text);
    r.fail(line.number, line.text, 0, name,
           fmt::format("not in the header ({}); expected a column named {} (case ignored)", names, accepted));
  }
  return {name, *found, 1.0, cells[*found].text};
}

// The columns a log is read by: time, x, y, z and the target (if any).
struct LogColumns {
  Column time;
  std::array<Column, 3> xyz;
  std::optional<Column> target;
  std::optional<Column> temperature;

  // A cell's column as messages name it: as the format does for those read, else the header's.
  std::string_view name(std::size_t c, const std::vector<detail::CsvCell>& header) const {
    if (target && c == target->index) return target->name;
    if (temperature && c == temperature->index) return temperature->name;
    if (c == time.index) return time.name;
    for (const Column& a : xyz)
      if (c == a.index) return a.name;
    return header[c].text;
  }
};

LogColumns find_columns(const detail::CsvReader& r, const detail::CsvLine& head,
                        const std::vector<detail::CsvCell>& header, const PointLogFormat& format) {
  LogColumns cols;
  // The time column: seconds (or ms by suffix), or a bare sample index.
  std::optional<Suffix> suffix;
  cols.time = format.indexed ? find_column(r, head, header, format.time_column, {}, suffix)
                             : find_column(r, head, header, format.time_column, kTimeSuffixes, suffix);
  cols.time.to_si = suffix ? suffix->to_si : 1.0;
  // x, y, z: the length unit from the suffix or the format; both given must agree.
  const std::array<const std::string*, 3> names{&format.x_column, &format.y_column, &format.z_column};
  for (std::size_t a = 0; a < 3; ++a) {
    Column& c = cols.xyz[a];
    c = find_column(r, head, header, *names[a], kLengthSuffixes, suffix);
    const std::size_t at = header[c.index].offset;
    if (suffix && format.length_unit > 0.0 && suffix->to_si != format.length_unit)
      r.fail(head.number, head.text, at, c.name,
             fmt::format("'{}' is in {} but the units were given as {}", detail::printable(c.header, 40),
                         unit_name(suffix->to_si), unit_name(format.length_unit)));
    if (!suffix && !(format.length_unit > 0.0))
      r.fail(head.number, head.text, at, c.name,
             fmt::format("units missing: '{}' has no unit suffix (_mm or _m) and no length unit was given (mm or m; "
                         "--units on the command line)",
                         detail::printable(c.header, 40)));
    c.to_si = suffix ? suffix->to_si : format.length_unit;
  }
  // The target column, if any: named by the format, or a header cell `target`.
  if (!format.target_column.empty()) {
    cols.target = find_column(r, head, header, format.target_column, {}, suffix);
  } else {
    for (std::size_t c = 0; c < header.size(); ++c)
      if (same_ignoring_case(header[c].text, "target")) cols.target = Column{"target", c, 1.0, header[c].text};
  }
  // The machine's temperature, if any [degC]: named by the format, or a header cell `temperature`
  // or `temperature_c`.
  if (!format.temperature_column.empty()) {
    cols.temperature = find_column(r, head, header, format.temperature_column, kTemperatureSuffixes, suffix);
  } else {
    for (std::size_t c = 0; c < header.size(); ++c)
      if (same_ignoring_case(header[c].text, "temperature") || same_ignoring_case(header[c].text, "temperature_c"))
        cols.temperature = Column{std::string(header[c].text), c, 1.0, header[c].text};  // named as the log names it
  }
  return cols;
}

// The target of a row (a new name is appended to log.target_names, with its first point in
// `last_of_target`).
int row_target(const detail::CsvReader& r, const detail::CsvLine& line, const detail::CsvCell& cell,
               const Column& column, PointLog& log, std::vector<std::size_t>& last_of_target) {
  if (cell.text.empty())
    r.fail(line.number, line.text, cell.offset, column.name, "empty; expected the name of the target measured");
  const auto it = std::find(log.target_names.begin(), log.target_names.end(), cell.text);
  if (it != log.target_names.end()) return static_cast<int>(it - log.target_names.begin());
  if (log.target_names.size() == kMaxTargets)
    r.fail(line.number, line.text, cell.offset, column.name,
           fmt::format("a {}th target '{}'; a log may carry at most {}", kMaxTargets + 1,
                       detail::printable(cell.text, 40), kMaxTargets));
  log.target_names.emplace_back(cell.text);
  last_of_target.push_back(log.stamps.size());
  return static_cast<int>(log.target_names.size()) - 1;
}

// The 1-based character column of a byte offset in a UTF-8 line.
int character_column(std::string_view text, std::size_t offset) {
  int col = 1;
  for (std::size_t i = 0; i < offset; ++i)
    if ((static_cast<unsigned char>(text[i]) & 0xC0) != 0x80) ++col;
  return col;
}

}  // namespace

PointLog parse_point_log(std::string_view text, std::string_view source, const PointLogFormat& format) {
  // A unit is honoured or refused, never ignored: also where every column carries a suffix.
  if (!(format.length_unit == 0.0 || (std::isfinite(format.length_unit) && format.length_unit > 0.0)))
    throw ParameterError(fmt::format("{}: length unit: expected metres per unit > 0 (1e-3 for mm, 1 for m) or 0 "
                                     "for the columns' suffixes, got {}",
                                     source, format.length_unit),
                         "length_unit");
  const detail::CsvReader r(source);
  text = detail::without_bom(text);
  const std::vector<detail::CsvLine> lines = detail::csv_lines(text);
  if (lines.empty())
    r.fail(1, {}, 0, format.time_column,
           fmt::format("{}; expected a header row naming the columns {}, {}, {}, {} and at least {} points",
                       text.empty() ? "empty text" : "no header row (only blank or comment lines)", format.time_column,
                       format.x_column, format.y_column, format.z_column, kMinLogPoints));
  const detail::CsvLine& head = lines[0];
  const std::vector<detail::CsvCell> header = detail::split_csv(head.text);
  const LogColumns cols = find_columns(r, head, header, format);
  const Column& time = cols.time;

  PointLog log;
  log.source = std::string(source);
  log.indexed = format.indexed;
  std::vector<std::size_t> last_of_target;  // per target: its last point
  if (!cols.target) log.target_names = {"A"};
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const detail::CsvLine& line = lines[k];
    const std::vector<detail::CsvCell> cells = detail::split_csv(line.text);
    if (cells.size() != header.size()) {
      const bool more = cells.size() > header.size();
      r.fail(line.number, line.text, more ? cells[header.size()].offset : line.text.size(),
             cols.name(more ? header.size() - 1 : cells.size(), header),
             fmt::format("{}; the row has {} cells, the header on line {} has {}",
                         more ? fmt::format("extra cell '{}'", detail::printable(cells[header.size()].text, 40))
                              : std::string("missing"),
                         cells.size(), head.number, header.size()));
    }
    const detail::CsvCell& tc = cells[time.index];
    const double stamp = r.number(line, tc, time.name, time.to_si);
    if (format.indexed && stamp != std::floor(stamp))
      r.fail(line.number, line.text, tc.offset, time.name,
             fmt::format("expected a whole sample index, got '{}'", detail::printable(tc.text, 40)));
    Vector3d p;
    for (std::size_t a = 0; a < 3; ++a)
      p[static_cast<int>(a)] = r.number(line, cells[cols.xyz[a].index], cols.xyz[a].name, cols.xyz[a].to_si);
    int t = 0;
    if (cols.target)
      t = row_target(r, line, cells[cols.target->index], *cols.target, log, last_of_target);
    else if (last_of_target.empty())
      last_of_target.push_back(0);
    // Times increase per target (a tracker may measure several targets at one instant).
    const std::size_t previous = last_of_target[static_cast<std::size_t>(t)];
    const char* per_target = cols.target ? " per target" : "";
    if (previous < log.stamps.size() && !(stamp > log.stamps[previous]))
      r.fail(line.number, line.text, tc.offset, time.name,
             format.indexed ? fmt::format("index {} is not after {} on line {}; indices must be strictly increasing{}",
                                          stamp, log.stamps[previous], log.lines[previous], per_target)
                            : fmt::format("time {} s is not after {} s on line {}; times must be strictly increasing{}",
                                          stamp, log.stamps[previous], log.lines[previous], per_target));
    if (cols.temperature) {
      const detail::CsvCell& cell = cells[cols.temperature->index];
      const double celsius = r.number(line, cell, cols.temperature->name, 1.0);
      if (!(celsius >= kMinLogTemperature && celsius <= kMaxLogTemperature))
        r.fail(line.number, line.text, cell.offset, cols.temperature->name,
               fmt::format("{} degC is not a machine's temperature; expected {} to {} degC", celsius,
                           kMinLogTemperature, kMaxLogTemperature));
      log.temperatures.push_back(celsius);
    }
    last_of_target[static_cast<std::size_t>(t)] = log.stamps.size();
    log.targets.push_back(t);
    log.stamps.push_back(stamp);
    log.points_T.push_back(p);
    log.lines.push_back(line.number);
    log.stamp_columns.push_back(character_column(line.text, tc.offset));
  }
  if (log.stamps.size() < kMinLogPoints)
    r.fail(lines.back().number, lines.back().text, 0, format.time_column,
           fmt::format("{} point{}; registering the tracker frame needs at least {}", log.stamps.size(),
                       log.stamps.size() == 1 ? "" : "s", kMinLogPoints));
  return log;
}

std::vector<double> trajectory_times(const PointLog& log, const TimeAlignment& alignment) {
  if (!std::isfinite(alignment.offset))
    throw Error(
        fmt::format("{}: time offset: expected a finite number of seconds, got {}", log.source, alignment.offset));
  if (log.indexed && !(std::isfinite(alignment.rate) && alignment.rate > 0.0))
    throw Error(fmt::format("{}: sample rate: expected > 0 Hz for a log of sample indices, got {}", log.source,
                            alignment.rate));
  if (!(std::isfinite(alignment.scale) && alignment.scale > 0.0))
    throw Error(
        fmt::format("{}: clock scale: expected a finite number > 0 (the log's seconds per second of the run), "
                    "got {}",
                    log.source, alignment.scale));
  std::vector<double> t(log.stamps.size());
  for (std::size_t k = 0; k < t.size(); ++k)
    t[k] = ((log.indexed ? log.stamps[k] / alignment.rate : log.stamps[k]) - alignment.offset) / alignment.scale;
  return t;
}

}  // namespace hexatwist
