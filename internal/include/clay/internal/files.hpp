#pragma once
// Reading a whole text file (internal, not installed): recipes read by the library, the studio
// and the Python package, with one message when the file cannot be read.
#include <clay/error.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace clay::internal {

/// The file's bytes. Throws clay::Error(Io) naming `what` and the file ("cannot read the recipe
/// \"x.json\"; check the path").
inline std::string read_text(const std::filesystem::path& file, const std::string& what) {
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw Error(ErrorCategory::Io,
                "cannot read the " + what + " \"" + file.string() + "\"; check the path");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace clay::internal
