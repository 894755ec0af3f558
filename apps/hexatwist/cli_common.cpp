// SPDX-License-Identifier: BSD-3-Clause
#include "cli_common.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "json.hpp"

namespace hexatwist::cli {

// Text typed by the user as it may appear inside a one-line message: control characters escaped.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f)
      out += fmt::format("\\x{:02x}", u);
    else
      out += c;
  }
  return out;
}

void add_model_options(CLI::App& app, ModelOptions& opts) {
  app.add_option("--config", opts.config,
                 "Platform YAML file (see configs/); default: the embedded seed platform, lead 10 mm");
}

std::string model_source(const ModelOptions& opts) {
  return opts.config.empty() ? std::string("embedded seed platform") : opts.config;
}

std::string read_text_file(const std::string& path, const std::string& option, const std::string& what,
                           std::size_t max_bytes) {
  try {
    return hexatwist::read_text_file(path, what, max_bytes);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, fmt::format("{}: {}", option, e.what()));
  }
}

void write_stdout(std::string_view text) {
  errno = 0;
  const bool written = std::fwrite(text.data(), 1, text.size(), stdout) == text.size();
  if (std::fflush(stdout) != 0 || !written || std::ferror(stdout))
    throw ExitError(kExitOutputFailed, fmt::format("cannot write to standard output: {}",
                                                   errno != 0 ? std::strerror(errno) : "write error"));
}

std::string defaults_note(const Config& config) {
  if (config.defaulted.empty()) return {};
  std::string names;
  for (std::size_t k = 0; k < config.defaulted.size(); ++k)
    names += (k == 0 ? "" : k + 1 == config.defaulted.size() ? " and " : ", ") + config.defaulted[k];
  return fmt::format(" ({}: the seed's defaults, not in the file)", names);
}

std::vector<Vector3d> targets_option(const std::string& text, const char* option) {
  std::vector<Vector3d> out;
  if (text.empty()) return out;
  for (std::size_t begin = 0;;) {
    const std::size_t semi = text.find(';', begin);
    const std::vector<double> t =
        parse_numbers(text.substr(begin, semi == std::string::npos ? std::string::npos : semi - begin), 3, option,
                      "x,y,z [mm, platform] of each target, ';' between targets");
    for (const double v : t) check_option(std::abs(v) < 1e4, option, v, "coordinates below 10 m in magnitude [mm]");
    out.emplace_back(t[0] / 1e3, t[1] / 1e3, t[2] / 1e3);
    if (semi == std::string::npos) break;
    begin = semi + 1;
  }
  if (out.size() + 1 > kMaxTargets)
    throw ExitError(kExitBadInput, fmt::format("{}: {} targets with the observation point, at most {}", option,
                                               out.size() + 1, kMaxTargets));
  return out;
}

std::string counted(std::size_t n, std::string_view noun) { return fmt::format("{} {}{}", n, noun, n == 1 ? "" : "s"); }

Strategy strategy_option(const std::string& text, const char* option) {
  if (Strategy s; parse_strategy(text, s)) return s;
  throw ExitError(kExitBadInput,
                  fmt::format("{}: expected {} or {}, got '{}'", option, to_string(Strategy::Conventional),
                              to_string(Strategy::Compensated), printable(text)));
}

Model load_model_from(const ModelOptions& opts) {
  try {
    if (opts.config.empty()) return default_model();
    return load_model(read_text_file(opts.config, opts.option, "config file", kMaxConfigBytes), opts.config);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
}

Config load_config_from(const ModelOptions& opts) {
  try {
    if (opts.config.empty()) return default_config();
    return load_config(read_text_file(opts.config, opts.option, "config file", kMaxConfigBytes), opts.config);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
}

Vector6d per_leg_option(const std::string& text, const char* option, const std::string& what, double lo, double hi,
                        double scale) {
  const bool six = text.find(',') != std::string::npos;
  const std::vector<double> v = parse_numbers(text, six ? 6 : 1, option, what);
  Vector6d out;
  for (int i = 0; i < kLegs; ++i) {
    const double x = v[six ? static_cast<std::size_t>(i) : 0];
    check_option(x >= lo && x <= hi, option, x, what);
    out[i] = x * scale;
  }
  return out;
}

namespace {

// ExitError(2) for a temperature option `option` given on a model whose legs do not expand.
void require_expansion(const Model& model, const char* option, const std::string& text, const char* what) {
  if (model.has_thermal()) return;
  throw ExitError(kExitBadInput, fmt::format("{} {}: the configuration's legs do not expand (leg_effects: "
                                             "length_expansion, lead_expansion), so {} changes nothing",
                                             option, printable(text), what));
}

}  // namespace

Vector6d temperature_option(const std::string& text, const Model& model) {
  if (text.empty()) return Vector6d::Constant(std::numeric_limits<double>::quiet_NaN());
  require_expansion(model, "--temperature-c", text, "a temperature");
  return per_leg_option(text, "--temperature-c",
                        fmt::format("a temperature from {:g} to {:g} degC, or six", kMinTemperature, kMaxTemperature),
                        kMinTemperature, kMaxTemperature, 1.0);
}

void range_option(const std::string& text, StationsSpec& run) {
  constexpr const char* kRangeWhat =
      "X_M,ROT_DEG: the stations within ±X_M [m] of home in x, y, z and ±ROT_DEG [deg] in roll, pitch, yaw";
  const std::vector<double> range = parse_numbers(text, 2, "--range", kRangeWhat);
  run.translation = range[0];
  run.rotation = deg2rad(range[1]);
  // The library's ranges (check_stations_spec: the count is the caller's), worded for this option.
  StationsSpec ranges = run;
  ranges.count = 1;
  try {
    check_stations_spec(ranges);
  } catch (const ParameterError& e) {
    throw ExitError(kExitBadInput, fmt::format("--range {}: {}", printable(text), e.what()));
  }
}

Vector6d temperature_rise_option(const std::string& text, const Model* model) {
  if (text.empty()) return Vector6d::Zero();
  const Vector6d rise = per_leg_option(text, "--temperature-rise-k",
                                       fmt::format("a temperature rise from {:g} to {:g} K over the run, or six",
                                                   -kMaxTemperatureRise, kMaxTemperatureRise),
                                       -kMaxTemperatureRise, kMaxTemperatureRise, 1.0);
  if (model != nullptr)
    if (const std::string_view why = check_temperature_rise(*model, rise); !why.empty())
      throw ExitError(kExitBadInput, fmt::format("--temperature-rise-k {}: {}", printable(text), why));
  return rise;
}

std::vector<double> parse_numbers(const std::string& text, std::size_t count, const std::string& option,
                                  const std::string& what) {
  std::vector<double> values;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = text.find(',', start);
    std::string item = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    // Allow spaces around numbers ("0.1, 0, 0").
    const auto first = item.find_first_not_of(" \t");
    const auto last = item.find_last_not_of(" \t");
    item = first == std::string::npos ? std::string() : item.substr(first, last - first + 1);
    double v = 0.0;
    const char* b = item.data();
    const char* e = item.data() + item.size();
    if (item.size() > 1 && *b == '+' && b[1] != '-' && b[1] != '+') ++b;  // from_chars takes no '+'
    const auto [ptr, ec] = std::from_chars(b, e, v);
    if (ec == std::errc::result_out_of_range && ptr == e)
      throw ExitError(kExitBadInput, fmt::format("{}: value {} ('{}') is out of range; expected {}", option,
                                                 values.size() + 1, printable(item), what));
    if (item.empty() || ec != std::errc() || ptr != e)
      throw ExitError(kExitBadInput, fmt::format("{}: value {} ('{}') is not a number; expected {}", option,
                                                 values.size() + 1, printable(item), what));
    if (!std::isfinite(v))
      throw ExitError(kExitBadInput, fmt::format("{}: value {} ('{}') is not finite; expected {}", option,
                                                 values.size() + 1, printable(item), what));
    values.push_back(v);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (values.size() != count)
    throw ExitError(kExitBadInput, fmt::format("{}: expected {} comma-separated numbers ({}), got {}", option, count,
                                               what, values.size()));
  return values;
}

void check_option(bool ok, std::string_view option, double value, std::string_view expected) {
  if (ok && std::isfinite(value)) return;
  throw ExitError(kExitBadInput, fmt::format("{} {}: expected {}", option, value, expected));
}

Pose parse_pose_m_deg(const std::string& text, const std::string& option) {
  const auto v = parse_numbers(text, 6, option, "x,y,z [m], roll,pitch,yaw [deg]");
  Pose p;
  p.position = Vector3d(v[0], v[1], v[2]);
  p.rpy = Vector3d(deg2rad(v[3]), deg2rad(v[4]), deg2rad(v[5]));
  return p;
}

void write_limit_json(JsonWriter& json, const LimitReport& r) {
  if (r.status == Status::Ok) {
    json.null();
    return;
  }
  json.begin_object().field("status", to_string(r.status));
  if (r.leg >= 0) json.field("leg", r.leg + 1);
  if (r.leg >= 0 || r.status == Status::PlatformSingularity) json.field("value", r.value).field("bound", r.bound);
  json.field("message", describe(r)).end_object();
}

}  // namespace hexatwist::cli
