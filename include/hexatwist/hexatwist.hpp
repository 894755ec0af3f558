// Umbrella header: the whole hexatwist library.
#pragma once

#include "hexatwist/compensation.hpp"
#include "hexatwist/config.hpp"
#include "hexatwist/error.hpp"
#include "hexatwist/forward.hpp"
#include "hexatwist/kinematics.hpp"
#include "hexatwist/limits.hpp"
#include "hexatwist/model.hpp"
#include "hexatwist/pose.hpp"
#include "hexatwist/status.hpp"
#include "hexatwist/trajectory.hpp"
#include "hexatwist/twist.hpp"
#include "hexatwist/types.hpp"
