// SPDX-License-Identifier: BSD-3-Clause
// Seeded random stress test of the real-time command stream (stream.hpp): random requests through
// stream_pose and stream_line, with random stream settings, on the seed platform and on random
// platforms whose U-joint axes lie close to their legs (so that the singularity limit is reached).
//
// Requests: valid poses (a smooth walk and random jumps), poses outside a limit, non-finite
// components, poses within 1e-9 of a U-joint singularity limit (bisection between a valid pose and
// one the limit check calls singular), pose lines (well formed in both angle units, malformed in
// a known way, random bytes). Checked independently of the stream's own checks, for every answer:
// - an emitted command (new or held) is finite, inside the stroke (check_stroke), and the pose it
//   means (forward kinematics of the command, motor-side lengths for the compensated strategy,
//   geometric for the conventional one, warm-started from the pose the command came from) is
//   inside every limit (check_limits, and the bend and singularity angles recomputed here), to a
//   tolerance for the FK solution;
// - without rate limits, an accepted pose gets exactly motor_commands' command;
// - a rejection has a status other than Ok that agrees with motor_commands (or the line parser),
//   names a leg 0..5 with finite value and bound for a limit, and where a line is malformed;
// - consecutive emitted commands respect the rate limits (|dm| <= vmax*period, |dv| <= amax*period),
//   except the acceleration right after a hold due to a failed check, as stream.hpp documents;
// - the answer line (format_stream_output) is one line shorter than kMaxOutputLength.
//
//   stress_stream [--count N] [--seed S]      N requests (default 500000), seed S (default 20211124)
//
// Prints the counts per kind, status and action; exit code 1 on any failed check (the first few
// are printed with everything needed to replay them), 2 on bad arguments.
#include <algorithm>
#include <array>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "support.hpp"

namespace hexatwist::test {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Tolerance of the independent limit check [m or rad]: the pose of a command is solved here again
// (to the FK tolerance), and a leg length or angle at a limit carries a few ulp. Largest excess
// measured over 6 x 10^6 requests (seeds 1-6): 1.1e-15.
constexpr double kLimitTol = 1e-14;

// ---------------------------------------------------------------------------------------------
// Platforms
// ---------------------------------------------------------------------------------------------

// Unit vector at `angle` [rad] from the unit vector `s`, in a random direction around it.
Vector3d tilted(std::mt19937_64& rng, const Vector3d& s, double angle) {
  const Vector3d u = s.unitOrthogonal();
  const Vector3d w = s.cross(u);
  const double phi = uniform(rng, -kPi, kPi);
  return std::cos(angle) * s + std::sin(angle) * (std::cos(phi) * u + std::sin(phi) * w);
}

// A random platform (support.hpp) whose fixed U-joint axes lie 18-35 deg from their legs at home,
// so that a bend of a few degrees reaches the 15 deg singularity margin before the 45 deg bend limit.
Model near_singular_platform(std::mt19937_64& rng) {
  for (;;) {
    ModelSpec spec = random_platform(rng).spec();
    spec.name = "random platform, U-joint axes near the legs";
    for (LegSpec& leg : spec.legs) {
      const Vector3d s0 = (leg.platform_P + Vector3d(0, 0, spec.home_height) - leg.base_B).normalized();
      leg.axis_base_B = tilted(rng, s0, deg2rad(uniform(rng, 18.0, 35.0)));
      leg.axis_platform_P = tilted(rng, s0, deg2rad(uniform(rng, 18.0, 35.0)));
    }
    try {
      return Model(spec);
    } catch (const Error&) {
      // a badly conditioned layout: draw again
    }
  }
}

double log_uniform(std::mt19937_64& rng, double lo, double hi) {
  return std::exp(uniform(rng, std::log(lo), std::log(hi)));
}

// A vector with components uniform in [-1, 1].
Vector6d random_direction(std::mt19937_64& rng) {
  Vector6d v;
  for (int k = 0; k < 6; ++k) v[k] = uniform(rng, -1.0, 1.0);
  return v;
}

Pose lerp(const Pose& a, const Pose& b, double s) {
  return Pose::from_vector((1.0 - s) * a.to_vector() + s * b.to_vector());
}

bool singular(Status s) { return s == Status::SingularBase || s == Status::SingularPlatform; }

// Pairs of poses about 1e-13 apart on either side of a U-joint singularity limit: bisection along the
// segment from a valid pose to one whose first violated limit is a singularity.
struct Boundary {
  Pose inside, outside;
};
std::vector<Boundary> singularity_boundaries(const Model& model, std::mt19937_64& rng, int wanted) {
  std::vector<Boundary> out;
  CommandReport report;
  for (int attempt = 0; attempt < 200 * wanted && static_cast<int>(out.size()) < wanted; ++attempt) {
    const Pose a = random_valid_pose(model, rng, 0.1, deg2rad(5));
    const Pose b = random_pose(rng, 0.4, deg2rad(35));
    if (!singular(compute_commands(model, b, report))) continue;
    double lo = 0.0, hi = 1.0;
    while (hi - lo > 1e-13) {
      const double mid = 0.5 * (lo + hi);
      (compute_commands(model, lerp(a, b, mid), report) == Status::Ok ? lo : hi) = mid;
    }
    if (compute_commands(model, lerp(a, b, lo), report) != Status::Ok) continue;
    if (singular(compute_commands(model, lerp(a, b, hi), report))) out.push_back({lerp(a, b, lo), lerp(a, b, hi)});
  }
  return out;
}

struct Platform {
  const Model* model;
  std::vector<Boundary> boundaries;  // empty for the seed platform (its bend limit comes first)
};

// ---------------------------------------------------------------------------------------------
// Requests
// ---------------------------------------------------------------------------------------------

enum class Kind { Walk, Jump, OutOfLimit, NonFinite, NearSingular, GoodLine, BadLine, Garbage, kCount };
constexpr std::array<const char*, static_cast<int>(Kind::kCount)> kKindNames = {
    "valid walk",       "valid jump",        "out of limit",    "non-finite",
    "near singularity", "line, well formed", "line, malformed", "line, random bytes"};

struct Request {
  Kind kind = Kind::Walk;
  Pose pose;             // the pose sent, or the pose the line means
  bool has_pose = true;  // false for a line that does not parse
  std::string line;      // for the line kinds
  AngleUnit unit = AngleUnit::Degrees;
  LineError expected_error = LineError::None;  // for BadLine
  int expected_field = -1;                     // for BadLine
};

// One field of a pose line in a random but valid spelling; `value` is what the spelling reads as.
std::string spell(std::mt19937_64& rng, double& value) {
  char buf[64];
  const int style = static_cast<int>(rng() % 4);
  if (style == 0)
    std::snprintf(buf, sizeof buf, "%.17g", value);
  else if (style == 1)
    std::snprintf(buf, sizeof buf, "%.6f", value);
  else if (style == 2)
    std::snprintf(buf, sizeof buf, "%.9e", value);
  else
    std::snprintf(buf, sizeof buf, "%g", value);
  value = std::strtod(buf, nullptr);  // what the text means (the C library reads it, not hexatwist)
  static constexpr std::array<const char*, 4> kBlanks = {"", " ", "\t", "  "};
  std::string s = kBlanks[rng() % 4];
  if (buf[0] != '-' && rng() % 4 == 0) s += '+';
  s += buf;
  s += kBlanks[rng() % 4];
  return s;
}

// A well-formed line for `pose` [m, rad] in `unit`; `pose` becomes what the line means.
std::string good_line(std::mt19937_64& rng, Pose& pose, AngleUnit unit) {
  Vector6d q = pose.to_vector();
  std::string line;
  for (int k = 0; k < 6; ++k) {
    double v = k >= 3 && unit == AngleUnit::Degrees ? rad2deg(q[k]) : q[k];
    if (k) line += ',';
    line += spell(rng, v);
    q[k] = k >= 3 && unit == AngleUnit::Degrees ? deg2rad(v) : v;
  }
  static constexpr std::array<const char*, 4> kEnds = {"", "\n", "\r\n", "\r"};
  pose = Pose::from_vector(q);
  return line + kEnds[rng() % 4];
}

// A line broken in one known way.
void bad_line(std::mt19937_64& rng, Request& r) {
  std::vector<std::string> fields = {"0.1", "-0.05", "0.2", "1.5", "-2", "30"};
  const int at = static_cast<int>(rng() % 6);
  switch (rng() % 7) {
    case 0:
      fields.resize(static_cast<std::size_t>(at));
      r.expected_error = at == 0 ? LineError::Empty : LineError::MissingFields;
      r.expected_field = at == 0 ? -1 : at;
      break;
    case 1:
      fields.push_back("0");
      r.expected_error = LineError::ExtraFields;
      r.expected_field = 6;
      break;
    case 2:
      fields[static_cast<std::size_t>(at)] = rng() % 2 ? "" : " \t ";
      r.expected_error = LineError::EmptyField;
      r.expected_field = at;
      break;
    case 3: {
      static constexpr std::array<const char*, 7> kWords = {"abc", "1.2.3", "0x1p3", "1e", "--1", "++1", "1 2"};
      fields[static_cast<std::size_t>(at)] = kWords[rng() % kWords.size()];
      r.expected_error = LineError::NotANumber;
      r.expected_field = at;
      break;
    }
    case 4:
      fields[static_cast<std::size_t>(at)] = rng() % 2 ? "1e999" : "-2e400";
      r.expected_error = LineError::OutOfRange;
      r.expected_field = at;
      break;
    case 5:
      r.line = std::string(kMaxLineLength + 1 + rng() % 100, ' ');
      r.line.replace(0, 11, "0,0,0,0,0,0");
      r.expected_error = LineError::TooLong;
      r.expected_field = -1;
      return;
    default:
      r.line = std::string(rng() % 5, ' ') + (rng() % 2 ? "\n" : "");
      r.expected_error = LineError::Empty;
      r.expected_field = -1;
      return;
  }
  for (std::size_t k = 0; k < fields.size(); ++k) {
    if (k) r.line += ',';
    r.line += fields[k];
  }
}

std::string garbage(std::mt19937_64& rng) {
  static constexpr std::string_view kChars = "0123456789,.,.e-+ \tnaifNAIF,x\r";
  std::string s(rng() % 90, ' ');
  for (char& c : s) c = rng() % 8 == 0 ? static_cast<char>(rng() % 256) : kChars[rng() % kChars.size()];
  return s;
}

// ---------------------------------------------------------------------------------------------
// Checks
// ---------------------------------------------------------------------------------------------

struct Tally {
  std::uint64_t requests = 0, failures = 0, fk_checks = 0, boundary_limit_reports = 0, holds_after_failed_check = 0;
  double worst_excess = -kInf;  // largest amount by which a verified command's pose lies outside a limit
  double worst_residual = 0.0;  // largest FK residual of a verified command [m]
  std::map<std::string, std::uint64_t> kinds, statuses, actions;
};

// Everything needed to replay a failure.
struct Context {
  std::uint64_t seed, index;
  const Platform* platform;
  const StreamSettings* settings;
  const Request* request;
};

Tally g_tally;

void fail(const Context& c, const StreamOutput& out, const std::string& what) {
  ++g_tally.failures;
  if (g_tally.failures > 10) return;
  const StreamSettings& s = *c.settings;
  std::fprintf(stderr,
               "FAIL request %" PRIu64 " (seed %" PRIu64
               ", %s, %s): %s\n"
               "  settings: %s, %s, period %.17g s, vmax %.17g m/s, amax %.17g m/s^2\n"
               "  pose %s; line '%s'\n  answer: input %" PRIu64
               ", status %s, action %s, rate limited %d, "
               "command %s, leg %d, value %.17g, bound %.17g\n",
               c.index, c.seed, c.platform->model->spec().name.c_str(), kKindNames[static_cast<int>(c.request->kind)],
               what.c_str(), s.strategy == Strategy::Compensated ? "compensated" : "conventional",
               s.on_reject == RejectPolicy::Hold ? "hold" : "skip", s.period, s.max_velocity, s.max_acceleration,
               str(c.request->pose).c_str(), c.request->line.c_str(), out.input,
               std::string(to_string(out.status)).c_str(), std::string(to_string(out.action)).c_str(),
               out.rate_limited ? 1 : 0, str(Pose::from_vector(out.command)).c_str(), out.limit.leg, out.limit.value,
               out.limit.bound);
}

double angle_between(const Vector3d& a, const Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// How far the legs of a solved pose lie outside the model's limits, recomputed from the geometry
// [m or rad; <= 0 inside]: stroke, bend of each U-joint from its home direction, and the angle
// between each leg and its joints' fixed axes (either sense of the axis).
double limit_excess(const Model& model, const LegState& legs) {
  const LimitSpec& lim = model.spec().limits;
  double excess = -kInf;
  for (int i = 0; i < kLegs; ++i) {
    const Leg& leg = model.leg(i);
    const Vector3d s = legs.s_B.row(i).transpose();
    const double l = legs.leg_B.row(i).norm();
    excess = std::max({excess, lim.length_min - l, l - lim.length_max});
    excess = std::max(excess, angle_between(s, leg.s_home_B) - lim.bend_max);
    excess = std::max(excess, angle_between(legs.R_BP.transpose() * s, leg.s_home_B) - lim.bend_max);
    if (model.geometry().has_axes[i] != 0.0) {
      const Vector3d axis_platform_B = legs.R_BP * leg.axis_platform_P;
      for (const Vector3d& axis : {leg.axis_base_B, axis_platform_B}) {
        const double a = angle_between(s, axis);
        excess = std::max(excess, lim.singularity_margin - std::min(a, kPi - a));
      }
    }
  }
  return excess;
}

// One stream: its settings, and what the checks remember between answers.
struct Session {
  const Platform* platform = nullptr;
  StreamSettings settings;
  StreamState state;
  bool had_command = false;                   // the stream had a command before this input
  bool has_previous = false;                  // a command was emitted (or started) in this session
  bool verified = false;                      // `previous` was solved and checked here
  Vector6d previous = Vector6d::Zero();       // the last emitted command [m]
  Vector6d previous_rate = Vector6d::Zero();  // its rate of change [m/s]
  Placement previous_placement;               // the pose it means, as solved here
};

// Checks an emitted command: finite, inside the stroke, its pose inside every limit.
void check_command(const Context& c, Session& s, const StreamOutput& out, bool from_pose) {
  const Model& model = *s.platform->model;
  if (!out.command.allFinite()) return fail(c, out, "non-finite command emitted");
  LimitReport report;
  if (check_stroke(model, out.command, report) != Status::Ok) return fail(c, out, "command outside the stroke");
  if (s.verified && out.command == s.previous) return;  // the same numbers as a command verified before

  // The pose the command means, from the pose it came from: the input pose for an unlimited new
  // command, else the previous command's pose (a rate-limited step or a hold is a small move).
  const LengthKind kind = s.settings.strategy == Strategy::Compensated ? LengthKind::Motor : LengthKind::Geometric;
  const Placement guess = from_pose ? placement_from_pose(c.request->pose) : s.previous_placement;
  FkResult fk;
  ++g_tally.fk_checks;
  if (forward_kinematics(model, out.command, kind, guess, fk) != Status::Ok)
    return fail(c, out, "the pose of an emitted command cannot be solved");
  g_tally.worst_residual = std::max(g_tally.worst_residual, fk.residual);
  const double excess = limit_excess(model, fk.legs);
  g_tally.worst_excess = std::max(g_tally.worst_excess, excess);
  if (excess > kLimitTol) return fail(c, out, "emitted command outside a limit by " + std::to_string(excess));
  if (check_limits(model, fk.legs, report) != Status::Ok) {
    // Only a pose on the limit itself, within the FK solution's error.
    if (!(std::abs(report.value - report.bound) <= kLimitTol))
      return fail(c, out, "check_limits rejects an emitted command");
    ++g_tally.boundary_limit_reports;
  }
  s.previous_placement = fk.placement;
}

void check_answer(const Context& c, Session& s, const StreamOutput& out, Status returned) {
  const Model& model = *s.platform->model;
  const StreamSettings& set = s.settings;
  const Request& r = *c.request;
  if (returned != out.status) return fail(c, out, "returned status differs from out.status");
  if (out.input != s.state.inputs) return fail(c, out, "input number is not the count of inputs");

  // The reason: what motor_commands (or the line) says about the request.
  Status expected = Status::MalformedInput;
  Vector6d expected_command = Vector6d::Zero();
  LimitReport expected_limit;
  if (r.has_pose) expected = motor_commands(model, r.pose, set.strategy, expected_command, expected_limit);
  if (r.kind == Kind::BadLine) {
    if (out.status != Status::MalformedInput) return fail(c, out, "malformed line not rejected as malformed");
    if (out.parse.error != r.expected_error || out.parse.field != r.expected_field)
      return fail(c, out,
                  "malformed line: wrong error " + std::string(to_string(out.parse.error)) + " field " +
                      std::to_string(out.parse.field));
  }
  if (out.status == Status::MalformedInput) {
    if (r.has_pose) return fail(c, out, "a well-formed line rejected as malformed");
    if (out.parse.error == LineError::None || out.parse.field < -1 || out.parse.field > 6 || out.parse.column < 0 ||
        static_cast<std::size_t>(out.parse.column) > r.line.size() + 1)
      return fail(c, out, "malformed line without a valid place");
  } else if (!r.has_pose) {
    return fail(c, out, "an unreadable line was accepted");
  } else if (expected != Status::Ok && out.status != expected) {
    return fail(c, out, "rejected with another reason than motor_commands' " + std::string(to_string(expected)));
  } else if (expected == Status::Ok && out.status != Status::Ok && !(set.rate_limited() && out.rate_limited)) {
    return fail(c, out, "a valid pose rejected without a rate-limit check");
  }
  if (!r.pose.is_finite() && r.has_pose && out.status != Status::NonFiniteInput)
    return fail(c, out, "non-finite pose not rejected as such");
  // The platform-singularity limit concerns the whole platform: leg -1.
  const bool leg_ok =
      out.status == Status::PlatformSingularity ? out.limit.leg == -1 : out.limit.leg >= 0 && out.limit.leg < kLegs;
  if (is_limit(out.status) && !(leg_ok && std::isfinite(out.limit.value) && std::isfinite(out.limit.bound)))
    return fail(c, out, "limit rejection without a leg, value and bound");
  if (out.status != Status::Ok && expected != Status::Ok && r.has_pose && out.limit.leg != expected_limit.leg)
    return fail(c, out, "limit rejection names another leg than motor_commands");

  // What was done: a new command only for an accepted pose; after a rejection, the policy.
  const bool had_command = s.had_command;
  if ((out.status == Status::Ok) != (out.action == CommandAction::New))
    return fail(c, out, "a new command exactly when the input is accepted");
  if (out.status != Status::Ok && !out.rate_limited) {
    const CommandAction policy =
        set.on_reject == RejectPolicy::Skip || !had_command ? CommandAction::None : CommandAction::Held;
    if (out.action != policy) return fail(c, out, "rejection not answered as the policy says");
  }
  if (out.action != CommandAction::None && !had_command && out.action != CommandAction::New)
    return fail(c, out, "a held command before any command");
  if (out.action == CommandAction::New && !out.rate_limited && out.command != expected_command)
    return fail(c, out, "accepted pose: command differs from motor_commands");
  if (!set.rate_limited() && out.rate_limited) return fail(c, out, "rate limited without rate limits");

  // Answer line.
  std::array<char, kMaxOutputLength> buf{};
  const StreamFormat format = out.input % 2 ? StreamFormat::Csv : StreamFormat::Json;
  const std::size_t n = format_stream_output(out, format, buf);
  const std::string_view line(buf.data(), n);
  if (n == 0 || n >= kMaxOutputLength || line.back() != '\n' || line.find('\n') != n - 1)
    return fail(c, out, "answer line empty, too long or not one line");
  if (format == StreamFormat::Csv && std::count(line.begin(), line.end(), ',') != 12)
    return fail(c, out, "CSV answer line without 13 fields: " + std::string(line));
  if (format == StreamFormat::Json && (line.front() != '{' || line.substr(n - 2) != "}\n"))
    return fail(c, out, "JSON answer line is not one object: " + std::string(line));

  if (out.action == CommandAction::None) return;
  const std::uint64_t failures = g_tally.failures;
  check_command(c, s, out, out.action == CommandAction::New && !out.rate_limited);
  if (g_tally.failures != failures) return;

  // Rate limits between consecutive emitted commands. The commands are doubles of about 2 m:
  // their differences carry a rounding error of a few ulp, divided by the period for a rate.
  if (s.has_previous && set.rate_limited()) {
    const double h = set.period;
    const double ulp = 4.0 * std::numeric_limits<double>::epsilon() * out.command.cwiseAbs().maxCoeff();
    const Vector6d rate = (out.command - s.previous) / h;
    const bool failed_check_hold = out.action == CommandAction::Held && out.rate_limited && out.command == s.previous;
    for (int i = 0; i < kLegs; ++i) {
      if (std::abs(out.command[i] - s.previous[i]) > set.max_velocity * h * (1 + 1e-9) + ulp)
        return fail(c, out, "leg " + std::to_string(i) + ": speed above max_velocity");
      if (!failed_check_hold &&
          std::abs(rate[i] - s.previous_rate[i]) > set.max_acceleration * h * (1 + 1e-9) + 2 * ulp / h)
        return fail(c, out, "leg " + std::to_string(i) + ": acceleration above max_acceleration");
    }
    if (failed_check_hold) ++g_tally.holds_after_failed_check;
    s.previous_rate = rate;
  } else {
    s.previous_rate.setZero();
  }
  s.previous = out.command;
  s.has_previous = s.verified = true;
}

// ---------------------------------------------------------------------------------------------
// The run
// ---------------------------------------------------------------------------------------------

StreamSettings random_settings(std::mt19937_64& rng) {
  StreamSettings s;
  s.strategy = rng() % 2 ? Strategy::Compensated : Strategy::Conventional;
  s.on_reject = rng() % 2 ? RejectPolicy::Hold : RejectPolicy::Skip;
  s.period = log_uniform(rng, 1e-4, 1e-2);
  s.max_velocity = rng() % 2 ? kInf : log_uniform(rng, 0.01, 2.0);
  s.max_acceleration = rng() % 2 ? kInf : log_uniform(rng, 0.1, 100.0);
  if (s.rate_limited()) s.on_reject = RejectPolicy::Hold;  // skip is refused with limits (check_stream_settings)
  return s;
}

Request random_request(std::mt19937_64& rng, const Platform& p, Pose& walk) {
  const Model& model = *p.model;
  Request r;
  r.unit = rng() % 2 ? AngleUnit::Degrees : AngleUnit::Radians;
  const double u = uniform(rng, 0, 1);
  r.kind = u < 0.30   ? Kind::Walk
           : u < 0.42 ? Kind::Jump
           : u < 0.54 ? Kind::OutOfLimit
           : u < 0.64 ? Kind::NonFinite
           : u < 0.78 ? Kind::NearSingular
           : u < 0.88 ? Kind::GoodLine
           : u < 0.94 ? Kind::BadLine
                      : Kind::Garbage;
  if (r.kind == Kind::NearSingular && p.boundaries.empty()) r.kind = Kind::Walk;
  CommandReport report;
  switch (r.kind) {
    case Kind::Walk: {
      // A small step of a smooth motion; it goes on from where it is only while it stays valid.
      const double step = log_uniform(rng, 1e-6, 1e-2);
      r.pose = Pose::from_vector(walk.to_vector() + step * random_direction(rng));
      if (compute_commands(model, r.pose, report) == Status::Ok) walk = r.pose;
      break;
    }
    case Kind::Jump:
      r.pose = walk = random_valid_pose(model, rng, 0.3, deg2rad(20));
      break;
    case Kind::OutOfLimit:
      r.pose = random_pose(rng, 1.5, deg2rad(90));
      break;
    case Kind::NonFinite: {
      Vector6d q = random_valid_pose(model, rng, 0.3, deg2rad(20)).to_vector();
      static constexpr std::array<double, 3> kBad = {kNaN, kInf, -kInf};
      for (int n = 1 + static_cast<int>(rng() % 3); n > 0; --n) q[static_cast<int>(rng() % 6)] = kBad[rng() % 3];
      r.pose = Pose::from_vector(q);
      break;
    }
    case Kind::NearSingular: {
      const Boundary& b = p.boundaries[rng() % p.boundaries.size()];
      r.pose = rng() % 2 ? b.inside : b.outside;
      if (rng() % 2)
        r.pose = Pose::from_vector(r.pose.to_vector() + log_uniform(rng, 1e-15, 1e-9) * random_direction(rng));
      break;
    }
    case Kind::GoodLine: {
      const double v = uniform(rng, 0, 1);
      r.pose = v < 0.5 ? random_valid_pose(model, rng, 0.3, deg2rad(20)) : random_pose(rng, 1.0, deg2rad(60));
      r.line = good_line(rng, r.pose, r.unit);
      if (v > 0.9) {  // non-finite words
        static constexpr std::array<const char*, 4> kWords = {"nan", "inf", "-inf", "NaN"};
        r.line = std::string(kWords[rng() % 4]) + r.line.substr(r.line.find(','));
        Vector6d q = r.pose.to_vector();
        q[0] = kNaN;  // what matters: not finite
        r.pose = Pose::from_vector(q);
      }
      break;
    }
    case Kind::BadLine:
      r.has_pose = false;
      bad_line(rng, r);
      break;
    case Kind::Garbage: {
      r.line = garbage(rng);
      LineParse where;
      r.has_pose = parse_pose_line(r.line, r.unit, r.pose, where);  // the rare line that reads
      break;
    }
    case Kind::kCount:
      break;
  }
  return r;
}

int run(std::uint64_t count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::vector<Model> models;
  models.push_back(seed_model());
  for (int k = 0; k < 4; ++k) models.push_back(near_singular_platform(rng));
  std::vector<Platform> platforms;
  for (const Model& m : models)
    platforms.push_back({&m, &m == &models[0] ? std::vector<Boundary>{} : singularity_boundaries(m, rng, 48)});
  for (std::size_t k = 1; k < platforms.size(); ++k)
    if (platforms[k].boundaries.empty()) {
      std::fprintf(stderr, "FAIL: no singularity boundary found on random platform %zu\n", k);
      return 1;
    }

  const auto t0 = std::chrono::steady_clock::now();
  std::uint64_t index = 0;
  while (index < count) {
    Session s;
    s.platform = &platforms[rng() % 2 ? 0 : 1 + rng() % (platforms.size() - 1)];
    s.settings = random_settings(rng);
    const Model& model = *s.platform->model;
    if (!check_stream_settings(s.settings).empty()) {
      std::fprintf(stderr, "FAIL: random settings refused: %s\n",
                   std::string(check_stream_settings(s.settings)).c_str());
      return 1;
    }
    Pose walk;
    if (rng() % 5 != 0) {  // most streams start at home; the others wait for their first valid pose
      if (start_stream(model, s.settings, Pose{}, s.state) != Status::Ok) {
        std::fprintf(stderr, "FAIL: start_stream at home refused on %s\n", model.spec().name.c_str());
        return 1;
      }
      s.has_previous = true;
      LimitReport lim;
      (void)motor_commands(model, Pose{}, s.settings.strategy, s.previous, lim);
    }
    const std::uint64_t length = std::min<std::uint64_t>(count - index, 1 + rng() % 2000);
    for (std::uint64_t k = 0; k < length; ++k, ++index) {
      const Request r = random_request(rng, *s.platform, walk);
      const bool line_kind = r.kind == Kind::GoodLine || r.kind == Kind::BadLine || r.kind == Kind::Garbage;
      StreamOutput out;
      s.had_command = s.state.has_command;
      const Status st = line_kind ? stream_line(model, s.settings, r.line, r.unit, s.state, out)
                                  : stream_pose(model, s.settings, r.pose, s.state, out);
      ++g_tally.requests;
      ++g_tally.kinds[kKindNames[static_cast<int>(r.kind)]];
      ++g_tally.statuses[std::string(to_string(out.status))];
      ++g_tally.actions[std::string(to_string(out.action)) + (out.rate_limited ? " (rate limited)" : "")];
      check_answer({seed, index, s.platform, &s.settings, &r}, s, out, st);
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  std::printf("stress_stream: %" PRIu64 " requests, seed %" PRIu64 ", %.1f s (%.2f us per request)\n", g_tally.requests,
              seed, seconds, 1e6 * seconds / static_cast<double>(std::max<std::uint64_t>(1, g_tally.requests)));
  const auto print = [](const char* title, const std::map<std::string, std::uint64_t>& m) {
    std::printf("%s\n", title);
    for (const auto& [name, n] : m) std::printf("  %-28s %10" PRIu64 "\n", name.c_str(), n);
  };
  print("requests by kind:", g_tally.kinds);
  print("answers by status:", g_tally.statuses);
  print("answers by command:", g_tally.actions);
  std::printf("emitted commands solved by FK and checked: %" PRIu64 "; largest FK residual %.3g m\n", g_tally.fk_checks,
              g_tally.worst_residual);
  std::printf("closest approach to a limit: %.3g m or rad beyond it (tolerance %.0e)\n", g_tally.worst_excess,
              kLimitTol);
  std::printf("limit reports on the limit itself (within tolerance): %" PRIu64 "; holds after a failed check: %" PRIu64
              "\n",
              g_tally.boundary_limit_reports, g_tally.holds_after_failed_check);
  std::printf("%s: %" PRIu64 " failed checks\n", g_tally.failures ? "FAILED" : "passed", g_tally.failures);
  return g_tally.failures ? 1 : 0;
}

}  // namespace
}  // namespace hexatwist::test

int main(int argc, char** argv) {
  std::uint64_t count = 500000, seed = hexatwist::test::kSeed;
  for (int i = 1; i < argc; ++i) {
    // --count N, --count=N, --seed S, --seed=S
    std::string_view name = argv[i], value;
    if (const std::size_t eq = name.find('='); eq != std::string_view::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    } else if (i + 1 < argc) {
      value = argv[++i];
    }
    if (name != "--count" && name != "--seed") {
      std::fprintf(stderr, "usage: stress_stream [--count N] [--seed S]\n");
      return 2;
    }
    const std::string text(value);
    char* end = nullptr;
    const unsigned long long v = std::strtoull(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0' || text[0] == '-' || text[0] == '+') {
      std::fprintf(stderr, "stress_stream: %s needs a non-negative integer, got '%s'\n", std::string(name).c_str(),
                   text.c_str());
      return 2;
    }
    (name == "--count" ? count : seed) = v;
  }
  return hexatwist::test::run(count, seed);
}
