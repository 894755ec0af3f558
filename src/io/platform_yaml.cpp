// SPDX-License-Identifier: BSD-3-Clause
#include "hexatwist/io/platform_yaml.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <initializer_list>
#include <set>
#include <string>

#include "hexatwist/error.hpp"
#include "hexatwist/io/config.hpp"

namespace hexatwist {
namespace {

// Shortest text that reads back to the same double.
YAML::Node number(double v) { return YAML::Node(fmt::format("{}", v == 0.0 ? 0.0 : v)); }  // -0 written as 0

// The shortest degrees text that load_config turns back into exactly `rad` (deg2rad of it == rad):
// rad2deg's nearest double does not always do that (1.5 deg -> rad -> deg -> rad moves by one
// ulp). Every angle loaded from degrees has such a text; an angle given in radians that no double
// in degrees maps to gets the nearest one.
YAML::Node degrees(double rad) {
  const double d = rad2deg(rad);
  if (!std::isfinite(d)) return number(d);
  for (int precision = 1; precision <= 17; ++precision) {
    for (const double c : {d, std::nextafter(d, -INFINITY), std::nextafter(d, INFINITY)}) {
      char buf[40];
      const auto r = std::to_chars(buf, buf + sizeof buf, c, std::chars_format::general, precision);
      double back = 0.0;
      std::from_chars(buf, r.ptr, back);
      if (deg2rad(back) == rad) return number(back);
    }
  }
  // Further neighbours (a few ulps away).
  double lo = d, hi = d;
  for (int k = 0; k < 8; ++k) {
    lo = std::nextafter(lo, -INFINITY);
    hi = std::nextafter(hi, INFINITY);
    if (deg2rad(lo) == rad) return number(lo);
    if (deg2rad(hi) == rad) return number(hi);
  }
  return number(d);
}

YAML::Node flow(std::initializer_list<double> values) {
  YAML::Node list(YAML::NodeType::Sequence);
  for (const double v : values) list.push_back(number(v));
  list.SetStyle(YAML::EmitterStyle::Flow);
  return list;
}

YAML::Node flow(const Vector3d& v) { return flow({v.x(), v.y(), v.z()}); }

YAML::Node flow(const Vector6d& v) { return flow({v[0], v[1], v[2], v[3], v[4], v[5]}); }

// The keys that describe the platform: replaced by the block, wherever the user had them.
const std::set<std::string> kPlatformKeys{"name",       "symmetric",      "legs",          "home_height",
                                          "screw",      "length_offsets", "home_commands", "observation_point",
                                          "leg_effects"};

const char* thread_name(ThreadSense t) { return t == ThreadSense::Right ? "right" : "left"; }
const char* driven_name(DrivenSide d) { return d == DrivenSide::Base ? "base" : "platform"; }

// Equal, NaN equal to NaN (a drive lead not given).
bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

// The legs of `platform` in the legs form, the screw block's values left to it.
YAML::Node legs_node(const ModelSpec& platform) {
  const LegSpec& first = platform.legs[0];
  YAML::Node legs(YAML::NodeType::Sequence);
  for (const LegSpec& leg : platform.legs) {
    YAML::Node n(YAML::NodeType::Map);
    n["base"] = flow(leg.base_B);
    n["platform"] = flow(leg.platform_P);
    n["base_axis"] = flow(leg.axis_base_B);
    n["platform_axis"] = flow(leg.axis_platform_P);
    if (leg.lead != first.lead) n["lead"] = number(leg.lead);
    // A leg that gives its own lead takes its drive lead from itself, not from the block.
    if (!same(leg.drive_lead, first.drive_lead) || (leg.lead != first.lead && !std::isnan(leg.drive_lead)))
      if (!std::isnan(leg.drive_lead)) n["drive_lead"] = number(leg.drive_lead);
    if (leg.thread != first.thread) n["thread"] = thread_name(leg.thread);
    if (leg.driven != first.driven) n["driven_side"] = driven_name(leg.driven);
    legs.push_back(n);
  }
  return legs;
}

// Error unless `designed` is `base` with other axes.
void check_only_axes(const ModelSpec& base, const ModelSpec& designed, std::string_view source) {
  const auto fail = [&](const std::string& what) {
    throw Error(
        fmt::format("{}: the designed platform differs from the configuration in {}; only the U-joint axes "
                    "may change",
                    source, what));
  };
  if (designed.home_height != base.home_height) fail("home_height");
  for (int i = 0; i < kLegs; ++i) {
    const LegSpec& a = base.legs[static_cast<std::size_t>(i)];
    const LegSpec& b = designed.legs[static_cast<std::size_t>(i)];
    if (a.base_B != b.base_B) fail(fmt::format("leg {}: base", i + 1));
    if (a.platform_P != b.platform_P) fail(fmt::format("leg {}: platform", i + 1));
    if ((a.axis_base_B == Vector3d::Zero()) != (b.axis_base_B == Vector3d::Zero()))
      fail(fmt::format("leg {}: base_axis (given in one, not the other)", i + 1));
    if ((a.axis_platform_P == Vector3d::Zero()) != (b.axis_platform_P == Vector3d::Zero()))
      fail(fmt::format("leg {}: platform_axis (given in one, not the other)", i + 1));
  }
}

// One number if the legs agree, else a list of six; infinity written as .inf.
YAML::Node per_leg(const ModelSpec& platform, double LegSpec::*member) {
  const auto value = [](double v) { return std::isinf(v) ? YAML::Node(".inf") : number(v); };
  const double first = platform.legs[0].*member;
  bool equal = true;
  for (const LegSpec& leg : platform.legs) equal = equal && leg.*member == first;
  if (equal) return value(first);
  YAML::Node list(YAML::NodeType::Sequence);
  for (const LegSpec& leg : platform.legs) list.push_back(value(leg.*member));
  list.SetStyle(YAML::EmitterStyle::Flow);
  return list;
}

// The `leg_effects` block: the fields that differ from their defaults (theory §4b).
YAML::Node leg_effects_node(const ModelSpec& platform) {
  YAML::Node block(YAML::NodeType::Map);
  const LegSpec defaults;
  const auto any = [&](double LegSpec::*member) {
    for (const LegSpec& leg : platform.legs)
      if (!(leg.*member == defaults.*member)) return true;
    return false;
  };
  for (const auto& [key, member] : {std::pair{"stiffness", &LegSpec::stiffness}, std::pair{"play", &LegSpec::play},
                                    std::pair{"home_direction", &LegSpec::home_direction},
                                    std::pair{"length_expansion", &LegSpec::length_expansion},
                                    std::pair{"lead_expansion", &LegSpec::lead_expansion}})
    if (any(member)) block[key] = per_leg(platform, member);
  // The temperature the geometry holds at: wherever it differs from the default, and always with
  // an expansion (the coefficients mean nothing without it).
  if (platform.reference_temperature != ModelSpec{}.reference_temperature || any(&LegSpec::length_expansion) ||
      any(&LegSpec::lead_expansion))
    block["reference_temperature"] = number(platform.reference_temperature);
  return block;
}

// The platform block, in the order the legs form reads.
YAML::Node platform_block(const ModelSpec& platform, const Model& model, bool write_home_commands) {
  const LegSpec& first = platform.legs[0];

  YAML::Node block(YAML::NodeType::Map);
  block["name"] = platform.name;
  block["home_height"] = number(platform.home_height);
  YAML::Node screw(YAML::NodeType::Map);
  screw["lead"] = number(first.lead);
  screw["thread"] = thread_name(first.thread);
  screw["driven_side"] = driven_name(first.driven);
  if (!std::isnan(first.drive_lead)) screw["drive_lead"] = number(first.drive_lead);
  block["screw"] = screw;
  block["legs"] = legs_node(platform);
  Vector6d offsets, homes;
  bool homes_differ = false;
  for (int i = 0; i < kLegs; ++i) {
    const LegSpec& leg = platform.legs[static_cast<std::size_t>(i)];
    offsets[i] = leg.length_offset;
    homes[i] = model.home_command()[i];
    homes_differ = homes_differ || !std::isnan(leg.home_command);
  }
  block["length_offsets"] = flow(offsets);
  if (write_home_commands || homes_differ) block["home_commands"] = flow(homes);
  block["observation_point"] = flow(platform.observation_P);
  if (const YAML::Node effects = leg_effects_node(platform); effects.size() > 0) block["leg_effects"] = effects;
  return block;
}

std::string with_header(std::string_view header, const YAML::Node& root) {
  std::string text;
  for (std::size_t begin = 0; begin < header.size();) {
    const std::size_t end = std::min(header.find('\n', begin), header.size());
    text += "# " + std::string(header.substr(begin, end - begin)) + "\n";
    begin = end + 1;
  }
  YAML::Emitter out;
  out << root;
  return text + out.c_str() + "\n";
}

}  // namespace

std::string model_yaml(const ModelSpec& spec) {
  const Model model(spec);
  YAML::Node root = platform_block(spec, model, false);
  YAML::Node limits(YAML::NodeType::Map);
  limits["length_min"] = number(spec.limits.length_min);
  limits["length_max"] = number(spec.limits.length_max);
  limits["bend_max_deg"] = degrees(spec.limits.bend_max);
  limits["singularity_margin_deg"] = degrees(spec.limits.singularity_margin);
  limits["jacobian_condition_max"] = number(spec.limits.jacobian_condition_max);
  root["limits"] = limits;
  root["pivot"] = flow(spec.pivot_P);
  return with_header({}, root);
}

std::string platform_config_yaml(std::string_view yaml_text, std::string_view source, const ModelSpec& platform,
                                 std::string_view header, bool write_home_commands) {
  (void)load_config(yaml_text, source);  // located errors for text that does not load
  const Model model(platform);           // and a platform that is no model
  const YAML::Node block = platform_block(platform, model, write_home_commands);
  // The user's keys in their order, the platform block where its first key stood.
  const YAML::Node original = YAML::Load(std::string(yaml_text));
  YAML::Node root(YAML::NodeType::Map);
  bool placed = false;
  for (const auto& kv : original) {
    const std::string key = kv.first.as<std::string>();
    if (kPlatformKeys.contains(key)) {
      if (!placed)
        for (const auto& b : block) root[b.first.as<std::string>()] = b.second;
      placed = true;
      continue;
    }
    root[key] = kv.second;
  }
  if (!placed)
    for (const auto& b : block) root[b.first.as<std::string>()] = b.second;

  const std::string text = with_header(header, root);
  (void)load_config(text, source);  // what is written loads (a bug here must not reach a file)
  return text;
}

std::string designed_config_yaml(std::string_view yaml_text, std::string_view source, const ModelSpec& designed,
                                 std::string_view header) {
  const Config config = load_config(yaml_text, source);  // located errors for text that does not load
  check_only_axes(config.rig.model().spec(), designed, source);
  return platform_config_yaml(yaml_text, source, designed, header, false);
}

}  // namespace hexatwist
