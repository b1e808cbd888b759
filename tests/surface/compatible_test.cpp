// make_compatible with sliver merging (issue #21 item 3): knots of different curves that nearly
// coincide are merged, exactly where the knot is removable, else within the stated tolerance.
#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/occt/fill.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/surface/projection.hpp>
#include <clay/surface/skin.hpp>
#include <clay/surface/surface_curves.hpp>

#include <algorithm>
#include <random>

#include "error_of.hpp"

using namespace clay::surface;
using clay::test::error_of;

namespace {

/// A cubic from `from` to `to` with the given interior knots and random bulges of up to
/// `bulge` mm at every control point: each knot carries shape (not removable).
BSplineCurve stroke(std::mt19937& rng, const std::vector<double>& interior,
                    const Eigen::Vector3d& from, const Eigen::Vector3d& to, double bulge) {
  std::vector<double> knots(4, 0.0);
  knots.insert(knots.end(), interior.begin(), interior.end());
  knots.insert(knots.end(), 4, 1.0);
  const auto n = static_cast<Eigen::Index>(knots.size()) - 4;
  std::uniform_real_distribution<double> d(-bulge, bulge);
  Points3 p(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double f = static_cast<double>(i) / static_cast<double>(n - 1);
    p.row(i) = ((1 - f) * from + f * to).transpose();
    if (i > 0 && i + 1 < n) p.row(i) += Eigen::RowVector3d(d(rng), d(rng), d(rng));
  }
  return make_curve(3, knots, p);
}

/// Largest distance from samples of `a` to the curve `b` (closest points: independent of how
/// either is parametrized).
double distance_to_curve(const BSplineCurve& a, const BSplineCurve& b, int count = 801) {
  const auto [t0, t1] = a.basis.domain();
  double worst = 0;
  for (double t : linspace(t0, t1, count))
    worst = std::max(worst, closest_point(b, evaluate(a, t), 16).distance);
  return worst;
}

double size_of(const std::vector<BSplineCurve>& curves) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto& c : curves) {
    lo = lo.cwiseMin(c.points.colwise().minCoeff().transpose());
    hi = hi.cwiseMax(c.points.colwise().maxCoeff().transpose());
  }
  return (hi - lo).norm();
}

}  // namespace

TEST_CASE("smallest_span_ratio is the shortest span over its longer neighbour", "[compatible]") {
  BSplineBasis b{3, {0, 0, 0, 0, 0.25, 0.5, 0.5003, 1, 1, 1, 1}};
  CHECK(smallest_span_ratio(b) == Approx(0.0003 / 0.4997).epsilon(1e-9));
  CHECK(smallest_span_ratio(clamped_uniform_basis(3, 4)) == 1.0);
  CHECK(smallest_span_ratio(clamped_uniform_basis(3, 8)) == Approx(1.0).epsilon(1e-12));
}

TEST_CASE("a removable knot next to another curve's knot is merged exactly", "[compatible]") {
  std::mt19937 rng(2101);
  const BSplineCurve a = stroke(rng, {0.25, 0.5, 0.75}, {0, 0, 0}, {400, 0, 0}, 20);
  // b carries a knot at 0.5003 that knot insertion put there: removable, so merging is exact.
  const BSplineCurve b =
      insert_knot(stroke(rng, {0.25, 0.75}, {0, 200, 0}, {400, 200, 30}, 20), 0.5003);
  REQUIRE(smallest_span_ratio(make_compatible({a, b})[0].basis) < 0.002);
  const CompatibleCurves out = make_compatible({a, b}, KnotMergeOptions{0.05, 1e-9});
  REQUIRE(out.merges.size() == 1);
  CHECK(out.merges[0].curve == 1);
  CHECK(!out.merges[0].reparametrized);
  CHECK(smallest_span_ratio(out.curves[0].basis) >= 0.05);
  CHECK(out.curves[0].basis.knots == out.curves[1].basis.knots);
  // Same parameters, same points (independent pointwise evaluation of the inputs).
  const std::vector<BSplineCurve> inputs{a, b};
  for (int k = 0; k < 2; ++k) {
    double worst = 0;
    for (double t : linspace(0, 1, 1001))
      worst = std::max(worst, (evaluate(out.curves[static_cast<size_t>(k)], t) -
                               evaluate(inputs[static_cast<size_t>(k)], t))
                                  .norm());
    CHECK(worst < 1e-12 * 500);
  }
  CHECK(out.max_deviation_mm < 1e-12 * 500);
}

TEST_CASE("strokes whose knots nearly coincide are merged within the tolerance", "[compatible]") {
  std::mt19937 rng(2102);
  // The case: two fitted strokes with knots at 0.50057 and 0.50089 (a span 1/780 of its
  // neighbours); each knot carries shape. At 1e-5 of the size a plain move of the knot is close
  // enough; at 1e-6 only a reparametrization is.
  const BSplineCurve a = stroke(rng, {0.25, 0.50057, 0.75}, {0, 0, 0}, {1000, 0, 0}, 40);
  const BSplineCurve b = stroke(rng, {0.25, 0.50089, 0.75}, {0, 300, 0}, {1000, 300, 60}, 40);
  const double relative = GENERATE(1e-5, 1e-6);
  const double tolerance = relative * size_of({a, b});
  REQUIRE(smallest_span_ratio(make_compatible({a, b})[0].basis) < 0.002);
  const CompatibleCurves out = make_compatible({a, b}, KnotMergeOptions{0.05, tolerance});
  INFO("tolerance " << tolerance << ", merges " << out.merges.size() << ", deviation "
                    << out.max_deviation_mm << ", knots added " << out.merges[0].knots_added);
  REQUIRE(out.merges.size() == 1);
  CHECK(out.merges[0].reparametrized == (relative < 1e-5));
  CHECK(smallest_span_ratio(out.curves[0].basis) >= 0.05);
  CHECK(out.max_deviation_mm <= tolerance);
  const std::vector<BSplineCurve> inputs{a, b};
  for (int k = 0; k < 2; ++k) {
    const BSplineCurve& c = out.curves[static_cast<size_t>(k)];
    const BSplineCurve& in = inputs[static_cast<size_t>(k)];
    // Independently, by closest points both ways: the shape moved by at most the tolerance.
    CHECK(distance_to_curve(c, in) <= tolerance);
    CHECK(distance_to_curve(in, c) <= tolerance);
    // input_parameter gives where each point came from.
    double worst = 0;
    for (double t : linspace(0, 1, 1001))
      worst = std::max(worst, (evaluate(c, t) - evaluate(in, input_parameter(out, k, t))).norm());
    CHECK(worst <= tolerance);
  }
}

TEST_CASE("a fill from strokes with nearly coinciding knots has no sliver span", "[compatible]") {
  std::mt19937 rng(2103);
  const Eigen::Vector3d p0(0, 0, 0), p1(1000, 0, 0), p2(1000, 400, 80), p3(0, 400, 60);
  const std::vector<BSplineCurve> sides = {
      stroke(rng, {0.25, 0.50057, 0.75}, p0, p1, 30), stroke(rng, {0.5}, p1, p2, 20),
      stroke(rng, {0.24971, 0.50089, 0.75}, p2, p3, 30), stroke(rng, {0.5}, p3, p0, 20)};
  const double size = size_of(sides);
  FillOptions keep;
  keep.min_span_ratio = 0;
  const BuiltSurface before = fill(sides, keep);
  REQUIRE(smallest_span_ratio(before.surface.u) < 0.002);
  CHECK(before.report.exact);

  const BuiltSurface built = fill(sides);  // the defaults: 0.05 and 1e-5 of the size
  INFO(built.report.brief());
  CHECK(smallest_span_ratio(built.surface.u) >= 0.05);
  CHECK(smallest_span_ratio(built.surface.v) >= 0.05);
  CHECK(!built.report.exact);
  CHECK_THAT(built.report.method, Catch::Contains("sliver"));
  CHECK(built.report.max_deviation_mm <= 1e-5 * size);
  // Independently: every side against the edge it became, by closest points both ways.
  const auto [ua, ub] = built.surface.u.domain();
  const auto [va, vb] = built.surface.v.domain();
  const std::vector<BSplineCurve> edges = {
      iso_curve_v(built.surface, va), iso_curve_u(built.surface, ub),
      iso_curve_v(built.surface, vb), iso_curve_u(built.surface, ua)};
  for (size_t k = 0; k < 4; ++k) {
    CHECK(distance_to_curve(edges[k], sides[k]) <= 1e-5 * size);
    CHECK(distance_to_curve(sides[k], edges[k]) <= 1e-5 * size);
  }
}

TEST_CASE("a loft merges slivers of its sections' knot union", "[compatible][loft]") {
  std::mt19937 rng(2104);
  std::vector<BSplineCurve> sections;
  const double knots[3] = {0.4, 0.4004, 0.3998};
  for (int k = 0; k < 3; ++k)
    sections.push_back(
        stroke(rng, {knots[k], 0.7}, {0, 200.0 * k, 0}, {500, 200.0 * k, 40.0 * k}, 25));
  const double size = size_of(sections);
  const BuiltSurface built = loft(sections);
  INFO(built.report.brief());
  CHECK(smallest_span_ratio(built.surface.u) >= 0.05);
  CHECK(!built.report.exact);
  CHECK(built.report.max_deviation_mm <= 1e-5 * size);
  const std::vector<double> v = loft_parameters(sections);
  for (size_t k = 0; k < sections.size(); ++k)
    CHECK(distance_to_curve(sections[k], iso_curve_v(built.surface, v[k])) <= 1e-5 * size);
}

TEST_CASE("a sliver that cannot be merged within the tolerance is an error", "[compatible]") {
  std::mt19937 rng(2105);
  const BSplineCurve a = stroke(rng, {0.3, 0.5}, {0, 0, 0}, {300, 0, 0}, 30);
  const BSplineCurve b = stroke(rng, {0.3, 0.52}, {0, 100, 0}, {300, 100, 0}, 30);
  const auto [category, message] = error_of([&] {
    make_compatible({a, b}, KnotMergeOptions{0.2, 1e-9}, {"side A", "side B"});
  });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Contains("side A") && Catch::Contains("side B") &&
                          Catch::Contains("min_span_ratio 0") && Catch::Contains("tolerance"));
  // With the sliver allowed, the union keeps it.
  CHECK(make_compatible({a, b}, KnotMergeOptions{0.0, 1e-9}).merges.empty());
}

TEST_CASE("knot merge options are checked", "[compatible]") {
  std::mt19937 rng(2106);
  const BSplineCurve a = stroke(rng, {0.5}, {0, 0, 0}, {300, 0, 0}, 30);
  for (const KnotMergeOptions& bad : {KnotMergeOptions{0.5, 1e-3}, KnotMergeOptions{-0.1, 1e-3},
                                      KnotMergeOptions{0.05, 0.0}, KnotMergeOptions{0.05, NAN}}) {
    const auto [category, message] = error_of([&] { make_compatible({a}, bad); });
    CHECK(category == clay::ErrorCategory::InvalidArgument);
    CHECK_THAT(message, Catch::Contains("KnotMergeOptions::"));
  }
  FillOptions f;
  f.min_span_ratio = 0.6;
  CHECK_THAT(f.problems().front(), Catch::Contains("min_span_ratio"));
  LoftOptions l;
  l.merge_tolerance = 0;
  CHECK_THAT(l.problems().front(), Catch::Contains("merge_tolerance"));
}
