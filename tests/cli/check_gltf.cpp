// clay_check_gltf GLB STEP: checks a glTF preview against the surfaces it previews (issue #18):
// the GLB's triangles, read back by tests/gltf_reader.hpp (not through OpenCASCADE), must cover
// the STEP file's surfaces — total area within 1 % of the NURBS area by Gauss–Legendre
// quadrature (surface_area), bounding box within 1e-3 of the size of a 401 x 401 sample of the
// NURBS. Prints the figures; exit 0 when both hold, 1 otherwise, 2 on a read error.
#include <clay/error.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/exchange.hpp>
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
