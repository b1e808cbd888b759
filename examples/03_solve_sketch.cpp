// Example 03: a constrained profile sketch — a slot of two lines and two arcs joined with G1,
// dimensioned and solved (DOF 0); then a contradicting dimension, which the solver names.
// Run: example_03_solve_sketch   (exit code 0 when both outcomes are as expected)
#include <clay/constraints.hpp>

#include <cmath>
#include <cstdio>
#include <numbers>

using namespace clay::constraints;

int main() {
  clay::sketch::Sketch s;
  const PlaneId xy = s.add_plane({});
  // Drawn roughly: centres 59 mm apart, radii 9.5 and 10.5, ends a little off.
  const Eigen::Vector2d right_centre(59, 0), left_centre(0, 0.5);
  auto polar = [](const Eigen::Vector2d& centre, double r, double degrees) {
    const double t = degrees * std::numbers::pi / 180;
    return Eigen::Vector2d(centre + r * Eigen::Vector2d(std::cos(t), std::sin(t)));
  };
  const PointId right = s.add_point(xy, right_centre), left = s.add_point(xy, left_centre);
  const PointId b = s.add_point(xy, polar(right_centre, 9.5, -95)),
                c = s.add_point(xy, polar(right_centre, 9.5, 88));
  const PointId d = s.add_point(xy, polar(left_centre, 10.5, 92)),
                a = s.add_point(xy, polar(left_centre, 10.5, 268));
  const EntityId bottom = s.add_line(a, b), top = s.add_line(c, d);
  const EntityId arc_right = s.add_arc(right, b, c, xy);  // counterclockwise from b up to c
  const EntityId arc_left = s.add_arc(left, d, a, xy);    // from d down to a

  std::vector<Constraint> cs = {
      fixed(left),
      horizontal(bottom),
      tangent(end_of(bottom), start_of(arc_right)),
      tangent(end_of(arc_right), start_of(top)),
      tangent(end_of(top), start_of(arc_left)),
      tangent(end_of(arc_left), start_of(bottom)),
      distance(left, right, 60),
      radius(arc_left, 10),
      equal_radius(arc_left, arc_right),
  };
  const SolveResult solved = solve(s, cs);
  std::printf("slot: %s\n", solved.report.summary.brief().c_str());
  std::printf("  %d unknowns, %d substituted, %d equations, %d component(s), DOF %d, %.3f ms\n",
              solved.report.unknowns, solved.report.substituted, solved.report.equations,
              solved.report.components, solved.report.degrees_of_freedom,
              1e3 * (solved.report.solve_seconds + solved.report.diagnose_seconds));
  const Eigen::Vector3d pa = clay::sketch::position(solved.sketch, a);
  const Eigen::Vector3d pb = clay::sketch::position(solved.sketch, b);
  std::printf("  bottom edge from (%.9f, %.9f) to (%.9f, %.9f)\n", pa.x(), pa.y(), pb.x(), pb.y());
  // Independent check: the bottom edge runs under the centres, 10 mm below them.
  const bool first_ok = solved.report.summary.converged() &&
                        solved.report.degrees_of_freedom == 0 && std::abs(pa.x() - 0) < 1e-9 &&
                        std::abs(pa.y() - (0.5 - 10)) < 1e-9 && std::abs(pb.x() - 60) < 1e-9;

  // A bottom length that contradicts the centre distance.
  cs.push_back(distance(a, b, 55));
  cs.back().label = "bottom length";
  const SolveResult clash = solve(s, cs);
  std::printf("with a 55 mm bottom length: %s\n", clash.report.summary.brief().c_str());
  for (const Dependency& dep : clash.report.conflicting) std::printf("  %s\n", dep.message.c_str());
  const bool second_ok = !clash.report.conflicting.empty();
  return first_ok && second_ok ? 0 : 1;
}
