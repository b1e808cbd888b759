#pragma once
// Splitting a bulk point deformation over std::thread workers: contiguous ranges, at least
// min_points_per_thread points each, the calling thread doing the first range.
#include <clay/deform/deformation.hpp>

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace clay::deform::detail {

inline constexpr std::size_t min_points_per_thread = 16384;

/// Calls f(begin, end) on disjoint contiguous ranges covering [0, n). Validates the options.
template <class F>
void parallel_ranges(std::size_t n, const DeformOptions& options, const F& f) {
  options.validate();
  std::size_t threads = options.threads > 0 ? static_cast<std::size_t>(options.threads)
                                            : std::max(1u, std::thread::hardware_concurrency());
  threads = std::max<std::size_t>(1, std::min(threads, n / min_points_per_thread));
  auto work = [&](std::size_t part) {
    const std::size_t b = n * part / threads, e = n * (part + 1) / threads;
    if (b < e) f(b, e);
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (std::size_t part = 1; part < threads; ++part) pool.emplace_back(work, part);
  work(0);
  for (auto& th : pool) th.join();
}

}  // namespace clay::deform::detail
