// SPDX-License-Identifier: BSD-3-Clause
// A platform written into a configuration's YAML: the legs form of a ModelSpec (every joint, axis,
// screw and offset explicit) in place of the user's platform keys, every other key of the user's
// text kept. What an identification (a corrected configuration) and a design write.
#pragma once

#include <string>
#include <string_view>

#include "hexatwist/kinematics/model.hpp"

namespace hexatwist {

/// The configuration `yaml_text` (which must load, see load_config) with its platform replaced by
/// `platform` in the legs form: `name`, `home_height`, `screw` (leg 1's lead, thread, driven side
/// and drive lead), `legs` (six entries with base, platform, base_axis, platform_axis, and a leg's
/// own lead, thread, driven_side or drive_lead where they differ from the screw block),
/// `length_offsets`, `home_commands` (when `write_home_commands`, or when a leg's differs from its
/// default) and `observation_point`; `symmetric` is removed. Every other key (limits, pivot,
/// servo, load, mechanism, simulation, study) keeps its value and its place; comments are dropped,
/// and the lines of `header` (may be empty) open the text as comments. Numbers are written in their
/// shortest form that reads back to the same double. Throws hexatwist::Error as load_config for text
/// that does not load, and if the result does not load to `platform`'s model.
std::string platform_config_yaml(std::string_view yaml_text, std::string_view source, const ModelSpec& platform,
                                 std::string_view header, bool write_home_commands);

/// A design's configuration (docs/theory/design.md §17): platform_config_yaml of `designed`, which
/// must be the text's platform with other U-joint axes (a `symmetric` block becomes the same platform
/// in the legs form). Throws hexatwist::Error as load_config for text that does not load, and naming
/// the leg and field when `designed` differs from the text's platform in more than its axes.
std::string designed_config_yaml(std::string_view yaml_text, std::string_view source, const ModelSpec& designed,
                                 std::string_view header);

/// The model `spec` alone as a configuration in the legs form: the platform block as above, its
/// limits (angles in degrees, as the file takes them) and pivot, nothing else. Loads back to the
/// same model, every double exactly. Throws hexatwist::Error if `spec` is no model.
std::string model_yaml(const ModelSpec& spec);

}  // namespace hexatwist
