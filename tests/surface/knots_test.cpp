#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>

#include <cmath>
#include <random>
#include <tuple>
#include <vector>

#include "error_of.hpp"
#include "random_geometry.hpp"

using namespace clay::surface;
using clay::test::relative_deviation;

TEST_CASE("knot insertion keeps curves unchanged", "[knots]") {
  std::mt19937 rng(31);
  for (int p = 1; p <= 7; ++p) {
    for (bool clamped : {true, false}) {
      const BSplineCurve c = clay::test::random_curve(rng, p, p + 5, true, clamped, p);
      const auto [a, b] = c.basis.domain();
      const double t = a + 0.37 * (b - a);
      const BSplineCurve once = insert_knot(c, t);
      CHECK(once.basis.count() == c.basis.count() + 1);
      CHECK(multiplicity(once.basis, t) == 1 + multiplicity(c.basis, t));
      CHECK(relative_deviation(c, once) < 1e-12);
      const BSplineCurve full = insert_knot(c, t, p);
      CHECK(multiplicity(full.basis, t) == p);
      CHECK(relative_deviation(c, full) < 1e-12);
      // At an existing knot and at the domain ends.
      const double k = c.basis.knots[static_cast<size_t>(p + 1)];
      if (k < b && multiplicity(c.basis, k) < p)
        CHECK(relative_deviation(c, insert_knot(c, k)) < 1e-12);
      if (!clamped && p > 1) {  // unclamped ends are simple knots: room for p - 1 more
        CHECK(relative_deviation(c, insert_knot(c, a)) < 1e-12);
        CHECK(relative_deviation(c, insert_knot(c, b, p - 1)) < 1e-12);
      }
    }
  }
}

TEST_CASE("knot insertion in u and v keeps surfaces unchanged", "[knots]") {
  std::mt19937 rng(32);
  for (int p = 1; p <= 5; ++p) {
    const BSplineSurface s =
        clay::test::random_surface(rng, p, 6 - p, p + 3, 9 - p, true, p != 3, 2);
    const BSplineSurface su = insert_knot_u(s, 0.41, 2 > p ? p : 2);
    const BSplineSurface sv = insert_knot_v(s, 0.77);
    CHECK(su.count_u() == s.count_u() + (2 > p ? p : 2));
    CHECK(sv.count_v() == s.count_v() + 1);
    CHECK(relative_deviation(s, su) < 1e-12);
    CHECK(relative_deviation(s, sv) < 1e-12);
  }
}

TEST_CASE("restricted keeps the surface over a box of its domain, parameters unchanged",
          "[knots]") {
  std::mt19937 rng(71);
  for (int p = 1; p <= 4; ++p)
    for (bool rational : {false, true}) {
      const BSplineSurface s =
          clay::test::random_surface(rng, p, 5 - p, p + 4, 8 - p, rational, true, 2);
      const auto [a, b] = s.u.domain();
      const auto [c, d] = s.v.domain();
      // Inside, at an existing knot (no insertion needed) and at the domain's own side.
      const double u0 = a + 0.23 * (b - a),
                   u1 = s.u.knots[s.u.knots.size() - 1 - static_cast<std::size_t>(p) - 1];
      const double v0 = c, v1 = c + 0.71 * (d - c);
      if (!(u1 > u0)) continue;
      const BSplineSurface r = restricted(s, u0, u1, v0, v1);
      INFO("degree " << p << (rational ? " rational" : ""));
      CHECK(r.u.domain() == std::pair{u0, u1});
      CHECK(r.v.domain() == std::pair{v0, v1});
      CHECK(r.u.degree == s.u.degree);
      double worst = 0;
      std::uniform_real_distribution<double> x(0, 1);
      for (int k = 0; k < 200; ++k) {
        const double u = u0 + x(rng) * (u1 - u0), v = v0 + x(rng) * (v1 - v0);
        worst = std::max(worst, (evaluate(r, u, v) - evaluate(s, u, v)).norm());
      }
      for (const double u : {u0, u1})
        for (const double v : {v0, v1})
          worst = std::max(worst, (evaluate(r, u, v) - evaluate(s, u, v)).norm());
      CHECK(worst <= 1e-12 * 100);
    }
  const BSplineSurface s = clay::test::random_surface(rng, 3, 3, 6, 6, false);
  // Plain copies: Clang 14 refuses structured bindings captured by lambdas.
  const double a = s.u.domain().first, b = s.u.domain().second;
  const double c = s.v.domain().first, d = s.v.domain().second;
  CHECK(clay::test::error_of([&] { (void)restricted(s, a - 1, b, c, d); }).first ==
        clay::ErrorCategory::InvalidArgument);
  CHECK(clay::test::error_of([&] { (void)restricted(s, a, b, d, d); }).first ==
        clay::ErrorCategory::InvalidArgument);
}

TEST_CASE("refinement equals repeated insertion and keeps the shape", "[knots]") {
  std::mt19937 rng(33);
  for (int p = 1; p <= 6; ++p) {
    for (bool clamped : {true, false}) {
      const BSplineCurve c = clay::test::random_curve(rng, p, p + 6, true, clamped);
      const auto [a, b] = c.basis.domain();
      std::vector<double> x = {a + 0.9 * (b - a), a + 0.1 * (b - a), a + 0.5 * (b - a)};
      if (p > 1) x.push_back(a + 0.5 * (b - a));  // a double knot
      if (!clamped && p > 1) {
        x.push_back(a);
        x.push_back(b);
      }
      const BSplineCurve r = refine_knots(c, x);
      BSplineCurve seq = c;
      for (double t : x) seq = insert_knot(seq, t);
      REQUIRE(r.basis.knots == seq.basis.knots);
      CHECK((r.points - seq.points).cwiseAbs().maxCoeff() < 1e-10);
      CHECK((r.weights - seq.weights).cwiseAbs().maxCoeff() < 1e-12);
      CHECK(relative_deviation(c, r) < 1e-12);
    }
  }
  std::mt19937 rng2(34);
  const BSplineSurface s = clay::test::random_surface(rng2, 3, 4, 7, 8, true);
  const std::vector<double> ku = {0.2, 0.2, 0.6, 0.95}, kv = {-0.5, 0.0, 1.5};
  CHECK(relative_deviation(s, refine_knots_u(s, ku)) < 1e-12);
  CHECK(relative_deviation(s, refine_knots_v(s, kv)) < 1e-12);
}

TEST_CASE("Bézier extraction: patches evaluate like the surface on their spans", "[knots]") {
  std::mt19937 rng(35);
  for (bool clamped : {true, false}) {
    const BSplineSurface s = clay::test::random_surface(rng, 3, 2, 7, 6, true, clamped, 2);
    const BezierPatches bez = extract_bezier(s);
    REQUIRE(bez.count_u() == static_cast<int>(breakpoints(s.u).size()) - 1);
    REQUIRE(bez.patches.size() == static_cast<size_t>(bez.count_u() * bez.count_v()));
    const auto [lo, hi] = control_box(s);
    const double size = (hi - lo).norm();
    double worst = 0;
    for (int i = 0; i < bez.count_u(); ++i)
      for (int j = 0; j < bez.count_v(); ++j) {
        const BSplineSurface& patch = bez.patch(i, j);
        CHECK(patch.count_u() == 4);
        CHECK(patch.count_v() == 3);
        CHECK(is_clamped(patch.u));
        for (double u : linspace(bez.breaks_u[static_cast<size_t>(i)],
                                 bez.breaks_u[static_cast<size_t>(i + 1)], 7))
          for (double v : linspace(bez.breaks_v[static_cast<size_t>(j)],
                                   bez.breaks_v[static_cast<size_t>(j + 1)], 7))
            worst = std::max(worst, (evaluate(patch, u, v) - evaluate(s, u, v)).norm());
      }
    CHECK(worst / size < 1e-12);
  }
  std::mt19937 rng2(36);
  const BSplineCurve c = clay::test::random_curve(rng2, 4, 9, true, false);
  const auto segments = extract_bezier(c);
  const auto breaks = breakpoints(c.basis);
  REQUIRE(segments.size() == breaks.size() - 1);
  double worst = 0;
  for (size_t k = 0; k < segments.size(); ++k)
    for (double t : linspace(breaks[k], breaks[k + 1], 11))
      worst = std::max(worst, (evaluate(segments[k], t) - evaluate(c, t)).norm());
  CHECK(worst < 1e-10);
}

TEST_CASE("knot operations refuse bad requests", "[knots][errors]") {
  std::mt19937 rng(37);
  const BSplineCurve c = clay::test::random_curve(rng, 3, 6, false);
  try {
    insert_knot(c, 1.5);
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::OutOfDomain);
    CHECK_THAT(e.what(), Catch::Contains("1.5") && Catch::Contains("insert_knot"));
  }
  try {
    insert_knot(c, 0.5, 4);
    FAIL("no throw");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::InvalidArgument);
    CHECK_THAT(e.what(), Catch::Contains("multiplicity 4") && Catch::Contains("at most 3"));
  }
  CHECK_THROWS_AS(insert_knot(c, 0.0), clay::Error);  // clamped end already at degree + 1
  CHECK_THROWS_AS(insert_knot(c, 0.5, -1), clay::Error);
  const std::vector<double> bad = {0.5, 2.0};
  CHECK_THROWS_AS(refine_knots(c, bad), clay::Error);
  BSplineCurve broken = c;
  broken.points(2, 2) = std::nan("");
  CHECK_THROWS_AS(extract_bezier(broken), clay::Error);
}

TEST_CASE("remove_knots undoes knot refinement and keeps the knots a shape needs", "[knots]") {
  std::mt19937 rng(77);
  for (int p = 1; p <= 6; ++p)
    for (bool rational : {false, true}) {
      const BSplineCurve c = clay::test::random_curve(rng, p, p + 4, rational);
      // Raising every interior knot to multiplicity p (Bézier form): all the new copies are
      // removable, no original knot is.
      std::vector<double> extra;
      const auto [a, b] = c.basis.domain();
      for (double k : c.basis.knots)
        if (k > a && k < b && (extra.empty() || extra.back() != k))
          for (int r = multiplicity(c.basis, k); r < p; ++r) extra.push_back(k);
      const BSplineCurve refined = refine_knots(c, extra);
      const int inserted = static_cast<int>(extra.size());
      const CurveKnotRemoval back = remove_knots(refined, 1e-9);
      CHECK(back.removed == inserted);
      CHECK(back.curve.basis.knots == c.basis.knots);
      CHECK((back.curve.points - c.points).cwiseAbs().maxCoeff() < 1e-9);
      CHECK((back.curve.weights - c.weights).cwiseAbs().maxCoeff() < 1e-11);
      // Random control points: no original knot can go within a tight tolerance.
      CHECK(remove_knots(c, 1e-9).removed == 0);
    }
  for (bool rational : {false, true}) {
    const BSplineSurface s = clay::test::random_surface(rng, 3, 2, 7, 6, rational);
    const BezierPatches bp = extract_bezier(s);  // the breaks
    std::vector<double> extra_u, extra_v;
    for (size_t i = 1; i + 1 < bp.breaks_u.size(); ++i)
      extra_u.insert(extra_u.end(), 2, bp.breaks_u[i]);
    for (size_t j = 1; j + 1 < bp.breaks_v.size(); ++j) extra_v.push_back(bp.breaks_v[j]);
    const BSplineSurface refined = refine_knots_v(refine_knots_u(s, extra_u), extra_v);
    const SurfaceKnotRemoval in_u = remove_knots_u(refined, 1e-9);
    const SurfaceKnotRemoval in_v = remove_knots_v(in_u.surface, 1e-9);
    CHECK(in_u.removed == static_cast<int>(extra_u.size()));
    CHECK(in_v.removed == static_cast<int>(extra_v.size()));
    CHECK(in_v.surface.u.knots == s.u.knots);
    CHECK(in_v.surface.v.knots == s.v.knots);
    CHECK(relative_deviation(s, in_v.surface) < 1e-12);
    // Both directions in one call: the same knots, the original surface again.
    const SurfaceKnotRemoval both = remove_knots(refined, 1e-9);
    CHECK(both.removed == static_cast<int>(extra_u.size() + extra_v.size()));
    CHECK(both.surface.u.knots == s.u.knots);
    CHECK(both.surface.v.knots == s.v.knots);
    CHECK(both.surface.is_rational() == rational);
    CHECK(relative_deviation(s, both.surface) < 1e-12);
  }
}

TEST_CASE(
    "join_bezier_patches undoes extract_bezier: C0 joined, then remove_knots gives the surface "
    "back",
    "[knots]") {
  std::mt19937 rng(41);
  for (bool rational : {false, true}) {
    const BSplineSurface s = clay::test::random_surface(rng, 3, 2, 7, 6, rational);
    BezierPatches bp = extract_bezier(s);
    // One patch raised in degree (exactly): the join elevates the others to match.
    bp.patches[1] = elevate_degree_v(elevate_degree_u(bp.patches[1], 2), 1);
    const BSplineSurface joined = join_bezier_patches(bp);
    CHECK(joined.u.degree == 5);
    CHECK(joined.v.degree == 3);
    CHECK(joined.is_rational() == rational);
    // C0: every interior break has multiplicity = degree
    for (std::size_t i = 1; i + 1 < bp.breaks_u.size(); ++i)
      CHECK(multiplicity(joined.u, bp.breaks_u[i]) == 5);
    CHECK(joined.points.rows() ==
          static_cast<Eigen::Index>((bp.count_u() * 5 + 1) * (bp.count_v() * 3 + 1)));
    CHECK(relative_deviation(s, joined) < 1e-13);
    // Without the elevated patch, removal gives the original knots and net back.
    const BSplineSurface plain = join_bezier_patches(extract_bezier(s));
    const SurfaceKnotRemoval in_u = remove_knots_u(plain, 1e-9);
    const SurfaceKnotRemoval in_v = remove_knots_v(in_u.surface, 1e-9);
    CHECK(in_v.surface.u.knots == s.u.knots);
    CHECK(in_v.surface.v.knots == s.v.knots);
    CHECK(relative_deviation(s, in_v.surface) < 1e-12);
  }
}

TEST_CASE("join_bezier_patches refuses patches that do not match their breaks or do not meet",
          "[knots][errors]") {
  std::mt19937 rng(43);
  const BSplineSurface s = clay::test::random_surface(rng, 2, 2, 5, 4, true);
  const BezierPatches good = extract_bezier(s);
  REQUIRE(good.count_u() == 3);
  REQUIRE(good.count_v() == 2);
  BezierPatches missing = good;
  missing.patches.pop_back();
  auto [category, what] = clay::test::error_of([&] { (void)join_bezier_patches(missing); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(what, Catch::Matchers::Contains("5 patches for 3 x 2 break intervals"));
  BezierPatches shifted = good;
  shifted.breaks_u[1] += 1e-3;  // patch (0, *) no longer spans its interval
  std::tie(category, what) = clay::test::error_of([&] { (void)join_bezier_patches(shifted); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(what, Catch::Matchers::Contains("patch (0, 0) is not one clamped Bézier span"));
  BezierPatches torn = good;
  torn.patches[3].points.row(0) +=
      Eigen::RowVector3d(0, 0, 1);  // patch (1, 1)'s corner leaves (1, 0)'s edge
  std::tie(category, what) = clay::test::error_of([&] { (void)join_bezier_patches(torn); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Catch::Matchers::Contains("neighbouring patches do not meet"));
  CHECK_THROWS_AS(join_bezier_patches(good, -1.0), clay::Error);
}

TEST_CASE("remove_knots keeps a knot whose exact removal would leave a weight <= 0", "[knots]") {
  // The Bézier arc with weights (1, -0.5, 1) has a positive weight function, 0.25 at t = 0.5;
  // inserting t = 0.5 gives positive weights (1, 0.25, 0.25, 1) and a valid NURBS. Removing the
  // knot again is exact in homogeneous space (gap 0) but brings back the weight -0.5, so it must
  // be refused: the curve comes back unchanged.
  clay::surface::Points3 points(4, 3);
  points << 0, 0, 0, -1, -1, 0, 3, -1, 0, 2, 0, 0;
  Eigen::VectorXd weights(4);
  weights << 1, 0.25, 0.25, 1;
  const BSplineCurve c =
      clay::surface::make_curve(2, {0, 0, 0, 0.5, 1, 1, 1}, std::move(points), weights);
  // Independent check of the premise: the homogeneous points are the split of the arc.
  const Eigen::Vector3d mid = clay::surface::evaluate(c, 0.5);
  CHECK((mid - Eigen::Vector3d(1, -1, 0)).norm() <= 1e-15);  // (0.25, -0.25, 0) / 0.25
  const auto removal = remove_knots(c, 1e-9);
  CHECK(removal.removed == 0);
  CHECK(clay::surface::identical(removal.curve, c));
  CHECK(clay::surface::problems(removal.curve).empty());
}

TEST_CASE("remove_knots refuses a negative or non-finite tolerance", "[knots]") {
  std::mt19937 rng(3);
  const BSplineCurve c = clay::test::random_curve(rng, 3, 6, false);
  const BSplineSurface s = clay::test::random_surface(rng, 2, 2, 4, 4, false);
  for (double bad : {-1e-9, std::nan(""), HUGE_VAL}) {
    const auto [category, what] = clay::test::error_of([&] { (void)remove_knots(c, bad); });
    CHECK(category == clay::ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Catch::Matchers::Contains("remove_knots: tolerance_mm"));
    CHECK_THROWS_AS(remove_knots_v(s, bad), clay::Error);
    CHECK_THROWS_AS(remove_knots(s, bad), clay::Error);
  }
}

TEST_CASE(
    "bezier_extraction: each span's operator maps the control points to a Bézier piece that "
    "evaluates like the curve",
    "[knots]") {
  std::mt19937 rng(5);
  for (int p = 1; p <= 5; ++p)
    for (bool clamped : {true, false}) {
      const BSplineCurve c = clay::test::random_curve(rng, p, p + 6, false, clamped, p);
      const std::vector<SpanExtraction> spans = bezier_extraction(c.basis);
      CHECK(spans.size() == breakpoints(c.basis).size() - 1);
      for (const SpanExtraction& e : spans) {
        REQUIRE(e.matrix.rows() == p + 1);
        // Partition of unity: every Bézier point is an affine combination.
        CHECK((e.matrix.rowwise().sum().array() - 1.0).abs().maxCoeff() < 1e-13);
        BSplineCurve piece;
        piece.basis.degree = p;
        piece.basis.knots.assign(static_cast<size_t>(p + 1), e.a);
        piece.basis.knots.insert(piece.basis.knots.end(), static_cast<size_t>(p + 1), e.b);
        piece.points = e.matrix * c.points.middleRows(e.first, p + 1);
        piece.weights = Eigen::VectorXd::Ones(p + 1);
        for (int k = 0; k <= 10; ++k) {
          const double t = k == 10 ? e.b : e.a + (e.b - e.a) * k / 10.0;
          CHECK((evaluate(piece, t) - evaluate(c, t)).norm() < 1e-11);
        }
      }
    }
}

TEST_CASE("c0_knots: the ends p + 1 times, every interior break p times, as a join writes them",
          "[knots]") {
  using clay::surface::c0_knots;
  CHECK(c0_knots({0.0, 0.25, 1.0}, 2) == std::vector<double>{0, 0, 0, 0.25, 0.25, 1, 1, 1});
  CHECK(c0_knots({0.0, 1.0}, 3) == std::vector<double>{0, 0, 0, 0, 1, 1, 1, 1});
  CHECK(c0_knots({-1.0, 0.5, 2.0, 3.0}, 3) ==
        std::vector<double>{-1, -1, -1, -1, 0.5, 0.5, 0.5, 2, 2, 2, 3, 3, 3, 3});
}
