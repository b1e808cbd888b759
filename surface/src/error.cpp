#include <clay/error.hpp>

namespace clay {

std::string_view to_string(ErrorCategory category) noexcept {
  switch (category) {
    case ErrorCategory::InvalidArgument:
      return "invalid argument";
    case ErrorCategory::InvalidGeometry:
      return "invalid geometry";
    case ErrorCategory::OutOfDomain:
      return "out of domain";
    case ErrorCategory::DegreeLimit:
      return "degree limit";
    case ErrorCategory::Io:
      return "i/o";
    case ErrorCategory::Exchange:
      return "exchange";
    case ErrorCategory::Document:
      return "document";
    case ErrorCategory::ToleranceNotMet:
      return "tolerance not met";
    case ErrorCategory::Internal:
      return "internal";
  }
  return "unknown";
}

Error::Error(ErrorCategory category, const std::string& message)
    : std::runtime_error(std::string(to_string(category)) + ": " + message),
      category_(category),
      message_(message) {}

}  // namespace clay
