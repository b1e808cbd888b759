#pragma once
// Where the B-rep tests write their files, the test models written by OpenCASCADE and read back
// by brep::read_model, and the lattice they are deformed by (shared by the tests of tests/brep).
#include <clay/deform/model_deformation.hpp>
#include <clay/occt/model_exchange.hpp>

#include <filesystem>
#include <string>

#include "occt_test_models.hpp"

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

/// A trilinear Bézier lattice around the box [lo, hi], its corner (1, 1, 1) moved by `move`.
inline deform::DeformationStack trilinear(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                          const Eigen::Vector3d& move) {
  deform::Frame frame;
  frame.origin = lo;
  frame.s = {hi.x() - lo.x(), 0, 0};
  frame.t = {0, hi.y() - lo.y(), 0};
  frame.u = {0, 0, hi.z() - lo.z()};
  auto lattice = deform::make_bezier_lattice(frame, {1, 1, 1});
  lattice.points.row(lattice.index(1, 1, 1)) += move.transpose();
  deform::DeformationStack stack;
  stack.steps.push_back({lattice, "corner", true});
  return stack;
}

}  // namespace clay::test
