// Writing configurations: a user's YAML with a designed platform's values put in, every other key
// kept (docs/theory/design.md §17).
#pragma once

#include <string>
#include <string_view>

#include "hexatwist/kinematics/model.hpp"

namespace hexatwist {

/// The configuration `yaml_text` with the fixed U-joint axes of `designed` (base_axis, platform_axis
/// of every leg). Every other key keeps its value and its place. A `symmetric` block, whose axes are
/// fixed tangential, becomes the same platform as explicit `home_height` and `legs` in its place
/// (and `observation_point`, when the block's default (Ra, 0, 0) was used). Comments are dropped; the
/// lines of `header` (may be empty) open the text as comments. Numbers round trip exactly. Throws
/// hexatwist::Error as load_config for text that does not load, and naming the leg and field when
/// `designed` differs from the text's platform in more than its axes.
std::string designed_config_yaml(std::string_view yaml_text, std::string_view source, const ModelSpec& designed,
                                 std::string_view header);

}  // namespace hexatwist
