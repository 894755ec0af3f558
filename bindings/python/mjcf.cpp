// SPDX-License-Identifier: BSD-3-Clause
// The platform as a MuJoCo model (mjcf.hpp): MJCF XML text of a Rig.
#include "hexatwist/io/mjcf.hpp"
#include "common.hpp"

namespace hexatwist::python {

void expose_mjcf(py::module_& m) {
  m.def(
      "mjcf", [](const py::object& config) { return mjcf_model(rig_of(config)->config->rig); },
      py::arg("rig") = py::none(),
      "The MJCF XML text (MuJoCo 2.2.2 or later) of a configuration (a Rig, YAML text, a path or None for the "
      "seed): base, six legs of housing, rotor, screw, rod and rod end, the platform with its payload; actuators "
      "'motorN' whose force is the motor torque [N m] (positive lengthens the leg). SI units, frame B as the "
      "world. Raises ConfigError for what MuJoCo cannot represent (a leg with lead 0 or without U-joint axes, "
      "leg bodies that are not rigid bodies once the rotor and screw are taken out).");
}

}  // namespace hexatwist::python
