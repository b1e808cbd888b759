// Exact FFD composition (compose.hpp) against the pointwise deformation of the original surface
// (deform_point after surface::evaluate) at random parameters, degrees against the per-direction
// rule computed here from how each test surface is built, knot vectors read back, and STEP/IGES
// round trips compared bit for bit.
#include <catch2/catch.hpp>

#include <clay/cancel.hpp>
#include <clay/deform.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/revolve.hpp>

#include <algorithm>
#include <filesystem>
#include <random>
#include <string>

#include "error_of.hpp"
#include "fixtures.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using clay::ErrorCategory;
using clay::surface::BSplineBasis;
using clay::surface::BSplineSurface;
using clay::test::error_of;
using clay::test::random_surface_in;
using clay::test::surface_in;
namespace fs = std::filesystem;

namespace {

/// Largest distance between the composed surface and the pointwise deformation of the original
/// at `n` random parameters.
template <class Map>
double deviation(const BSplineSurface& original, const BSplineSurface& composed, const Map& map,
                 int n, std::mt19937& rng) {
  const auto [u0, u1] = original.u.domain();
  const auto [v0, v1] = original.v.domain();
  std::uniform_real_distribution<double> cu(u0, u1), cv(v0, v1);
  double worst = 0;
  for (int k = 0; k < n; ++k) {
    const double u = cu(rng), v = cv(rng);
    const Eigen::Vector3d expected = map(clay::surface::evaluate(original, u, v));
    worst = std::max(worst, (clay::surface::evaluate(composed, u, v) - expected).norm());
  }
  return worst;
}

fs::path fresh_folder(const std::string& name) {
  const fs::path folder = fs::path(CLAY_TEST_OUTPUT_DIR) / "compose" / name;
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

/// Writes `s` to STEP and IGES, reads both back and requires bit-identical surfaces.
void require_round_trips(const BSplineSurface& s, const fs::path& folder, const std::string& name) {
  const fs::path step = folder / (name + ".step"), iges = folder / (name + ".igs");
  clay::surface::write_step({s}, step);
  clay::surface::write_iges({s}, iges);
  const auto from_step = clay::surface::read_step(step);
  const auto from_iges = clay::surface::read_iges(iges);
  REQUIRE(from_step.size() == 1);
  REQUIRE(from_iges.size() == 1);
  CHECK(clay::surface::identical(from_step[0], s));
  CHECK(clay::surface::identical(from_iges[0], s));
}

int multiplicity_of(const std::vector<double>& knots, double value) {
  return static_cast<int>(std::count(knots.begin(), knots.end(), value));
}

}  // namespace

TEST_CASE("compose_exact matches the pointwise Bezier FFD on random surfaces and lattices") {
  std::mt19937 rng(2024);
  std::uniform_int_distribution<int> degree(1, 3), extra(0, 2);
  const fs::path folder = fresh_folder("random");
  int params = 0;
  for (int c = 0; c < 20; ++c) {
    const Frame frame = clay::test::random_frame(rng, c % 5 == 4);
    // lattice degrees each >= 1, total <= 8
    std::array<int, 3> ld{1, 1, 1};
    std::uniform_int_distribution<int> total(3, 8), axis(0, 2);
    for (int k = total(rng) - 3; k > 0; --k) ++ld[static_cast<size_t>(axis(rng))];
    const BezierLattice lattice = clay::test::displaced(make_bezier_lattice(frame, ld), rng);
    const int p = degree(rng), q = degree(rng);
    const bool rational = c % 2 == 1;
    const BSplineSurface s =
        random_surface_in(frame, p, q, p + 1 + extra(rng), q + 1 + extra(rng), rational, rng);
    const ComposeResult r = compose_exact(lattice, s);
    const double size = clay::test::size_of(lattice.points);
    const auto map = [&](const Eigen::Vector3d& x) { return deform_point(lattice, x); };
    INFO("case " << c << " degrees " << p << "x" << q << " lattice " << ld[0] << ld[1] << ld[2]
                 << (rational ? " rational" : "") << ": " << r.report.brief());
    const double dev = deviation(s, r.surface, map, 500, rng);
    params += 500;
    CHECK(dev <= 1e-12 * size);
    CHECK(r.report.max_relative_deviation <= 1e-12);
    CHECK(r.report.exact);
    CHECK(r.report.summary.converged());
    CHECK(r.report.summary.final_residual == r.report.max_relative_deviation);
    CHECK(r.report.summary.message == r.report.brief());
    CHECK(r.surface.is_rational() == rational);
    // Random control points: every coordinate has full degree, so the rule gives (L p, L q).
    const int L = ld[0] + ld[1] + ld[2];
    CHECK(r.report.degree_u == L * p);
    CHECK(r.report.degree_v == L * q);
    CHECK(r.report.control_points == static_cast<long>(r.surface.count_u()) * r.surface.count_v());
    if (c % 4 == 0) {  // exchange is lossless: the same surface, so the same deviation
      require_round_trips(r.surface, folder, "case" + std::to_string(c));
      const auto back = clay::surface::read_step(folder / ("case" + std::to_string(c) + ".step"));
      CHECK(deviation(s, back[0], map, 100, rng) <= 1e-12 * size);
      const auto back_iges =
          clay::surface::read_iges(folder / ("case" + std::to_string(c) + ".igs"));
      CHECK(deviation(s, back_iges[0], map, 100, rng) <= 1e-12 * size);
    }
  }
  CHECK(params >= 10000);
}

TEST_CASE("compose_exact stops between patches when its caller cancels, and composes after") {
  std::mt19937 rng(40);
  const Frame frame = clay::test::random_frame(rng, false);
  const BezierLattice lattice = clay::test::displaced(make_bezier_lattice(frame, {2, 2, 1}), rng);
  const BSplineSurface s = random_surface_in(frame, 2, 2, 6, 6, false, rng);  // 4 x 4 patches
  int asked = 0;
  {
    const clay::CancelScope scope([&] { return ++asked == 3; });
    try {
      (void)compose_exact(lattice, s);
      FAIL("compose_exact ran to its end");
    } catch (const clay::Cancelled& c) {
      CHECK(c.where == "an exact composition");
    }
  }
  CHECK(asked == 3);  // asked once per patch: it stopped at the third of 16
  // Nothing is left behind: the same composition runs whole afterwards, exact.
  const ComposeResult r = compose_exact(lattice, s);
  const auto map = [&](const Eigen::Vector3d& x) { return deform_point(lattice, x); };
  CHECK(deviation(s, r.surface, map, 200, rng) <= 1e-12 * clay::test::size_of(lattice.points));
}

TEST_CASE("compose_exact degrees follow the per-direction rule") {
  std::mt19937 rng(7);
  Frame frame = clay::test::random_frame(rng);
  std::uniform_real_distribution<double> c(0.1, 0.9);
  const BezierLattice tricubic = clay::test::displaced(make_bezier_lattice(frame, {3, 3, 3}), rng);
  const auto map = [&](const Eigen::Vector3d& x) { return deform_point(tricubic, x); };
  const double size = clay::test::size_of(tricubic.points);

  SECTION("planar bicubic parallel to a lattice face: u constant, s and t general") {
    // u = 0.4 everywhere: d(u) = 0, d(s) = d(t) = 3 in both directions -> 3*3 + 3*3 + 3*0 = 18.
    for (bool rational : {false, true}) {
      const BSplineSurface s = surface_in(frame, 3, 3, 5, 4, rational, rng, [&](int, int) {
        return Eigen::Vector3d(c(rng), c(rng), 0.4);
      });
      const ComposeResult r = compose_exact(tricubic, s);
      CHECK(r.report.degree_u == 18);
      CHECK(r.report.degree_v == 18);
      CHECK(deviation(s, r.surface, map, 300, rng) <= 1e-12 * size);
    }
  }
  SECTION("axis-aligned sheet: s depends on the first parameter only, t on the second") {
    // s = x_i (cubic in the first parameter, constant in the second), t = y_j, u = 0.3:
    // first direction 3*3, second 3*3 -> 9 x 9.
    std::vector<double> x{0.1, 0.35, 0.4, 0.7, 0.9}, y{0.2, 0.3, 0.6, 0.8};
    const BSplineSurface s = surface_in(frame, 3, 3, 5, 4, false, rng, [&](int i, int j) {
      return Eigen::Vector3d(x[size_t(i)], y[size_t(j)], 0.3);
    });
    const ComposeResult r = compose_exact(tricubic, s);
    CHECK(r.report.degree_u == 9);
    CHECK(r.report.degree_v == 9);
    CHECK(deviation(s, r.surface, map, 300, rng) <= 1e-12 * size);
  }
  SECTION("bicubic that is an elevated bilinear plane: degree 1 per coordinate") {
    // Control points affine in the Greville abscissae (a, b) = (i/3, j/3): s, t, u are affine in
    // (a, b), degree 1 in each parameter -> 3 + 3 + 3 = 9 in both directions.
    BSplineSurface s = surface_in(frame, 3, 3, 4, 4, false, rng, [&](int i, int j) {
      const double a = i / 3.0, b = j / 3.0;
      return Eigen::Vector3d(0.1 + 0.6 * a + 0.2 * b, 0.1 + 0.2 * a + 0.6 * b,
                             0.2 + 0.1 * a + 0.1 * b);
    });
    s.u = clay::surface::clamped_uniform_basis(3, 4);  // one Bézier patch: Greville = i/3
    s.v = clay::surface::clamped_uniform_basis(3, 4);
    const ComposeResult r = compose_exact(tricubic, s);
    CHECK(r.report.degree_u == 9);
    CHECK(r.report.degree_v == 9);
    CHECK(deviation(s, r.surface, map, 300, rng) <= 1e-12 * size);
  }
  SECTION("general bicubic in a (2, 2, 2) lattice and a (3, 3, 1) lattice") {
    const BSplineSurface s = random_surface_in(frame, 3, 3, 6, 6, false, rng);
    for (std::array<int, 3> ld : {std::array<int, 3>{2, 2, 2}, std::array<int, 3>{3, 3, 1}}) {
      const BezierLattice lattice = clay::test::displaced(make_bezier_lattice(frame, ld), rng);
      const ComposeResult r = compose_exact(lattice, s);
      const int expected = 3 * (ld[0] + ld[1] + ld[2]);
      CHECK(r.report.degree_u == expected);
      CHECK(r.report.degree_v == expected);
      CHECK(deviation(
                s, r.surface, [&](const Eigen::Vector3d& p) { return deform_point(lattice, p); },
                300, rng) <= 1e-12 * clay::test::size_of(lattice.points));
    }
  }
}

TEST_CASE("compose_exact keeps a revolved rational surface exact") {
  std::mt19937 rng(11);
  clay::surface::BSplineCurve profile;
  profile.basis = clay::surface::clamped_uniform_basis(3, 5);
  profile.points.resize(5, 3);
  profile.points << 10, 0, 0, 14, 0, 5, 9, 0, 10, 12, 0, 15, 8, 0, 20;
  profile.weights = Eigen::VectorXd::Ones(5);
  const BSplineSurface s = clay::surface::revolve(profile, {}, 360.0).surface;
  REQUIRE(s.is_rational());
  Frame frame;
  frame.origin = Eigen::Vector3d(-16, -16, -1);
  frame.s = Eigen::Vector3d(32, 0, 0);
  frame.t = Eigen::Vector3d(0, 32, 0);
  frame.u = Eigen::Vector3d(0, 0, 22);
  const BezierLattice lattice = clay::test::displaced(make_bezier_lattice(frame, {2, 2, 1}), rng);
  const ComposeResult r = compose_exact(lattice, s);
  const double size = clay::test::size_of(lattice.points);
  INFO(r.report.brief());
  CHECK(deviation(
            s, r.surface, [&](const Eigen::Vector3d& p) { return deform_point(lattice, p); }, 1000,
            rng) <= 1e-12 * size);
  CHECK(r.surface.is_rational());
  // u around the axis (degree 2, homogeneous), v the polynomial cubic profile: s and t have
  // homogeneous degree (2, 3), u (height) depends on v only but is rational in u: (2, 3) too.
  CHECK(r.report.degree_u == 5 * 2);
  CHECK(r.report.degree_v == 5 * 3);
  require_round_trips(r.surface, fresh_folder("revolve"), "vase");
}

TEST_CASE("compose_exact removes knots down to the continuity of the input") {
  std::mt19937 rng(5);
  const Frame frame = clay::test::random_frame(rng);
  // C2 bicubic: uniform knots, 3 x 3 Bézier patches.
  std::uniform_real_distribution<double> c(0.05, 0.95);
  BSplineSurface s = random_surface_in(frame, 3, 3, 6, 6, false, rng);
  s.u = clay::surface::clamped_uniform_basis(3, 6);
  s.v = clay::surface::clamped_uniform_basis(3, 6);
  const BezierLattice lattice = clay::test::displaced(make_bezier_lattice(frame, {2, 2, 2}), rng);
  const auto map = [&](const Eigen::Vector3d& p) { return deform_point(lattice, p); };
  const double size = clay::test::size_of(lattice.points);
  const ComposeResult r = compose_exact(lattice, s);
  const ComposeResult patchwork = compose_exact(lattice, s, ComposeOptions{0.0, 4});
  REQUIRE(r.report.degree_u == 18);
  REQUIRE(r.report.degree_v == 18);
  for (const double k : clay::surface::breakpoints(s.u))
    if (k != 0 && k != 1) {
      CHECK(multiplicity_of(r.surface.u.knots, k) == 18 - 2);
      CHECK(multiplicity_of(r.surface.v.knots, k) == 18 - 2);
      CHECK(multiplicity_of(patchwork.surface.u.knots, k) == 18);
    }
  CHECK(r.report.knots_removed == 2 * 2 * 2);
  CHECK(patchwork.report.knots_removed == 0);
  CHECK(r.surface.count_u() == 3 * 18 + 1 - 4);
  CHECK(deviation(s, r.surface, map, 500, rng) <= 1e-12 * size);
  CHECK(deviation(s, patchwork.surface, map, 500, rng) <= 1e-12 * size);
}

TEST_CASE("compose_exact with a B-spline lattice splits at knot planes met along iso-lines") {
  std::mt19937 rng(17);
  const Frame frame = clay::test::random_frame(rng);
  const BSplineLattice lattice =
      clay::test::displaced(make_bspline_lattice(frame, {3, 3, 2}, {3, 2, 1}), rng);
  const auto map = [&](const Eigen::Vector3d& p) { return deform_point(lattice, p); };
  const double size = clay::test::size_of(lattice.points);

  SECTION("a sheet in the lattice frame: s depends on u only, t on v only") {
    std::vector<double> x{0.05, 0.3, 0.6, 0.7, 0.95}, y{0.1, 0.4, 0.6, 0.9};
    std::uniform_real_distribution<double> h(0.2, 0.8);
    for (bool rational : {false, true}) {
      BSplineSurface s = surface_in(frame, 3, 2, 5, 4, false, rng, [&](int i, int j) {
        return Eigen::Vector3d(x[size_t(i)], y[size_t(j)], h(rng));
      });
      if (rational)  // product weights a_i b_j: s = Σ a_i N_i x_i / Σ a_i N_i stays a function of u
        for (int i = 0; i < 5; ++i)
          for (int j = 0; j < 4; ++j)
            s.weights(s.index(i, j)) = (1.0 + 0.3 * i) * (1.5 - 0.1 * j * j);
      const ComposeResult r = compose_exact(lattice, s);
      INFO(r.report.brief());
      CHECK(r.report.splits > 0);
      CHECK(deviation(s, r.surface, map, 1000, rng) <= 1e-12 * size);
      CHECK(r.report.max_relative_deviation <= 1e-12);
      if (!rational) require_round_trips(r.surface, fresh_folder("sheet"), "sheet");
    }
  }
  SECTION("a rational sheet across the plane between a moved and an unmoved cell (issue #39)") {
    // One point of the last cell in s moved: the first cell is affine (composed by its
    // monomials, weight W^1), the last one is not (W^4). Neighbours must share homogeneous
    // points to be joined; a rational fillet of a real part was refused ("neighbouring patches
    // do not meet") until every patch took the tensor route there.
    BSplineLattice bulged = make_bspline_lattice(frame, {2, 2, 2}, {2, 1, 1});
    const auto n = bulged.counts();
    bulged.points.row(bulged.index(n[0] - 1, 1, n[2] - 1)) += 0.2 * frame.u.transpose();
    const auto bulged_map = [&](const Eigen::Vector3d& p) { return deform_point(bulged, p); };
    std::vector<double> x{0.05, 0.3, 0.6, 0.7, 0.95}, y{0.1, 0.4, 0.6, 0.9};
    BSplineSurface s = surface_in(frame, 3, 2, 5, 4, false, rng, [&](int i, int j) {
      return Eigen::Vector3d(x[size_t(i)], y[size_t(j)], 0.5);
    });
    for (int i = 0; i < 5; ++i)
      for (int j = 0; j < 4; ++j) s.weights(s.index(i, j)) = (1.0 + 0.3 * i) * (1.5 - 0.1 * j);
    const ComposeResult r = compose_exact(bulged, s);
    INFO(r.report.brief());
    CHECK(r.report.splits > 0);
    CHECK(deviation(s, r.surface, bulged_map, 1000, rng) <= 1e-12 * size);
  }
  SECTION("a small patch inside one cell composes with that cell") {
    const BSplineSurface s = surface_in(frame, 2, 2, 3, 3, true, rng, [&](int i, int j) {
      return Eigen::Vector3d(0.4 + 0.05 * i, 0.1 + 0.1 * j, 0.3 + 0.1 * i * j);
    });
    const ComposeResult r = compose_exact(lattice, s);
    CHECK(r.report.splits == 0);
    CHECK(r.report.patches == 1);
    CHECK(deviation(s, r.surface, map, 500, rng) <= 1e-12 * size);
  }
  SECTION("a diagonal crossing of a knot plane needs a refit: the error names the crossing") {
    const BSplineSurface s = surface_in(frame, 1, 1, 2, 2, false, rng, [&](int i, int j) {
      return Eigen::Vector3d(0.1 + 0.8 * i * (1 - j) + 0.4 * j, 0.2 + 0.1 * j + 0.1 * i, 0.5);
    });
    const auto [category, what] = error_of([&] { compose_exact(lattice, s); });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Contains("knot plane s = ") && Contains("patch (0, 0)") &&
                         Contains("at parameter") && Contains("refit tolerance"));
  }
}

// Issue #18: touching a knot plane is not crossing it, and crossings closer together than any
// sampling step are still found. The lattice has 2 cells in t: the knot plane t = 0.5.
TEST_CASE(
    "compose_exact with a B-spline lattice: a surface tangent to a knot plane composes exactly") {
  std::mt19937 rng(29);
  const Frame frame = clay::test::random_frame(rng);
  const BSplineLattice lattice =
      clay::test::displaced(make_bspline_lattice(frame, {3, 3, 2}, {3, 2, 1}), rng);
  const auto map = [&](const Eigen::Vector3d& p) { return deform_point(lattice, p); };
  const double size = clay::test::size_of(lattice.points);
  // t(u, v) = base + sign 0.3 (4u(1-u)) (4v(1-v)): Bernstein coefficients of 4x(1-x) are 0, 2, 0.
  // Its extremum, at (0.5, 0.5), is base + sign 0.3: exactly on the plane for base 0.2 (from
  // below) and 0.8 (from above); the convex hull reaches 1.4 (or -0.4), so only a certificate
  // of the true extremum can tell that the surface stays on one side.
  const double f[3] = {0, 2, 0};
  for (double sign : {1.0, -1.0}) {
    const double base = sign > 0 ? 0.2 : 0.8;
    const BSplineSurface s = surface_in(frame, 2, 2, 3, 3, false, rng, [&](int i, int j) {
      return Eigen::Vector3d(0.4 + 0.05 * i, base + sign * 0.3 * f[i] * f[j], 0.3 + 0.1 * j);
    });
    INFO("touching from " << (sign > 0 ? "below" : "above"));
    const ComposeResult r = compose_exact(lattice, s);
    INFO(r.report.brief());
    CHECK(r.report.patches == 1);
    CHECK(deviation(s, r.surface, map, 1000, rng) <= 1e-12 * size);
    // The touching point itself: the lattice's two cells meet there with C^2 continuity, so both
    // sides give the same point; the composed surface must too.
    CHECK((clay::surface::evaluate(r.surface, 0.5, 0.5) - map(clay::surface::evaluate(s, 0.5, 0.5)))
              .norm() <= 1e-12 * size);
  }
  SECTION(
      "lifted by 1e-6 the same surface crosses the plane in a tiny region: refused, with the true "
      "value") {
    const BSplineSurface s = surface_in(frame, 2, 2, 3, 3, false, rng, [&](int i, int j) {
      return Eigen::Vector3d(0.4 + 0.05 * i, 0.2 + 1e-6 + 0.3 * f[i] * f[j], 0.3 + 0.1 * j);
    });
    const auto [category, what] = error_of([&] { compose_exact(lattice, s); });
    CHECK(category == ErrorCategory::InvalidArgument);
    // The value is the surface's own (1e-6 above the plane), at the top of the bump.
    CHECK_THAT(what, Contains("knot plane t = 0.5") &&
                         Catch::Matchers::Matches(
                             ".*\\(t = 0\\.50000(09|1)[0-9]* at parameter "
                             "\\((0\\.5|0\\.4999)[0-9]*, (0\\.5|0\\.4999)[0-9]*\\).*"));
    CHECK_THAT(what, !Contains("bound"));
  }
}

TEST_CASE(
    "compose_exact with a B-spline lattice splits at two crossings of a knot plane inside one "
    "sampling step") {
  std::mt19937 rng(31);
  const Frame frame = clay::test::random_frame(rng);
  const BSplineLattice lattice =
      clay::test::displaced(make_bspline_lattice(frame, {3, 3, 2}, {3, 2, 1}), rng);
  const auto map = [&](const Eigen::Vector3d& p) { return deform_point(lattice, p); };
  const double size = clay::test::size_of(lattice.points);
  // t(u) = 0.5 + e - k (u - m)^2 crosses t = 0.5 at m -+ 0.003, between the samples 0.5 and
  // 0.515625 of a 64-step scan (both below the plane); s depends on v only.
  const double m = 0.5 + 1.0 / 256, k = 1.9, e = 1.71e-5;
  const double q0 = 0.5 + e - k * m * m, q1 = 0.5 + e - k * (1 - m) * (1 - m), slope0 = 2 * k * m;
  const double t[3] = {q0, q0 + slope0 / 2, q1};  // Bernstein coefficients of the quadratic
  const BSplineSurface s = surface_in(frame, 2, 1, 3, 2, false, rng, [&](int i, int j) {
    return Eigen::Vector3d(0.4 + 0.1 * j, t[i], 0.5);
  });
  const ComposeResult r = compose_exact(lattice, s);
  INFO(r.report.brief());
  CHECK(r.report.splits == 2 * 2);  // two knots, each to multiplicity 2
  // Both crossings are knots of the result, within rounding of the closed form m -+ sqrt(e / k).
  const std::vector<double> breaks = clay::surface::breakpoints(r.surface.u);
  for (double root : {m - std::sqrt(e / k), m + std::sqrt(e / k)})
    CHECK(std::any_of(breaks.begin(), breaks.end(),
                      [&](double b) { return std::abs(b - root) < 1e-9; }));
  CHECK(deviation(s, r.surface, map, 2000, rng) <= 1e-12 * size);
}

TEST_CASE("compose_exact composes a polynomial taper exactly") {
  std::mt19937 rng(23);
  Taper taper;
  taper.frame.origin = Eigen::Vector3d(5, -3, 2);
  taper.frame.axis = Eigen::Vector3d(0.2, 0.3, 1);
  taper.frame.reference = Eigen::Vector3d(1, 0, 0.1);
  taper.profile = {1.0, 0.02, 3e-4};
  const Frame frame = clay::test::random_frame(rng);
  const auto map = [&](const Eigen::Vector3d& p) { return deform_point(taper, p); };
  for (bool rational : {false, true}) {
    const BSplineSurface s = random_surface_in(frame, 3, 2, 5, 4, rational, rng);
    const ComposeResult r = compose_exact(taper, s);
    const auto box = clay::surface::control_box(s);
    INFO(r.report.brief());
    CHECK(deviation(s, r.surface, map, 1000, rng) <= 1e-12 * (box.second - box.first).norm());
    // D d(z) + e with D = 2: (2*3 + 3, 2*2 + 2).
    CHECK(r.report.degree_u == 9);
    CHECK(r.report.degree_v == 6);
    require_round_trips(r.surface, fresh_folder("taper"), rational ? "rational" : "polynomial");
  }
  // A plane perpendicular to the axis: z constant, r(z) constant, the degrees stay (3, 2).
  const Eigen::Vector3d ez = taper.frame.axis.normalized();
  const Eigen::Vector3d ex =
      (Eigen::Vector3d(1, 0, 0.1) - Eigen::Vector3d(1, 0, 0.1).dot(ez) * ez).normalized();
  const Eigen::Vector3d ey = ez.cross(ex);
  Frame flat;
  flat.origin = taper.frame.origin + 7 * ez;
  flat.s = 20 * ex, flat.t = 20 * ey, flat.u = ez;
  const BSplineSurface plane = surface_in(flat, 3, 2, 4, 3, false, rng, [&](int, int) {
    std::uniform_real_distribution<double> c(0, 1);
    return Eigen::Vector3d(c(rng), c(rng), 0.0);
  });
  const ComposeResult r = compose_exact(taper, plane);
  CHECK(r.report.degree_u == 3);
  CHECK(r.report.degree_v == 2);
  CHECK(deviation(plane, r.surface, map, 300, rng) <= 1e-12 * 40);
}

TEST_CASE("compose_exact errors name the problem and the fix") {
  std::mt19937 rng(31);
  const Frame frame = clay::test::random_frame(rng);
  // Displaced: a general tricubic FFD, total degree 9 (an undisplaced one is affine and keeps the
  // surface's degrees).
  const BezierLattice lattice = clay::test::displaced(make_bezier_lattice(frame, {3, 3, 3}), rng);
  const BSplineSurface inside = random_surface_in(frame, 3, 3, 4, 4, false, rng);

  SECTION("degree above the exchange limit") {
    const auto [category, what] = error_of([&] { compose_exact(lattice, inside); });
    CHECK(category == ErrorCategory::DegreeLimit);
    CHECK_THAT(what, Contains("degree (27, 27)") && Contains("25") && Contains("lower degree") &&
                         Contains("refit tolerance"));
  }
  SECTION("degree above the exchange limit for a taper") {
    Taper taper;
    taper.profile = std::vector<double>(9, 1e-3);
    const auto [category, what] = error_of([&] { compose_exact(taper, inside); });
    CHECK(category == ErrorCategory::DegreeLimit);
    CHECK_THAT(what, Contains("degree (27, 27)") && Contains("profile"));
  }
  SECTION("degree above the receiver's limit (ComposeOptions::max_degree)") {
    // A trilinear displaced lattice on a bicubic: exact degree (3 + 3 + 3) = 9 at most; with a
    // receiver capped at degree 8 it must fail before composing, naming the option.
    const BezierLattice low = clay::test::displaced(make_bezier_lattice(frame, {1, 1, 1}), rng);
    ComposeOptions options;
    const ComposeResult ok = compose_exact(low, inside, options);
    const int degree = std::max(ok.report.degree_u, ok.report.degree_v);
    REQUIRE(degree > 3);
    options.max_degree = degree - 1;
    const auto [category, what] = error_of([&] { compose_exact(low, inside, options); });
    CHECK(category == ErrorCategory::DegreeLimit);
    CHECK_THAT(what, Contains("ComposeOptions::max_degree") &&
                         Contains("above the limit " + std::to_string(degree - 1)));
    options.max_degree = degree;
    CHECK(compose_exact(low, inside, options).report.degree_u == ok.report.degree_u);
  }
  SECTION("max_degree outside [1, 50]") {
    for (int bad : {0, -3, 51}) {
      ComposeOptions options;
      options.max_degree = bad;
      const auto [category, what] = error_of([&] { compose_exact(lattice, inside, options); });
      CHECK(category == ErrorCategory::InvalidArgument);
      CHECK_THAT(what, Contains("max_degree = " + std::to_string(bad)) &&
                           Contains("1 <= max_degree <= 50"));
    }
  }
  SECTION("surface leaving the lattice") {
    const BSplineSurface out = surface_in(frame, 2, 2, 3, 3, false, rng, [&](int i, int j) {
      return Eigen::Vector3d(0.5 + 0.4 * i, 0.2 + 0.3 * j, 0.5);  // s reaches 1.3 at i = 2
    });
    const BezierLattice low = make_bezier_lattice(frame, {1, 1, 1});
    const auto [category, what] = error_of([&] { compose_exact(low, out); });
    CHECK(category == ErrorCategory::OutOfDomain);
    CHECK_THAT(what, Contains("local coordinate s") && Contains("enlarge the lattice"));
    const BSplineLattice bl = make_bspline_lattice(frame, {2, 2, 2}, {2, 2, 2});
    CHECK(error_of([&] { compose_exact(bl, out); }).first == ErrorCategory::OutOfDomain);
  }
  SECTION("bad options, lattice, surface and taper") {
    ComposeOptions bad;
    bad.knot_tolerance = -1;
    auto e = error_of([&] { compose_exact(lattice, inside, bad); });
    CHECK(e.first == ErrorCategory::InvalidArgument);
    CHECK_THAT(e.second, Contains("knot_tolerance"));
    bad = {};
    bad.check_samples = -2;
    CHECK_THAT(error_of([&] { bad.validate(); }).second, Contains("check_samples"));
    BezierLattice broken = lattice;
    broken.points.conservativeResize(3, 3);
    CHECK(error_of([&] { compose_exact(broken, inside); }).first == ErrorCategory::InvalidGeometry);
    BSplineSurface nan = inside;
    nan.points(0, 0) = std::nan("");
    CHECK(error_of([&] {
            compose_exact(make_bezier_lattice(frame, {1, 1, 1}), nan);
          }).first == ErrorCategory::InvalidGeometry);
    Taper taper;
    taper.profile.clear();
    CHECK(error_of([&] { compose_exact(taper, inside); }).first == ErrorCategory::InvalidGeometry);
    BSplineLattice bl = make_bspline_lattice(frame, {2, 2, 2}, {2, 2, 2});
    bl.points.conservativeResize(2, 3);
    CHECK(error_of([&] { compose_exact(bl, inside); }).first == ErrorCategory::InvalidGeometry);
  }
}

TEST_CASE("ComposeReport brief states the figures") {
  std::mt19937 rng(3);
  const Frame frame = clay::test::random_frame(rng);
  const BSplineSurface s = random_surface_in(frame, 2, 2, 3, 3, false, rng);
  const ComposeResult r = compose_exact(make_bezier_lattice(frame, {1, 1, 1}), s);
  // The undisplaced lattice is the identity, of total degree 1: the surface comes back with its
  // own degrees (2, 2), not the tensor-product rule's (3*2, 3*2).
  CHECK(r.report.degree_u == 2);
  CHECK_THAT(r.report.brief(), Contains("degree 2 x 2") && Contains("1 patches"));
  std::mt19937 rng2(4);
  CHECK(deviation(
            s, r.surface, [](const Eigen::Vector3d& p) { return p; }, 200, rng2) <= 1e-12 * 100);
}

TEST_CASE("compose_exact finds lower degrees: an axis-aligned affine sheet") {
  // s = 0.1 + 0.8 a and u = 0.2 + 0.1 a depend on the first parameter only (degree 1), t = 0.1 +
  // 0.8 b on the second: in a tricubic lattice 3*1 + 3*0 + 3*1 = 6 and 3*1 = 3.
  std::mt19937 rng(13);
  const Frame frame = clay::test::random_frame(rng);
  BSplineSurface s = surface_in(frame, 3, 3, 4, 4, false, rng, [&](int i, int j) {
    const double a = i / 3.0, b = j / 3.0;
    return Eigen::Vector3d(0.1 + 0.8 * a, 0.1 + 0.8 * b, 0.2 + 0.1 * a);
  });
  s.u = clay::surface::clamped_uniform_basis(3, 4);
  s.v = clay::surface::clamped_uniform_basis(3, 4);
  const BezierLattice lattice = clay::test::displaced(make_bezier_lattice(frame, {3, 3, 3}), rng);
  const ComposeResult r = compose_exact(lattice, s);
  CHECK(r.report.degree_u == 6);
  CHECK(r.report.degree_v == 3);
  CHECK(deviation(
            s, r.surface, [&](const Eigen::Vector3d& p) { return deform_point(lattice, p); }, 300,
            rng) <= 1e-12 * clay::test::size_of(lattice.points));
}

TEST_CASE(
    "compose_exact composes at the lattice's true total degree: affine lattices keep the "
    "surface's degrees") {
  std::mt19937 rng(29);
  const Frame frame = clay::test::random_frame(rng);
  const auto deviation_from = [&](const auto& lattice, const BSplineSurface& s,
                                  const BSplineSurface& composed) {
    return deviation(
        s, composed, [&](const Eigen::Vector3d& p) { return deform_point(lattice, p); }, 500, rng);
  };
  SECTION("a trilinear lattice whose top corners all move by one vector, a tricubic affine one") {
    BezierLattice trilinear = make_bezier_lattice(frame, {1, 1, 1});
    const Eigen::Vector3d shift(3.0, -2.0, 5.0);
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j)
        trilinear.points.row(trilinear.index(i, j, 1)) += shift.transpose();
    // Control points of an affine map A x + b are the map of the undisplaced ones (Bernstein
    // polynomials reproduce linear functions).
    BezierLattice tricubic = make_bezier_lattice(frame, {3, 3, 3});
    Eigen::Matrix3d a = Eigen::Matrix3d::Identity();
    a(0, 1) = 0.3, a(2, 0) = -0.2, a(1, 1) = 1.4;
    for (Eigen::Index r = 0; r < tricubic.points.rows(); ++r)
      tricubic.points.row(r) =
          (a * tricubic.points.row(r).transpose()).transpose() + Eigen::RowVector3d(1, 2, 3);
    for (bool rational : {false, true}) {
      const BSplineSurface s = random_surface_in(frame, 3, 3, 6, 5, rational, rng);
      for (const BezierLattice* lattice : {&trilinear, &tricubic}) {
        // The tensor-product rule gives 3 (1 + 1 + 1) = 9 and 3 (3 + 3 + 3) = 27 (above the
        // exchange limit 25); an affine map of a bicubic is a bicubic.
        const ComposeResult r = compose_exact(*lattice, s);
        CHECK(r.report.degree_u == 3);
        CHECK(r.report.degree_v == 3);
        CHECK(deviation_from(*lattice, s, r.surface) <=
              1e-12 * clay::test::size_of(lattice->points));
        CHECK(r.report.max_relative_deviation <= 1e-12);
      }
    }
  }
  SECTION("a tricubic lattice of total degree 2") {
    // Local displacement s + 0.2 s^2, t + 0.2 t u, u: Bernstein coefficients i/3 + 0.2 i(i-1)/6,
    // j/3 + 0.2 (j/3)(k/3), k/3 (s^2 = Σ C(i,2)/C(3,2) B_i^3). A general bicubic (and its weights)
    // composes to degree 2 * 3 = 6, not 27.
    BezierLattice quadratic = make_bezier_lattice(frame, {3, 3, 3});
    for (int i = 0; i <= 3; ++i)
      for (int j = 0; j <= 3; ++j)
        for (int k = 0; k <= 3; ++k)
          quadratic.points.row(quadratic.index(i, j, k)) =
              frame
                  .point(i / 3.0 + 0.2 * i * (i - 1) / 6.0, j / 3.0 + 0.2 * (j / 3.0) * (k / 3.0),
                         k / 3.0)
                  .transpose();
    for (bool rational : {false, true}) {
      const BSplineSurface s = random_surface_in(frame, 3, 3, 5, 5, rational, rng);
      const ComposeResult r = compose_exact(quadratic, s);
      CHECK(r.report.degree_u == 6);
      CHECK(r.report.degree_v == 6);
      CHECK(deviation_from(quadratic, s, r.surface) <=
            1e-12 * clay::test::size_of(quadratic.points));
    }
  }
  SECTION("an undisplaced B-spline lattice: the identity, cell by cell") {
    const BSplineLattice identity = make_bspline_lattice(frame, {3, 3, 2}, {3, 2, 1});
    std::vector<double> x{0.05, 0.3, 0.6, 0.7, 0.95}, y{0.1, 0.4, 0.6, 0.9};
    std::uniform_real_distribution<double> h(0.2, 0.8);
    const BSplineSurface s = surface_in(frame, 3, 2, 5, 4, false, rng, [&](int i, int j) {
      return Eigen::Vector3d(x[size_t(i)], y[size_t(j)], h(rng));
    });
    const ComposeResult r = compose_exact(identity, s);
    CHECK(r.report.splits > 0);
    CHECK(r.report.degree_u == 3);
    CHECK(r.report.degree_v == 2);
    CHECK(deviation_from(identity, s, r.surface) <= 1e-12 * clay::test::size_of(identity.points));
  }
}

TEST_CASE("Exact composition keeps a closed side closed and a pole a point, bit for bit",
          "[compose]") {
  // A full revolution of a half circle whose ends lie exactly on the axis: closed in u, its
  // first and last columns collapsed to the poles.
  clay::surface::Points3 p(5, 3);
  p << 0, 0, -30, 30, 0, -30, 30, 0, 0, 30, 0, 30, 0, 0, 30;
  Eigen::VectorXd w(5);
  w << 1, std::sqrt(0.5), 1, std::sqrt(0.5), 1;
  const auto sphere =
      clay::surface::revolve(clay::surface::make_curve(2, {0, 0, 0, 0.5, 0.5, 1, 1, 1}, p, w),
                             {{0, 0, 0}, {0, 0, 1}}, 360)
          .surface;
  Frame f;
  f.origin = {-40, -40, -40};
  f.s = {80, 5, 0};
  f.t = {0, 80, 3};
  f.u = {2, 0, 80};
  BezierLattice lattice = make_bezier_lattice(f, {2, 2, 2});
  lattice.points.row(lattice.index(1, 1, 2)) += Eigen::RowVector3d(4, -3, 9);
  lattice.points.row(lattice.index(2, 1, 1)) += Eigen::RowVector3d(6, 2, -1);
  const auto result = compose_exact(lattice, sphere);
  const auto& s = result.surface;
  const int mu = s.count_u(), mv = s.count_v();
  for (int j = 0; j < mv; ++j) {
    CHECK(s.points.row(s.index(0, j)) == s.points.row(s.index(mu - 1, j)));
    CHECK(s.weights[s.index(0, j)] == s.weights[s.index(mu - 1, j)]);
  }
  const Eigen::RowVector3d south =
      deform_point(lattice, sphere.points.row(0).transpose()).transpose();
  const Eigen::RowVector3d north =
      deform_point(lattice, sphere.points.row(sphere.count_v() - 1).transpose()).transpose();
  for (int i = 0; i < mu; ++i) {
    CHECK(s.points.row(s.index(i, 0)) == south);
    CHECK(s.points.row(s.index(i, mv - 1)) == north);
  }
  CHECK(result.report.max_relative_deviation < 1e-13);
}
