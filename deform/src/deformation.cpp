#include <clay/deform/deformation.hpp>

#include <clay/error.hpp>

#include <string>

namespace clay::deform {

void DeformOptions::validate() const {
  if (threads < 0 || threads > 1024)
    throw Error(ErrorCategory::InvalidArgument,
                "DeformOptions::threads = " + std::to_string(threads) +
                    " breaks the rule 0 <= threads <= 1024 (0 = one per hardware thread)");
}

}  // namespace clay::deform
