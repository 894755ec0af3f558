// SPDX-License-Identifier: BSD-3-Clause
// Umbrella header: the whole hexatwist library, in the order its subsystems depend on each other.
#pragma once

#include "hexatwist/error.hpp"
#include "hexatwist/status.hpp"
#include "hexatwist/types.hpp"
#include "hexatwist/version.hpp"

#include "hexatwist/kinematics/batch.hpp"
#include "hexatwist/kinematics/compensation.hpp"
#include "hexatwist/kinematics/forward.hpp"
#include "hexatwist/kinematics/kinematics.hpp"
#include "hexatwist/kinematics/leg_effects.hpp"
#include "hexatwist/kinematics/limits.hpp"
#include "hexatwist/kinematics/model.hpp"
#include "hexatwist/kinematics/pose.hpp"
#include "hexatwist/kinematics/stream.hpp"
#include "hexatwist/kinematics/twist.hpp"
#include "hexatwist/kinematics/workspace.hpp"

#include "hexatwist/motion/trajectory.hpp"

#include "hexatwist/dynamics/dynamics.hpp"
#include "hexatwist/dynamics/mechanism.hpp"
#include "hexatwist/dynamics/motor_sizing.hpp"
#include "hexatwist/dynamics/rig.hpp"

#include "hexatwist/simulation/effect_cost.hpp"
#include "hexatwist/simulation/servo.hpp"
#include "hexatwist/simulation/simulation.hpp"
#include "hexatwist/simulation/study.hpp"

#include "hexatwist/calibration/identification.hpp"
#include "hexatwist/calibration/log_clock.hpp"
#include "hexatwist/calibration/measurement.hpp"
#include "hexatwist/calibration/observations.hpp"
#include "hexatwist/calibration/parameter_errors.hpp"
#include "hexatwist/calibration/parameter_set.hpp"
#include "hexatwist/calibration/point_log.hpp"
#include "hexatwist/calibration/registration.hpp"
#include "hexatwist/calibration/station_plan.hpp"
#include "hexatwist/calibration/stations.hpp"
#include "hexatwist/calibration/synthesis.hpp"
#include "hexatwist/calibration/validation.hpp"

#include "hexatwist/design/axis_design.hpp"
#include "hexatwist/design/required_workspace.hpp"
#include "hexatwist/design/tolerance.hpp"
#include "hexatwist/design/tolerance_calibration.hpp"
#include "hexatwist/design/workspace_boundary.hpp"
#include "hexatwist/design/workspace_map.hpp"
#include "hexatwist/design/workspace_volume.hpp"

#include "hexatwist/io/config.hpp"
#include "hexatwist/io/gcode.hpp"
#include "hexatwist/io/mjcf.hpp"
#include "hexatwist/io/platform_yaml.hpp"
#include "hexatwist/io/text_file.hpp"
