#include "hexatwist/io/config_writer.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "hexatwist/error.hpp"
#include "hexatwist/io/config.hpp"

namespace hexatwist {
namespace {

// Shortest text that reads back to the same double.
YAML::Node number(double v) { return YAML::Node(fmt::format("{}", v)); }

YAML::Node flow3(const Vector3d& v) {
  YAML::Node list(YAML::NodeType::Sequence);
  for (int k = 0; k < 3; ++k) list.push_back(number(v[k]));
  list.SetStyle(YAML::EmitterStyle::Flow);
  return list;
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

}  // namespace

std::string designed_config_yaml(std::string_view yaml_text, std::string_view source, const ModelSpec& designed,
                                 std::string_view header) {
  const Config config = load_config(yaml_text, source);  // located errors for text that does not load
  const ModelSpec& base = config.rig.model().spec();
  check_only_axes(base, designed, source);

  const YAML::Node root = YAML::Load(std::string(yaml_text));
  const auto leg_axes = [&](YAML::Node leg, int i) {
    const LegSpec& d = designed.legs[static_cast<std::size_t>(i)];
    if (d.axis_base_B != Vector3d::Zero()) leg["base_axis"] = flow3(d.axis_base_B);
    if (d.axis_platform_P != Vector3d::Zero()) leg["platform_axis"] = flow3(d.axis_platform_P);
  };
  // A new mapping in the same key order, the symmetric block replaced in its place.
  YAML::Node out(YAML::NodeType::Map);
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (key == "symmetric") {
      out["home_height"] = number(designed.home_height);
      YAML::Node legs(YAML::NodeType::Sequence);
      for (int i = 0; i < kLegs; ++i) {
        const LegSpec& d = designed.legs[static_cast<std::size_t>(i)];
        YAML::Node leg(YAML::NodeType::Map);
        leg["base"] = flow3(d.base_B);
        leg["platform"] = flow3(d.platform_P);
        leg_axes(leg, i);
        legs.push_back(leg);
      }
      out["legs"] = legs;
      // The legs form's default point A is another (the farthest platform joint): write the block's.
      if (!root["observation_point"]) out["observation_point"] = flow3(base.observation_P);
    } else if (key == "legs") {
      YAML::Node legs = YAML::Clone(kv.second);
      for (std::size_t i = 0; i < legs.size(); ++i) leg_axes(legs[i], static_cast<int>(i));
      out["legs"] = legs;
    } else {
      out[key] = kv.second;
    }
  }

  std::string text;
  for (std::size_t begin = 0; begin < header.size();) {
    const std::size_t end = std::min(header.find('\n', begin), header.size());
    text += "# " + std::string(header.substr(begin, end - begin)) + "\n";
    begin = end + 1;
  }
  YAML::Emitter emitter;
  emitter << out;
  return text + emitter.c_str() + "\n";
}

}  // namespace hexatwist
