#include "cli_common.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
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

std::string read_text_file(const std::string& path, const std::string& option, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw ExitError(kExitBadInput, fmt::format("{}: '{}' is a directory, expected {}", option, printable(path), what));
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw ExitError(kExitBadInput, fmt::format("{}: cannot read {} '{}': {}", option, what, printable(path),
                                               errno != 0 ? std::strerror(errno) : "cannot open"));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_file_or_stdout(const std::string& path, std::string_view content) {
  if (path.empty())
    write_stdout(content);
  else
    write_output_file(path, content);
}

void write_output_file(const std::string& file, std::string_view content) {
  OutputSet set;
  set.add(file, std::string(content));
  set.commit();
}

void check_distinct_outputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  namespace fs = std::filesystem;
  for (std::size_t a = 0; a < outputs.size(); ++a)
    for (std::size_t b = a + 1; b < outputs.size(); ++b) {
      if (outputs[a].second.empty() || outputs[b].second.empty()) continue;
      std::error_code ea, eb;
      const fs::path pa = fs::weakly_canonical(outputs[a].second, ea);
      const fs::path pb = fs::weakly_canonical(outputs[b].second, eb);
      if ((!ea && !eb) ? pa == pb : outputs[a].second == outputs[b].second)
        throw ExitError(kExitBadInput, fmt::format("{} and {} both name '{}': one run's outputs never overwrite each "
                                                   "other; nothing was written",
                                                   outputs[a].first, outputs[b].first, printable(outputs[b].second)));
    }
}

OutputSet::~OutputSet() {
  if (!committed_) roll_back();
}

void OutputSet::add(const std::string& path, std::string content) {
  pending_.push_back({path, path + ".tmp", std::move(content)});
  paths_.push_back(path);
}

void OutputSet::adopt(const std::string& path) {
  adopted_.push_back(path);
  paths_.push_back(path);
}

void OutputSet::roll_back() noexcept {
  std::error_code ec;
  for (const Pending& p : pending_)
    if (p.staged) std::filesystem::remove(p.tmp, ec);
  for (const std::string& a : adopted_) std::filesystem::remove(a, ec);
}

void OutputSet::stage() {
  namespace fs = std::filesystem;
  for (Pending& p : pending_) {
    if (p.staged) continue;
    std::error_code ec;
    if (fs::is_directory(p.path, ec)) {
      roll_back();
      throw ExitError(kExitOutputFailed,
                      fmt::format("cannot write '{}': it is a directory; nothing was written", printable(p.path)));
    }
    errno = 0;
    std::ofstream out(p.tmp, std::ios::binary | std::ios::trunc);
    p.staged = static_cast<bool>(out);  // from here on, the temporary is ours to remove
    out.write(p.content.data(), static_cast<std::streamsize>(p.content.size()));
    out.close();
    if (!out) {
      const int err = errno;
      roll_back();
      throw ExitError(kExitOutputFailed, fmt::format("cannot write '{}': {}; nothing was written", printable(p.path),
                                                     err != 0 ? std::strerror(err) : "write error"));
    }
    p.content.clear();
    p.content.shrink_to_fit();
  }
}

void OutputSet::commit() {
  namespace fs = std::filesystem;
  stage();
  for (std::size_t k = 0; k < pending_.size(); ++k) {
    std::error_code ec;
    fs::rename(pending_[k].tmp, pending_[k].path, ec);
    if (ec) {
      // The files already renamed are this run's: remove them with the rest, so no partial set is left.
      std::error_code ignore;
      for (std::size_t r = 0; r < k; ++r) fs::remove(pending_[r].path, ignore);
      roll_back();
      committed_ = true;
      throw ExitError(kExitOutputFailed, fmt::format("cannot write '{}': {}; nothing was written",
                                                     printable(pending_[k].path), ec.message()));
    }
    pending_[k].staged = false;
  }
  committed_ = true;
}

void write_stdout(std::string_view text) {
  errno = 0;
  const bool written = std::fwrite(text.data(), 1, text.size(), stdout) == text.size();
  if (std::fflush(stdout) != 0 || !written || std::ferror(stdout))
    throw ExitError(kExitOutputFailed, fmt::format("cannot write to standard output: {}",
                                                   errno != 0 ? std::strerror(errno) : "write error"));
}

void write_stdout_or_withdraw(std::string_view text, const std::vector<std::string>& files) {
  try {
    write_stdout(text);
  } catch (const ExitError&) {
    std::error_code ignored;
    for (const std::string& f : files) std::filesystem::remove(f, ignored);
    throw;
  }
}

Model load_model_from(const ModelOptions& opts) {
  try {
    if (opts.config.empty()) return default_model();
    return load_model(read_text_file(opts.config, "--config", "config file"), opts.config);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
}

Config load_config_from(const ModelOptions& opts) {
  try {
    if (opts.config.empty()) return default_config();
    return load_config(read_text_file(opts.config, "--config", "config file"), opts.config);
  } catch (const Error& e) {
    throw ExitError(kExitBadInput, e.what());
  }
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

std::string describe_limit(const LimitReport& r) {
  if (r.status == Status::Ok) return "ok";
  const std::string leg = r.leg >= 0 ? fmt::format("leg {}: ", r.leg + 1) : std::string();
  switch (r.status) {
    case Status::StrokeBelowMin:
      return fmt::format("{}length {:.6f} m is below the minimum {:.6f} m (limits.length_min)", leg, r.value, r.bound);
    case Status::StrokeAboveMax:
      return fmt::format("{}length {:.6f} m is above the maximum {:.6f} m (limits.length_max)", leg, r.value, r.bound);
    case Status::BendBase:
    case Status::BendPlatform:
      return fmt::format("{}{} U-joint bends {:.3f} deg, above the limit {:.3f} deg (limits.bend_max_deg)", leg,
                         r.status == Status::BendBase ? "base" : "platform", rad2deg(r.value), rad2deg(r.bound));
    case Status::SingularBase:
    case Status::SingularPlatform:
      return fmt::format(
          "{}leg is {:.3f} deg from the {} U-joint's fixed axis, inside the singularity margin {:.3f} deg "
          "(limits.singularity_margin_deg)",
          leg, rad2deg(r.value), r.status == Status::SingularBase ? "base" : "platform", rad2deg(r.bound));
    case Status::MotorSpeedAboveMax:
      return fmt::format("{}motor speed {:.0f} rpm is above the limit {:.0f} rpm (servo.max_speed_rpm)", leg,
                         r.value * 60.0 / (2.0 * kPi), r.bound * 60.0 / (2.0 * kPi));
    case Status::TorqueAboveMax:
      return fmt::format("{}holding the load takes {:.2f} N m, above the motor's limit {:.2f} N m (servo.torque_limit)",
                         leg, r.value, r.bound);
    case Status::PlatformSingularity:
      return fmt::format(
          "the platform is near a singularity: the Jacobian's condition number {:.4g} is above the limit "
          "{:.4g} (limits.jacobian_condition_max)",
          r.value, r.bound);
    default:
      return leg + std::string(describe(r.status));
  }
}

void write_limit_json(JsonWriter& json, const LimitReport& r) {
  if (r.status == Status::Ok) {
    json.null();
    return;
  }
  json.begin_object().field("status", to_string(r.status));
  if (r.leg >= 0) json.field("leg", r.leg + 1);
  if (r.leg >= 0 || r.status == Status::PlatformSingularity) json.field("value", r.value).field("bound", r.bound);
  json.field("message", describe_limit(r)).end_object();
}

}  // namespace hexatwist::cli
