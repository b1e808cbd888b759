// Certified refit (issue #7 item 4): every fit is checked at random parameters the refit never
// sampled, against a deformation computed here independently where a closed form exists (twist as
// an Eigen rotation, taper as a radial scale); the certified bound must hold there and be within a
// sensible factor of what the check finds. Knot-plane crossings are found independently by
// sampling the surface's lattice coordinates.
#include <catch2/catch.hpp>

#include <clay/deform.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/degree_elevation.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/knots.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/skin.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <set>
#include <utility>

#include "error_of.hpp"
#include "fixtures.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinRel;
using clay::ErrorCategory;
using clay::Termination;
using clay::test::error_of;
namespace surface = clay::surface;

namespace {

/// A cubic open section: an arc-like curve of 6 control points at height z, scaled by `scale`
/// and wobbled by `wobble`.
surface::BSplineCurve section(double z, double scale, double wobble) {
  surface::Points3 p(6, 3);
  for (int i = 0; i < 6; ++i) {
    const double a = 0.6 * i;
    p.row(i) << scale * 40 * std::cos(a), scale * (25 + wobble * (i % 2)) * std::sin(a), z;
  }
  return surface::make_curve(3, {0, 0, 0, 0, 1.0 / 3, 2.0 / 3, 1, 1, 1, 1}, p);
}

/// A loft through four sections from z = 0 to z = 120 mm.
surface::BSplineSurface loft_surface() {
  std::vector<surface::BSplineCurve> sections{section(0, 1.0, 0), section(40, 0.8, 6),
                                              section(80, 1.1, -4), section(120, 0.9, 3)};
  return surface::loft(sections).surface;
}

/// Largest |fit(u, v) − target(S(u, v))| at `n` uniform random parameters.
template <class Target>
double random_deviation(const surface::BSplineSurface& original, const surface::BSplineSurface& fit,
                        Target target, int n, unsigned seed) {
  std::mt19937 rng(seed);
  const double u0 = original.u.knots[static_cast<std::size_t>(original.u.degree)];
  const double u1 = original.u.knots[static_cast<std::size_t>(original.u.count())];
  const double v0 = original.v.knots[static_cast<std::size_t>(original.v.degree)];
  const double v1 = original.v.knots[static_cast<std::size_t>(original.v.count())];
  std::uniform_real_distribution<double> du(u0, u1), dv(v0, v1);
  double worst = 0;
  for (int k = 0; k < n; ++k) {
    const double u = du(rng), v = dv(rng);
    const Eigen::Vector3d want = target(surface::evaluate(original, u, v));
    worst = std::max(worst, (surface::evaluate(fit, u, v) - want).norm());
  }
  return worst;
}

/// A flat bicubic sheet through the middle of a frame, tilted, local coordinates in [lo, hi].
surface::BSplineSurface sheet_in(const Frame& f, double lo, double hi, double tilt) {
  const surface::BSplineBasis b = surface::clamped_uniform_basis(3, 5);
  surface::Points3 p(25, 3);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      const double s = lo + (hi - lo) * i / 4.0, t = lo + (hi - lo) * j / 4.0;
      p.row(i * 5 + j) = f.point(s, t, 0.5 + tilt * (s - t) + 0.05 * std::sin(3.0 * s)).transpose();
    }
  return surface::make_surface(b, b, p);
}

}  // namespace

TEST_CASE("Refit of a twisted loft meets 1e-4 of its size, verified independently", "[refit]") {
  const surface::BSplineSurface loft = loft_surface();
  Twist twist;
  twist.angle = {0.0, 0.01};  // 1.2 rad over the 120 mm of the loft
  const RefitResult r = refit_deformed(twist, loft);
  const RefitReport& rep = r.report;
  INFO(rep.brief() << " / " << rep.summary.brief());
  REQUIRE(rep.summary.termination == Termination::Converged);
  REQUIRE(rep.certified);
  CHECK(rep.degree_u == 3);
  CHECK(rep.degree_v == 3);
  CHECK(r.surface.u.degree == 3);
  CHECK(rep.sampled_max <= rep.certified_bound_mm);
  CHECK(rep.certified_bound_mm <= rep.tolerance_mm);
  CHECK(rep.crossings.empty());

  // the twist computed here: a rotation by 0.01 z about the z axis
  auto rotate = [](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return Eigen::AngleAxisd(0.01 * x.z(), Eigen::Vector3d::UnitZ()) * x;
  };
  // size: the deformed surface's box from a dense grid, computed here
  const auto us = surface::linspace(0, 1, 60), vs = surface::linspace(0, 1, 60);
  surface::Points3 grid = surface::evaluate_grid(loft, us, vs);
  for (Eigen::Index k = 0; k < grid.rows(); ++k)
    grid.row(k) = rotate(grid.row(k).transpose()).transpose();
  const double size = (grid.colwise().maxCoeff() - grid.colwise().minCoeff()).norm();
  CHECK_THAT(rep.tolerance_mm, WithinRel(1e-4 * size, 0.02));

  const double check = random_deviation(loft, r.surface, rotate, 4000, 11);
  INFO("independent check " << check << " mm, bound " << rep.certified_bound_mm << " mm");
  CHECK(check <= rep.certified_bound_mm);
  CHECK(check <= 1e-4 * size);
  CHECK(rep.certified_bound_mm <= 10 * check);  // the bound is not wildly pessimistic
  CHECK(check <= rep.sampled_max * 1.5);        // the sampled figure is representative
}

TEST_CASE("refit_surface makes a small certified bicubic copy of a dense high-degree surface",
          "[refit]") {
  // What exact composition and style refinement make: the loft (bicubic, C2 joins at 1/3 and 2/3)
  // elevated to degree 6 x 5 and given 24 more knots per direction (C5 and C4 joins there), then
  // moved by a displaced trilinear lattice, exactly. Its editable copy drops the smooth knots.
  std::mt19937 rng(21);
  surface::BSplineSurface dense =
      surface::elevate_degree_v(surface::elevate_degree_u(loft_surface(), 3), 2);
  std::vector<double> extra;
  for (int k = 1; k <= 24; ++k) extra.push_back((k - 0.5) / 24.0 + 0.003);
  dense = surface::refine_knots_v(surface::refine_knots_u(dense, extra), extra);
  Frame f;
  f.origin = {-60, -50, -10};
  f.s = {120, 0, 0};
  f.t = {0, 100, 0};
  f.u = {0, 0, 140};
  const BezierLattice lattice = clay::test::displaced(make_bezier_lattice(f, {1, 1, 1}), rng, 0.1);
  const surface::BSplineSurface exact = compose_exact(lattice, dense).surface;
  INFO("exact: degree " << exact.u.degree << " x " << exact.v.degree << ", " << exact.points.rows()
                        << " control points");
  REQUIRE(exact.u.degree > 3);
  RefitOptions options;  // bicubic, 1e-4 of the size
  options.keep_breakpoints = false;
  const RefitResult editable = refit_surface(exact, options);
  INFO(editable.report.brief());
  REQUIRE(editable.report.summary.converged());
  REQUIRE(editable.report.certified);
  CHECK(editable.surface.u.degree == 3);
  CHECK(editable.surface.v.degree == 3);
  CHECK(editable.report.certified_bound_mm <= editable.report.tolerance_mm);
  // The bound holds against the exact surface at parameters the refit never sampled.
  const double check = random_deviation(
      exact, editable.surface, [](const Eigen::Vector3d& x) { return x; }, 4000, 5);
  INFO("independent check " << check << " mm");
  CHECK(check <= editable.report.certified_bound_mm);
  // A small net: far fewer control points than the exact result, and than a refit that keeps
  // every breakpoint.
  options.keep_breakpoints = true;
  const RefitResult kept = refit_surface(exact, options);
  INFO(kept.report.brief());
  REQUIRE(kept.report.summary.converged());
  CHECK(4 * editable.surface.points.rows() < exact.points.rows());
  CHECK(2 * editable.surface.points.rows() < kept.surface.points.rows());
  // The loft's C2 joins (a cubic cannot follow their third derivatives) are kept.
  CHECK(surface::multiplicity(editable.surface.u, 1.0 / 3) >= 1);
  // A crease (a C0 breakpoint) is kept with multiplicity 3.
  const std::vector<double> crease(static_cast<std::size_t>(exact.u.degree), 0.5);
  options.keep_breakpoints = false;
  const RefitResult copy = refit_surface(surface::refine_knots_u(exact, crease), options);
  REQUIRE(copy.report.summary.converged());
  CHECK(surface::multiplicity(copy.surface.u, 0.5) == 3);
}

TEST_CASE("refit_surface with a fixed net rebuilds on uniform knots, certified", "[refit]") {
  // The loft (bicubic, joins at 1/3 and 2/3) rebuilt as 14 x 11 control points on uniform knots.
  const surface::BSplineSurface parent = loft_surface();
  RefitOptions options;
  options.count_u = 14;
  options.count_v = 11;
  options.relative_tolerance = 1e-3;
  const RefitResult rebuilt = refit_surface(parent, options);
  INFO(rebuilt.report.brief());
  CHECK(rebuilt.surface.u.count() == 14);
  CHECK(rebuilt.surface.v.count() == 11);
  CHECK(rebuilt.surface.u.knots == surface::clamped_uniform_basis(3, 14).knots);
  CHECK(rebuilt.report.knots_added_u == 0);
  REQUIRE(rebuilt.report.certified);
  // The certified bound holds at parameters the fit never sampled.
  const double check = random_deviation(
      parent, rebuilt.surface, [](const Eigen::Vector3d& x) { return x; }, 4000, 6);
  INFO("independent check " << check << " mm");
  CHECK(check <= rebuilt.report.certified_bound_mm);
  CHECK(rebuilt.report.summary.converged() ==
        (rebuilt.report.certified_bound_mm <= rebuilt.report.tolerance_mm));
  // Too few control points for a tight tolerance: not converged, and the message says what to
  // raise; no knot is added to a fixed net.
  options.count_u = options.count_v = 4;
  options.relative_tolerance = 1e-7;
  const RefitResult coarse = refit_surface(parent, options);
  CHECK(!coarse.report.summary.converged());
  CHECK(coarse.surface.points.rows() == 16);
  CHECK_THAT(coarse.report.summary.message, Contains("count_u, count_v"));
  // Bad counts are named.
  RefitOptions bad;
  bad.count_u = 10;
  CHECK_THAT(bad.problems().front(), Contains("give both"));
  bad.count_v = 2;
  CHECK_THAT(bad.problems().front(), Contains("[4, 1000]"));
}

TEST_CASE("Bezier lattice refit bound is a true bound within a sensible factor", "[refit]") {
  std::mt19937 rng(5);
  const Frame f = clay::test::random_frame(rng);
  const BezierLattice lattice = clay::test::displaced(make_bezier_lattice(f, {2, 2, 2}), rng, 0.12);
  const surface::BSplineSurface sheet = sheet_in(f, 0.1, 0.9, 0.2);
  RefitOptions options;
  options.relative_tolerance = 1e-5;
  const RefitResult r = refit_deformed(lattice, sheet, options);
  INFO(r.report.brief());
  REQUIRE(r.report.summary.converged());
  REQUIRE(r.report.certified);
  CHECK(r.report.crossings.empty());  // inside the lattice
  const double check = random_deviation(
      sheet, r.surface, [&](const Eigen::Vector3d& x) { return deform_point(lattice, x); }, 4000,
      3);
  INFO("independent check " << check);
  CHECK(check <= r.report.certified_bound_mm);
  CHECK(r.report.certified_bound_mm <= 10 * check);
  CHECK(r.report.certified_bound_mm <= r.report.tolerance_mm);
}

TEST_CASE("B-spline lattice knot planes crossed by the surface are detected and reported",
          "[refit]") {
  std::mt19937 rng(8);
  const Frame f = clay::test::random_frame(rng);
  const BSplineLattice lattice =
      clay::test::displaced(make_bspline_lattice(f, {2, 2, 2}, {3, 3, 3}), rng, 0.05);
  const surface::BSplineSurface sheet = sheet_in(f, 0.05, 0.95, 0.25);
  RefitOptions options;
  options.relative_tolerance = 1e-4;
  const RefitResult r = refit_deformed(lattice, sheet, options);
  INFO(r.report.brief() << " / " << r.report.summary.message);
  REQUIRE(r.report.certified);
  REQUIRE(r.report.summary.converged());
  REQUIRE_FALSE(r.report.crossings.empty());
  CHECK_THAT(r.report.summary.message, Contains("crossings"));

  // every interior knot plane the surface crosses (found by sampling its local coordinates) is
  // among the reported crossings
  std::set<std::pair<int, double>> reported;
  for (const KnotPlaneCrossing& c : r.report.crossings) {
    reported.insert({c.axis, c.plane});
    CHECK(c.sampled_max <= c.bound);
    CHECK(c.bound <= r.report.tolerance_mm);
    CHECK(c.step == 0);
  }
  const auto us = surface::linspace(0, 1, 80);
  const surface::Points3 grid = surface::evaluate_grid(sheet, us, us);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (Eigen::Index k = 0; k < grid.rows(); ++k) {
    const Eigen::Vector3d l = local_coordinates(f, grid.row(k).transpose());
    lo = lo.cwiseMin(l), hi = hi.cwiseMax(l);
  }
  int crossed = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (double plane : {1.0 / 3, 2.0 / 3}) {
      if (!(lo[axis] < plane && hi[axis] > plane)) continue;
      ++crossed;
      bool found = false;
      for (const auto& [a, value] : reported) found |= a == axis && std::abs(value - plane) < 1e-12;
      CHECK(found);
    }
  CHECK(crossed >= 4);  // s and t planes at least

  const double check = random_deviation(
      sheet, r.surface, [&](const Eigen::Vector3d& x) { return deform_point(lattice, x); }, 3000,
      4);
  INFO("independent check " << check);
  CHECK(check <= r.report.certified_bound_mm);
}

TEST_CASE("Refit keeps the original's C0 seams and breakpoints", "[refit]") {
  // a bicubic surface with a C0 knot (multiplicity 3) at u = 0.5
  surface::BSplineBasis bu;
  bu.degree = 3;
  bu.knots = {0, 0, 0, 0, 0.5, 0.5, 0.5, 1, 1, 1, 1};
  const surface::BSplineBasis bv = surface::clamped_uniform_basis(3, 4);
  surface::Points3 p(7 * 4, 3);
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 4; ++j) p.row(i * 4 + j) << 10.0 * i, 10.0 * j, (i == 3 ? 8.0 : 0.0) + j;
  const surface::BSplineSurface s = surface::make_surface(bu, bv, p);
  Taper taper;
  taper.profile = {1.0, 0.004};
  const RefitResult r = refit_deformed(taper, s);
  REQUIRE(r.report.summary.converged());
  REQUIRE(r.report.certified);
  CHECK(surface::multiplicity(r.surface.u, 0.5) == 3);
  // the taper computed here: (x, y) scaled by 1 + 0.004 z
  const double check = random_deviation(
      s, r.surface,
      [](const Eigen::Vector3d& x) {
        const double k = 1 + 0.004 * x.z();
        return Eigen::Vector3d(k * x.x(), k * x.y(), x.z());
      },
      2000, 9);
  CHECK(check <= r.report.certified_bound_mm);
  CHECK(r.report.certified_bound_mm <= r.report.tolerance_mm);
}

TEST_CASE("Refit of a rational surface under a stack is certified", "[refit]") {
  std::mt19937 rng(21);
  surface::BSplineSurface s;
  s.u = surface::clamped_uniform_basis(2, 4);
  s.v = surface::clamped_uniform_basis(2, 4);
  s.points.resize(16, 3);
  s.weights.resize(16);
  std::uniform_real_distribution<double> c(-1, 1), w(0.5, 2);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      s.points.row(i * 4 + j) << 20.0 * i + 3 * c(rng), 20.0 * j + 3 * c(rng), 10 * c(rng);
      s.weights(i * 4 + j) = w(rng);
    }
  surface::validate(s);
  DeformationStack stack;
  Taper taper;
  taper.profile = {1.0, 0.01};
  Twist twist;
  twist.frame.origin = Eigen::Vector3d(30, 30, 0);
  twist.angle = {0.0, 0.02};
  stack.steps = {{taper, "taper", true}, {twist, "twist", true}};
  RefitOptions options;
  options.relative_tolerance = 0;
  options.tolerance_mm = 1e-3;
  const RefitResult r = refit_deformed(stack, s, options);
  INFO(r.report.brief());
  REQUIRE(r.report.certified);
  REQUIRE(r.report.summary.converged());
  CHECK_THAT(r.report.tolerance_mm, WithinRel(1e-3, 1e-15));
  const double check = random_deviation(
      s, r.surface, [&](const Eigen::Vector3d& x) { return deform_point(stack, x); }, 3000, 2);
  CHECK(check <= r.report.certified_bound_mm);
  CHECK(r.report.certified_bound_mm <= 1e-3);
}

TEST_CASE("A bend region end crossing the surface gets a first-derivative bound", "[refit]") {
  const surface::BSplineSurface sheet = surface::make_surface(
      surface::clamped_uniform_basis(3, 4), surface::clamped_uniform_basis(3, 4), [] {
        surface::Points3 p(16, 3);
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) p.row(i * 4 + j) << 10.0 * i, 20.0 * j - 30, 2.0 * i;
        return p;
      }());
  Bend bend;
  bend.y_min = -5;
  bend.y_max = 5;
  bend.rate = 0.05;
  RefitOptions options;
  options.relative_tolerance = 1e-3;
  options.max_iterations = 3;
  const RefitResult r = refit_deformed(bend, sheet, options);
  INFO(r.report.brief() << " / " << r.report.summary.message);
  REQUIRE(r.report.certified);
  CHECK(r.report.lipschitz_cells > 0);
  CHECK_THAT(r.report.summary.message, Contains("only C0"));
  const double check = random_deviation(
      sheet, r.surface, [&](const Eigen::Vector3d& x) { return deform_point(bend, x); }, 3000, 6);
  CHECK(check <= r.report.certified_bound_mm);
  CHECK(r.report.sampled_max <= r.report.certified_bound_mm);
}

TEST_CASE("Point maps and extended lattices are fitted but not certified", "[refit]") {
  const surface::BSplineSurface loft = loft_surface();
  const PointMap wave = [](const Eigen::Vector3d& x) {
    return Eigen::Vector3d(x.x() + 2 * std::sin(x.z() / 30), x.y(), x.z());
  };
  const RefitResult r = refit_deformed(wave, loft);
  CHECK_FALSE(r.report.certified);
  CHECK(std::isinf(r.report.certified_bound_mm));
  CHECK(r.report.summary.converged());
  CHECK(r.report.sampled_max <= r.report.tolerance_mm);
  CHECK_THAT(r.report.summary.message, Contains("not certified"));
  CHECK_THAT(r.report.summary.message, Contains("point map"));
  CHECK_THAT(r.report.brief(), Contains("not certified"));
  // a sanity check, not a certificate: the 4x-denser sample is representative here
  CHECK(random_deviation(loft, r.surface, wave, 2000, 5) <= 2 * r.report.tolerance_mm);

  std::mt19937 rng(3);
  const Frame f = clay::test::random_frame(rng);
  const BezierLattice b = make_bezier_lattice(f, {3, 3, 3});
  ExtendedLattice e;
  e.rest = b.points;
  e.points = clay::test::displaced(b, rng, 0.05).points;
  Chunk chunk;
  for (int k = 0; k < chunk_control_points; ++k) chunk[static_cast<std::size_t>(k)] = k;
  e.chunks = {chunk};
  RefitOptions options;
  options.relative_tolerance = 1e-4;
  options.max_iterations = 2;
  const RefitResult x = refit_deformed(e, sheet_in(f, 0.2, 0.8, 0.1), options);
  CHECK_FALSE(x.report.certified);
  CHECK_THAT(x.report.summary.message, Contains("Newton-frozen"));
}

TEST_CASE("Refit limits end in a not-converged report", "[refit]") {
  const surface::BSplineSurface loft = loft_surface();
  Twist twist;
  twist.angle = {0.0, 0.02};
  RefitOptions options;
  options.relative_tolerance = 1e-7;
  options.max_iterations = 1;
  const RefitResult r = refit_deformed(twist, loft, options);
  CHECK(r.report.summary.termination == Termination::NotConverged);
  CHECK(r.report.summary.iterations == 1);
  CHECK_THAT(r.report.summary.message, Contains("iteration limit 1"));
  CHECK(r.report.certified_bound_mm > r.report.tolerance_mm);

  options.max_iterations = 10;
  options.max_control_points = 100;
  const RefitResult c = refit_deformed(twist, loft, options);
  CHECK(c.report.summary.termination == Termination::NotConverged);
  CHECK_THAT(c.report.summary.message, Contains("control point limit 100"));
  CHECK(c.surface.count_u() * c.surface.count_v() <= 100);

  // The per-direction cap bounds the dense least squares' memory (issue #18): it stops the
  // refinement before either direction passes it, and the message names it.
  options.max_control_points = 40000;
  options.max_count_per_direction = 12;
  const RefitResult d = refit_deformed(twist, loft, options);
  CHECK(d.report.summary.termination == Termination::NotConverged);
  CHECK_THAT(d.report.summary.message, Contains("control point limit per direction 12"));
  CHECK(d.surface.count_u() <= 12);
  CHECK(d.surface.count_v() <= 12);
}

TEST_CASE("Refit from a uniform start under a cap puts its knots where the error is", "[refit]") {
  // A 100 x 100 mm bicubic sheet with a narrow bump near (20, 20): the error of a quintic fit
  // lives there.
  const auto b = surface::clamped_uniform_basis(3, 40);
  const auto x = surface::greville_abscissae(b);
  surface::Points3 p(1600, 3);
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const double u = 100 * x[static_cast<size_t>(i)], v = 100 * x[static_cast<size_t>(j)];
      p.row(i * 40 + j) << u, v,
          6 * std::exp(-((u - 20) * (u - 20) + (v - 20) * (v - 20)) / 40) + 0.05 * u;
    }
  const surface::BSplineSurface sheet = surface::make_surface(b, b, p);
  RefitOptions o;
  o.degree = 5;
  o.relative_tolerance = 0;
  o.tolerance_mm = 0.035;
  o.keep_breakpoints = false;
  o.initial_count = 8;
  o.max_count_per_direction = 20;
  const RefitResult adaptive = refit_surface(sheet, o);
  INFO(adaptive.report.summary.message);
  REQUIRE(adaptive.report.summary.converged());
  REQUIRE(adaptive.report.certified);
  CHECK(adaptive.surface.u.degree == 5);
  CHECK(adaptive.surface.count_u() <= 20);
  CHECK(adaptive.surface.count_v() <= 20);
  // The knots crowd round the bump: more interior knots below 0.4 than above 0.6.
  auto knots_in = [](const std::vector<double>& k, double a, double c) {
    return std::count_if(k.begin(), k.end(), [&](double t) { return t > a && t < c; });
  };
  CHECK(knots_in(adaptive.surface.u.knots, 0, 0.4) > knots_in(adaptive.surface.u.knots, 0.6, 1));
  // The certified bound holds at 201 x 201 points of the sheet.
  double worst = 0;
  for (int i = 0; i <= 200; ++i)
    for (int j = 0; j <= 200; ++j)
      worst = std::max(worst, (surface::evaluate(adaptive.surface, i / 200.0, j / 200.0) -
                               surface::evaluate(sheet, i / 200.0, j / 200.0))
                                  .norm());
  CHECK(worst <= adaptive.report.certified_bound_mm);
  // The uniform net of the cap's size misses where the adaptive one meets.
  RefitOptions uniform = o;
  uniform.initial_count = 0;
  uniform.count_u = uniform.count_v = 20;
  const RefitResult fixed = refit_surface(sheet, uniform);
  INFO(fixed.report.summary.message);
  CHECK_FALSE(fixed.report.summary.converged());
  CHECK(fixed.report.certified_bound_mm > o.tolerance_mm);  // 0.047 mm against 0.029 mm
  // At a cap of 16 the splits alone reach 16 x 16 and miss; the knots are then moved until each
  // span carries an equal share of the error (de Boor's equidistribution): 0.020 mm, where the
  // uniform 16 x 16 net is 0.398 mm off.
  RefitOptions tight = o;
  tight.max_count_per_direction = 16;
  const RefitResult moved = refit_surface(sheet, tight);
  INFO(moved.report.summary.message);
  REQUIRE(moved.report.summary.converged());
  CHECK(moved.surface.count_u() == 16);
  CHECK(moved.surface.count_v() == 16);
  double moved_worst = 0;
  for (int i = 0; i <= 200; ++i)
    for (int j = 0; j <= 200; ++j)
      moved_worst = std::max(moved_worst, (surface::evaluate(moved.surface, i / 200.0, j / 200.0) -
                                           surface::evaluate(sheet, i / 200.0, j / 200.0))
                                              .norm());
  CHECK(moved_worst <= moved.report.certified_bound_mm);
  CHECK(moved.report.certified_bound_mm <= o.tolerance_mm);
  RefitOptions uniform16 = uniform;
  uniform16.count_u = uniform16.count_v = 16;
  CHECK(refit_surface(sheet, uniform16).report.certified_bound_mm > 10 * o.tolerance_mm);
  // Under a cap too small for the tolerance: the message names the cap and the net it reached.
  o.max_count_per_direction = 10;
  const RefitResult capped = refit_surface(sheet, o);
  CHECK_FALSE(capped.report.summary.converged());
  CHECK_THAT(capped.report.summary.message,
             Contains("control point limit per direction 10 reached (net 10 x 10)"));
}

TEST_CASE("Refit with matched curves follows the map's position and normal along them", "[refit]") {
  // A vertical wall S(u, v) = (100 u - 50, 20, 60 v) twisted about z at 0.01 rad/mm (0.6 rad at
  // the top): a fit to 0.5 mm alone lets its boundary and a diagonal wander; matched, both follow
  // the twist within 0.0005 mm and 0.008 deg (alone: 0.0026 mm, 0.031 deg), checked against the
  // closed form at points the refit never sampled.
  surface::Points3 corners(4, 3);
  corners << -50, 20, 0, -50, 20, 60, 50, 20, 0, 50, 20, 60;
  const surface::BSplineBasis linear = surface::clamped_uniform_basis(1, 2);
  const surface::BSplineSurface wall = surface::make_surface(linear, linear, corners);
  Twist twist;
  twist.angle = {0.0, 0.01};
  const double k = 0.01;
  // The twisted wall's point and partial derivatives in closed form: R(k z) S, z = 60 v.
  auto exact = [&](double u, double v) {
    const double x = 100 * u - 50, z = 60 * v, c = std::cos(k * z), s = std::sin(k * z);
    struct {
      Eigen::Vector3d point, du, dv;
    } e;
    e.point = {c * x - s * 20, s * x + c * 20, z};
    e.du = {100 * c, 100 * s, 0};
    e.dv = {60 * k * (-s * x - c * 20), 60 * k * (c * x - s * 20), 60};
    return e;
  };
  // A diagonal and the border u = 0, as pcurves (u, v, 0) of t in [0, 1].
  surface::Points3 diagonal(2, 3), border(2, 3);
  diagonal << 0, 0, 0, 1, 1, 0;
  border << 0, 0, 0, 0, 1, 0;
  const std::vector<MatchedCurve> curves = {{surface::make_curve(1, {0, 0, 1, 1}, diagonal), 0, 1},
                                            {surface::make_curve(1, {0, 0, 1, 1}, border), 0, 1}};
  RefitOptions alone;
  alone.tolerance_mm = 0.5;
  alone.relative_tolerance = 0;
  RefitOptions matched = alone;
  matched.matched_curves = curves;
  matched.matched_gap_mm = 0.0005;
  matched.matched_angle_deg = 0.008;
  const RefitResult a = refit_deformed(twist, wall, alone);
  const RefitResult m = refit_deformed(twist, wall, matched);
  INFO(a.report.summary.message << "\n" << m.report.summary.message);
  REQUIRE(a.report.summary.converged());
  REQUIRE(m.report.summary.converged());
  REQUIRE(m.report.certified);
  CHECK(m.report.certified_bound_mm <= 0.5);  // the whole surface keeps its certificate
  CHECK(m.report.matched_gap_mm <= 0.0005);
  CHECK(m.report.matched_angle_deg <= 0.008);
  CHECK(m.report.matched_samples > 100);
  // Independent check between the refit's samples (t at odd multiples of 1/2001).
  auto worst = [&](const surface::BSplineSurface& fit) {
    std::pair<double, double> w{0, 0};
    for (const MatchedCurve& c : curves)
      for (int j = 0; j < 1000; ++j) {
        const Eigen::Vector3d uv = surface::evaluate(c.pcurve, (2 * j + 1) / 2001.0);
        const auto e = exact(uv.x(), uv.y());
        const auto d = surface::derivatives(fit, uv.x(), uv.y(), 1);
        const Eigen::Vector3d n = d.du.cross(d.dv), want = e.du.cross(e.dv);
        w.first = std::max(w.first, (d.point - e.point).norm());
        w.second = std::max(w.second,
                            std::atan2(n.cross(want).norm(), n.dot(want)) * 180 / std::numbers::pi);
      }
    return w;
  };
  const auto [gap_alone, angle_alone] = worst(a.surface);
  const auto [gap, angle] = worst(m.surface);
  INFO("alone: " << gap_alone << " mm, " << angle_alone << " deg; matched: " << gap << " mm, "
                 << angle << " deg");
  CHECK(gap <= 0.0005 * 1.5);
  CHECK(angle <= 0.008 * 1.5);
  // the fit alone wanders from both figures: matching is what keeps them
  CHECK(angle_alone > 0.008);
  CHECK(gap_alone > 0.0005);
}

TEST_CASE("Refit errors name the field, the value and the fix", "[refit][errors]") {
  const surface::BSplineSurface loft = loft_surface();
  Twist twist;
  auto options_error = [&](RefitOptions o, const char* field) {
    const auto [category, what] = error_of([&] { refit_deformed(twist, loft, o); });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Contains(field));
  };
  RefitOptions o;
  o.degree = 0;
  options_error(o, "degree = 0");
  o = {};
  o.degree = 26;
  options_error(o, "degree = 26");
  o = {};
  // One tolerance, its unit chosen: neither, both, a negative or a NaN one is refused.
  o.relative_tolerance = 0;
  options_error(o, "relative_tolerance = 0 and tolerance_mm = 0: exactly one must be > 0");
  o = {};
  o.tolerance_mm = 0.01;
  options_error(o, "relative_tolerance = 1e-04 and tolerance_mm = 0.01: exactly one");
  o = {};
  o.relative_tolerance = -1e-4;
  options_error(o, "relative_tolerance = -1e-04: must be finite and >= 0");
  o = {};
  o.relative_tolerance = std::numeric_limits<double>::quiet_NaN();
  options_error(o, "relative_tolerance = nan");
  o = {};
  o.relative_tolerance = 0;
  o.tolerance_mm = 0.01;
  CHECK(o.problems().empty());
  o = {};
  o.max_iterations = 0;
  options_error(o, "max_iterations = 0");
  o = {};
  o.max_control_points = 15;
  options_error(o, "max_control_points = 15");
  o = {};
  o.max_count_per_direction = 3;
  options_error(o, "max_count_per_direction = 3");
  o = {};
  o.certificate_share = 1;
  options_error(o, "certificate_share = 1");
  o = {};
  o.initial_count = 3;  // below degree + 1
  options_error(o, "initial_count = 3");

  surface::BSplineSurface bad = loft;
  bad.points(0, 0) = std::numeric_limits<double>::quiet_NaN();
  auto [c1, w1] = error_of([&] { refit_deformed(twist, bad); });
  CHECK(c1 == ErrorCategory::InvalidGeometry);
  CHECK_THAT(w1, Contains("refit_deformed surface"));

  Twist bad_twist;
  bad_twist.angle = {};
  auto [c2, w2] = error_of([&] { refit_deformed(bad_twist, loft); });
  CHECK(c2 == ErrorCategory::InvalidGeometry);

  auto [c3, w3] = error_of([&] { refit_deformed(PointMap{}, loft); });
  CHECK(c3 == ErrorCategory::InvalidArgument);
  CHECK_THAT(w3, Contains("empty"));

  const PointMap broken = [](const Eigen::Vector3d& x) {
    return x.z() > 60 ? Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()) : x;
  };
  auto [c4, w4] = error_of([&] { refit_deformed(broken, loft); });
  CHECK(c4 == ErrorCategory::InvalidArgument);
  CHECK_THAT(w4, Contains("non-finite"));

  const PointMap collapse = [](const Eigen::Vector3d&) { return Eigen::Vector3d(1, 2, 3); };
  auto [c5, w5] = error_of([&] { refit_deformed(collapse, loft); });
  CHECK(c5 == ErrorCategory::InvalidGeometry);
  CHECK_THAT(w5, Contains("zero size") &&
                     Contains("give the tolerance in mm (RefitOptions::tolerance_mm"));
}

TEST_CASE("Refit's matched curves need their figures and a valid range", "[refit][errors]") {
  const surface::BSplineSurface s = loft_surface();
  surface::Points3 line(2, 3);
  line << 0, 0, 0, 1, 1, 0;
  RefitOptions o;
  o.matched_curves = {{surface::make_curve(1, {0, 0, 1, 1}, line), 0, 1}};
  const auto [category, missing] = error_of([&] { refit_deformed(Twist{}, s, o); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(missing, Contains("matched_gap_mm = 0") && Contains("matched_angle_deg") &&
                          Contains("both must be given"));
  o.matched_gap_mm = 0.001;
  o.matched_angle_deg = 0.01;
  o.matched_curves[0].t1 = 2;
  const auto range = error_of([&] { refit_deformed(Twist{}, s, o); }).second;
  CHECK_THAT(range, Contains("matched_curves[0]: t0 = 0, t1 = 2") &&
                        Contains("within the pcurve's domain [0, 1]"));
  o.matched_curves[0].t1 = 1;
  o.matched_curvature = -0.1;
  const auto curvature = error_of([&] { refit_deformed(Twist{}, s, o); });
  CHECK(curvature.first == ErrorCategory::InvalidArgument);
  CHECK_THAT(curvature.second, Contains("matched_curvature = -0.1") && Contains("[0, 1)"));
}

TEST_CASE("Refit's matched curves are sampled to their ends, never past them", "[refit]") {
  // t0 + (t1 - t0) k / (n - 1) rounds past t1 at k = n - 1 for some (t0, t1, n): a cylinder
  // face's [pi/2, pi] with 12 samples gave pi + 4.4e-16, outside the pcurve's domain (class A,
  // g2_block.step). Domains of 40 random ends, each face twisted and fitted with its 4 sides:
  // every fit samples its sides and ends within the figures.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> start(-4, 4), width(0.1, 7);
  for (int n = 0; n < 40; ++n) {
    const double a = start(rng), b = a + width(rng);
    surface::Points3 corners(4, 3);
    corners << 0, 0, 0, 0, 30, 0, 40, 0, 2, 40, 30, 0;
    const auto face = surface::make_surface({1, {a, a, b, b}}, {1, {0, 0, 1, 1}}, corners);
    RefitOptions o;
    o.relative_tolerance = 0;
    o.tolerance_mm = 0.01;
    o.matched_gap_mm = 0.001;
    o.matched_angle_deg = 0.01;
    auto side = [&](double u0, double v0, double u1, double v1, double t0, double t1) {
      surface::Points3 ends(2, 3);
      ends << u0, v0, 0, u1, v1, 0;
      return MatchedCurve{surface::make_curve(1, {t0, t0, t1, t1}, ends), t0, t1};
    };
    o.matched_curves = {side(a, 0, b, 0, a, b), side(a, 1, b, 1, a, b), side(a, 0, a, 1, 0, 1),
                        side(b, 0, b, 1, 0, 1)};
    Twist twist;
    twist.frame.origin = {20, 15, 0};
    twist.angle = {0, 0.01};
    const RefitResult r = refit_deformed(twist, face, o);
    INFO("domain [" << a << ", " << b << "]: " << r.report.brief());
    CHECK(r.report.summary.converged());
    CHECK(r.report.matched_samples > 0);
    CHECK(r.report.matched_gap_mm <= o.matched_gap_mm);
  }
}

TEST_CASE("Refit keeps a closed side closed and a pole a point, bit for bit", "[refit]") {
  // A full revolution of a half circle: closed in u (first row == last row), both ends of the
  // profile on the axis (the columns j = 0 and j = last collapse to the poles).
  surface::Points3 p(5, 3);
  p << 0, 0, -30, 30, 0, -30, 30, 0, 0, 30, 0, 30, 0, 0, 30;  // ends exactly on the axis
  Eigen::VectorXd w(5);
  w << 1, std::sqrt(0.5), 1, std::sqrt(0.5), 1;
  const auto profile = surface::make_curve(2, {0, 0, 0, 0.5, 0.5, 1, 1, 1}, p, w);
  const auto sphere = surface::revolve(profile, {{0, 0, 0}, {0, 0, 1}}, 360).surface;
  Twist twist;
  twist.frame.origin = {5, -3, 0};
  twist.frame.axis = {0.1, 0.2, 1};
  twist.angle = {0.1, 0.02};
  RefitOptions options;
  options.relative_tolerance = 1e-3;
  const auto fit = refit_deformed(twist, sphere, options);
  const auto& s = fit.surface;
  const int mu = s.count_u(), mv = s.count_v();
  for (int j = 0; j < mv; ++j)
    CHECK(s.points.row(s.index(0, j)) == s.points.row(s.index(mu - 1, j)));
  const Eigen::RowVector3d south = deform_point(twist, Eigen::Vector3d(0, 0, -30)).transpose();
  const Eigen::RowVector3d north = deform_point(twist, Eigen::Vector3d(0, 0, 30)).transpose();
  for (int i = 0; i < mu; ++i) {
    CHECK(s.points.row(s.index(i, 0)) == south);
    CHECK(s.points.row(s.index(i, mv - 1)) == north);
  }
  CHECK(fit.report.certified);
  CHECK(fit.report.certified_bound_mm <= fit.report.tolerance_mm);
}

namespace {

/// Normal curvature of `s` along u at (u, v): (S_uu . n) / |S_u|^2.
double curvature_along_u(const surface::BSplineSurface& s, double u, double v) {
  const auto d = surface::derivatives(s, u, v, 2);
  return d.duu.dot(d.du.cross(d.dv).normalized()) / d.du.squaredNorm();
}

}  // namespace

TEST_CASE("Refit with matched curves keeps a seam's continuity whatever the fit's error",
          "[refit]") {
  // A cylinder r 10, h 40 (a rational circle revolved: C1 but not C2 across its seam, a speed
  // that grows at one end and shrinks at the other), twisted about a tilted, offset axis, fitted
  // at degree 5 with at most 40 control points per direction (class A's 32 leave the circles
  // 1.3 times their 0.0005 mm) with its two circles and its seam matched. Across the seam the fit
  // must meet itself G1 and G2 to rounding (tied), not to the fit's error; checked on the fit
  // between the samples.
  surface::Points3 line(2, 3);
  line << 10, 0, 0, 10, 0, 40;
  const auto cylinder =
      surface::revolve(surface::make_curve(1, {0, 0, 1, 1}, line), {{0, 0, 0}, {0, 0, 1}}, 360)
          .surface;
  Twist twist;
  twist.frame.origin = {3, -2, 0};
  twist.frame.axis = {0.1, 0.05, 1};
  twist.angle = {0, 0.01};
  const auto [u0, u1] = cylinder.u.domain();
  const auto [v0, v1] = cylinder.v.domain();
  auto iso = [&](double a0, double b0, double a1, double b1, int order) {
    surface::Points3 ends(2, 3);
    ends << a0, b0, 0, a1, b1, 0;
    return MatchedCurve{surface::make_curve(1, {0, 0, 1, 1}, ends), 0, 1, order};
  };
  RefitOptions o;
  o.degree = 5;
  o.relative_tolerance = 0;
  o.tolerance_mm = 0.01;
  o.initial_count = 8;
  o.max_count_per_direction = 40;
  o.keep_breakpoints = false;
  o.matched_gap_mm = 0.0005;
  o.matched_angle_deg = 0.008;
  // the circles (sharp edges to the caps: position only) and the seam's two sides (G2)
  o.matched_curves = {iso(u0, v0, u1, v0, 0), iso(u0, v1, u1, v1, 0), iso(u0, v0, u0, v1, 2),
                      iso(u1, v0, u1, v1, 2)};
  const RefitResult r = refit_deformed(twist, cylinder, o);
  INFO(r.report.summary.message);
  REQUIRE(r.report.summary.converged());
  REQUIRE(r.report.certified);
  const auto& s = r.surface;
  double angle = 0, jump = 0;
  for (int k = 0; k <= 100; ++k) {
    const double v = v0 + (v1 - v0) * (k + 0.37) / 101.3;  // between the refit's samples
    const auto a = surface::derivatives(s, u0, v, 1), b = surface::derivatives(s, u1, v, 1);
    const Eigen::Vector3d na = a.du.cross(a.dv), nb = b.du.cross(b.dv);
    angle = std::max(angle, std::atan2(na.cross(nb).norm(), na.dot(nb)) * 180 / std::numbers::pi);
    const double ka = curvature_along_u(s, u0, v), kb = curvature_along_u(s, u1, v);
    jump = std::max(jump, std::abs(ka - kb) / std::max(std::abs(ka), std::abs(kb)));
    CHECK((a.point - b.point).norm() == 0.0);  // one row: the same point bit for bit
  }
  INFO("seam: " << angle << " deg, relative curvature jump " << jump);
  CHECK(angle < 1e-8);
  CHECK(jump < 1e-8);
  // the fit itself is 0.01 mm from the twisted cylinder at most, far from these figures
  CHECK(r.report.certified_bound_mm <= 0.01);
  CHECK(r.report.certified_bound_mm > 1e-7);
}

TEST_CASE("Refit with matched curves keeps only the position along a sharp edge", "[refit]") {
  // The twisted wall of the test above with an unreachable angle (1e-7 deg): along an edge of
  // order 0 (sharp: its faces' angle is not continuity) the fit converges, its gap within the
  // figure; the same edge as a tangent one (order 1) cannot.
  surface::Points3 corners(4, 3);
  corners << -50, 20, 0, -50, 20, 60, 50, 20, 0, 50, 20, 60;
  const surface::BSplineBasis linear = surface::clamped_uniform_basis(1, 2);
  const surface::BSplineSurface wall = surface::make_surface(linear, linear, corners);
  Twist twist;
  twist.angle = {0.0, 0.01};
  surface::Points3 border(2, 3);
  border << 0, 0, 0, 0, 1, 0;
  RefitOptions o;
  o.relative_tolerance = 0;
  o.tolerance_mm = 0.5;
  o.max_iterations = 6;
  o.matched_gap_mm = 0.0005;
  o.matched_angle_deg = 1e-7;
  o.matched_curves = {{surface::make_curve(1, {0, 0, 1, 1}, border), 0, 1, 0}};
  const RefitResult sharp = refit_deformed(twist, wall, o);
  INFO(sharp.report.summary.message);
  CHECK(sharp.report.summary.converged());
  CHECK(sharp.report.matched_gap_mm <= 0.0005);
  CHECK(sharp.report.matched_angle_deg == 0);  // not measured along a sharp edge
  // independently: the fit's border against the closed form, between the samples
  double gap = 0;
  for (int j = 0; j < 500; ++j) {
    const double v = (2 * j + 1) / 1001.0, z = 60 * v, c = std::cos(0.01 * z),
                 s = std::sin(0.01 * z);
    gap = std::max(gap, (surface::evaluate(sharp.surface, 0, v) -
                         Eigen::Vector3d(c * -50 - s * 20, s * -50 + c * 20, z))
                            .norm());
  }
  CHECK(gap <= 0.0005 * 1.5);
  o.matched_curves[0].order = 1;
  const RefitResult tangent = refit_deformed(twist, wall, o);
  CHECK_FALSE(tangent.report.summary.converged());
  CHECK(tangent.report.matched_angle_deg > 1e-7);
}
