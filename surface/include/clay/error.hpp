#pragma once
/// clay::Error — the one exception type raised at Clayform's API boundaries.
///
/// Every error carries a category (what kind of problem, mapped to exit codes by the CLI) and a
/// message that names the offending object, the value found and what would fix it.
#include <clay/surface/export.hpp>

#include <stdexcept>
#include <string>
#include <string_view>

namespace clay {

/// What kind of problem an Error reports.
enum class ErrorCategory {
  InvalidArgument,  ///< a parameter or option outside its documented range
  InvalidGeometry,  ///< geometry that breaks an invariant (knots, counts, weights, NaN)
  OutOfDomain,      ///< a parameter outside the object's parameter domain
  DegreeLimit,      ///< a degree above what an exchange format or algorithm supports
  Io,               ///< a file could not be read, written or renamed
  Exchange,         ///< a STEP/IGES/glTF translation failed or produced invalid geometry
  Document,         ///< a malformed JSON document (a recipe, a deformation stack, a studio
                    ///< autosave) or a reference in it to a missing object
  ToleranceNotMet,  ///< a result misses its tolerance (a refit's certified bound, a style target):
                    ///< a failure, not a warning; the message names the figure and the way out
  Internal,         ///< a kernel bug: please report it
};

/// Human-readable name of a category ("invalid geometry", ...).
CLAY_SURFACE_API std::string_view to_string(ErrorCategory category) noexcept;

/// The exception raised by Clayform. what() is "<category>: <message>".
class CLAY_SURFACE_API Error : public std::runtime_error {
 public:
  /// Build an error of `category` whose message names the object, the value and the fix.
  Error(ErrorCategory category, const std::string& message);

  /// The category of the error.
  ErrorCategory category() const noexcept { return category_; }
  /// The message without the category prefix.
  const std::string& message() const noexcept { return message_; }

 private:
  ErrorCategory category_;
  std::string message_;
};

}  // namespace clay
