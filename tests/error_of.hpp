#pragma once
// Catching a clay::Error in tests: its category and message, or a test failure when none is thrown.
#include <catch2/catch.hpp>

#include <clay/error.hpp>

#include <functional>
#include <string>
#include <utility>

namespace clay::test {

/// Category and what() of the clay::Error thrown by f; fails the test when nothing is thrown.
inline std::pair<clay::ErrorCategory, std::string> error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const clay::Error& e) {
    return {e.category(), e.what()};
  }
  FAIL("no clay::Error was thrown");
  return {};
}

}  // namespace clay::test
