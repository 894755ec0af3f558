#include "hexatwist/trajectory.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>
#include <system_error>

#include "hexatwist/error.hpp"

namespace hexatwist {
namespace {

// Largest number of poses a sweep or a resampling may produce (48 bytes each).
constexpr double kMaxSamples = 1e8;

// Text from the input as it may appear inside a one-line message: control characters escaped,
// and (if `max` is set) cut at a character boundary after `max` bytes.
std::string printable(std::string_view s, std::size_t max = std::string_view::npos) {
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

void check_limit(double value, const char* name) {
  if (!std::isfinite(value)) throw Error(fmt::format("motion limits: {} must be finite, got {}", name, value));
  if (value <= 0.0) throw Error(fmt::format("motion limits: {} must be > 0, got {}", name, value));
}

}  // namespace

// ---- jerk-limited move ----------------------------------------------------------------------

JerkLimitedMove::JerkLimitedMove(double distance, const MotionLimits& limits) : distance_(distance), limits_(limits) {
  if (!std::isfinite(distance))
    throw Error(fmt::format("jerk-limited move: distance must be finite, got {}", distance));
  check_limit(limits.velocity, "velocity");
  check_limit(limits.acceleration, "acceleration");
  check_limit(limits.jerk, "jerk");
  sign_ = distance < 0.0 ? -1.0 : 1.0;
  length_ = std::abs(distance);
  if (length_ == 0.0) return;  // no motion: every segment has zero length

  const double V = limits.velocity, A = limits.acceleration, J = limits.jerk, D = length_;
  // The acceleration phase that reaches a peak velocity v (rest to v) covers v * (its duration)/2
  // and the deceleration phase the same, so the move covers D(v) = v * T_acc(v) without cruise;
  // D grows with v. Pick the largest peak velocity allowed: V if D(V) <= D (then cruise), else
  // the v with D(v) = D, with the acceleration limit reached (v >= A^2/J) or not.
  const double a_full = A * A / J;  // peak velocity at which the acceleration just reaches A
  if (V >= a_full) {
    t_jerk_ = A / J;
    t_accel_ = V / A - t_jerk_;
  } else {
    t_jerk_ = std::sqrt(V / J);
    t_accel_ = 0.0;
  }
  const bool cruise = V * (2.0 * t_jerk_ + t_accel_) <= D;
  if (!cruise) {
    if (D >= 2.0 * A * A * A / (J * J)) {
      // A reached, V not: v^2 + v A^2/J - A D = 0, the positive root in a cancellation-free form.
      t_jerk_ = A / J;
      const double v_peak = 2.0 * A * D / (a_full + std::sqrt(a_full * a_full + 4.0 * A * D));
      t_accel_ = std::max(0.0, v_peak / A - t_jerk_);
    } else {
      // Neither reached: D = 2 J t_jerk^3.
      t_jerk_ = std::cbrt(D / (2.0 * J));
      t_accel_ = 0.0;
    }
  }

  // Exact integration of the first three segments (jerk +J, 0, -J) from rest.
  const double tj = t_jerk_, ta = t_accel_;
  peak_accel_ = J * tj;
  v_[0] = 0.5 * J * tj * tj;
  p_[0] = J * tj * tj * tj / 6.0;
  v_[1] = v_[0] + peak_accel_ * ta;
  p_[1] = p_[0] + v_[0] * ta + 0.5 * peak_accel_ * ta * ta;
  v_[2] = v_[1] + peak_accel_ * tj - 0.5 * J * tj * tj;
  p_[2] = p_[1] + v_[1] * tj + 0.5 * peak_accel_ * tj * tj - J * tj * tj * tj / 6.0;
  // Cruise covers what the two ramps leave; none when V is not reached (the ramps meet).
  t_cruise_ = cruise ? std::max(0.0, (D - 2.0 * p_[2]) / v_[2]) : 0.0;
  duration_ = 2.0 * (2.0 * tj + ta) + t_cruise_;
  if (!std::isfinite(duration_) || !std::isfinite(p_[2]) || !std::isfinite(v_[2]) || !(v_[2] > 0.0))
    throw Error(
        fmt::format("jerk-limited move: distance {} with limits velocity {}, acceleration {}, jerk {} is out of the "
                    "range of a double",
                    distance, V, A, J));
}

MotionSample JerkLimitedMove::first_half(double t) const noexcept {
  const double J = limits_.jerk, tj = t_jerk_;
  const double t1 = tj, t2 = tj + t_accel_, t3 = 2.0 * tj + t_accel_;
  MotionSample s;
  if (t < t1) {
    s.jerk = J;
    s.acceleration = J * t;
    s.velocity = 0.5 * J * t * t;
    s.position = J * t * t * t / 6.0;
  } else if (t < t2) {
    const double u = t - t1;
    s.acceleration = peak_accel_;
    s.velocity = v_[0] + peak_accel_ * u;
    s.position = p_[0] + v_[0] * u + 0.5 * peak_accel_ * u * u;
  } else if (t <= t3) {  // a zero-length cruise: the midpoint belongs to a jerk segment
    const double u = t - t2;
    s.jerk = -J;
    s.acceleration = peak_accel_ - J * u;
    s.velocity = v_[1] + peak_accel_ * u - 0.5 * J * u * u;
    s.position = p_[1] + v_[1] * u + 0.5 * peak_accel_ * u * u - J * u * u * u / 6.0;
  } else {
    s.velocity = v_[2];
    s.position = p_[2] + v_[2] * (t - t3);
  }
  return s;
}

MotionSample JerkLimitedMove::sample(double t) const noexcept {
  if (length_ == 0.0) return {};
  if (std::isnan(t)) {
    constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    return {nan, nan, nan, nan};
  }
  t = std::min(std::max(t, 0.0), duration_);
  MotionSample s;
  if (t <= 0.5 * duration_) {
    s = first_half(t);
  } else {
    // The deceleration mirrors the acceleration: p(T - u) = D - p(u), v even, a odd, j even.
    s = first_half(duration_ - t);
    s.position = length_ - s.position;
    s.acceleration = -s.acceleration;
  }
  s.position *= sign_;
  s.velocity *= sign_;
  s.acceleration *= sign_;
  s.jerk *= sign_;
  return s;
}

std::array<double, 8> JerkLimitedMove::switch_times() const noexcept {
  const double t3 = 2.0 * t_jerk_ + t_accel_;
  const double T = duration_;
  return {0.0, t_jerk_, t_jerk_ + t_accel_, t3, T - t3, T - t_jerk_ - t_accel_, T - t_jerk_, T};
}

// ---- fixed-period trajectories --------------------------------------------------------------

double Trajectory::duration() const noexcept {
  return poses.size() < 2 ? 0.0 : dt * static_cast<double>(poses.size() - 1);
}

Trajectory sweep_trajectory(int coordinate, double amplitude, const MotionLimits& limits, double dwell, double dt) {
  if (coordinate < 0 || coordinate > 5)
    throw Error(fmt::format("sweep: coordinate must be 0..5 (x, y, z, roll, pitch, yaw), got {}", coordinate));
  if (!std::isfinite(amplitude) || amplitude <= 0.0)
    throw Error(fmt::format("sweep: amplitude must be finite and > 0, got {}", amplitude));
  if (!std::isfinite(dwell) || dwell < 0.0)
    throw Error(fmt::format("sweep: dwell must be finite and >= 0 s, got {}", dwell));
  if (!std::isfinite(dt) || dt <= 0.0) throw Error(fmt::format("sweep: dt must be finite and > 0 s, got {}", dt));

  // Four dwells around three moves: 0 -> +a, +a -> -a, -a -> 0.
  const JerkLimitedMove out(amplitude, limits), across(-2.0 * amplitude, limits), back(amplitude, limits);
  struct Stage {
    const JerkLimitedMove* move;
    double start_time;  // [s]
    double start;       // coordinate at the start of the move
  };
  const double t_out = dwell;
  const double t_across = t_out + out.duration() + dwell;
  const double t_back = t_across + across.duration() + dwell;
  const double total = t_back + back.duration() + dwell;
  const Stage stages[3] = {{&out, t_out, 0.0}, {&across, t_across, amplitude}, {&back, t_back, -amplitude}};

  // Rounded up, but a total that is a whole number of dt up to rounding is not pushed one further.
  const double steps = std::ceil(total / dt - 1e-9);
  if (!(steps + 1.0 <= kMaxSamples))
    throw Error(fmt::format("sweep: {} s at dt = {} s is more than {:.0f} samples", total, dt, kMaxSamples));
  const auto n = static_cast<std::size_t>(std::max(steps, 1.0));

  Trajectory traj;
  traj.dt = dt;
  traj.poses.resize(n + 1);
  for (std::size_t k = 0; k < n; ++k) {
    const double t = traj.time(k);
    // The move under way (or the last one begun): before it starts and after it ends the
    // clamped sample holds its start or end.
    const Stage* stage = &stages[0];
    for (const Stage& s : stages)
      if (t >= s.start_time) stage = &s;
    Vector6d q = Vector6d::Zero();
    q[coordinate] = stage->start + stage->move->sample(t - stage->start_time).position;
    traj.poses[k] = Pose::from_vector(q);
  }
  // poses[n] stays home: the end, exactly.
  return traj;
}

// ---- CSV ------------------------------------------------------------------------------------

namespace {

// A header name and the factor from its unit to SI.
struct Unit {
  const char* header;
  double to_si;
};
struct ColumnSpec {
  const char* name;
  std::array<Unit, 3> units;  // {nullptr, 0} pads a column with fewer units
};

// Degrees to radians, as the factor of a unit suffix.
constexpr double kDeg = kPi / 180.0;

constexpr ColumnSpec kColumns[7] = {
    {"t", {{{"t", 1.0}, {"t_s", 1.0}, {nullptr, 0.0}}}},
    {"x", {{{"x", 1.0}, {"x_m", 1.0}, {"x_mm", 1e-3}}}},
    {"y", {{{"y", 1.0}, {"y_m", 1.0}, {"y_mm", 1e-3}}}},
    {"z", {{{"z", 1.0}, {"z_m", 1.0}, {"z_mm", 1e-3}}}},
    {"roll", {{{"roll", kDeg}, {"roll_deg", kDeg}, {"roll_rad", 1.0}}}},
    {"pitch", {{{"pitch", kDeg}, {"pitch_deg", kDeg}, {"pitch_rad", 1.0}}}},
    {"yaw", {{{"yaw", kDeg}, {"yaw_deg", kDeg}, {"yaw_rad", 1.0}}}},
};
constexpr const char* kHeaderWhat =
    "the header row t, x, y, z, roll, pitch, yaw (unit suffixes: t_s; _m or _mm; _deg or _rad)";

bool blank(char c) { return c == ' ' || c == '\t'; }

// One cell of a line: its text without the surrounding whitespace, and where that text starts.
struct Cell {
  std::string_view text;
  std::size_t offset;  // byte offset in the line of `text` (of the cell's start if `text` is empty)
};

// Splits a line at commas and trims each cell.
std::vector<Cell> split(std::string_view line) {
  std::vector<Cell> cells;
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

class CsvReader {
 public:
  explicit CsvReader(std::string_view source) : source_(printable(source)) {}

  // "source:line:column: column 'name': message"; `offset` is a byte offset into `line`, shown
  // as a 1-based character column (UTF-8 continuation bytes do not count).
  [[noreturn]] void fail(int line_no, std::string_view line, std::size_t offset, std::string_view column,
                         const std::string& message) const {
    int col = 1;
    for (std::size_t i = 0; i < offset && i < line.size(); ++i)
      if ((static_cast<unsigned char>(line[i]) & 0xC0) != 0x80) ++col;
    throw Error(fmt::format("{}:{}:{}: column '{}': {}", source_, line_no, col, column, message));
  }

  // The factor to SI of each column, from the header row.
  std::array<double, 7> header(int line_no, std::string_view line) const {
    const std::vector<Cell> cells = split(line);
    std::array<double, 7> factor{};
    for (std::size_t c = 0; c < 7; ++c) {
      const ColumnSpec& spec = kColumns[c];
      // "'x', 'x_m' or 'x_mm'"
      std::string names;
      for (std::size_t k = 0; k < spec.units.size() && spec.units[k].header != nullptr; ++k) {
        const bool last = k + 1 == spec.units.size() || spec.units[k + 1].header == nullptr;
        names += fmt::format("{}'{}'", k == 0 ? "" : last ? " or " : ", ", spec.units[k].header);
      }
      if (c >= cells.size())
        fail(line_no, line, line.size(), spec.name,
             fmt::format("missing from the header; expected {} as column {} of {}", names, c + 1, kHeaderWhat));
      const Cell& cell = cells[c];
      bool found = false;
      for (const Unit& u : spec.units)
        if (u.header != nullptr && cell.text == u.header) factor[c] = u.to_si, found = true;
      if (!found) {
        const char* hint = cell.text.find(';') != std::string_view::npos ? " (cells are separated by commas)" : "";
        fail(line_no, line, cell.offset, spec.name,
             fmt::format("expected {} as column {} of {}, got '{}'{}", names, c + 1, kHeaderWhat,
                         printable(cell.text, 40), hint));
      }
    }
    if (cells.size() > 7)
      fail(line_no, line, cells[7].offset, "yaw",
           fmt::format("extra column '{}' after 'yaw'; expected exactly 7 columns t, x, y, z, roll, pitch, yaw",
                       printable(cells[7].text, 40)));
    return factor;
  }

  // The seven values of a data row, in SI units.
  Vector6d row(int line_no, std::string_view line, const std::array<double, 7>& factor, double& t) const {
    const std::vector<Cell> cells = split(line);
    if (cells.size() < 7)
      fail(line_no, line, line.size(), kColumns[cells.size()].name,
           fmt::format("missing; the row has {} cells, expected 7 (t, x, y, z, roll, pitch, yaw)", cells.size()));
    if (cells.size() > 7)
      fail(line_no, line, cells[7].offset, "yaw",
           fmt::format("extra cell '{}' after 'yaw'; the row has {} cells, expected 7 (t, x, y, z, roll, pitch, yaw)",
                       printable(cells[7].text, 40), cells.size()));
    std::array<double, 7> v{};
    for (std::size_t c = 0; c < 7; ++c) {
      const Cell& cell = cells[c];
      const char* name = kColumns[c].name;
      std::string_view text = cell.text;
      if (text.empty()) fail(line_no, line, cell.offset, name, "empty cell; expected a number");
      // from_chars takes no leading '+', a person may type one.
      if (text.size() > 1 && text[0] == '+' && text[1] != '-' && text[1] != '+') text.remove_prefix(1);
      double x = 0.0;
      const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), x);
      const std::string shown = printable(cell.text, 40);
      if (ec == std::errc::result_out_of_range && end == text.data() + text.size())
        fail(line_no, line, cell.offset, name, fmt::format("number out of range, got '{}'", shown));
      if (ec != std::errc() || end != text.data() + text.size())
        fail(line_no, line, cell.offset, name, fmt::format("expected a number, got '{}'", shown));
      if (!std::isfinite(x))
        fail(line_no, line, cell.offset, name, fmt::format("expected a finite number, got '{}'", shown));
      v[c] = x * factor[c];
      if (!std::isfinite(v[c]))
        fail(line_no, line, cell.offset, name,
             fmt::format("number out of range after unit conversion, got '{}'", shown));
    }
    t = v[0];
    Vector6d q;
    for (int k = 0; k < 6; ++k) q[k] = v[static_cast<std::size_t>(k) + 1];
    return q;
  }

  const std::string& source() const { return source_; }

 private:
  std::string source_;
};

}  // namespace

TimedPoses parse_trajectory_csv(std::string_view text, std::string_view source) {
  const CsvReader r(source);
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte-order mark (spreadsheets)

  TimedPoses out;
  std::array<double, 7> factor{};
  bool have_header = false;
  int line_no = 0, header_line = 0;
  std::string_view last_line;
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

    if (!have_header) {
      factor = r.header(line_no, line);
      have_header = true;
      header_line = line_no;
      last_line = line;
      continue;
    }
    double t = 0.0;
    const Vector6d q = r.row(line_no, line, factor, t);
    if (!out.t.empty() && !(t > out.t.back())) {
      const std::size_t at = split(line)[0].offset;
      r.fail(line_no, line, at, "t",
             fmt::format("time {} s is not after {} s on line {}; times must be strictly increasing", t, out.t.back(),
                         out.lines.back()));
    }
    out.t.push_back(t);
    out.poses.push_back(Pose::from_vector(q));
    out.lines.push_back(line_no);
    last_line = line;
  }

  if (!have_header)
    r.fail(1, {}, 0, "t",
           fmt::format("{}; expected {} and at least 2 data rows",
                       text.empty() ? "empty text" : "no header row (only blank or comment lines)", kHeaderWhat));
  if (out.t.size() < 2)
    r.fail(out.t.empty() ? header_line : out.lines.back(), last_line, 0, "t",
           fmt::format("{} data row{}; a trajectory needs at least 2 rows (times)", out.t.size(),
                       out.t.size() == 1 ? "" : "s"));
  return out;
}

// ---- resampling -----------------------------------------------------------------------------

Trajectory resample(const TimedPoses& samples, double dt) {
  const std::vector<double>& t = samples.t;
  if (!std::isfinite(dt) || dt <= 0.0) throw Error(fmt::format("resample: dt must be finite and > 0 s, got {}", dt));
  if (t.size() != samples.poses.size())
    throw Error(fmt::format("resample: {} times but {} poses", t.size(), samples.poses.size()));
  if (t.size() < 2) throw Error(fmt::format("resample: need at least 2 samples, got {}", t.size()));
  const std::size_t m = t.size();
  // Where a sample came from, for messages.
  const auto at = [&](std::size_t i) {
    return i < samples.lines.size() ? fmt::format("sample {} (line {})", i, samples.lines[i])
                                    : fmt::format("sample {}", i);
  };
  std::vector<Vector6d> q(m);
  for (std::size_t i = 0; i < m; ++i) {
    if (!std::isfinite(t[i])) throw Error(fmt::format("resample: {}: time is not finite ({})", at(i), t[i]));
    if (i > 0 && !(t[i] > t[i - 1]))
      throw Error(fmt::format("resample: {}: time {} s is not after {} s", at(i), t[i], t[i - 1]));
    if (!samples.poses[i].is_finite()) throw Error(fmt::format("resample: {}: pose is not finite", at(i)));
    q[i] = samples.poses[i].to_vector();
  }

  // Slopes (Fritsch-Carlson monotone cubic, "PCHIP", per coordinate): a weighted harmonic mean
  // of the two neighbouring secants where they agree in sign, else 0; at the ends, the three-point
  // one-sided slope, limited the same way. The curve then never overshoots the samples: a hold
  // stays a hold and a move does not swing past its end (waypoint files are common input).
  // Lines are reproduced exactly.
  std::vector<Vector6d> slope(m);
  const auto secant = [&](std::size_t i) -> Vector6d { return (q[i + 1] - q[i]) / (t[i + 1] - t[i]); };
  if (m == 2) {
    slope[0] = slope[1] = secant(0);
  } else {
    for (std::size_t i = 1; i + 1 < m; ++i) {
      const double h0 = t[i] - t[i - 1], h1 = t[i + 1] - t[i];
      const Vector6d d0 = secant(i - 1), d1 = secant(i);
      const double w0 = 2.0 * h1 + h0, w1 = h1 + 2.0 * h0;
      for (int c = 0; c < 6; ++c) slope[i][c] = d0[c] * d1[c] > 0.0 ? (w0 + w1) / (w0 / d0[c] + w1 / d1[c]) : 0.0;
    }
    const auto end_slope = [](double h0, double h1, double d0, double d1) {
      double e = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
      if (e * d0 <= 0.0) return 0.0;
      if (d0 * d1 <= 0.0 && std::abs(e) > 3.0 * std::abs(d0)) e = 3.0 * d0;
      return e;
    };
    const Vector6d a0 = secant(0), a1 = secant(1), z0 = secant(m - 2), z1 = secant(m - 3);
    for (int c = 0; c < 6; ++c) {
      slope[0][c] = end_slope(t[1] - t[0], t[2] - t[1], a0[c], a1[c]);
      slope[m - 1][c] = end_slope(t[m - 1] - t[m - 2], t[m - 2] - t[m - 3], z0[c], z1[c]);
    }
  }

  const double span = t.back() - t.front();
  const double steps = std::floor(span / dt + 1e-9);
  if (!(steps + 1.0 <= kMaxSamples))
    throw Error(fmt::format("resample: {} s at dt = {} s is more than {:.0f} samples", span, dt, kMaxSamples));
  const auto n = static_cast<std::size_t>(steps);

  Trajectory traj;
  traj.t0 = t.front();
  traj.dt = dt;
  traj.poses.resize(n + 1);
  const double snap = 1e-9 * dt;  // a grid time this close to an input time is that time
  std::size_t i = 0;              // interval [t[i], t[i+1]] of the current grid time
  for (std::size_t k = 0; k <= n; ++k) {
    const double tk = std::min(traj.time(k), t.back());
    while (i + 2 < m && t[i + 1] <= tk + snap) ++i;
    if (std::abs(tk - t[i]) <= snap) {
      traj.poses[k] = samples.poses[i];
    } else if (std::abs(tk - t[i + 1]) <= snap) {
      traj.poses[k] = samples.poses[i + 1];
    } else {
      // Cubic Hermite on [t[i], t[i+1]] in s = (t - t[i]) / h.
      const double h = t[i + 1] - t[i];
      const double s = std::clamp((tk - t[i]) / h, 0.0, 1.0);
      const double s2 = s * s, s3 = s2 * s;
      const double h00 = 2.0 * s3 - 3.0 * s2 + 1.0, h10 = s3 - 2.0 * s2 + s;
      const double h01 = -2.0 * s3 + 3.0 * s2, h11 = s3 - s2;
      const Vector6d qk = h00 * q[i] + h10 * h * slope[i] + h01 * q[i + 1] + h11 * h * slope[i + 1];
      // Finite samples whose differences or rates overflow a double (1e308 m next to 0 m) give
      // an infinite slope: no pose can be interpolated there.
      if (!qk.allFinite())
        throw Error(fmt::format("resample: between {} and {}: the interpolation overflows a double (a value or "
                                "its rate of change beyond 1e308)", at(i), at(i + 1)));
      traj.poses[k] = Pose::from_vector(qk);
    }
  }
  return traj;
}

}  // namespace hexatwist
