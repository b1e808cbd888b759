#pragma once
// Per-step wall times of a benchmark's loop, for the p50 and p95 an issue's figures ask for
// (Google Benchmark reports means), as counters in milliseconds.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <vector>

namespace clay::bench {

/// Record each step from its start (record(t0)); report() sets the counters p50_ms and p95_ms.
struct StepTimes {
  std::vector<double> ms;
  void record(std::chrono::steady_clock::time_point t0) {
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  void report(benchmark::State& state) const {
    if (ms.empty()) return;
    auto quantile = [&](double f) {
      std::vector<double> v = ms;
      const auto k = static_cast<std::ptrdiff_t>(f * static_cast<double>(v.size() - 1));
      std::nth_element(v.begin(), v.begin() + k, v.end());
      return v[static_cast<std::size_t>(k)];
    };
    state.counters["p50_ms"] = quantile(0.5);
    state.counters["p95_ms"] = quantile(0.95);
  }
};

}  // namespace clay::bench
