// Example 07 — exact FFD composition: a bicubic sheet (4 x 4 Bézier patches, C2) deformed by a
// Bézier lattice of degrees (2, 2, 1) whose top layer is pushed up into a dome. compose_exact
// gives the deformed surface as one exact NURBS surface, written to STEP and IGES and read back.
// The sheet's s depends on its u only and t on its v only (cubics), its height on both: by the
// rule 2*3 + 2*0 + 1*3 = 9 per direction, not (2+2+1)*3 = 15; the interior knots come out with
// multiplicity 9 - 2 = 7 (C2 kept).
//
//   example_07_compose_exact [output folder]   (default: a folder in the system temp dir)
//
// Exits non-zero if the composed surface differs from the pointwise deformation by more than
// 1e-12 of the lattice size, or if a read-back surface is not bit-identical.
#include <clay/deform.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>

using namespace clay::deform;
namespace surface = clay::surface;

int main(int argc, char** argv) {
  try {
    const std::filesystem::path folder =
        argc > 1 ? std::filesystem::path(argv[1])
                 : std::filesystem::temp_directory_path() / "clayform-example-07";
    std::filesystem::create_directories(folder);

    Frame frame;  // a 200 x 120 x 60 mm box
    frame.origin = {-100, -60, -10};
    frame.s = {200, 0, 0};
    frame.t = {0, 120, 0};
    frame.u = {0, 0, 60};
    BezierLattice lattice = make_bezier_lattice(frame, {2, 2, 1});
    lattice.points.row(lattice.index(1, 1, 1)) += Eigen::RowVector3d(0, 0, 40);  // the dome
    lattice.points.row(lattice.index(1, 1, 0)) += Eigen::RowVector3d(0, 0, 15);

    // A gently waved bicubic sheet in the middle of the box: 7 x 7 control points, uniform knots.
    surface::BSplineSurface sheet;
    sheet.u = surface::clamped_uniform_basis(3, 7, 0, 1);
    sheet.v = surface::clamped_uniform_basis(3, 7, 0, 1);
    sheet.points.resize(49, 3);
    sheet.weights = Eigen::VectorXd::Ones(49);
    for (int i = 0; i < 7; ++i)
      for (int j = 0; j < 7; ++j)
        sheet.points.row(sheet.index(i, j)) =
            frame.point(0.1 + 0.8 * i / 6, 0.1 + 0.8 * j / 6, 0.3 + 0.05 * ((i + j) % 3))
                .transpose();

    const ComposeResult result = compose_exact(lattice, sheet);
    std::printf("%s\n", result.report.brief().c_str());

    // Independent check: the pointwise deformation at a grid of parameters.
    double worst = 0;
    for (int a = 0; a <= 40; ++a)
      for (int b = 0; b <= 40; ++b) {
        const double u = a / 40.0, v = b / 40.0;
        const Eigen::Vector3d expected = deform_point(lattice, surface::evaluate(sheet, u, v));
        worst = std::max(worst, (surface::evaluate(result.surface, u, v) - expected).norm());
      }
    const double size =
        (lattice.points.colwise().maxCoeff() - lattice.points.colwise().minCoeff()).norm();
    std::printf("pointwise check: max deviation %.3g mm (%.3g of the lattice size)\n", worst,
                worst / size);

    const auto step = folder / "composed.step", iges = folder / "composed.igs";
    const surface::ExchangeReport written = surface::write_step({result.surface}, step);
    surface::write_iges({result.surface}, iges);
    const bool same = surface::identical(surface::read_step(step).at(0), result.surface) &&
                      surface::identical(surface::read_iges(iges).at(0), result.surface);
    std::printf("wrote %s and %s (degree %d, %ld control points), read back %s\n",
                step.string().c_str(), iges.string().c_str(), written.max_degree,
                written.control_points, same ? "bit-identical" : "DIFFERENT");
    return worst <= 1e-12 * size && same ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
