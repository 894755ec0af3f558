// SPDX-License-Identifier: BSD-3-Clause
// Fixed-size types shared by every hexatwist header: six legs, 3-D vectors.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

namespace hexatwist {

/// Number of legs of a Stewart platform.
inline constexpr int kLegs = 6;

using Vector3d = Eigen::Vector3d;
using Matrix3d = Eigen::Matrix3d;
using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// One value per leg, leg 0 first (the CLI and documents number legs 1..6).
template <class T>
using PerLeg = std::array<T, kLegs>;

/// Six 3-vectors, one per leg: row i is leg i's vector. Column-major, so each coordinate of the
/// six legs is contiguous and per-leg arithmetic vectorises across legs.
using LegVectors = Eigen::Matrix<double, kLegs, 3>;

/// pi, to the precision of a double.
inline constexpr double kPi = 3.14159265358979323846;

/// Degrees to radians.
constexpr double deg2rad(double deg) noexcept { return deg * (kPi / 180.0); }
/// Radians to degrees.
constexpr double rad2deg(double rad) noexcept { return rad * (180.0 / kPi); }

}  // namespace hexatwist
