// SPDX-License-Identifier: BSD-3-Clause
// The figures of a study, simulate or measure report (drawn by figures.hpp), and the names and
// axes they share with the report's tables.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "figures.hpp"
#include "study_report.hpp"

namespace hexatwist::cli {

/// Pose coordinate names, x .. yaw.
inline constexpr const char* kCoordinateNames[6] = {"x", "y", "z", "roll", "pitch", "yaw"};

/// "compensated" or "conventional".

/// The swept coordinate of a sample as plotted: m for translations, deg for rotations, or the time
/// for a user trajectory.
double displacement(const ReportedTest& t, double time, const Vector6d& desired);

/// The x-axis label that goes with displacement().
std::string displacement_label(const ReportedTest& t);

/// A test's figures, written as `dir`/NAME_error, NAME_legs and (measured) NAME_measured: the
/// observation-point error of both strategies (and the compensated one zoomed), each leg's twist
/// and length error, and the measured error beside the simulated one.
std::vector<Figure> figures_of(const std::filesystem::path& dir, const ReportedTest& t, const Model& model);

}  // namespace hexatwist::cli
