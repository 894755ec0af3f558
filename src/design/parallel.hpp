// SPDX-License-Identifier: BSD-3-Clause
// Internal: the design subsystem's batch work split over threads in fixed blocks, so that a result
// never depends on the number of threads (each item is computed alone, into its own slot).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace hexatwist::detail {

/// Threads for a setting: `threads` if > 0, else every core.
inline unsigned thread_count(int threads) noexcept {
  if (threads > 0) return static_cast<unsigned>(threads);
  return std::max(1u, std::thread::hardware_concurrency());
}

/// Runs body(begin, end) over [0, n) in blocks of `block` items on `threads` threads (0 = every
/// core), blocks taken in turn; the calling thread works too. The first exception a block throws is
/// rethrown once every thread has stopped.
template <class F>
void for_blocks(std::size_t n, std::size_t block, int threads, F&& body) {
  block = std::max<std::size_t>(block, 1);
  const std::size_t blocks = (n + block - 1) / block;
  const std::size_t workers = std::min<std::size_t>(thread_count(threads), blocks);
  if (workers <= 1) {
    for (std::size_t b = 0; b < blocks; ++b) body(b * block, std::min(n, (b + 1) * block));
    return;
  }
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto run = [&] {
    try {
      for (std::size_t b = next++; b < blocks; b = next++) body(b * block, std::min(n, (b + 1) * block));
    } catch (...) {
      next = blocks;  // the others stop at their next block
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(workers - 1);
  for (std::size_t w = 1; w < workers; ++w) pool.emplace_back(run);
  run();
  for (std::thread& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

/// A computation's progress told to a caller's callback as (items done, items in all) after each
/// block, one call at a time whichever thread finished it: the callback need not be thread-safe.
class BlockProgress {
 public:
  BlockProgress(const std::function<void(std::size_t, std::size_t)>& report, std::size_t total)
      : report_(report), total_(total) {}
  void add(std::size_t items) {
    if (!report_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    done_ += items;
    report_(done_, total_);
  }

 private:
  const std::function<void(std::size_t, std::size_t)>& report_;
  std::size_t total_;
  std::size_t done_ = 0;
  std::mutex mutex_;
};

}  // namespace hexatwist::detail
