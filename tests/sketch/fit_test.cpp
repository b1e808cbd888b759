#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/sketch/oversketch.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <numbers>

#include "sketch/sketch_geometry.hpp"

using namespace clay::sketch;
using Catch::Matchers::WithinAbs;
using clay::surface::BSplineCurve;
using clay::surface::Points3;

namespace {

/// A fair nonplanar clamped cubic about 125 mm long (the "known smooth curve" of the noisy tests).
BSplineCurve true_curve() {
  Points3 p(6, 3);
  p << 0, 0, 0,     //
      25, 25, 10,   //
      50, 35, -5,   //
      70, 5, 15,    //
      85, -15, 20,  //
      105, 5, 5;
  return clay::surface::make_curve(3, {0, 0, 0, 0, 0.35, 0.65, 1, 1, 1, 1}, p);
}

/// Largest distance from the stroke's points to a dense polyline of the curve (independent of the
/// fitter's own foot points).
double stroke_deviation(const Points3& pts, const BSplineCurve& c) {
  const Points3 poly = clay::test::polyline(clay::test::analytic(c), 4000);
  double worst = 0;
  for (Eigen::Index i = 0; i < pts.rows(); ++i)
    worst = std::max(worst, clay::test::distance_to_polyline(pts.row(i).transpose(), poly));
  return worst;
}

constexpr double noise_sigma = 0.15;  // mm per coordinate

/// 300 points of true_curve() with Gaussian noise, fitted at a tolerance of 3 sigma, and how the
/// fit compares with the truth.
struct NoisyCase {
  Stroke stroke;
  StrokeFit fit;
  double to_truth = 0;      ///< mm, both ways on dense samples
  double energy_ratio = 0;  ///< int kappa^2 ds of the fit / of the truth (Simpson)
};

NoisyCase noisy_case(unsigned seed) {
  const BSplineCurve truth = true_curve();
  const auto exact = clay::test::analytic(truth);
  clay::test::Gaussian g(seed);
  NoisyCase out;
  out.stroke.points = clay::test::noisy_samples(exact, 300, noise_sigma, g);
  FitOptions o;
  o.tolerance_mm = 3 * noise_sigma;
  out.fit = fit_stroke(out.stroke, o);
  REQUIRE(out.fit.curves.size() == 1);
  const auto fitted = clay::test::analytic(out.fit.curves[0].curve);
  out.to_truth = clay::test::curve_distance(fitted, exact);
  out.energy_ratio =
      clay::test::bending_energy(fitted, clay::test::unit_breaks(out.fit.curves[0].curve)) /
      clay::test::bending_energy(exact, clay::test::unit_breaks(truth));
  return out;
}

}  // namespace

// OCCT's default fitter (GeomAPI_PointsToBSpline with its default settings) interpolates the
// noise of this kind of stroke: 302 control points for 300 points. Ours looks through it.
TEST_CASE("noisy 3D stroke: few control points, within 0.2 mm of the true curve, as fair",
          "[fit]") {
  const NoisyCase n = noisy_case(2024);
  CHECK_FALSE(n.fit.closed);
  CHECK(n.fit.corners.empty());
  const FittedCurve& c = n.fit.curves[0];
  INFO(c.summary.brief());
  CHECK(c.summary.converged());
  CHECK(c.control_points <= 20);
  CHECK(c.curve.basis.degree == 3);
  CHECK(clay::surface::is_clamped(c.curve.basis));
  CHECK(n.to_truth <= 0.2);
  CHECK(n.energy_ratio <= 1.5);
  CHECK(n.energy_ratio >= 1 / 1.5);
  // The reported deviation is the stroke's distance to the curve (checked on a dense polyline).
  CHECK_THAT(c.max_deviation_mm, WithinAbs(stroke_deviation(n.stroke.points, c.curve), 1e-4));
  CHECK(c.rms_deviation_mm < c.max_deviation_mm);
  CHECK(c.first_point == 0);
  CHECK(c.last_point == 299);
  // The noise is the only thing left: the rms residual is about sqrt(2) sigma (two normal
  // components), and the noise estimate is near sigma.
  CHECK_THAT(c.rms_deviation_mm, WithinAbs(std::sqrt(2.0) * noise_sigma, 0.03));
  CHECK_THAT(c.noise, WithinAbs(noise_sigma, 0.03));
}

TEST_CASE("noisy 3D strokes, other seeds: the same quality", "[fit]") {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    const NoisyCase n = noisy_case(seed);
    const int control_points = n.fit.curves[0].control_points;
    INFO("seed " << seed << ": " << control_points << " control points, " << n.to_truth
                 << " mm from the truth, energy ratio " << n.energy_ratio);
    CHECK(control_points <= 20);
    CHECK(n.to_truth <= 0.25);  // the stroke's ends carry the most uncertainty
    CHECK(n.energy_ratio <= 1.5);
    CHECK(n.energy_ratio >= 1 / 1.5);
  }
}

TEST_CASE("a clean stroke is fitted within a tight tolerance, ends interpolated", "[fit]") {
  // 60 points of a helix arc, no noise, 1 um tolerance.
  Stroke s;
  s.points.resize(60, 3);
  for (int i = 0; i < 60; ++i) {
    const double a = 3.0 * i / 59;
    s.points.row(i) << 40 * std::cos(a), 40 * std::sin(a), 8 * a;
  }
  FitOptions o;
  o.tolerance_mm = 1e-3;
  const StrokeFit fit = fit_stroke(s, o);
  REQUIRE(fit.curves.size() == 1);
  const FittedCurve& c = fit.curves[0];
  INFO(c.summary.brief());
  CHECK(c.summary.converged());
  CHECK(c.max_deviation_mm <= o.tolerance_mm);
  CHECK(stroke_deviation(s.points, c.curve) <= o.tolerance_mm + 1e-5);
  // Clean: the end estimate stays at the drawn point (within the tolerance it may move).
  CHECK((c.curve.points.row(0) - s.points.row(0)).norm() <= o.tolerance_mm);
  CHECK((c.curve.points.row(c.curve.points.rows() - 1) - s.points.row(59)).norm() <=
        o.tolerance_mm);
}

TEST_CASE("strokes with a corner are split there: two curves sharing the corner", "[fit]") {
  // An L (90 degree turn) and a V (140 degree turn), 3D, noisy.
  const Eigen::Vector3d corner(30, 20, 10);
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> legs = {
      {Eigen::Vector3d(-60, 0, 0), Eigen::Vector3d(0, 50, 20)},
      {Eigen::Vector3d(-50, -40, 10), Eigen::Vector3d(50, -30, 0)}};
  unsigned seed = 7;
  for (const auto& [in, out] : legs) {
    clay::test::Gaussian g(seed++);
    const double sigma = 0.1;
    Stroke s;
    s.points.resize(200, 3);
    for (int i = 0; i < 200; ++i) {
      const double f = i / 199.0;
      const Eigen::Vector3d p = f < 0.5 ? Eigen::Vector3d(corner + in * (1 - 2 * f))
                                        : Eigen::Vector3d(corner + out * (2 * f - 1));
      s.points.row(i) = p.transpose() + g.vector(sigma);
    }
    FitOptions o;
    o.tolerance_mm = 3 * sigma;
    const StrokeFit fit = fit_stroke(s, o);
    INFO(fit.summary.brief());
    REQUIRE(fit.curves.size() == 2);
    REQUIRE(fit.corners.size() == 1);
    CHECK(std::abs(fit.corners[0] - 99) <= 2);
    const auto& a = fit.curves[0].curve;
    const auto& b = fit.curves[1].curve;
    // G0: the joint is one point, bit for bit.
    CHECK(a.points.row(a.points.rows() - 1) == b.points.row(0));
    CHECK(fit.curves[0].last_point + 1 == fit.curves[1].first_point);
    // The joint is at the drawn corner, within the tolerance.
    CHECK((b.points.row(0).transpose() - corner).norm() <= o.tolerance_mm);
    // Each leg is straight to within the noise: its curve stays near the true segment.
    for (const auto* c : {&fit.curves[0], &fit.curves[1]}) {
      CHECK(c->summary.converged());
      CHECK(c->control_points <= 8);
    }
    // brief() tells the same counts, with the control points counted on the curves themselves.
    const auto total = a.points.rows() + b.points.rows();
    CHECK_THAT(fit.brief(),
               Catch::Matchers::StartsWith("2 curves (open), 1 corner, " + std::to_string(total) +
                                           " control points") &&
                   Catch::Matchers::EndsWith("; converged"));
  }
}

TEST_CASE("a closed noisy stroke gives one closed curve, G1 (indeed C2) at the seam", "[fit]") {
  // A tilted ellipse, 40 x 25 mm, drawn once round; the pen stops short of the start.
  clay::test::Gaussian g(11);
  const double sigma = 0.1;
  const Eigen::Matrix3d tilt =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  Stroke s;
  const int n = 250;
  s.points.resize(n, 3);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * std::numbers::pi * i / n;
    s.points.row(i) = (tilt * Eigen::Vector3d(40 * std::cos(a), 25 * std::sin(a), 0)).transpose() +
                      g.vector(sigma);
  }
  FitOptions o;
  o.tolerance_mm = 3 * sigma;
  const StrokeFit fit = fit_stroke(s, o);
  INFO(fit.summary.brief());
  REQUIRE(fit.curves.size() == 1);
  CHECK(fit.closed);
  const FittedCurve& c = fit.curves[0];
  CHECK(c.closed);
  CHECK(c.summary.converged());
  CHECK(c.control_points <= 20);
  CHECK(clay::surface::is_clamped(c.curve.basis));
  // Closes exactly.
  CHECK(c.curve.points.row(0) == c.curve.points.row(c.curve.points.rows() - 1));
  // Seam: tangent direction and curvature vector agree across it.
  const auto [t0, t1] = c.curve.basis.domain();
  const auto d0 = clay::surface::derivatives(c.curve, t0, 2);
  const auto d1 = clay::surface::derivatives(c.curve, t1, 2);
  const double angle = std::atan2(d0.d1.cross(d1.d1).norm(), d0.d1.dot(d1.d1));
  CHECK(angle <= 1e-9);
  CHECK((d0.d1 - d1.d1).norm() <= 1e-9 * d0.d1.norm());  // C1 as parametrized
  CHECK((d0.d2 - d1.d2).norm() <= 1e-7 * d0.d2.norm());  // C2
  // Near the true ellipse: every sample of the fit within 0.15 mm of it.
  const clay::test::Analytic ellipse{
      [&](double t) {
        const double a = 2 * std::numbers::pi * t;
        return Eigen::Vector3d(tilt * Eigen::Vector3d(40 * std::cos(a), 25 * std::sin(a), 0));
      },
      nullptr, nullptr};
  const Points3 dense = clay::test::polyline(ellipse, 4000);
  double worst = 0;
  for (double t : clay::surface::linspace(t0, t1, 400))
    worst = std::max(worst,
                     clay::test::distance_to_polyline(clay::surface::evaluate(c.curve, t), dense));
  CHECK(worst <= 0.15);
}

TEST_CASE("strokes on a sketch plane give curves lying in the plane", "[fit]") {
  const SketchPlane plane =
      make_plane(Eigen::Vector3d(10, -20, 30), Eigen::Vector3d(1, -2, 3), Eigen::Vector3d(1, 0, 0));
  clay::test::Gaussian g(5);
  auto drawn = [&](auto shape, int n) {
    Stroke s;
    s.plane = plane;
    s.points.resize(n, 3);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d xy = shape(double(i) / n);
      // Drawn a little off the plane (a hand in the air): 0.5 mm along the normal, and noise.
      s.points.row(i) =
          (to_world(plane, xy) + 0.5 * std::sin(9.0 * i / n) * plane.normal()).transpose() +
          g.vector(0.05);
    }
    return s;
  };
  const auto wave = [](double f) { return Eigen::Vector2d(100 * f, 15 * std::sin(5 * f)); };
  const auto ell = [](double f) {
    return f < 0.5 ? Eigen::Vector2d(0, 60 * (1 - 2 * f)) : Eigen::Vector2d(60 * (2 * f - 1), 0);
  };
  const auto circle = [](double f) {
    return Eigen::Vector2d(30 * std::cos(2 * std::numbers::pi * f),
                           30 * std::sin(2 * std::numbers::pi * f));
  };
  FitOptions o;
  o.tolerance_mm = 0.15;
  int closed = 0, split = 0;
  for (const Stroke& s : {drawn(wave, 200), drawn(ell, 200), drawn(circle, 200)}) {
    const StrokeFit fit = fit_stroke(s, o);
    INFO(fit.summary.brief());
    CHECK(fit.summary.converged());
    CHECK(fit.plane_offset >= 0.5);
    closed += fit.closed;
    split += fit.curves.size() > 1;
    for (const auto& c : fit.curves) {
      double off = 0;
      for (Eigen::Index i = 0; i < c.curve.points.rows(); ++i)
        off = std::max(off, std::abs(signed_distance(plane, c.curve.points.row(i).transpose())));
      const auto [a, b] = c.curve.basis.domain();
      for (double t : clay::surface::linspace(a, b, 500))
        off = std::max(off, std::abs(signed_distance(plane, clay::surface::evaluate(c.curve, t))));
      CHECK(off <= 1e-12);
    }
  }
  CHECK(closed == 1);  // the circle
  CHECK(split == 1);   // the L
}
TEST_CASE("a closed stroke with corners gives a closed chain of curves", "[fit]") {
  // A noisy triangle drawn once round, starting mid-side.
  const Eigen::Vector3d v[3] = {{0, 0, 0}, {80, 10, 20}, {30, 60, -10}};
  clay::test::Gaussian g(21);
  Stroke s;
  const int per_side = 90;
  s.points.resize(3 * per_side, 3);
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < per_side; ++i) {
      const double f = (i + 0.5 * per_side) / per_side;  // start half way along the first side
      const int a = (k + int(f)) % 3, b = (a + 1) % 3;
      const double u = f - int(f);
      s.points.row(k * per_side + i) = ((1 - u) * v[a] + u * v[b]).transpose() + g.vector(0.08);
    }
  FitOptions o;
  o.tolerance_mm = 0.25;
  const StrokeFit fit = fit_stroke(s, o);
  INFO(fit.summary.brief());
  CHECK(fit.closed);
  REQUIRE(fit.curves.size() == 3);
  REQUIRE(fit.corners.size() == 3);
  for (size_t k = 0; k < 3; ++k) {
    const auto& a = fit.curves[k].curve;
    const auto& b = fit.curves[(k + 1) % 3].curve;
    CHECK(a.points.row(a.points.rows() - 1) == b.points.row(0));  // shared corner, bit for bit
    CHECK_FALSE(fit.curves[k].closed);
    // Each joint is at a vertex of the triangle.
    double nearest = 1e9;
    for (const auto& vertex : v)
      nearest = std::min(nearest, (b.points.row(0).transpose() - vertex).norm());
    CHECK(nearest <= o.tolerance_mm);
  }
}

TEST_CASE("a sparse stroke (points farther apart than 10 x tolerance) keeps its corners", "[fit]") {
  // A 240 x 160 rectangle drawn fast: 6 mm between points, tolerance 0.5 (window 5 mm alone would
  // sit inside the smoothing's rounding of each corner).
  const Eigen::Vector3d c[4] = {{-120, -80, 0}, {120, -80, 0}, {120, 80, 0}, {-120, 80, 0}};
  const Eigen::Vector3d path[6] = {{0, -80, 0}, c[1], c[2], c[3], c[0], {0, -80, 0}};
  std::vector<Eigen::Vector3d> pts;
  for (int leg = 0; leg < 5; ++leg) {
    const int steps = static_cast<int>(std::lround((path[leg + 1] - path[leg]).norm() / 6));
    for (int k = 0; k < steps; ++k)
      pts.push_back(path[leg] + (path[leg + 1] - path[leg]) * (double(k) / steps));
  }
  pts.push_back(path[5]);
  Stroke s;
  s.points.resize(static_cast<Eigen::Index>(pts.size()), 3);
  for (size_t k = 0; k < pts.size(); ++k) s.points.row(static_cast<Eigen::Index>(k)) = pts[k];
  FitOptions o;
  o.tolerance_mm = 0.5;
  const StrokeFit fit = fit_stroke(s, o);
  INFO(fit.summary.brief());
  REQUIRE(fit.curves.size() == 4);
  for (size_t k = 0; k < 4; ++k) {
    const auto& a = fit.curves[k].curve;
    double nearest = 1e9;
    for (const auto& vertex : c)
      nearest = std::min(nearest, (a.points.row(a.points.rows() - 1).transpose() - vertex).norm());
    CHECK(nearest <= 1e-6);  // straight legs: their lines meet at the corner
  }
}

TEST_CASE("FitOptions and OversketchOptions list every bad field", "[fit]") {
  FitOptions f;
  f.tolerance_mm = 0;
  f.degree = 1;
  f.closing_ratio = 0.9;
  CHECK(f.problems().size() == 3);
  OversketchOptions o;
  o.capture_distance = -1;
  o.fit.max_iterations = 0;
  CHECK(o.problems().size() == 2);
  CHECK_THROWS_AS(o.validate(), clay::Error);
}
