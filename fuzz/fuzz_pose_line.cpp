// SPDX-License-Identifier: BSD-3-Clause
// Fuzz target: pose lines through the real-time stream on the seed platform
// (hexatwist::parse_pose_line, stream_line, format_stream_output). The first byte chooses the
// stream settings (strategy, reject policy, angle unit, rate limits, start at home, output
// format); the rest is cut into lines at '\n', each one input of the same stream. Nothing may
// throw (the functions are noexcept), crash or trip a sanitizer, and every answer must keep the
// stream's promises: a malformed line is rejected as MalformedInput where the parser says, an
// emitted command is finite and inside the stroke, a limit names its leg, and the answer is one
// line shorter than kMaxOutputLength whose numbers read back exactly.
#include <array>
#include <cmath>
#include <cstdlib>

#include "fuzz_support.hpp"
#include "hexatwist/hexatwist.hpp"

namespace {

using namespace hexatwist;

StreamSettings settings_from(std::uint8_t flags) {
  StreamSettings s;
  s.strategy = flags & 1 ? Strategy::Conventional : Strategy::Compensated;
  s.on_reject = flags & 2 ? RejectPolicy::Skip : RejectPolicy::Hold;
  if (flags & 8) {
    s.max_velocity = 0.2;      // [m/s]
    s.max_acceleration = 2.0;  // [m/s^2]
  }
  return s;
}

// The six commands of a CSV answer read back to the numbers sent (shortest round-trip form).
void check_csv_numbers(std::string_view line, const StreamOutput& out) {
  std::size_t at = 0;
  for (int field = 0; field < 3; ++field) at = line.find(',', at) + 1;  // input, status, command
  for (int i = 0; i < kLegs; ++i) {
    const std::size_t end = line.find(',', at);
    const std::string cell(line.substr(at, end - at));
    if (out.action == CommandAction::None) {
      fuzz::require(cell.empty(), "a number where no command was emitted");
    } else {
      char* stop = nullptr;
      const double v = std::strtod(cell.c_str(), &stop);
      fuzz::require(!cell.empty() && *stop == '\0' && v == out.command[i], "a command that does not read back");
    }
    at = end + 1;
  }
}

void check_answer(const Model& model, std::string_view input, AngleUnit unit, const StreamOutput& out, Status st,
                  StreamFormat format) {
  Pose pose;
  LineParse where;
  const bool parsed = parse_pose_line(input, unit, pose, where);
  fuzz::require(parsed == (where.error == LineError::None), "parse result and error disagree");
  fuzz::require(st == out.status, "returned status differs from out.status");
  if (!parsed) {
    fuzz::require(st == Status::MalformedInput, "an unreadable line was not rejected as malformed");
    fuzz::require(out.parse.error == where.error && out.parse.field == where.field && out.parse.column == where.column,
                  "stream_line and parse_pose_line disagree on a malformed line");
    fuzz::require(where.field >= -1 && where.field <= kLegs && where.column >= 0 &&
                      static_cast<std::size_t>(where.column) <= input.size() + 1,
                  "malformed line: field or column out of range");
  } else {
    fuzz::require(st != Status::MalformedInput, "a readable line rejected as malformed");
    if (!pose.is_finite()) fuzz::require(st == Status::NonFiniteInput, "a non-finite pose not rejected as such");
  }
  fuzz::require((st == Status::Ok) == (out.action == CommandAction::New), "a new command exactly for an accepted pose");
  if (is_limit(st))
    fuzz::require(
        out.limit.leg >= 0 && out.limit.leg < kLegs && std::isfinite(out.limit.value) && std::isfinite(out.limit.bound),
        "a limit without its leg, value and bound");
  if (out.action != CommandAction::None) {
    LimitReport report;
    fuzz::require(out.command.allFinite(), "a non-finite command emitted");
    fuzz::require(check_stroke(model, out.command, report) == Status::Ok, "a command outside the stroke emitted");
  }

  std::array<char, kMaxOutputLength> buffer{};
  const std::size_t n = format_stream_output(out, format, buffer);
  const std::string_view line(buffer.data(), n);
  fuzz::require(n > 0 && n < kMaxOutputLength, "answer line empty or too long");
  fuzz::require(line.back() == '\n' && line.find('\n') == n - 1, "answer is not one line");
  fuzz::require(format_stream_output(out, format, std::span<char>(buffer.data(), kMaxOutputLength - 1)) == 0,
                "an answer written into a buffer shorter than kMaxOutputLength");
  if (format == StreamFormat::Csv) check_csv_numbers(line, out);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Model model = default_model();
  if (size == 0) return 0;
  const std::uint8_t flags = data[0];
  const StreamSettings settings = settings_from(flags);
  const AngleUnit unit = flags & 4 ? AngleUnit::Radians : AngleUnit::Degrees;
  const StreamFormat format = flags & 16 ? StreamFormat::Json : StreamFormat::Csv;
  StreamState state;
  if (flags & 32) fuzz::require(start_stream(model, settings, Pose{}, state) == Status::Ok, "cannot start at home");

  std::string_view text = fuzz::as_text(data + 1, size - 1);
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    const std::string_view line = text.substr(0, nl == std::string_view::npos ? text.size() : nl + 1);
    text.remove_prefix(line.size());
    StreamOutput out;
    const Status st = stream_line(model, settings, line, unit, state, out);
    check_answer(model, line, unit, out, st, format);
  }
  return 0;
}
