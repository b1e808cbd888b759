#include <clay/summary.hpp>

#include <cstdio>

namespace clay {

std::string Summary::brief() const {
  const char* what = termination == Termination::Converged      ? "converged"
                     : termination == Termination::NotConverged ? "not converged"
                                                                : "failed";
  char buffer[160];
  std::snprintf(buffer, sizeof buffer, "%s in %d iterations, residual %.3g (from %.3g)", what,
                iterations, final_residual, initial_residual);
  std::string line = buffer;
  if (!message.empty()) line += ": " + message;
  return line;
}

}  // namespace clay
