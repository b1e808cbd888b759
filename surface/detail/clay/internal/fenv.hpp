#pragma once
// The floating-point environment held for a scope (internal, not installed).
#include <cfenv>

namespace clay::internal {

/// While alive, floating-point exceptions raise flags but do not trap; the caller's environment,
/// its traps and flags, comes back on the way out. For code that meets non-finite values by
/// design: strtod reports a literal beyond the range of a double by raising overflow, as C
/// requires, and OpenCASCADE's algorithms may divide by zero and expect IEEE results. A host that
/// traps those exceptions (the Debug tests do, tests/main.cpp) would otherwise die of the very
/// number a reader exists to refuse.
class FpTrapsHeld {
 public:
  FpTrapsHeld() { std::feholdexcept(&saved_); }
  ~FpTrapsHeld() { std::fesetenv(&saved_); }
  FpTrapsHeld(const FpTrapsHeld&) = delete;
  FpTrapsHeld& operator=(const FpTrapsHeld&) = delete;

 private:
  std::fenv_t saved_;
};

}  // namespace clay::internal
