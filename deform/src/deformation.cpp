#include <clay/deform/deformation.hpp>

#include <clay/error.hpp>
#include <clay/internal/checks.hpp>

#include <string>

namespace clay::deform {

std::vector<std::string> DeformOptions::problems() const {
  std::vector<std::string> out;
  if (threads < 0 || threads > 1024)
    out.push_back("DeformOptions::threads = " + std::to_string(threads) +
                  " breaks the rule 0 <= threads <= 1024 (0 = one per hardware thread)");
  return out;
}

void DeformOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

}  // namespace clay::deform
