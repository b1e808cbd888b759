// A program outside the Clayform tree: builds a surface, evaluates it against a closed form and
// writes a STEP file through the installed library; solves a small sketch (clay_constraints, which
// links Ceres privately), deforms a point with an undisplaced lattice and round-trips a
// deformation stack through JSON (clay_deform, which links nlohmann-json privately).
#include <clay/constraints.hpp>
#include <clay/deform.hpp>
#include <clay/occt.hpp>
#include <clay/version.hpp>

#include <cmath>
#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  using namespace clay::surface;
  if (argc != 2) return 2;
  Points3 p(4, 3);
  p << 0, 0, 0, 0, 10, 0, 10, 0, 0, 10, 10, 5;
  const BSplineSurface s =
      make_surface(clamped_uniform_basis(1, 2), clamped_uniform_basis(1, 2), p);
  const double z = evaluate(s, 0.5, 0.5).z();  // bilinear: 5 * u * v
  const ExchangeReport r = write_step({s}, argv[1]);
  // A segment fixed at one end, horizontal, 7 mm long: its far end lands at (7, 0, 0).
  clay::sketch::Sketch sk;
  const auto plane = sk.add_plane({});
  const auto a = sk.add_point(plane, {0, 0}), b = sk.add_point(plane, {5, 1});
  const auto line = sk.add_line(a, b);
  namespace cs = clay::constraints;
  const cs::SolveResult solved =
      cs::solve(sk, {cs::fixed(a), cs::horizontal(line), cs::distance(a, b, 7)});
  const double far = (clay::sketch::position(solved.sketch, b) - Eigen::Vector3d(7, 0, 0)).norm();
  // An undisplaced lattice is the identity.
  const clay::deform::BezierLattice lattice =
      clay::deform::make_bezier_lattice({Eigen::Vector3d::Zero(), Eigen::Vector3d(10, 0, 0),
                                         Eigen::Vector3d(0, 10, 0), Eigen::Vector3d(0, 0, 10)},
                                        {3, 3, 3});
  const double moved =
      (clay::deform::deform_point(lattice, Eigen::Vector3d(2, 3, 4)) - Eigen::Vector3d(2, 3, 4))
          .norm();
  const clay::deform::DeformationStack stack{
      {{lattice, "global"}, {clay::deform::Twist{{}, {0.0, 0.1}}, "twist"}}};
  const Eigen::Vector3d x(2, 3, 4);
  const bool stack_ok =
      clay::deform::deform_point(clay::deform::stack_from_json(clay::deform::to_json(stack)), x) ==
      clay::deform::deform_point(stack, x);
  const bool ok =
      std::abs(z - 1.25) < 1e-15 && r.valid && read_step(argv[1]).size() == 1 &&
      solved.report.summary.converged() && far < 1e-10 && moved < 1e-12 && stack_ok &&
      clay::version() == CLAYFORM_VERSION_STRING;  // the installed headers and library agree
  std::printf("consumer %s (z = %.17g, Clayform %s)\n", ok ? "ok" : "FAILED", z,
              std::string(clay::version()).c_str());
  return ok ? 0 : 1;
}
