// libFuzzer target: clay::deform::stack_from_json on arbitrary bytes. Its contract
// (clay/deform/stack.hpp): malformed input throws clay::Error, nothing else; a stack it accepts
// is valid, so to_json writes it and reading that back gives the same text (numbers in shortest
// round-trip form). Any other exception, a sanitizer report, a failed assertion or a
// floating-point trap (invalid, divide by zero, overflow) is a finding.
#include <clay/deform/stack.hpp>
#include <clay/error.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <string_view>

#include "fuzz_traps.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  clay::fuzz::enable_traps();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  clay::deform::DeformationStack stack;
  try {
    stack = clay::deform::stack_from_json(text);
  } catch (const clay::Error&) {
    return 0;  // bad text, reported as promised
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stack_from_json threw something other than clay::Error: %s\n", e.what());
    std::abort();
  }
  std::string once, twice;
  try {
    once = clay::deform::to_json(stack);
    twice = clay::deform::to_json(clay::deform::stack_from_json(once));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "an accepted stack did not round-trip: %s\n", e.what());
    std::abort();
  }
  if (once != twice) {
    std::fprintf(stderr, "an accepted stack's JSON changed on a round trip:\n%s\n%s\n",
                 once.c_str(), twice.c_str());
    std::abort();
  }
  return 0;
}
