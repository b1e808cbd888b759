// A program outside the Clayform tree: builds a surface, evaluates it against a closed form and
// writes a STEP file through the installed library.
#include <clay/deform.hpp>

#include <cmath>
#include <cstdio>

int main(int argc, char** argv) {
  using namespace clay::surface;
  if (argc != 2) return 2;
  Points3 p(4, 3);
  p << 0, 0, 0, 0, 10, 0, 10, 0, 0, 10, 10, 5;
  const BSplineSurface s = make_surface(clamped_uniform_basis(1, 2), clamped_uniform_basis(1, 2), p);
  const double z = evaluate(s, 0.5, 0.5).z();  // bilinear: 5 * u * v
  const ExchangeReport r = write_step({s}, argv[1]);
  const bool ok = std::abs(z - 1.25) < 1e-15 && r.valid && read_step(argv[1]).size() == 1;
  std::printf("consumer %s (z = %.17g)\n", ok ? "ok" : "FAILED", z);
  return ok ? 0 : 1;
}
