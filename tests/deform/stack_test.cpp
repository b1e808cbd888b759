// Deformation stacks: the composition of the steps' own deform_point (computed here step by
// step), the bulk path against it, JSON round trips bit for bit, and every malformed input.
#include <catch2/catch.hpp>

#include <clay/deform.hpp>

#include <bit>
#include <cfenv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <tuple>

#include "error_of.hpp"
#include "fixtures.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using clay::ErrorCategory;
using clay::test::error_of;

static_assert(PointDeformation<DeformationStack>);

namespace {

/// The four-step stack of the tests: a displaced Bézier lattice (global), a twist about an axis
/// through it, a displaced B-spline lattice over the twisted region, a bend.
DeformationStack sample_stack(std::mt19937& rng) {
  const Frame f = clay::test::random_frame(rng);
  const Eigen::Vector3d centre = f.point(0.5, 0.5, 0.5);
  const BezierLattice bezier = clay::test::displaced(make_bezier_lattice(f, {3, 2, 3}), rng, 0.08);
  Twist twist{{centre, f.u, f.s}, {0.1, 0.01, -1e-4}};
  Frame g = f;  // a bigger lattice around the twisted region
  g.origin = f.point(-0.25, -0.25, -0.25);
  g.s *= 1.5, g.t *= 1.5, g.u *= 1.5;
  const BSplineLattice bspline =
      clay::test::displaced(make_bspline_lattice(g, {3, 2, 3}, {3, 4, 2}), rng, 0.06);
  Bend bend{{centre, f.t, f.u}, -20, 25, 2, 0.02};
  return {{{bezier, "global", true},
           {twist, "twist", true},
           {bspline, "local", true},
           {bend, "", true}}};
}

Points3 sample_points(const DeformationStack& stack, std::mt19937& rng, int n) {
  return clay::test::sample_points(std::get<BezierLattice>(stack.steps[0].deformation).frame, rng,
                                   n, -0.1, 1.1);
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

template <class M>
bool same_bits(const M& a, const M& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return false;
  for (Eigen::Index i = 0; i < a.size(); ++i)
    if (!same_bits(a.data()[i], b.data()[i])) return false;
  return true;
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!same_bits(a[i], b[i])) return false;
  return true;
}

bool same_bits(const Frame& a, const Frame& b) {
  return same_bits(a.origin, b.origin) && same_bits(a.s, b.s) && same_bits(a.t, b.t) &&
         same_bits(a.u, b.u);
}
bool same_bits(const AxisFrame& a, const AxisFrame& b) {
  return same_bits(a.origin, b.origin) && same_bits(a.axis, b.axis) &&
         same_bits(a.reference, b.reference);
}

bool same_step(const Deformation& a, const Deformation& b) {
  if (a.index() != b.index()) return false;
  if (auto* p = std::get_if<BezierLattice>(&a)) {
    const auto& q = std::get<BezierLattice>(b);
    return same_bits(p->frame, q.frame) && p->degrees == q.degrees &&
           same_bits(p->points, q.points);
  }
  if (auto* p = std::get_if<BSplineLattice>(&a)) {
    const auto& q = std::get<BSplineLattice>(b);
    bool ok = same_bits(p->frame, q.frame) && same_bits(p->points, q.points);
    for (int d = 0; d < 3; ++d)
      ok = ok && p->bases[d].degree == q.bases[d].degree &&
           same_bits(p->bases[d].knots, q.bases[d].knots);
    return ok;
  }
  if (auto* p = std::get_if<ExtendedLattice>(&a)) {
    const auto& q = std::get<ExtendedLattice>(b);
    return same_bits(p->rest, q.rest) && same_bits(p->points, q.points) && p->chunks == q.chunks;
  }
  if (auto* p = std::get_if<Taper>(&a)) {
    const auto& q = std::get<Taper>(b);
    return same_bits(p->frame, q.frame) && same_bits(p->profile, q.profile);
  }
  if (auto* p = std::get_if<Twist>(&a)) {
    const auto& q = std::get<Twist>(b);
    return same_bits(p->frame, q.frame) && same_bits(p->angle, q.angle);
  }
  const auto& p = std::get<Bend>(a);
  const auto& q = std::get<Bend>(b);
  return same_bits(p.frame, q.frame) && same_bits(p.y_min, q.y_min) &&
         same_bits(p.y_max, q.y_max) && same_bits(p.center, q.center) && same_bits(p.rate, q.rate);
}

/// A stack of every kind with random full-precision numbers (tiny, huge, negative, subnormal).
DeformationStack random_stack(std::mt19937& rng) {
  std::uniform_real_distribution<double> c(-1, 1);
  auto messy = [&] {
    return c(rng) * std::pow(10.0, std::uniform_int_distribution<int>(-12, 12)(rng));
  };
  DeformationStack s = sample_stack(rng);
  Taper taper{{Eigen::Vector3d(messy(), messy(), 1 / 3.0), Eigen::Vector3d(c(rng), c(rng), 1),
               Eigen::Vector3d(1, c(rng), c(rng))},
              {1 + c(rng), messy(), 4.9e-324, -0.0}};
  s.steps.push_back({taper, "taper \"quoted\" \\ ünïcode", false});
  const Frame f = clay::test::random_frame(rng);
  auto knots = clay::surface::clamped_uniform_basis(2, 5);
  knots.knots[3] = 0.1 + 0.3 * std::abs(c(rng));  // non-uniform interior knot
  s.steps.push_back({clay::test::displaced(
                         make_bspline_lattice(f, {knots, clay::surface::clamped_uniform_basis(1, 2),
                                                  clay::surface::clamped_uniform_basis(3, 4)}),
                         rng, 0.2),
                     "non-uniform", true});
  return s;
}

}  // namespace

TEST_CASE("a stack applies its steps in order, the first one globally", "[deform][stack]") {
  std::mt19937 rng(21);
  const DeformationStack stack = sample_stack(rng);
  const auto& bezier = std::get<BezierLattice>(stack.steps[0].deformation);
  const auto& twist = std::get<Twist>(stack.steps[1].deformation);
  const auto& bspline = std::get<BSplineLattice>(stack.steps[2].deformation);
  const auto& bend = std::get<Bend>(stack.steps[3].deformation);
  const Points3 points = sample_points(stack, rng, 300);
  int moved_by_each = 0;
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    const Eigen::Vector3d x = points.row(r).transpose();
    const Eigen::Vector3d a = deform_point(bezier, x), b = deform_point(twist, a),
                          c = deform_point(bspline, b), d = deform_point(bend, c);
    CHECK(same_bits(deform_point(stack, x), d));
    moved_by_each += (a != x) && (b != a) && (c != b) && (d != c);
  }
  CHECK(moved_by_each > 100);  // the sample exercises every step
  // Order matters: the reversed stack gives another map.
  DeformationStack reversed{{stack.steps.rbegin(), stack.steps.rend()}};
  CHECK((deform_point(reversed, points.row(0).transpose()) -
         deform_point(stack, points.row(0).transpose()))
            .norm() > 1e-3);
  // A disabled step is skipped; an empty stack is the identity.
  DeformationStack skipping = stack;
  skipping.steps[1].enabled = false;
  const Eigen::Vector3d x = points.row(5).transpose();
  CHECK(same_bits(deform_point(skipping, x),
                  deform_point(bend, deform_point(bspline, deform_point(bezier, x)))));
  CHECK(same_bits(deform_point(DeformationStack{}, x), x));
}

TEST_CASE("deform_points on a stack equals deform_point per point", "[deform][stack]") {
  std::mt19937 rng(22);
  DeformationStack stack = sample_stack(rng);
  stack.steps.push_back(
      {Taper{{Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(0, 1, 1), Eigen::Vector3d(1, 0, 0)},
             {1, 0.002, -1e-5}},
       "", true});
  stack.steps.push_back({Twist{}, "off", false});
  const Points3 points = sample_points(stack, rng, 40000);  // two workers
  const Points3 out = deform_points(stack, points, DeformOptions{2});
  const double size = clay::test::size_of(points);
  double worst = 0;
  for (Eigen::Index r = 0; r < points.rows(); r += 13)
    worst = std::max(
        worst, (out.row(r).transpose() - deform_point(stack, points.row(r).transpose())).norm());
  CHECK(worst < 1e-13 * size);
  Points3 in_place = points;
  deform_points(stack, in_place, in_place, DeformOptions{2});
  CHECK(same_bits(in_place, out));
  CHECK(same_bits(deform_points(DeformationStack{}, points), points));
}

TEST_CASE("JSON round trips every kind bit for bit", "[deform][stack]") {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 3; ++trial) {
    const DeformationStack stack = random_stack(rng);
    const std::string text = to_json(stack);
    CHECK_THAT(
        text, Contains("\"format\": \"clayform.deformation-stack\"") && Contains("\"version\": 1"));
    const DeformationStack back = stack_from_json(text);
    REQUIRE(back.steps.size() == stack.steps.size());
    for (std::size_t i = 0; i < stack.steps.size(); ++i) {
      CHECK(same_step(back.steps[i].deformation, stack.steps[i].deformation));
      CHECK(back.steps[i].name == stack.steps[i].name);
      CHECK(back.steps[i].enabled == stack.steps[i].enabled);
    }
    CHECK(to_json(back) == text);  // and the text is stable
    const Points3 points = sample_points(stack, rng, 500);
    CHECK(same_bits(deform_points(back, points), deform_points(stack, points)));
  }
  // Every kind name appears, and an empty stack round-trips too.
  const std::string text = to_json(random_stack(rng));
  for (const char* kind : {"bezier_lattice", "bspline_lattice", "taper", "twist", "bend"})
    CHECK_THAT(text, Contains(std::string("\"kind\":\"") + kind + "\""));
  CHECK(stack_from_json(to_json(DeformationStack{})).steps.empty());
  CHECK(kind_name(Bend{}) == "bend");
  CHECK(kind_name(ExtendedLattice{}) == "extended_lattice");
}

TEST_CASE("hand-written JSON may leave out name and enabled and use integers", "[deform][stack]") {
  const DeformationStack s =
      stack_from_json(R"({"format": "clayform.deformation-stack", "version": 1, "steps": [
      {"kind": "twist", "frame": {"origin": [0, 0, 0], "axis": [0, 0, 2], "reference": [1, 0, 0]}, "angle": [0, 1]}]})");
  REQUIRE(s.steps.size() == 1);
  CHECK(s.steps[0].enabled);
  CHECK(s.steps[0].name.empty());
  const Eigen::Vector3d p = deform_point(s, {1, 0, std::numbers::pi / 2});  // θ = z: a quarter turn
  CHECK((p - Eigen::Vector3d(0, 1, std::numbers::pi / 2)).norm() < 1e-15);
}

TEST_CASE("malformed stack JSON is rejected naming the path and the fix", "[deform][stack]") {
  std::mt19937 rng(24);
  const std::string good = to_json(sample_stack(rng));
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    const auto at = t.find(from);
    REQUIRE(at != std::string::npos);
    return t.replace(at, from.size(), to);
  };
  auto recipe_error = [](const std::string& text) {
    const auto [category, what] = error_of([&] { stack_from_json(text); });
    CHECK(category == ErrorCategory::Document);
    return what;
  };
  CHECK_THAT(recipe_error("{\"format\": "),
             Contains("not valid JSON") && Contains("fix the syntax"));
  CHECK_THAT(recipe_error(replaced("\"version\": 1", "\"version\": 2")),
             Contains("version: the number 2 is not supported") && Contains("reads version 1"));
  CHECK_THAT(
      recipe_error(replaced("clayform.deformation-stack", "clayform.recipe")),
      Contains(
          "format: expected \"clayform.deformation-stack\", found the string \"clayform.recipe\""));
  CHECK_THAT(
      recipe_error(replaced("\"kind\":\"twist\"", "\"kind\":\"wobble\"")),
      Contains("steps[1].kind: unknown kind \"wobble\"") &&
          Contains("one of bezier_lattice, bspline_lattice, extended_lattice, taper, twist, bend"));
  CHECK_THAT(recipe_error(replaced("\"rate\":", "\"rat\":1,\"rate\":")),
             Contains("steps[3].rat: unknown key \"rat\" in a bend step") &&
                 Contains("y_min, y_max, center, rate"));
  CHECK_THAT(recipe_error(replaced(",\"y_min\":-20.0", "")),
             Contains("steps[3].y_min: missing; give the start of the bent region"));
  // points[5] of the first lattice with two numbers.
  {
    std::string t = good;
    std::size_t at = t.find("\"points\":[");
    for (int k = 0; k < 7; ++k) at = t.find('[', at + 1);  // the array, then points[0..5]
    const auto comma = t.find(',', at);
    const auto close = t.find(']', at);
    t.erase(comma, close - comma);  // keep only x
    t.insert(t.find(']', at), ",1");
    CHECK_THAT(
        recipe_error(t),
        Contains("steps[0].points[5]: expected [x, y, z] (3 numbers, mm), found an array of 2"));
  }
  CHECK_THAT(recipe_error(replaced("\"degrees\":[3,2,3]", "\"degrees\":[3,2]")),
             Contains("steps[0].degrees: expected 3 integers, found an array of 2"));
  CHECK_THAT(
      recipe_error(replaced("\"degrees\":[3,2,3]", "\"degrees\":[3,2.5,3]")),
      Contains(
          "steps[0].degrees[1]: expected an integer in [0, 1000000000], found the number 2.5"));
  // Wrong counts: one degree more than the points given.
  CHECK_THAT(recipe_error(replaced("\"degrees\":[3,2,3]", "\"degrees\":[3,3,3]")),
             Contains("steps[0] (bezier_lattice 'global')") && Contains("48 control points") &&
                 Contains("4 x 4 x 4 = 64"));
  // NaN: written as null by JSON libraries, or a number out of range.
  CHECK_THAT(recipe_error(replaced("\"rate\":0.02", "\"rate\":null")),
             Contains("steps[3].rate: expected a number (any finite number), found null"));
  CHECK_THAT(recipe_error(replaced("\"rate\":0.02", "\"rate\":NaN")), Contains("not valid JSON"));
  CHECK_THAT(recipe_error(replaced("\"rate\":0.02", "\"rate\":1e999")),
             Contains("could not be read") && Contains("number overflow"));
  CHECK_THAT(recipe_error(replaced("\"y_min\":-20.0", "\"y_min\":30.0")),
             Contains("steps[3] (bend): y_min = 30 > y_max = 25"));
  CHECK_THAT(recipe_error(replaced("\"enabled\":true", "\"enabled\":1")),
             Contains("steps[0].enabled: expected true or false, found the number 1"));
  CHECK_THAT(recipe_error(replaced("\"frame\":{\"origin\"", "\"frame\":{\"o\":0,\"origin\"")),
             Contains("steps[0].frame.o: unknown key \"o\" in a lattice frame"));
  CHECK_THAT(
      recipe_error(replaced("\"angle\":[", "\"angle\":[\"0\",")),
      Contains("steps[1].angle[0]: expected a number (any finite number), found the string \"0\""));
  CHECK_THAT(recipe_error("[1, 2]"), Contains("(top level): expected the stack"));
  CHECK_THAT(recipe_error(R"({"format": "clayform.deformation-stack", "version": 1, "steps": {}})"),
             Contains("steps: expected an array of steps, found an object"));
  CHECK_THAT(
      recipe_error(
          R"({"format": "clayform.deformation-stack", "version": 1, "steps": [{"kind": "bspline_lattice"}]})"),
      Contains("steps[0].frame: missing; give the lattice frame"));
  CHECK_THAT(
      recipe_error(
          R"({"format": "clayform.deformation-stack", "version": 1, "steps": [{"name": "x"}]})"),
      Contains("steps[0].kind: missing; give the kind of deformation"));
  CHECK_THAT(recipe_error(R"({"format": "clayform.deformation-stack", "steps": []})"),
             Contains("version: missing; give \"version\": 1"));
}

TEST_CASE("every malformed step field is named with its path", "[deform][stack]") {
  const std::string head = R"({"format": "clayform.deformation-stack", "version": 1, "steps": [)";
  const std::string axis =
      R"("frame": {"origin": [0, 0, 0], "axis": [0, 0, 1], "reference": [1, 0, 0]})";
  const std::string cube =
      R"("frame": {"origin": [0, 0, 0], "s": [1, 0, 0], "t": [0, 1, 0], "u": [0, 0, 1]})";
  const std::string basis = R"({"degree": 1, "knots": [0, 0, 1, 1]})";
  const std::pair<std::string, std::string> cases[] = {
      {"7", "steps[0]: expected a step"},
      {R"({"kind": 3})", "steps[0].kind: expected a string, found the number 3"},
      {R"({"kind": "twist", "name": 5, )" + axis + R"(, "angle": [0]})",
       "steps[0].name: expected a string, found the number 5"},
      {R"({"kind": "twist", "frame": [1, 2, 3], "angle": [0]})",
       "steps[0].frame: expected an axis frame"},
      {R"({"kind": "twist", "frame": {"origin": [0, 0, 0], "axis": [0, 0, 1]}, "angle": [0]})",
       "steps[0].frame.reference: missing; give [x, y, z]"},
      {R"({"kind": "twist", )" + axis + R"(, "angle": 0.5})",
       "steps[0].angle: expected an array of numbers, found the number 0.5"},
      {R"({"kind": "taper", )" + axis + R"(, "profile": []})",
       "steps[0] (taper): profile is empty"},
      {R"({"kind": "bezier_lattice", )" + cube + R"(, "degrees": [1, 1, 1], "points": {}})",
       "steps[0].points: expected an array of points [x, y, z], found an object"},
      {R"({"kind": "bezier_lattice", )" + cube + R"(, "degrees": [1, 1, 1e12], "points": []})",
       "steps[0].degrees[2]: expected an integer in [0, 1000000000], found the number 1e+12"},
      {R"({"kind": "bezier_lattice", )" + cube +
           R"(, "degrees": [1, 1, 10000000000], "points": []})",
       "steps[0].degrees[2]: expected an integer in [0, 1000000000], found the number 1e+10"},
      {R"({"kind": "bspline_lattice", )" + cube + R"(, "bases": [)" + basis + "," + basis +
           R"(], "points": []})",
       "steps[0].bases: expected 3 bases (along S, T, U), found an array of 2"},
      {R"({"kind": "bspline_lattice", )" + cube + R"(, "bases": [)" + basis + "," + basis +
           R"(, 4], "points": []})",
       "steps[0].bases[2]: expected a basis"},
      {R"({"kind": "bspline_lattice", )" + cube + R"(, "bases": [)" + basis + "," + basis +
           R"(, {"degree": 1, "knots": [0, 0, 1, 1], "weights": []}], "points": []})",
       "steps[0].bases[2].weights: unknown key \"weights\" in a basis"},
      {R"({"kind": "bspline_lattice", )" + cube + R"(, "bases": [)" + basis + "," + basis +
           R"(, {"degree": 1, "knots": [0, 0, 2, 2]}], "points": []})",
       "steps[0] (bspline_lattice)"},
  };
  for (const auto& [step, expected] : cases) {
    const std::string text =
        head + step + "]}";  // the lambda captures this, not the binding (Clang 14)
    const auto [category, what] = error_of([&] { stack_from_json(text); });
    CHECK(category == ErrorCategory::Document);
    CHECK_THAT(what, Contains(expected));
  }
  CHECK_THAT(error_of([&] { stack_from_json(head + "], \"extra\": 1}"); }).second,
             Contains("extra: unknown key \"extra\" in the stack"));
}

TEST_CASE("an invalid stack is rejected naming the step", "[deform][stack]") {
  std::mt19937 rng(25);
  DeformationStack stack = sample_stack(rng);
  std::get<Twist>(stack.steps[1].deformation).angle[1] = std::numeric_limits<double>::quiet_NaN();
  auto [category, what] = error_of([&] { to_json(stack); });
  CHECK(category == ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("steps[1] (twist 'twist'): angle[1] = nan is not finite"));
  CHECK_THAT(error_of([&] { deform_points(stack, Points3::Zero(3, 3)); }).second,
             Contains("steps[1] (twist 'twist')"));
  stack = sample_stack(rng);
  std::get<BSplineLattice>(stack.steps[2].deformation).points(4, 2) =
      std::numeric_limits<double>::infinity();
  CHECK_THAT(error_of([&] { validate(stack); }).second,
             Contains("steps[2] (bspline_lattice 'local')") && Contains("P_0,0,4"));
  CHECK(problems(sample_stack(rng)).empty());
  stack = sample_stack(rng);
  stack.steps[1].name = "bad \xff byte";
  std::tie(category, what) = error_of([&] { to_json(stack); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(what, Contains("steps[1].name is not valid UTF-8"));
}

// ---- extended lattices in stacks ---------------------------------------------------------------

namespace {

/// A skewed cylinder far from the origin: 8 sectors, 2 rings, 2 layers, merged axis.
CylinderSpec stack_cylinder() {
  CylinderSpec s;
  s.origin = Eigen::Vector3d(40, -25, 60);
  s.axis = Eigen::Vector3d(0.2, -0.3, 1.0);
  s.reference = Eigen::Vector3d(1, 0.5, 0);
  s.radius = 30;
  s.height = 45;
  s.sectors = 8;
  s.rings = 2;
  s.layers = 2;
  return s;
}

/// The cylinder's orthonormal frame, computed here: e1 (angle 0), e2, a (axis).
struct CylinderAxes {
  Eigen::Vector3d e1, e2, a;
  explicit CylinderAxes(const CylinderSpec& s) : a(s.axis.normalized()) {
    e1 = (s.reference - s.reference.dot(a) * a).normalized();
    e2 = a.cross(e1);
  }
};

/// The cylindrical lattice with every control point moved by up to `amount` mm at random.
ExtendedLattice displaced_cylinder(const CylinderSpec& s, std::mt19937& rng, double amount) {
  ExtendedLattice L = make_cylindrical_lattice(s);
  std::uniform_real_distribution<double> c(-amount, amount);
  for (Eigen::Index r = 0; r < L.points.rows(); ++r)
    L.points.row(r) += Eigen::RowVector3d(c(rng), c(rng), c(rng));
  return L;
}

/// `n` points in and around the cylinder: radius up to 1.2 R, height from -0.1 H to 1.1 H.
Points3 around_cylinder(const CylinderSpec& s, std::mt19937& rng, int n) {
  const CylinderAxes ax(s);
  std::uniform_real_distribution<double> u(0, 1);
  Points3 p(n, 3);
  for (int r = 0; r < n; ++r) {
    const double rho = 1.2 * s.radius * std::sqrt(u(rng)), phi = 2 * std::numbers::pi * u(rng);
    const double h = s.height * (1.2 * u(rng) - 0.1);
    p.row(r) =
        (s.origin + h * ax.a + rho * (std::cos(phi) * ax.e1 + std::sin(phi) * ax.e2)).transpose();
  }
  return p;
}

/// [a displaced B-spline lattice around the cylinder (global), the displaced cylindrical extended
/// lattice, a twist about the cylinder's axis].
DeformationStack extended_stack(std::mt19937& rng) {
  const CylinderSpec s = stack_cylinder();
  const CylinderAxes ax(s);
  Frame g;
  g.origin = s.origin - 40 * ax.e1 - 40 * ax.e2 - 10 * ax.a;
  g.s = 80 * ax.e1;
  g.t = 80 * ax.e2;
  g.u = 65 * ax.a;
  const BSplineLattice global =
      clay::test::displaced(make_bspline_lattice(g, {3, 2, 3}, {2, 3, 2}), rng, 0.03);
  const Twist twist{{s.origin, s.axis, s.reference}, {0.05, 0.01}};
  return {{{global, "global", true},
           {displaced_cylinder(s, rng, 2.0), "cylinder", true},
           {twist, "twist", true}}};
}

/// A chunk collapsed to the segment from (0, 0, 0) to (0, 0, 9): a point 1e-8 mm off it lies
/// in the chunk's convex hull test but has no root, so freezing leaves it unresolved.
ExtendedLattice segment_chunk() {
  ExtendedLattice L;
  L.rest.resize(64, 3);
  L.chunks.resize(1);
  for (int e = 0; e < 64; ++e) {
    L.rest.row(e) = Eigen::RowVector3d(0, 0, 3.0 * (e % 4));
    L.chunks[0][static_cast<std::size_t>(e)] = e;
  }
  L.points = L.rest;
  for (int e = 0; e < 64; ++e) L.points(e, 0) += 2.0;  // the image: the segment moved along x
  return L;
}

/// The row of chunks[chunk][entry] in `text` replaced by `value` (JSON written by to_json).
std::string with_chunk_entry(std::string text, std::size_t chunk, std::size_t entry,
                             const std::string& value) {
  std::size_t at = text.find("\"chunks\":[");
  REQUIRE(at != std::string::npos);
  at += 10;                                                             // the '[' of chunks[0]
  for (std::size_t c = 0; c < chunk; ++c) at = text.find('[', at + 1);  // of chunks[chunk]
  std::size_t begin = at + 1;
  for (std::size_t e = 0; e < entry; ++e) begin = text.find(',', begin) + 1;
  const std::size_t end = text.find_first_of(",]", begin);
  return text.replace(begin, end - begin, value);
}

}  // namespace

TEST_CASE("an extended lattice step is the composition of the steps' own deform_point",
          "[deform][stack]") {
  std::mt19937 rng(31);
  const DeformationStack stack = extended_stack(rng);
  const auto& global = std::get<BSplineLattice>(stack.steps[0].deformation);
  const auto& cylinder = std::get<ExtendedLattice>(stack.steps[1].deformation);
  const auto& twist = std::get<Twist>(stack.steps[2].deformation);
  const Points3 points = around_cylinder(stack_cylinder(), rng, 200);
  int moved_by_each = 0;
  for (Eigen::Index r = 0; r < points.rows(); ++r) {
    const Eigen::Vector3d x = points.row(r).transpose();
    const Eigen::Vector3d a = deform_point(global, x), b = deform_point(cylinder, a),
                          c = deform_point(twist, b);
    CHECK(same_bits(deform_point(stack, x), c));
    moved_by_each += (a != x) && (b != a) && (c != b);
  }
  CHECK(moved_by_each > 100);  // most points lie in the cylinder
}

TEST_CASE(
    "deform_points on a stack with an extended lattice equals deform_point and reports the freeze",
    "[deform][stack]") {
  std::mt19937 rng(32);
  const DeformationStack stack = extended_stack(rng);
  const Points3 points = around_cylinder(stack_cylinder(), rng, 3000);  // freezes on two workers
  Points3 out;
  StackReport report;
  deform_points(stack, points, out, report, DeformOptions{2});
  const double size = clay::test::size_of(points);
  double worst = 0;
  for (Eigen::Index r = 0; r < points.rows(); ++r)
    worst = std::max(
        worst, (out.row(r).transpose() - deform_point(stack, points.row(r).transpose())).norm());
  INFO("bulk vs deform_point " << worst / size << " of the size " << size << " mm");
  CHECK(worst < 1e-13 * size);
  REQUIRE(report.freezes.size() == 1);
  CHECK(report.freezes[0].step == 1);
  const FreezeReport& f = report.freezes[0].report;
  CHECK(report.converged());
  CHECK(f.inside + f.outside == points.rows());
  CHECK(f.inside > points.rows() / 2);
  CHECK(f.outside > 100);
  CHECK_THAT(report.brief(),
             Contains("steps[1]: frozen 3000 points: ") && Contains(" 0 unresolved"));
  // The overloads without a report, in place, give the same bits.
  CHECK(same_bits(deform_points(stack, points, DeformOptions{2}), out));
  Points3 in_place = points;
  deform_points(stack, in_place, in_place, DeformOptions{2});
  CHECK(same_bits(in_place, out));
  // A disabled extended step is not frozen; the report is overwritten.
  DeformationStack skipping = stack;
  skipping.steps[1].enabled = false;
  deform_points(skipping, points, out, report);
  CHECK(report.freezes.empty());
  CHECK(report.converged());
  CHECK(report.brief() == "no extended lattice step");
}

TEST_CASE("points an extended lattice step cannot place are left unchanged and reported",
          "[deform][stack]") {
  const Twist twist{{Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()},
                    {0, 0.1}};
  const DeformationStack stack{{{segment_chunk(), "segment", true}, {twist, "twist", true}}};
  Points3 points(2, 3);
  points << 0, 0, 4.5,  // on the segment: found, moved by 2 along x
      1e-8, 0, 4.5;     // off it: unresolved, unchanged by step 0
  Points3 out;
  StackReport report;
  deform_points(stack, points, out, report);
  REQUIRE(report.freezes.size() == 1);
  CHECK_FALSE(report.converged());
  CHECK(report.summary.termination == clay::Termination::NotConverged);
  CHECK(report.summary.message == report.brief());
  CHECK(report.freezes[0].report.summary.termination == clay::Termination::NotConverged);
  CHECK(report.freezes[0].report.unresolved == 1);
  CHECK_THAT(report.brief(),
             Contains("steps[0]: frozen 2 points: 1 inside, 0 outside, 1 unresolved"));
  const Eigen::Vector3d off = points.row(1).transpose();
  CHECK(same_bits(Eigen::Vector3d(out.row(1).transpose()), deform_point(twist, off)));
  CHECK(same_bits(deform_point(stack, off), deform_point(twist, off)));
  CHECK((out.row(0).transpose() - deform_point(twist, Eigen::Vector3d(2, 0, 4.5))).norm() < 1e-12);
}

TEST_CASE("JSON round trips a displaced cylindrical lattice bit for bit", "[deform][stack]") {
  std::mt19937 rng(33);
  const DeformationStack stack = extended_stack(rng);
  const std::string text = to_json(stack);
  CHECK_THAT(
      text,
      Contains("\"kind\":\"extended_lattice\",\"name\":\"cylinder\",\"enabled\":true,\"rest\":[["));
  const DeformationStack back = stack_from_json(text);
  REQUIRE(back.steps.size() == stack.steps.size());
  for (std::size_t i = 0; i < stack.steps.size(); ++i)
    CHECK(same_step(back.steps[i].deformation, stack.steps[i].deformation));
  CHECK(to_json(back) == text);
  const Points3 points = around_cylinder(stack_cylinder(), rng, 1500);
  CHECK(same_bits(deform_points(back, points), deform_points(stack, points)));
}

TEST_CASE("malformed extended lattice JSON is rejected naming the path", "[deform][stack]") {
  std::mt19937 rng(34);
  const DeformationStack stack = extended_stack(rng);
  const std::string good = to_json(stack);
  const auto rows = std::get<ExtendedLattice>(stack.steps[1].deformation).rest.rows();
  const std::string range = "(0.." + std::to_string(rows - 1) + ")";
  auto recipe_error = [](const std::string& text) {
    const auto [category, what] = error_of([&] { stack_from_json(text); });
    CHECK(category == ErrorCategory::Document);
    return what;
  };
  CHECK_THAT(recipe_error(with_chunk_entry(good, 3, 17, "5000")),
             Contains("steps[1].chunks[3][17]: index 5000 is out of range " + range) &&
                 Contains("give a row of rest"));
  CHECK_THAT(recipe_error(with_chunk_entry(good, 0, 63, "-1")),
             Contains("steps[1].chunks[0][63]: index -1 is out of range " + range));
  CHECK_THAT(recipe_error(with_chunk_entry(good, 2, 5, "7.5")),
             Contains("steps[1].chunks[2][5]: expected an integer, found the number 7.5"));
  CHECK_THAT(
      recipe_error(with_chunk_entry(good, 4, 0, "0,0")),
      Contains("steps[1].chunks[4]: expected 64 indices") && Contains("found an array of 65"));

  const std::string head =
      R"({"format": "clayform.deformation-stack", "version": 1, "steps": [{"kind": "extended_lattice", )";
  std::string chunk = "[0";
  for (int e = 1; e < 64; ++e) chunk += ",0";
  chunk += "]";
  const std::string two = R"("rest": [[0, 0, 0], [1, 2, 3]], )";
  const std::pair<std::string, std::string> cases[] = {
      {R"("rest": [[0, 0, 0], [1, 2, 3]], "points": [[0, 0, 0]], "chunks": [])",
       "steps[0].points: found 1 control points but rest has 2; give one current position per rest "
       "control point"},
      {two + R"("points": [[0, 0, 0], [1, 2, 3]], "chunks": [[0, 1, 1]])",
       "steps[0].chunks[0]: expected 64 indices (control point (i, j, k) at (i * 4 + j) * 4 + k), "
       "found an array of 3"},
      {two + R"("points": [[0, 0, 0], [1, 2, 3]], "chunks": {})",
       "steps[0].chunks: expected an array of chunks"},
      {two + R"("points": [[0, 0, 0], [1, 2, 3]], "chunks": [7])",
       "steps[0].chunks[0]: expected 64 indices"},
      {two + R"("points": [[0, 0, 0], [1, 2, 3]])",
       "steps[0].chunks: missing; give the chunks, each 64 row indices"},
      {two + R"("points": [[0, 0, 0], [1, 2, 3]], "chunks": [], "frame": 1)",
       "steps[0].frame: unknown key \"frame\" in an extended_lattice step; the keys are: kind, "
       "name, enabled, rest, points, chunks"},
      {R"("rest": [], "points": [], "chunks": [[0]])", "steps[0].chunks[0]: expected 64 indices"},
      {R"("rest": [], "points": [], "chunks": [)" + chunk + "]",
       "steps[0].chunks[0][0]: index 0 is out of range (rest has no rows)"},
      {two + R"("points": [[0, 0, 0], [1, 2, null]], "chunks": [])",
       "steps[0].points[1][2]: expected a number (any finite number), found null"},
      // The lattice's own problems(), prefixed with the step.
      {two + R"("points": [[0, 0, 0], [1, 2, 3]], "chunks": [])",
       "steps[0] (extended_lattice): no chunks"},
  };
  for (const auto& [fields, expected] : cases) {
    const auto what = recipe_error(head + fields + "}]}");
    CHECK_THAT(what, Contains(expected));
  }
  // A chunk on one repeated row has zero extent: the lattice's own problem, named by step.
  std::string flat = "[5";
  for (int e = 1; e < 64; ++e) flat += ",5";
  flat += "]";
  std::string t = good;
  t.insert(t.find("\"chunks\":[") + 10, flat + ",");
  CHECK_THAT(recipe_error(t),
             Contains("steps[1] (extended_lattice 'cylinder'): chunk 0 has zero extent"));
}

TEST_CASE("a number beyond a double leaves the caller's floating-point environment as it was",
          "[deform][stack]") {
  // strtod reports 1e999 by raising overflow; a host trapping overflow (the Debug tests do) died of
  // it inside stack_from_json (issue #19). The parser runs with the traps held, the flags restored.
  std::feclearexcept(FE_ALL_EXCEPT);
#if defined(__GLIBC__)
  const int traps = fegetexcept();
#endif
  const auto [category, what] = error_of([] {
    stack_from_json(
        R"({"format": "clayform.deformation-stack", "version": 1, "steps": [{"kind": "taper",
        "frame": {"origin": [0, 0, 0], "axis": [0, 0, 1], "reference": [1, 0, 0]}, "profile": [1, 1e999]}]})");
  });
  CHECK(category == ErrorCategory::Document);
  CHECK_THAT(what, Contains("number overflow parsing '1e999'") && Contains("give finite numbers"));
  CHECK(std::fetestexcept(FE_OVERFLOW | FE_INVALID | FE_DIVBYZERO) == 0);
#if defined(__GLIBC__)
  CHECK(fegetexcept() == traps);
#endif
}

TEST_CASE("the stack reader reports every problem at once, each with its path", "[deform][stack]") {
  // Three independent faults in two steps and the header: one read names all three.
  const std::string text = R"({"format": "clayform.deformation-stack", "version": 1, "steps": [
    {"kind": "twist", "frame": {"origin": [0, 0, "x"], "axis": [0, 0, 1], "reference": [1, 0, 0]}, "angle": [0]},
    {"kind": "bend", "frame": {"origin": [0, 0, 0], "axis": [0, 0, 1], "reference": [1, 0, 0]},
     "y_min": 0, "y_max": 1, "center": 0, "rate": null}], "colour": "red"})";
  const auto [category, what] = error_of([&] { stack_from_json(text); });
  CHECK(category == ErrorCategory::Document);
  CHECK_THAT(what, Contains("steps[0].frame.origin[2]: expected a number (any finite number), "
                            "found the string \"x\""));
  CHECK_THAT(what, Contains("steps[1].rate: expected a number (any finite number), found null"));
  CHECK_THAT(what, Contains("colour: unknown key \"colour\" in the stack"));
}
