// clay_check_gltf GLB STEP: checks a glTF preview against the surfaces it previews (issue #18):
// the GLB's triangles, read back by tests/gltf_reader.hpp (not through OpenCASCADE), must cover
// the STEP file's surfaces — total area within 1 % of the NURBS area by Gauss–Legendre
// quadrature (surface_area), bounding box within 1e-3 of the size of a 401 x 401 sample of the
// NURBS. A STEP file holding a solid (a whole model, brep::read_model) is checked by volume
// instead, its faces being trimmed: the volume the GLB's triangles enclose (divergence theorem)
// within 1 % of the solids' volume by Green's theorem on the trimmed NURBS faces
// (brep::volume_mm3), and every triangle corner within 1 % of the size of the model's box.
// Prints the figures; exit 0 when they hold, 1 otherwise, 2 on a read error.
#include <clay/brep/volume.hpp>
#include <clay/error.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/tessellate.hpp>

#include <cstdio>
#include <exception>

#include "gltf_reader.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: clay_check_gltf FILE.glb FILE.step\n");
    return 2;
  }
  try {
    const clay::test::GltfTriangles mesh = clay::test::read_glb(argv[1]);
    const clay::brep::Model model = clay::brep::read_model(argv[2]).model;
    if (clay::brep::counts(model).solids > 0) {
      const double exact = clay::brep::volume_mm3(model);
      double volume = 0;
      for (const auto& t : mesh.triangles) volume += t[0].dot(t[1].cross(t[2])) / 6;
      // The model's box from its faces' points on a 33 x 33 grid (a loose box: the untrimmed
      // NURBS reaches a little past the faces, and the preview must stay inside it).
      Eigen::AlignedBox3d box;
      for (const auto& face : clay::brep::flattened(model).faces) {
        const auto [u0, u1] = face.surface.u.domain();
        const auto [v0, v1] = face.surface.v.domain();
        const auto grid = clay::surface::evaluate_grid(
            face.surface, clay::surface::linspace(u0, u1, 33), clay::surface::linspace(v0, v1, 33));
        for (Eigen::Index r = 0; r < grid.rows(); ++r)
          box.extend(Eigen::Vector3d(grid.row(r).transpose()));
      }
      const Eigen::AlignedBox3d got = mesh.box();
      const double size = box.diagonal().norm();
      const double outside =
          std::max({(box.min() - got.min()).maxCoeff(), (got.max() - box.max()).maxCoeff(), 0.0});
      const double volume_error = std::abs(volume - exact) / std::abs(exact);
      std::printf(
          "%s: %zu triangles, volume %.6g mm^3 (the solids' %.6g mm^3, off %.3g %%), %.3g of the "
          "size outside the model's box\n",
          argv[1], mesh.triangles.size(), volume, exact, 100 * volume_error, outside / size);
      const bool ok = !mesh.triangles.empty() && volume_error <= 0.01 && outside <= 0.01 * size;
      if (!ok) std::printf("FAILED: the preview does not enclose the model's solids\n");
      return ok ? 0 : 1;
    }
    double area = 0;
    Eigen::AlignedBox3d box;
    for (const auto& s : clay::surface::read_step(argv[2])) {
      area += clay::surface::surface_area(s, 2);
      const auto [u0, u1] = s.u.domain();
      const auto [v0, v1] = s.v.domain();
      const auto dense = clay::surface::evaluate_grid(s, clay::surface::linspace(u0, u1, 401),
                                                      clay::surface::linspace(v0, v1, 401));
      for (Eigen::Index r = 0; r < dense.rows(); ++r)
        box.extend(Eigen::Vector3d(dense.row(r).transpose()));
    }
    const Eigen::AlignedBox3d got = mesh.box();
    const double size = box.diagonal().norm();
    const double area_error = std::abs(mesh.area() - area) / area;
    const double box_error =
        std::max((got.min() - box.min()).norm(), (got.max() - box.max()).norm()) / size;
    std::printf(
        "%s: %zu triangles, area %.6g mm^2 (NURBS %.6g mm^2, off %.3g %%), bounding box off %.3g "
        "of the size\n",
        argv[1], mesh.triangles.size(), mesh.area(), area, 100 * area_error, box_error);
    const bool ok = !mesh.triangles.empty() && area_error <= 0.01 && box_error <= 1e-3;
    if (!ok) std::printf("FAILED: the preview does not cover its surfaces\n");
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "clay_check_gltf: %s\n", e.what());
    return 2;
  }
}
