// clay::version(): the version compiled into the library (clay/version.hpp is generated from the
// same project(VERSION), so a mismatch means headers and library come from different builds).
#include <clay/version.hpp>

namespace clay {

std::string_view version() noexcept { return CLAYFORM_VERSION_STRING; }

Version version_numbers() noexcept { return header_version; }

}  // namespace clay
