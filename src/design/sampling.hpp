// SPDX-License-Identifier: BSD-3-Clause
// Internal: seeded random numbers addressed by (seed, index), the same on every machine and in any
// order of evaluation, so that sample k of a Monte Carlo study is the same platform whichever
// thread, chunk or worker draws it (docs/theory/design.md §18).
#pragma once

#include <cmath>
#include <cstdint>

#include "hexatwist/types.hpp"

namespace hexatwist::detail {

/// SplitMix64's output function (Steele, Lea and Flood 2014): a bijection of 64-bit words that
/// mixes every input bit into every output bit.
constexpr std::uint64_t mix64(std::uint64_t z) noexcept {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// The numbers of one sample: SplitMix64 started from a state that (seed, index) fix.
class SampleStream {
 public:
  SampleStream(std::uint64_t seed, std::uint64_t index) noexcept
      : state_(mix64(seed ^ 0x6a09e667f3bcc909ULL) ^ mix64(index + 0x9e3779b97f4a7c15ULL)) {}
  /// The next 64 random bits.
  std::uint64_t bits() noexcept { return mix64(state_ += 0x9e3779b97f4a7c15ULL); }
  /// Uniform in [0, 1), 53 bits.
  double uniform() noexcept { return static_cast<double>(bits() >> 11) * 0x1.0p-53; }
  /// Uniform in [-1, 1).
  double symmetric() noexcept { return 2.0 * uniform() - 1.0; }
  /// Standard normal (Box-Muller, one value per pair of uniforms; 1 - u is in (0, 1]).
  double normal() noexcept {
    const double r = std::sqrt(-2.0 * std::log(1.0 - uniform()));
    return r * std::cos(2.0 * kPi * uniform());
  }

 private:
  std::uint64_t state_;
};

}  // namespace hexatwist::detail
