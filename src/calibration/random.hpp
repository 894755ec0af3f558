// SPDX-License-Identifier: BSD-3-Clause
// Internal: seeded random numbers that are the same on every platform. The raw output of
// std::mt19937_64 is fixed bit for bit by the standard; its distributions are left to each library,
// so they would make the same seed give other numbers elsewhere.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "hexatwist/types.hpp"

namespace hexatwist::detail {

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  /// Uniform in [0, 1), 53 bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  /// Uniform in [-1, 1).
  double symmetric() { return 2.0 * uniform() - 1.0; }
  /// Standard normal (Box-Muller; 1 - u is in (0, 1], so the logarithm is finite).
  double normal() {
    const double r = std::sqrt(-2.0 * std::log(1.0 - uniform()));
    return r * std::cos(2.0 * kPi * uniform());
  }

 private:
  std::mt19937_64 engine_;
};

}  // namespace hexatwist::detail
