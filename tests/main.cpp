// Catch2 main. Debug builds trap floating-point exceptions (invalid, divide by zero, overflow) so a
// NaN born inside the kernel stops the test where it is made (libigl's practice).
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#if !defined(NDEBUG) && defined(__GLIBC__)
#include <fenv.h>
#endif

int main(int argc, char* argv[]) {
#if !defined(NDEBUG) && defined(__GLIBC__)
  feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
#endif
  return Catch::Session().run(argc, argv);
}
