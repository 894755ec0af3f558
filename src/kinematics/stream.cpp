// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/kinematics/stream.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace hexatwist {

// ---------------------------------------------------------------------------------------------
// Pose lines
// ---------------------------------------------------------------------------------------------

std::string_view to_string(LineError e) noexcept {
  switch (e) {
    case LineError::None:
      return "none";
    case LineError::Empty:
      return "empty";
    case LineError::TooLong:
      return "too_long";
    case LineError::MissingFields:
      return "missing_fields";
    case LineError::ExtraFields:
      return "extra_fields";
    case LineError::EmptyField:
      return "empty_field";
    case LineError::NotANumber:
      return "not_a_number";
    case LineError::OutOfRange:
      return "out_of_range";
  }
  return "unknown";
}

namespace {

bool is_blank(char c) noexcept { return c == ' ' || c == '\t'; }

bool line_error(LineParse& where, LineError error, int field, std::size_t column) noexcept {
  where.error = error;
  where.field = field;
  where.column = static_cast<int>(column);
  return false;
}

}  // namespace

bool parse_pose_line(std::string_view line, AngleUnit unit, Pose& pose, LineParse& where) noexcept {
  where = LineParse{};
  while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
  if (line.size() > kMaxLineLength) return line_error(where, LineError::TooLong, -1, 0);
  if (std::all_of(line.begin(), line.end(), is_blank)) return line_error(where, LineError::Empty, -1, 0);

  double v[kLegs];
  std::size_t start = 0;
  for (int field = 0;; ++field) {
    const std::size_t comma = line.find(',', start);
    const std::size_t stop = comma == std::string_view::npos ? line.size() : comma;
    if (field == kLegs) return line_error(where, LineError::ExtraFields, field, start + 1);
    std::size_t b = start, e = stop;
    while (b < e && is_blank(line[b])) ++b;
    while (e > b && is_blank(line[e - 1])) --e;
    if (b == e) return line_error(where, LineError::EmptyField, field, start + 1);
    // from_chars takes no leading '+'; a person (or another program) may write one.
    std::size_t first = b;
    if (e - b > 1 && line[b] == '+' && line[b + 1] != '+' && line[b + 1] != '-') ++first;
    const auto [ptr, ec] = std::from_chars(line.data() + first, line.data() + e, v[field]);
    if (ec == std::errc::result_out_of_range && ptr == line.data() + e)
      return line_error(where, LineError::OutOfRange, field, b + 1);
    if (ec != std::errc() || ptr != line.data() + e) return line_error(where, LineError::NotANumber, field, b + 1);
    if (comma == std::string_view::npos) {
      if (field + 1 < kLegs) return line_error(where, LineError::MissingFields, field + 1, line.size() + 1);
      break;
    }
    start = comma + 1;
  }
  const double angle = unit == AngleUnit::Degrees ? kPi / 180.0 : 1.0;
  pose.position = Vector3d(v[0], v[1], v[2]);
  pose.rpy = Vector3d(v[3] * angle, v[4] * angle, v[5] * angle);
  return true;
}

// ---------------------------------------------------------------------------------------------
// The stream
// ---------------------------------------------------------------------------------------------

bool StreamSettings::rate_limited() const noexcept {
  return std::isfinite(max_velocity) || std::isfinite(max_acceleration);
}

std::string_view check_stream_settings(const StreamSettings& s) noexcept {
  if (!(std::isfinite(s.period) && s.period > 0.0)) return "period must be a positive, finite time [s]";
  if (!(s.max_velocity > 0.0)) return "max_velocity must be positive [m/s] (infinite for no limit)";
  if (!(s.max_acceleration > 0.0)) return "max_acceleration must be positive [m/s^2] (infinite for no limit)";
  // A skipped input leaves the drive holding the last command: it would stop within one period,
  // whatever the limits say, and jump back to speed after. Hold keeps the limits through rejections.
  if (s.on_reject == RejectPolicy::Skip && s.rate_limited())
    return "on_reject: skip leaves the drive without a command for each rejected input, so it stops within one "
           "period, outside the rate limits; use hold, which keeps moving within the limits";
  if (const std::string_view why = check_leg_inputs(s.inputs); !why.empty()) return why;
  return check_fk_options(s.fk);
}

std::string_view check_stream_settings(const Model& model, const StreamSettings& s) noexcept {
  if (const std::string_view why = check_stream_settings(s); !why.empty()) return why;
  // A limit that lets one input's step cross the whole stroke can never bind: a rate so slow (or a
  // limit so large) says something else than the user meant.
  const double stroke = model.spec().limits.length_max - model.spec().limits.length_min;
  if (std::isfinite(s.max_velocity) && !(s.max_velocity * s.period < stroke))
    return "max_velocity: one input period at this speed is longer than the whole stroke, so the limit would never "
           "apply; give a faster input rate or a smaller limit";
  if (std::isfinite(s.max_acceleration) && !(s.max_acceleration * s.period * s.period < stroke))
    return "max_acceleration: one input period at this acceleration covers more than the whole stroke, so the limit "
           "would never apply; give a faster input rate or a smaller limit";
  return {};
}

std::string_view to_string(CommandAction a) noexcept {
  switch (a) {
    case CommandAction::New:
      return "new";
    case CommandAction::Held:
      return "held";
    case CommandAction::None:
      return "none";
  }
  return "unknown";
}

namespace {

// The lengths a command of `strategy` means: motor-side lengths of the twist-aware model when
// compensating, geometric leg lengths (once the legs' zero errors are added back) when the twist
// is ignored. A command is inside the limits when the pose it means is.
LengthKind command_kind(const Model& model, Strategy strategy) noexcept {
  return strategy == Strategy::Compensated && model.has_twist() ? LengthKind::Motor : LengthKind::Geometric;
}

// One step of a per-leg second-order rate limiter towards `target`: the speed is the largest that
// can still stop at the target with the acceleration limit (discrete braking distance
// v^2/2a + v h/2), at most max_velocity, and changes by at most max_acceleration * period.
// Returns true if the step reaches the target on every leg (then next == target exactly).
bool limit_rate(const StreamSettings& s, const Vector6d& command, const Vector6d& target, Vector6d& velocity,
                Vector6d& next) noexcept {
  const double h = s.period, a = s.max_acceleration, vmax = s.max_velocity;
  const double dv = a * h;  // inf without an acceleration limit
  bool reached = true;
  for (int i = 0; i < kLegs; ++i) {
    const double e = target[i] - command[i];
    double speed = std::abs(e) / h;
    if (std::isfinite(a)) speed = std::min(speed, std::sqrt(0.25 * dv * dv + 2.0 * a * std::abs(e)) - 0.5 * dv);
    speed = std::min(speed, vmax);
    double v = std::copysign(speed, e);
    if (std::isfinite(a)) v = std::clamp(v, velocity[i] - dv, velocity[i] + dv);
    v = std::clamp(v, -vmax, vmax);
    if (v == e / h) {
      next[i] = target[i];
    } else {
      next[i] = command[i] + v * h;
      reached = false;
    }
    velocity[i] = (next[i] - command[i]) / h;
  }
  return reached;
}

void emit(StreamState& state, StreamOutput& out, CommandAction action, const Vector6d& command,
          const Placement& placement) noexcept {
  state.command = command;
  state.placement = placement;
  state.has_command = true;
  out.action = action;
  out.command = command;
}

// Moves the emitted command towards state.target under the rate limits and checks a step that
// stops short of it through forward kinematics. On a failed check the last command is held (the
// velocity drops to zero) and the failure is returned.
Status advance(const Model& model, const StreamSettings& s, StreamState& state, StreamOutput& out,
               CommandAction action) noexcept {
  if (!s.rate_limited() || !state.has_command) {
    state.velocity.setZero();
    emit(state, out, action, state.target, state.target_placement);
    return Status::Ok;
  }
  Vector6d velocity = state.velocity, next;
  if (limit_rate(s, state.command, state.target, velocity, next)) {
    state.velocity = velocity;
    emit(state, out, action, next, state.target_placement);
    return Status::Ok;
  }
  out.rate_limited = true;
  LimitReport report;
  const LengthKind kind = command_kind(model, s.strategy);
  const Vector6d lengths = kind == LengthKind::Geometric ? Vector6d(next + model.geometry().length_offset) : next;
  Status st = kind == LengthKind::Motor && model.has_leg_effects()
                  ? forward_kinematics(model, lengths, s.inputs, &state.play.direction, state.placement, state.fk, s.fk)
                  : forward_kinematics(model, lengths, kind, state.placement, state.fk, s.fk);
  if (st == Status::Ok) st = check_limits(model, state.fk.legs, report);
  if (st == Status::Ok) st = check_stroke(model, next, report);
  if (st != Status::Ok) {
    state.velocity.setZero();
    out.action = CommandAction::Held;
    out.command = state.command;
    if (out.status == Status::Ok) out.limit = report;
    return st;
  }
  state.velocity = velocity;
  emit(state, out, action, next, state.fk.placement);
  return Status::Ok;
}

Status reject(const Model& model, const StreamSettings& s, StreamState& state, StreamOutput& out) noexcept {
  if (s.on_reject == RejectPolicy::Skip || !state.has_command) {
    out.action = CommandAction::None;
    return out.status;
  }
  // Hold: towards the last valid target; the rejection stays the status whatever the step does.
  (void)advance(model, s, state, out, CommandAction::Held);
  return out.status;
}

}  // namespace

Status start_stream(const Model& model, const StreamSettings& settings, const Pose& pose, StreamState& state) noexcept {
  state.has_command = false;
  state.velocity.setZero();
  LimitReport report;
  Vector6d command;
  start_play(model, model.home_command(), state.play);
  const Status st = motor_commands(model, pose, settings.strategy, settings.inputs, &state.play, command, report);
  if (st != Status::Ok) return st;
  state.command = state.target = command;
  state.placement = state.target_placement = placement_from_pose(pose);
  state.has_command = true;
  return Status::Ok;
}

Status stream_pose(const Model& model, const StreamSettings& settings, const Pose& pose, StreamState& state,
                   StreamOutput& out) noexcept {
  out = StreamOutput{};
  out.input = ++state.inputs;
  Vector6d command;
  out.status = motor_commands(model, pose, settings.strategy, settings.inputs, &state.play, command, out.limit);
  if (out.status != Status::Ok) return reject(model, settings, state, out);
  state.target = command;
  state.target_placement = placement_from_pose(pose);
  out.status = advance(model, settings, state, out, CommandAction::New);
  return out.status;
}

Status stream_line(const Model& model, const StreamSettings& settings, std::string_view line, AngleUnit unit,
                   StreamState& state, StreamOutput& out) noexcept {
  Pose pose;
  LineParse where;
  if (parse_pose_line(line, unit, pose, where)) return stream_pose(model, settings, pose, state, out);
  out = StreamOutput{};
  out.input = ++state.inputs;
  out.status = Status::MalformedInput;
  out.parse = where;
  return reject(model, settings, state, out);
}

// ---------------------------------------------------------------------------------------------
// Answer lines
// ---------------------------------------------------------------------------------------------

namespace {

// Appends to a fixed buffer; remembers an overflow instead of writing past the end.
class LineWriter {
 public:
  explicit LineWriter(std::span<char> buffer) noexcept : buf_(buffer) {}

  void text(std::string_view s) noexcept {
    if (s.size() > buf_.size() - n_) {
      overflow_ = true;
      return;
    }
    std::copy(s.begin(), s.end(), buf_.data() + n_);
    n_ += s.size();
  }
  template <class T>
  void number(T v) noexcept {
    const auto [ptr, ec] = std::to_chars(buf_.data() + n_, buf_.data() + buf_.size(), v);
    if (ec != std::errc()) {
      overflow_ = true;
      return;
    }
    n_ = static_cast<std::size_t>(ptr - buf_.data());
  }
  std::size_t size() const noexcept { return overflow_ ? 0 : n_; }

 private:
  std::span<char> buf_;
  std::size_t n_ = 0;
  bool overflow_ = false;
};

constexpr std::string_view kFieldNames[kLegs] = {"x", "y", "z", "roll", "pitch", "yaw"};

std::string_view line_error_words(LineError e) noexcept {
  switch (e) {
    case LineError::None:
      return "";
    case LineError::Empty:
      return "empty line";
    case LineError::TooLong:
      return "line longer than 1024 characters";
    case LineError::MissingFields:
      return "missing (a pose has six fields: x y z roll pitch yaw)";
    case LineError::ExtraFields:
      return "extra field (more than six)";
    case LineError::EmptyField:
      return "empty field";
    case LineError::NotANumber:
      return "not a number";
    case LineError::OutOfRange:
      return "number out of range";
  }
  return "";
}

// Short comma- and quote-free text for people: where a line is malformed, or what the status means.
void write_detail(LineWriter& w, const StreamOutput& out) noexcept {
  if (out.status == Status::MalformedInput) {
    const LineParse& p = out.parse;
    if (p.field >= 0 && p.field < kLegs) {
      w.text("field ");
      w.number(p.field + 1);
      w.text(" (");
      w.text(kFieldNames[p.field]);
      w.text(") ");
    } else if (p.field == kLegs) {
      w.text("field 7 ");
    }
    if (p.column > 0) {
      w.text("at column ");
      w.number(p.column);
      w.text(": ");
    }
    w.text(line_error_words(p.error));
  } else if (out.status != Status::Ok) {
    w.text(describe(out.status));
  }
  if (out.rate_limited) w.text(out.status == Status::Ok ? "rate limited" : "; rate-limited step");
}

bool has_limit(const StreamOutput& out) noexcept {
  return out.limit.leg >= 0 && std::isfinite(out.limit.value) && std::isfinite(out.limit.bound);
}

void write_csv(LineWriter& w, const StreamOutput& out) noexcept {
  w.number(out.input);
  w.text(",");
  w.text(to_string(out.status));
  w.text(",");
  w.text(to_string(out.action));
  for (int i = 0; i < kLegs; ++i) {
    w.text(",");
    if (out.action != CommandAction::None) w.number(out.command[i]);
  }
  w.text(",");
  if (has_limit(out)) {
    w.number(out.limit.leg + 1);
    w.text(",");
    w.number(out.limit.value);
    w.text(",");
    w.number(out.limit.bound);
  } else {
    w.text(",,");
  }
  w.text(",");
  write_detail(w, out);
  w.text("\n");
}

void write_json(LineWriter& w, const StreamOutput& out) noexcept {
  w.text("{\"input\":");
  w.number(out.input);
  w.text(",\"status\":\"");
  w.text(to_string(out.status));
  w.text("\",\"command\":\"");
  w.text(to_string(out.action));
  w.text("\",\"m\":");
  if (out.action == CommandAction::None) {
    w.text("null");
  } else {
    for (int i = 0; i < kLegs; ++i) {
      w.text(i == 0 ? "[" : ",");
      w.number(out.command[i]);
    }
    w.text("]");
  }
  w.text(",\"rate_limited\":");
  w.text(out.rate_limited ? "true" : "false");
  if (has_limit(out)) {
    w.text(",\"leg\":");
    w.number(out.limit.leg + 1);
    w.text(",\"value\":");
    w.number(out.limit.value);
    w.text(",\"bound\":");
    w.number(out.limit.bound);
  } else {
    w.text(",\"leg\":null,\"value\":null,\"bound\":null");
  }
  w.text(",\"detail\":\"");
  write_detail(w, out);
  w.text("\"}\n");
}

}  // namespace

std::size_t format_stream_output(const StreamOutput& out, StreamFormat format, std::span<char> buffer) noexcept {
  if (buffer.size() < kMaxOutputLength) return 0;
  LineWriter w(buffer.first(kMaxOutputLength));
  if (format == StreamFormat::Csv)
    write_csv(w, out);
  else
    write_json(w, out);
  return w.size();
}

}  // namespace hexatwist
