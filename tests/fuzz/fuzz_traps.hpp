#pragma once
// The floating-point traps of the Debug tests (tests/main.cpp) for a fuzz target: invalid,
// divide by zero and overflow end the run, so a reader that computes with a value it should have
// refused is a finding. Call from LLVMFuzzerInitialize.
#if defined(__GLIBC__)
#include <fenv.h>
#endif

namespace clay::fuzz {

inline void enable_traps() {
#if defined(__GLIBC__)
  feenableexcept(FE_INVALID | FE_DIVBYZERO | FE_OVERFLOW);
#endif
}

}  // namespace clay::fuzz
