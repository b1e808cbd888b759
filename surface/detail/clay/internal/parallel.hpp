#pragma once
// Splitting bulk work into parts and running them on an Executor (internal, not installed). The
// one place where the kernel decides how many threads a call uses.
#include <clay/cancel.hpp>
#include <clay/parallel.hpp>

#include <algorithm>
#include <cstddef>
#include <thread>

namespace clay::internal {

/// How many parts n items are split into: `requested` when > 0, else the hardware's threads; no
/// more than n / min_per_part (a part smaller than that costs more to start than it saves), and
/// at least 1.
inline std::size_t part_count(int requested, std::size_t n, std::size_t min_per_part) {
  const std::size_t wanted = requested > 0 ? static_cast<std::size_t>(requested)
                                           : std::max(1u, std::thread::hardware_concurrency());
  return std::max<std::size_t>(1, std::min(wanted, n / std::max<std::size_t>(1, min_per_part)));
}

/// Runs work(part) for every part in [0, parts): inline when there is one part, else on
/// `executor` (run_on_threads when it is empty).
template <class Work>
void run_parts(std::size_t parts, const Executor& executor, const Work& work) {
  if (parts <= 1) {
    if (parts == 1) work(std::size_t{0});
    return;
  }
  if (executor) {
    // An embedder's pool runs the parts on its threads: the caller's cancel check goes along.
    executor(parts, [&work, check = current_cancel_check()](std::size_t part) {
      const CancelScope scope(check);
      work(part);
    });
    return;
  }
  run_on_threads(parts, [&work](std::size_t part) { work(part); });  // carries the check itself
}

}  // namespace clay::internal
