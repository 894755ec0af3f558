// SPDX-License-Identifier: BSD-3-Clause
// Fuzz target: a YAML configuration (hexatwist::load_config). Bad text must end in
// hexatwist::Error with a one-line message that starts with the source name; any other exception,
// a crash or a sanitizer finding is a bug. A configuration that loads must give a model whose
// real-time functions answer at home and at a small pose with finite numbers.
#include <cmath>

#include "fuzz_support.hpp"
#include "hexatwist/hexatwist.hpp"

namespace {

using namespace hexatwist;

void exercise(const Model& model) {
  Pose nudge;
  nudge.position = {0.01, -0.01, 0.02};
  nudge.rpy = {deg2rad(1.0), deg2rad(-2.0), deg2rad(3.0)};
  CommandReport report;
  FkResult fk;
  for (const Pose& pose : {Pose{}, nudge}) {
    if (compute_commands(model, pose, report) != Status::Ok) continue;
    fuzz::require(report.compensated.allFinite() && report.conventional.allFinite(),
                  "non-finite command with status ok");
    // Twist-aware FK from home back to the pose: any status, but a finite answer when it is Ok.
    if (forward_kinematics(model, report.compensated, LengthKind::Motor, Placement{}, fk) == Status::Ok)
      fuzz::require(fk.pose.is_finite() && std::isfinite(fk.residual), "non-finite FK solution with status ok");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const Config config = load_config(fuzz::as_text(data, size), "fuzz");
    exercise(config.rig.model());
  } catch (const Error& e) {
    fuzz::require_message(e, "fuzz");
  }
  return 0;
}
