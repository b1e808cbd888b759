#pragma once
// Where the B-rep tests write their files, and the test models written by OpenCASCADE and read
// back by brep::read_model (shared by the tests of tests/brep).
#include <clay/brep/exchange.hpp>

#include <filesystem>
#include <string>

#include "occt/test_models.hpp"

namespace clay::test {

/// CLAY_TEST_OUTPUT_DIR/folder/name, the folder created.
inline std::filesystem::path test_output(const std::string& folder, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::path(CLAY_TEST_OUTPUT_DIR) / folder;
  std::filesystem::create_directories(dir);
  return dir / name;
}

/// `model` written to `file` (STEP or IGES by its extension) and read back whole.
inline brep::Model read_test_model(surface::occt_reference::TestModel model,
                                   const std::filesystem::path& file) {
  surface::occt_reference::write_test_model(model, file);
  return brep::read_model(file).model;
}

}  // namespace clay::test
