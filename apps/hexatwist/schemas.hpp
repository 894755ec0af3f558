// SPDX-License-Identifier: BSD-3-Clause
// The name and version of each JSON document the tool writes, its first field ("schema"). Each is a
// file in docs/schemas/ (NAME.schema.json, with the version in its $id), and the tests validate the
// tool's outputs against them (tests/docs/check_schemas.py). A change that breaks a reader (a field
// removed or renamed, another type or unit) bumps the version here and in the file, and is listed
// in CHANGELOG.md; a field added is not a break, but goes into the schema file.
#pragma once

namespace hexatwist::cli::schema {

inline constexpr const char* kIk = "hexatwist.ik/1";                // ik --json
inline constexpr const char* kFk = "hexatwist.fk/1";                // fk --json
inline constexpr const char* kCompare = "hexatwist.compare/1";      // compare --json
inline constexpr const char* kConfig = "hexatwist.config/1";        // config --json
inline constexpr const char* kIdentify = "hexatwist.identify/2";    // identify --json (2: lead, thread per leg)
inline constexpr const char* kStations = "hexatwist.stations/1";    // stations --json
inline constexpr const char* kTruth = "hexatwist.truth/1";          // synth's truth file
inline constexpr const char* kReport = "hexatwist.report/1";        // study, simulate, measure: summary.json
inline constexpr const char* kDynamics = "hexatwist.dynamics/1";    // dynamics: summary.json
inline constexpr const char* kDesign = "hexatwist.design/1";        // design --json
inline constexpr const char* kTolerance = "hexatwist.tolerance/1";  // tolerance: summary.json, --json
inline constexpr const char* kWorkspace = "hexatwist.workspace/1";  // workspace: summary.json, --json

}  // namespace hexatwist::cli::schema
