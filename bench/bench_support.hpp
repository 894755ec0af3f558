// SPDX-License-Identifier: BSD-3-Clause
// Shared by the benchmarks: the seed platform, poses inside its limits, a realistic 1 kHz motion,
// repetition statistics, and a per-call timer for latency percentiles.
#pragma once

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <random>
#include <vector>
#if defined(__x86_64__)
#include <x86intrin.h>
#endif

#include "hexatwist/hexatwist.hpp"

namespace hexatwist::bench {

inline const Model& model() {
  static const Model m = default_model();
  return m;
}

// Poses inside every limit, spread over the seed's test range (+-0.5 m, +-30 deg).
inline const std::vector<Pose>& random_poses() {
  static const std::vector<Pose> poses = [] {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> pos(-0.5, 0.5), rot(-deg2rad(30), deg2rad(30));
    std::vector<Pose> out;
    CommandReport rep;
    while (out.size() < 1024) {
      Pose p;
      p.position = {pos(rng), pos(rng), pos(rng)};
      p.rpy = {rot(rng), rot(rng), rot(rng)};
      if (compute_commands(model(), p, rep) == Status::Ok) out.push_back(p);
    }
    return out;
  }();
  return poses;
}

// A realistic motion sampled at 1 kHz: all six axes moving (up to 0.2 m and 15 deg, 0.35-0.65 Hz),
// inside every limit.
struct Motion {
  std::vector<Placement> poses;
  std::vector<Vector6d> motor;  // compensated commands = the motor-side lengths of each pose
};
inline const Motion& motion() {
  static const Motion m = [] {
    Motion out;
    for (int k = 0; k < 10000; ++k) {
      const double t = 1e-3 * k, w = 2 * kPi * 0.5;
      Pose p;
      p.position = {0.2 * std::sin(w * t), 0.15 * std::sin(1.3 * w * t), 0.15 * std::sin(0.7 * w * t)};
      p.rpy = {deg2rad(6) * std::sin(0.9 * w * t), deg2rad(10) * std::sin(1.1 * w * t), deg2rad(15) * std::sin(w * t)};
      Vector6d cmd;
      LimitReport lim;
      if (motor_commands(model(), p, Strategy::Compensated, cmd, lim) != Status::Ok) std::abort();
      out.poses.push_back(placement_from_pose(p));
      out.motor.push_back(cmd);
    }
    return out;
  }();
  return m;
}

/// Repetitions with the median, the worst (max) and the best (min) repetition.
inline void add_statistics(benchmark::internal::Benchmark* b) {
  b->Repetitions(15)
      ->ReportAggregatesOnly(true)
      ->ComputeStatistics("max", [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); })
      ->ComputeStatistics("min", [](const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); });
}

/// Per-call latencies: each call is timed on its own (the CPU's invariant time-stamp counter on
/// x86-64, steady_clock elsewhere), the timer's own cost (the median of an empty interval) is
/// subtracted, and the percentiles become counters in ns: p50, p99, p999 (99.9 %) and max.
class Latencies {
 public:
  explicit Latencies(std::size_t capacity) { samples_.reserve(capacity); }

  static std::uint64_t now() noexcept {
#if defined(__x86_64__)
    unsigned aux = 0;
    return __rdtscp(&aux);  // waits until the instructions before it are done
#else
    return static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count());
#endif
  }
  void add(std::uint64_t t0, std::uint64_t t1) { samples_.push_back(t1 - t0); }

  void report(benchmark::State& state) {
    if (samples_.empty()) return;
    const double scale = ns_per_tick();
    const double overhead = timer_overhead();
    std::sort(samples_.begin(), samples_.end());
    const auto at = [&](double q) {
      const auto k = static_cast<std::size_t>(q * static_cast<double>(samples_.size() - 1));
      return std::max(0.0, static_cast<double>(samples_[k]) - overhead) * scale;
    };
    state.counters["p50_ns"] = at(0.5);
    state.counters["p99_ns"] = at(0.99);
    state.counters["p999_ns"] = at(0.999);
    state.counters["max_ns"] = at(1.0);
    samples_.clear();
  }

 private:
  // Ticks per ns, measured once against steady_clock over 50 ms.
  static double ns_per_tick() {
    static const double v = [] {
      using clock = std::chrono::steady_clock;
      const auto t0 = clock::now();
      const std::uint64_t c0 = now();
      while (clock::now() - t0 < std::chrono::milliseconds(50)) {
      }
      const std::uint64_t c1 = now();
      const double ns = std::chrono::duration<double, std::nano>(clock::now() - t0).count();
      return ns / static_cast<double>(c1 - c0);
    }();
    return v;
  }
  static double timer_overhead() {
    static const double v = [] {
      std::vector<std::uint64_t> d(10001);
      for (auto& x : d) {
        const std::uint64_t t0 = now();
        x = now() - t0;
      }
      std::nth_element(d.begin(), d.begin() + 5000, d.end());
      return static_cast<double>(d[5000]);
    }();
    return v;
  }
  std::vector<std::uint64_t> samples_;
};

}  // namespace hexatwist::bench
