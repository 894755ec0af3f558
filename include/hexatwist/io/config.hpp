// SPDX-License-Identifier: BSD-3-Clause
// Platform configuration in YAML: parse text into a Model. Reading files is the caller's job.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "hexatwist/dynamics/rig.hpp"
#include "hexatwist/simulation/study.hpp"

namespace hexatwist {

/// The seed platform (configs/seed.yaml, embedded at build time) as YAML text.
std::string_view seed_config_yaml() noexcept;

/// Parses a YAML platform configuration. `source` names the text in error messages (a file name).
/// Throws hexatwist::Error with a single line "source:line:column: field 'x.y': what was expected".
ModelSpec parse_model_spec(std::string_view yaml_text, std::string_view source);

/// parse_model_spec followed by Model validation (errors are prefixed with `source`).
Model load_model(std::string_view yaml_text, std::string_view source);

/// The embedded default: the seed platform with a 10 mm lead.
Model default_model();

/// A whole configuration: the platform and, in the optional sections `servo`, `load`,
/// `simulation` and `study`, its drives, load, simulation rates and test motion (defaults where
/// a section or key is absent; configs/seed.yaml lists them all).
struct ConfigSpec {
  RigSpec rig;
  StudySpec study;
  /// The sections of the drives and the load the text leaves out, in the order servo, load,
  /// mechanism: their values are the seed's defaults (a report says so beside the platform's name).
  std::vector<std::string> defaulted;
};

/// Parses a whole configuration (errors as parse_model_spec).
ConfigSpec parse_config_spec(std::string_view yaml_text, std::string_view source);

/// A validated configuration.
struct Config {
  Rig rig;
  StudySpec study;
  std::vector<std::string> defaulted;  ///< as ConfigSpec::defaulted
};

/// parse_config_spec followed by validation of the rig and the study (errors located in the text).
Config load_config(std::string_view yaml_text, std::string_view source);

/// The embedded seed configuration with its servo, load and study sections.
Config default_config();

}  // namespace hexatwist
