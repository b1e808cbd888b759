// A program that uses only the OCCT-free core (Clayform::surface): builds, evaluates, refines and
// tessellates a NURBS surface. tests/house/check_core_only.cmake runs ldd on it: no OpenCASCADE
// library may be loaded (issue #19: evaluating a NURBS once loaded ~30 OCCT toolkits).
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/surface/tessellate.hpp>

#include <cmath>
#include <cstdio>

int main() {
  using namespace clay::surface;
  Points3 p(4, 3);
  p << 0, 0, 0, 0, 10, 0, 10, 0, 0, 10, 10, 5;
  const BSplineSurface s =
      make_surface(clamped_uniform_basis(1, 2), clamped_uniform_basis(1, 2), p);
  const double z = evaluate(s, 0.5, 0.5).z();  // bilinear: 5 u v
  const double area = mesh_area(tessellate(insert_knot_u(s, 0.5, 1)));
  std::printf("z(0.5, 0.5) = %.17g, mesh area %.6g mm^2\n", z, area);
  return std::abs(z - 1.25) < 1e-15 && area > 100 ? 0 : 1;
}
