#pragma once
// Splitting a bulk point deformation into parts: contiguous ranges of at least
// min_points_per_thread points, run on the options' executor (clay/internal/parallel.hpp).
#include <clay/deform/deformation.hpp>
#include <clay/internal/parallel.hpp>

#include <cstddef>

namespace clay::deform::detail {

inline constexpr std::size_t min_points_per_thread = 16384;

/// Calls f(begin, end) on disjoint contiguous ranges covering [0, n). Validates the options.
template <class F>
void parallel_ranges(std::size_t n, const DeformOptions& options, const F& f) {
  options.validate();
  const std::size_t parts = internal::part_count(options.threads, n, min_points_per_thread);
  internal::run_parts(parts, options.executor, [&](std::size_t part) {
    const std::size_t b = n * part / parts, e = n * (part + 1) / parts;
    if (b < e) f(b, e);
  });
}

}  // namespace clay::deform::detail
