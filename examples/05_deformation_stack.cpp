// Example 05 — a deformation stack on a sampled parent surface: a global B-spline lattice bulge,
// a local cylindrical extended lattice pushing a dent (Coquillart 1990), a twist about the long
// axis and a bend over a middle region (Barr, as in Güdükbay–Özgüç 1990 §3). The stack is written
// to JSON, read back and applied again: the deformed points must be identical.
//
//   example_05_deformation_stack [output folder]   (default: a folder in the system temp dir)
//
// Exits non-zero if the lattice may fold, a point could not be frozen, the bulk path differs from
// deform_point by more than 1e-12 of the model size, or the JSON round trip changes a single bit.
#include <clay/deform.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

using namespace clay::deform;
namespace surface = clay::surface;

namespace {

/// A bicubic dome 200 x 80 mm, 20 mm high, its long axis along x.
surface::BSplineSurface parent_surface() {
  const int nu = 6, nv = 5;
  Points3 net(nu * nv, 3);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double x = -100 + 200.0 * i / (nu - 1), y = -40 + 80.0 * j / (nv - 1);
      const double z = 20 * (1 - (x / 120) * (x / 120)) * (1 - (y / 50) * (y / 50));
      net.row(i * nv + j) << x, y, z;
    }
  return surface::make_surface(surface::clamped_uniform_basis(3, nu),
                               surface::clamped_uniform_basis(3, nv), net);
}

bool identical(const Points3& a, const Points3& b) {
  return a.rows() == b.rows() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

int run(const std::filesystem::path& folder) {
  const surface::BSplineSurface hood = parent_surface();
  const Points3 samples =
      surface::evaluate_grid(hood, surface::linspace(0, 1, 81), surface::linspace(0, 1, 41));

  // 1. Global: a B-spline lattice around the surface, its middle columns raised (more on top).
  Frame frame;
  frame.origin = {-110, -50, -10};
  frame.s = {220, 0, 0};
  frame.t = {0, 100, 0};
  frame.u = {0, 0, 50};
  BSplineLattice bulge = make_bspline_lattice(frame, {3, 3, 2}, {3, 3, 1});  // 6 x 6 x 3 points
  for (int i = 2; i <= 3; ++i)
    for (int j = 2; j <= 3; ++j)
      for (int k = 0; k <= 2; ++k)
        bulge.points.row(bulge.index(i, j, k)) += Eigen::RowVector3d(0, 0, 2 + 4 * k);
  const JacobianBounds jacobian = jacobian_bounds(bulge);  // volume ratio bounds, fold_free

  // 2. Local: a cylindrical extended lattice around a vertical axis; its inner control points
  //    pushed down (deepest on the axis), the mantle kept, so the dent meets the surface C0.
  CylinderSpec spec;
  spec.origin = {45, 10, -10};
  spec.radius = 22;
  spec.height = 55;
  spec.sectors = 8;
  spec.rings = 2;
  spec.layers = 1;
  ExtendedLattice dent = make_cylindrical_lattice(spec);
  for (int radial = 0; radial < 3 * spec.rings; ++radial)  // radial 3 * rings: the mantle stays
    for (int angular = 0; angular < 3 * spec.sectors; ++angular)
      for (int axial = 0; axial <= 3 * spec.layers; ++axial) {
        // Set, not add: an axis row is shared by every angular index.
        const int row = cylindrical_index(spec, radial, angular, axial);
        dent.points(row, 2) = dent.rest(row, 2) - 7 * std::pow(1 - radial / 6.0, 2);
      }

  // 3. A twist about the long axis, 2 mrad per mm; 4. a bend of the middle 120 mm.
  const Twist twist{{Eigen::Vector3d(0, 0, 10), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ()},
                    {0, 0.002}};
  const Bend bend{{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitZ()},
                  -60,
                  60,
                  0,
                  0.003};  // y_min, y_max, centre, rate (rad/mm): radius 333 mm

  DeformationStack stack{
      {{bulge, "bulge", true}, {dent, "dent", true}, {twist, "twist", true}, {bend, "bend", true}}};
  Points3 out;
  StackReport report;                                    // what freezing the dent's points did
  deform_points(stack, samples, out, report);            // lattices frozen once, steps in order
  const std::string text = to_json(stack);               // clayform.deformation-stack, version 1
  const DeformationStack again = stack_from_json(text);  // bit-identical
  const Points3 out_again = deform_points(again, samples);

  // Write the JSON (a temporary file renamed, so nothing is half-written) and read it back.
  std::filesystem::create_directories(folder);
  const std::filesystem::path file = folder / "deformation_stack.json";
  const std::filesystem::path partial = folder / "deformation_stack.json.partial";
  {
    std::ofstream os(partial, std::ios::binary);
    os << text;
    if (!os) throw std::runtime_error("could not write " + partial.string());
  }
  std::filesystem::rename(partial, file);
  std::ifstream is(file, std::ios::binary);
  const std::string read_back{std::istreambuf_iterator<char>(is), std::istreambuf_iterator<char>()};
  const Points3 out_file = deform_points(stack_from_json(read_back), samples);

  // Checks: the bulk path against the stack's reference deform_point on a subset.
  const double size = (samples.colwise().maxCoeff() - samples.colwise().minCoeff()).norm();
  double worst = 0, moved = 0;
  for (Eigen::Index r = 0; r < samples.rows(); ++r) {
    moved = std::max(moved, (out.row(r) - samples.row(r)).norm());
    if (r % 37 == 0)
      worst = std::max(
          worst, (out.row(r).transpose() - deform_point(stack, samples.row(r).transpose())).norm());
  }
  const bool same = identical(out, out_again) && identical(out, out_file) && read_back == text;
  std::printf("%lld points of the parent surface, 4 steps; largest displacement %.3f mm\n",
              static_cast<long long>(samples.rows()), moved);
  std::printf("bulge lattice: volume ratio in [%.4f, %.4f], fold free: %s\n", jacobian.min,
              jacobian.max, jacobian.fold_free ? "yes" : "no");
  std::printf("dent: %s\n", report.brief().c_str());
  std::printf("bulk vs deform_point: %.2e of the size (%.1f mm)\n", worst / size, size);
  std::printf("JSON: %zu bytes in %s; read back and applied again: %s\n", text.size(),
              file.string().c_str(), same ? "identical" : "DIFFERENT");
  return jacobian.fold_free && report.converged() && worst <= 1e-12 * size && same ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::filesystem::path folder =
        argc > 1 ? std::filesystem::path(argv[1])
                 : std::filesystem::temp_directory_path() / "clayform-example-05";
    return run(folder);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "example 05 failed: %s\n", e.what());
    return 2;
  }
}
