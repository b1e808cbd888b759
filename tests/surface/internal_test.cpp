// The shared internal helpers (clay/internal/) and the default executor (clay/parallel.hpp),
// against closed forms.
#include <catch2/catch.hpp>

#include <clay/cancel.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/math.hpp>
#include <clay/internal/parallel.hpp>
#include <clay/parallel.hpp>

#include <atomic>
#include <cfenv>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include "error_of.hpp"

using namespace clay;
using clay::test::error_of;

TEST_CASE("binomial: Pascal's rows against the product formula and the row sums 2^n") {
  CHECK(internal::binomial(10, 3) == 120.0);
  CHECK(internal::binomial(5, -1) == 0.0);
  CHECK(internal::binomial(5, 6) == 0.0);
  CHECK_THROWS_AS(internal::binomial_row(internal::max_binomial_row + 1), clay::Error);
  // Exact through n = 56: C(56, 28) = 7,648,690,600,760,440 < 2^53.
  CHECK(internal::binomial(56, 28) == 7648690600760440.0);
  for (int n = 0; n <= 53; ++n) {  // every entry and partial sum is an integer <= 2^53: exact
    double sum = 0;
    for (int k = 0; k <= n; ++k) sum += internal::binomial(n, k);
    CHECK(sum == std::ldexp(1.0, n));
  }
  // Beyond 2^53 the entries are still close to the exact value (product formula in long double).
  long double c = 1;
  for (int i = 1; i <= 90; ++i) c = c * (180 - 90 + i) / i;
  CHECK(std::abs(internal::binomial(180, 90) / static_cast<double>(c) - 1) < 1e-13);
}

TEST_CASE(
    "gauss_legendre: n points integrate x^k exactly for k <= 2n - 1, the 8-point constants agree") {
  for (int n = 1; n <= 20; ++n) {
    const internal::GaussRule rule = internal::gauss_legendre(n);
    for (int k = 0; k <= 2 * n - 1; ++k) {
      double sum = 0;
      for (size_t i = 0; i < rule.nodes.size(); ++i)
        sum += rule.weights[i] * std::pow(rule.nodes[i], k);
      const double exact = k % 2 ? 0.0 : 2.0 / (k + 1);  // ∫_{-1}^{1} x^k dx
      CHECK(std::abs(sum - exact) < 1e-14);
    }
  }
  const internal::GaussRule eight = internal::gauss_legendre(8);
  for (size_t i = 0; i < 8; ++i) {
    CHECK(std::abs(eight.nodes[i] - internal::gauss8_nodes[i]) < 1e-15);
    CHECK(std::abs(eight.weights[i] - internal::gauss8_weights[i]) < 1e-15);
  }
  // ∫_1^3 x^15 dx = (3^16 - 1) / 16, exact for the 8-point rule.
  const double integral =
      internal::gauss_legendre_8(1.0, 3.0, [](double x) { return std::pow(x, 15); });
  CHECK(std::abs(integral / ((std::pow(3.0, 16) - 1) / 16) - 1) < 1e-14);
}

TEST_CASE("all_finite: finds NaN and infinities without raising FE_INVALID") {
  Eigen::Matrix<double, 2, 3> m = Eigen::Matrix<double, 2, 3>::Ones();
  CHECK(internal::all_finite(m));
  m(1, 2) = std::numeric_limits<double>::infinity();
  std::feclearexcept(FE_ALL_EXCEPT);
  CHECK_FALSE(internal::all_finite(m));
  // Eigen's allFinite() computes inf - inf here; ours must not (the Debug suite traps it).
  CHECK(std::fetestexcept(FE_INVALID) == 0);
  m(1, 2) = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(internal::all_finite(m.row(1)));
  CHECK(internal::all_finite(m.row(0)));
}

TEST_CASE("throw_problems lists every problem in one typed error") {
  const auto [category, what] = error_of([] {
    internal::throw_if(ErrorCategory::InvalidArgument, {"a: is 1; give 2", "b: is 3; give 4"});
  });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK(what == "invalid argument: a: is 1; give 2; b: is 3; give 4");
  CHECK_NOTHROW(internal::throw_if(ErrorCategory::InvalidArgument, {}));
}

TEST_CASE("part_count: requested parts, capped by the work, at least one") {
  CHECK(internal::part_count(4, 100000, 1000) == 4);
  CHECK(internal::part_count(4, 2500, 1000) == 2);
  CHECK(internal::part_count(4, 10, 1000) == 1);
  CHECK(internal::part_count(0, 0, 1000) == 1);
  // 0 asks for one part per hardware thread.
  CHECK(internal::part_count(0, std::size_t{1} << 40, 1) ==
        std::max(1u, std::thread::hardware_concurrency()));
}

TEST_CASE("run_on_threads runs every part once and rethrows a task's exception after all ended") {
  std::vector<std::atomic<int>> runs(7);
  run_on_threads(7, [&](std::size_t part) { ++runs[part]; });
  for (const auto& r : runs) CHECK(r.load() == 1);

  std::atomic<int> finished{0};
  CHECK_THROWS_AS(run_on_threads(5,
                                 [&](std::size_t part) {
                                   if (part == 3) throw std::runtime_error("part 3");
                                   ++finished;
                                 }),
                  std::runtime_error);
  CHECK(finished.load() == 4);
  CHECK_NOTHROW(run_on_threads(0, [](std::size_t) { throw std::runtime_error("never called"); }));
}

TEST_CASE("a CancelScope stops the loops that ask, on the threads the work is split over") {
  // No scope: nothing cancels.
  CHECK_NOTHROW(throw_if_cancelled("a loop"));
  CHECK(!current_cancel_check());
  std::atomic<int> asked{0};
  {
    const CancelScope scope([&] { return ++asked > 2; });
    CHECK_NOTHROW(throw_if_cancelled("a loop"));
    CHECK_NOTHROW(throw_if_cancelled("a loop"));
    try {
      throw_if_cancelled("the third round");
      FAIL("not cancelled");
    } catch (const Cancelled& c) {
      CHECK(c.where == "the third round");
    }
    {
      // The innermost scope decides; closing it gives the outer one back.
      const CancelScope inner([] { return false; });
      CHECK_NOTHROW(throw_if_cancelled("inner"));
    }
    CHECK_THROWS_AS(throw_if_cancelled("outer again"), Cancelled);
  }
  CHECK_NOTHROW(throw_if_cancelled("closed"));

  // The work run_on_threads and run_parts split over threads carries the caller's check: every
  // part stops, and the caller gets Cancelled (not a clay::Error: no fallback takes it).
  std::atomic<bool> stop{false};
  const CancelScope scope([&] { return stop.load(); });
  std::atomic<int> finished{0};
  run_on_threads(4, [&](std::size_t) {
    throw_if_cancelled("part");
    ++finished;
  });
  CHECK(finished.load() == 4);
  stop = true;
  CHECK_THROWS_AS(run_on_threads(4, [&](std::size_t) { throw_if_cancelled("part"); }), Cancelled);
  const Executor pool = [](std::size_t parts, const std::function<void(std::size_t)>& task) {
    // an embedder's pool: the parts on threads of its own
    std::vector<std::thread> threads;
    std::exception_ptr first;
    std::mutex m;
    for (std::size_t p = 0; p < parts; ++p)
      threads.emplace_back([&, p] {
        try {
          task(p);
        } catch (...) {
          const std::lock_guard lock(m);
          first = std::current_exception();
        }
      });
    for (auto& t : threads) t.join();
    if (first) std::rethrow_exception(first);
  };
  CHECK_THROWS_AS(internal::run_parts(3, pool, [](std::size_t) { throw_if_cancelled("part"); }),
                  Cancelled);
}

TEST_CASE("run_parts hands the parts to a supplied executor, and runs one part inline") {
  std::size_t asked = 0;
  const Executor serial = [&](std::size_t parts, const std::function<void(std::size_t)>& task) {
    asked = parts;
    for (std::size_t p = 0; p < parts; ++p) task(p);
  };
  std::vector<int> seen;
  internal::run_parts(3, serial, [&](std::size_t part) { seen.push_back(static_cast<int>(part)); });
  CHECK(asked == 3);
  CHECK(seen == std::vector<int>{0, 1, 2});
  asked = 0;
  internal::run_parts(1, serial, [&](std::size_t) {});
  CHECK(asked == 0);  // one part: no executor round trip
}
