// libFuzzer target: clay::recipe::check_recipe on arbitrary bytes. Its contract
// (clay/recipe/recipe.hpp): every problem of the text at once, and never a throw for bad text. So
// an exception escaping it is a finding, and so is a sanitizer report, a failed assertion, a
// floating-point trap (invalid, divide by zero, overflow) and a problem without a message.
#include <clay/recipe/recipe.hpp>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string_view>

#include "fuzz_traps.hpp"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  clay::fuzz::enable_traps();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    for (const auto& problem : clay::recipe::check_recipe(text, CLAY_FUZZ_BASE_DIR)) {
      if (problem.message.empty()) {
        std::fprintf(stderr, "check_recipe reported a problem without a message at \"%s\"\n",
                     problem.path.c_str());
        std::abort();
      }
      (void)clay::recipe::to_string(problem);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "check_recipe threw: %s\n", e.what());
    std::abort();
  }
  return 0;
}
