// SPDX-License-Identifier: BSD-3-Clause
// The platform as a MuJoCo model (MJCF XML, docs/theory.md §15): base, six legs of housing, rotor,
// screw, rod and rod end, and the platform with its payload, closed by weld equalities at the
// platform U-joints; the screw-nut pair and the motor's gear as joint equalities.
#pragma once

#include <string>

#include "hexatwist/dynamics/rig.hpp"

namespace hexatwist {

/// The MJCF text of `rig` (MuJoCo 2.2.2 or later; needs no MuJoCo to write). Names: bodies
/// "platform", "housingN", "rotorN", "screwN", "rodN", "endN"; joints "platform" (free) and
/// "legN_ja", "legN_jb", "legN_screw", "legN_nut", "legN_slide", "legN_je", "legN_jd",
/// "legN_rotor"; equalities "legN_weld", "legN_helix", "legN_gear"; actuators "motorN", whose force
/// is the motor torque of hexatwist (positive lengthens the leg) [N m]. At qpos0 the platform is at
/// home and every equality holds. Throws hexatwist::Error for what the model cannot represent: a
/// leg with lead 0 (no screw to couple) or without U-joint axes, and leg bodies whose inertia minus
/// the rotor's and screw's transverse inertia (lumped into them in hexatwist) is not a rigid
/// body's (docs/theory.md §15).
std::string mjcf_model(const Rig& rig);

}  // namespace hexatwist
