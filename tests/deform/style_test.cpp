// Style deformation (Han–De Amicis–Conti 2007): influence factors, key points, the paper's forces,
// locality, λ, the constraint classes, mirror symmetry and the exact target mode. Every figure is
// checked against an independent computation: closed forms on a flat surface, closest-point
// distances, mirrored control vertices, normals of the parent and the result.
#include <catch2/catch.hpp>

#include <clay/deform/style.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <cstring>
#include <limits>

#include "error_of.hpp"

using namespace clay::deform;
using Catch::Matchers::WithinAbs;
using clay::surface::BSplineCurve;
using clay::surface::BSplineSurface;
using clay::surface::Points3;

namespace {

constexpr double pi = 3.14159265358979323846;

// A bicubic surface on [0, 1]^2 (clamped uniform knots) whose control point (i, j) is
// f(xi_i, eta_j) at the Greville abscissae.
template <class F>
BSplineSurface net_surface(int nu, int nv, F f) {
  auto bu = clay::surface::clamped_uniform_basis(3, nu);
  auto bv = clay::surface::clamped_uniform_basis(3, nv);
  const auto xu = clay::surface::greville_abscissae(bu), xv = clay::surface::greville_abscissae(bv);
  Points3 p(nu * nv, 3);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j)
      p.row(i * nv + j) = f(xu[static_cast<size_t>(i)], xv[static_cast<size_t>(j)]).transpose();
  return clay::surface::make_surface(bu, bv, p);
}

// A flat square 100 x 100 mm in z = 0: by linear precision S(u, v) = (100 u, 100 v, 0) exactly.
BSplineSurface flat(int n = 15) {
  return net_surface(n, n, [](double u, double v) { return Eigen::Vector3d(100 * u, 100 * v, 0); });
}

// A car hood 1200 x 800 mm with a crown, mirror-symmetric about y = 0 (v -> 1 - v).
BSplineSurface hood(int nu = 12, int nv = 12) {
  return net_surface(nu, nv, [](double u, double v) {
    const double x = -600 + 1200 * u, y = -400 + 800 * v;
    return Eigen::Vector3d(
        x, y, 80 * (1 - (x / 700) * (x / 700)) * (1 - (y / 500) * (y / 500)) + 0.05 * x);
  });
}

// A sail: luff along u (5 m), chord along v narrowing toward the head, camber in z; uneven knots.
BSplineSurface sail() {
  clay::surface::BSplineBasis bu{3, {0, 0, 0, 0, 0.1, 0.25, 0.45, 0.7, 1, 1, 1, 1}};
  clay::surface::BSplineBasis bv{3, {0, 0, 0, 0, 0.2, 0.35, 0.5, 0.75, 1, 1, 1, 1}};
  const auto xu = clay::surface::greville_abscissae(bu), xv = clay::surface::greville_abscissae(bv);
  const int nu = bu.count(), nv = bv.count();
  Points3 p(nu * nv, 3);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double u = xu[static_cast<size_t>(i)], v = xv[static_cast<size_t>(j)];
      const double chord = 2000 * (1 - 0.7 * u);
      p.row(i * nv + j) << chord * v, 5000 * u, 300 * std::sin(pi * v) * (1 - 0.5 * u);
    }
  return clay::surface::make_surface(bu, bv, p);
}

// An ellipse centred at c in the plane z = c.z with semi-axes a (x) and b (y): the exact rational
// circle scaled (an affine map of the control points keeps a rational curve exact).
BSplineCurve ellipse(const Eigen::Vector3d& c, double a, double b) {
  BSplineCurve e = clay::surface::circular_arc(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(),
                                               Eigen::Vector3d::UnitY(), 1.0, 0.0, 2 * pi);
  for (Eigen::Index r = 0; r < e.points.rows(); ++r) {
    e.points(r, 0) = c.x() + a * e.points(r, 0);
    e.points(r, 1) = c.y() + b * e.points(r, 1);
    e.points(r, 2) = c.z();
  }
  return e;
}

// A cubic Bézier curve through four control points.
BSplineCurve bezier(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                    const Eigen::Vector3d& d) {
  Points3 p(4, 3);
  p << a.transpose(), b.transpose(), c.transpose(), d.transpose();
  return clay::surface::make_curve(3, {0, 0, 0, 0, 1, 1, 1, 1}, p);
}

// The hood's bound (an ellipse 700 x 500 mm around the centre, above the hood) and a target
// running across it in y, 30-60 mm above the hood; both mirror-symmetric about y = 0.
BSplineCurve hood_bound() { return ellipse({0, 0, 150}, 350, 250); }
BSplineCurve hood_target() {
  return bezier({-60, -180, 70}, {-40, -60, 150}, {-40, 60, 150}, {-60, 180, 70});
}

bool rows_identical(const Points3& a, const Points3& b, Eigen::Index r) {
  return std::memcmp(a.row(r).data(), b.row(r).data(), 3 * sizeof(double)) == 0;
}

double size_of(const BSplineSurface& s) {
  return (s.points.colwise().maxCoeff() - s.points.colwise().minCoeff()).norm();
}

// Largest angle (degrees) between the normals of a and b at the bound curve's closest points on a.
double normal_jump_along(const BSplineSurface& a, const BSplineSurface& b,
                         const BSplineCurve& bound) {
  double worst = 0;
  for (double t : clay::surface::linspace(0, 1, 97)) {
    const auto p = clay::surface::closest_point(a, clay::surface::evaluate(bound, t));
    const Eigen::Vector3d na = clay::surface::unit_normal(a, p.u, p.v);
    const Eigen::Vector3d nb = clay::surface::unit_normal(b, p.u, p.v);
    worst = std::max(worst, std::atan2(na.cross(nb).norm(), na.dot(nb)) * 180 / pi);
  }
  return worst;
}

}  // namespace

TEST_CASE("influence factors: Greville points inside the projected bound (Han et al. eq. 2)",
          "[style]") {
  const BSplineSurface s = flat();
  const Eigen::Vector3d c(48, 53, 0);
  const double radius = 31;
  const auto xu = clay::surface::greville_abscissae(s.u);
  for (double lift : {0.0, 12.0}) {  // drawn on the surface or above it: the projection is the same
    const InfluenceRegion region =
        influence_factors(s, ellipse(c + Eigen::Vector3d(0, 0, lift), radius, radius));
    REQUIRE(region.factors.size() == 225u);
    int checked = 0;
    for (int i = 0; i < 15; ++i)
      for (int j = 0; j < 15; ++j) {
        const Eigen::Vector2d g(100 * xu[static_cast<size_t>(i)], 100 * xu[static_cast<size_t>(j)]);
        const double d = (g - c.head<2>()).norm() - radius;
        if (std::abs(d) < 0.05) continue;  // within the chord error of the sampled circle
        CHECK(region.inside(i, j) == (d < 0));
        ++checked;
      }
    CHECK(checked > 200);
    CHECK(region.polygon.size() == static_cast<size_t>(StyleOptions{}.bound_samples - 1));
  }
}

TEST_CASE("influence from the target marks the vertices supporting its projection (Han et al. 5)",
          "[style]") {
  const BSplineSurface s = flat();
  const BSplineCurve target = bezier({20.3, 40.1, 5}, {40, 45, 9}, {60, 45, 9}, {80.7, 40.2, 5});
  StyleOptions options;
  options.boundary_rows = 0;  // the support band itself, not widened
  const InfluenceRegion region = influence_from_target(s, target, options);
  CHECK(region.polygon.empty());
  // Independent: vertex (i, j) is marked iff N_i(u) N_j(v) > 0 at some point of the projected
  // target, whose parameters are (x / 100, y / 100) on this surface.
  std::vector<double> nu(4), nv(4);
  std::vector<std::uint8_t> expected(225, 0);
  for (double t : clay::surface::linspace(0, 1, 200)) {
    const Eigen::Vector3d x = clay::surface::evaluate(target, t);
    const double u = x.x() / 100, v = x.y() / 100;
    const int ku = clay::surface::find_span(s.u, u), kv = clay::surface::find_span(s.v, v);
    clay::surface::basis_functions(s.u, ku, u, nu);
    clay::surface::basis_functions(s.v, kv, v, nv);
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b)
        if (nu[static_cast<size_t>(a)] * nv[static_cast<size_t>(b)] > 0)
          expected[static_cast<size_t>((ku - 3 + a) * 15 + kv - 3 + b)] = 1;
  }
  CHECK(region.factors == expected);
  // Widened by boundary_rows = 2 layers (Chebyshev distance), independently dilated here.
  options.boundary_rows = 2;
  const InfluenceRegion wide = influence_from_target(s, target, options);
  for (int i = 0; i < 15; ++i)
    for (int j = 0; j < 15; ++j) {
      bool near = false;
      for (int a = std::max(0, i - 2); a <= std::min(14, i + 2); ++a)
        for (int b = std::max(0, j - 2); b <= std::min(14, j + 2); ++b)
          near = near || expected[static_cast<size_t>(a * 15 + b)];
      CHECK(wide.inside(i, j) == near);
    }
}

TEST_CASE("key points lie on the target where it crosses the control-net rows (Han et al. eq. 8)",
          "[style]") {
  const BSplineSurface s = flat();
  const double h = 7;
  const Eigen::Vector3d a(12, 30, h), b(83, 60, h);
  const BSplineCurve line = bezier(a, a + (b - a) / 3, a + 2 * (b - a) / 3, b);
  const InfluenceRegion region = influence_factors(s, ellipse({50, 50, 0}, 49, 49));
  const KeyPoints keys = key_points(s, region, line);
  CHECK(keys.direction == KeyDirection::U);  // 71 mm along x against 30 along y
  CHECK(keys.constraint_class == ConstraintClass::WellConstrained);
  const auto xu = clay::surface::greville_abscissae(s.u);
  std::vector<int> rows;
  for (int r = 0; r < 15; ++r)
    if (100 * xu[static_cast<size_t>(r)] >= 12 && 100 * xu[static_cast<size_t>(r)] <= 83)
      rows.push_back(r);
  REQUIRE(keys.points.size() == rows.size());
  for (size_t k = 0; k < rows.size(); ++k) {
    const KeyPoint& p = keys.points[k];
    CHECK(p.row == rows[k]);
    CHECK_THAT(p.point.x(), WithinAbs(100 * xu[static_cast<size_t>(rows[k])], 1e-9));
    CHECK_THAT(p.point.y(), WithinAbs(30 + 30 * (p.point.x() - 12) / 71, 1e-9));  // on the line
    CHECK_THAT(p.distance, WithinAbs(h, 1e-12));
    CHECK_THAT(p.normal.z(), WithinAbs(1, 1e-15));
    CHECK((p.foot - (p.point - Eigen::Vector3d(0, 0, h))).norm() < 1e-9);
    CHECK(p.influenced);
  }
}

TEST_CASE("paper mode: forces along the normal, peak and symmetric fall-off (eqs. 3-13)",
          "[style]") {
  const BSplineSurface s = flat();
  const auto xv = clay::surface::greville_abscissae(s.v);
  const double y7 = 100 * xv[7];  // the target runs exactly over column 7
  const double h = 7;
  const BSplineCurve line = bezier({25, y7, h}, {40, y7, h}, {60, y7, h}, {75, y7, h});
  const BSplineCurve bound = ellipse({50, y7, 0}, 45, 30);  // symmetric about column 7
  StyleOptions options;
  options.lambda = 0.5;
  const StyleResult r = style_deform(s, bound, line, options);
  CHECK_THAT(r.report.brief(), Catch::Matchers::StartsWith(r.report.summary.brief()) &&
                                   Catch::Matchers::Contains("key points"));
  const InfluenceRegion region = influence_factors(s, bound);
  CHECK(r.report.constraint_class == ConstraintClass::WellConstrained);
  CHECK(r.report.direction == KeyDirection::U);
  REQUIRE(std::ssize(r.report.key_points) > 3);
  for (Eigen::Index row = 0; row < s.points.rows(); ++row) {
    const Eigen::RowVector3d d = r.surface.points.row(row) - s.points.row(row);
    CHECK(d.head<2>().norm() == 0.0);  // moved along the normal (0, 0, 1) only
    CHECK(d.z() >= 0);
    CHECK(d.z() <= options.lambda * h + 1e-12);
  }
  for (const KeyPoint& k : r.report.key_points) {
    // The peak vertex under the key point moves by exactly λ D (eq. 9), its neighbours
    // symmetrically.
    const auto z = [&](int j) { return r.surface.points(k.row * 15 + j, 2); };
    CHECK_THAT(z(7), WithinAbs(options.lambda * h, 1e-12));
    for (int d = 1; d <= 7; ++d) CHECK_THAT(z(7 - d), WithinAbs(z(7 + d), 1e-12));
    CHECK(z(6) < z(7));
  }
  // Relaxation (eqs. 10-11): rows beyond the end key points inside the bound still move, less.
  const int first = r.report.key_points.front().row;
  bool relaxed = false;
  for (int i = 0; i < first; ++i)
    if (region.inside(i, 7)) {
      CHECK(r.surface.points(i * 15 + 7, 2) > 0);
      CHECK(r.surface.points(i * 15 + 7, 2) < options.lambda * h);
      relaxed = true;
    }
  CHECK(relaxed);
  // Without smoothing only the two neighbours of the peak get the force (eqs. 4-5): here one.
  options.smoothing = false;
  options.relaxation = false;
  const StyleResult plain = style_deform(s, bound, line, options);
  CHECK(plain.report.moved_vertices >= std::ssize(plain.report.key_points));
  CHECK(plain.report.moved_vertices <= 2 * std::ssize(plain.report.key_points));
  for (const KeyPoint& k : plain.report.key_points) {  // the area weights sum to 1 (eq. 4)
    double sum = 0;
    for (int j = 0; j < 15; ++j) sum += plain.surface.points(k.row * 15 + j, 2);
    CHECK_THAT(sum, WithinAbs(options.lambda * h, 1e-12));
  }
}

TEST_CASE("locality: vertices outside the bound are bit-identical, in both modes", "[style]") {
  const BSplineSurface s = hood(16, 16);
  const double size = size_of(s);
  for (StyleMode mode : {StyleMode::Paper, StyleMode::Exact}) {
    StyleOptions options;
    options.mode = mode;
    const StyleResult r = style_deform(s, hood_bound(), hood_target(), options);
    INFO(r.report.message);
    const BSplineSurface& before = r.refined_parent;
    if (mode == StyleMode::Paper) {
      CHECK(clay::surface::identical(before, s));  // the paper's mode never changes the knots
    } else {
      CHECK(r.report.knots_inserted > 0);  // the ends of the target need a finer net here
      for (double u : clay::surface::linspace(0, 1, 9))  // knot insertion is exact
        for (double v : clay::surface::linspace(0, 1, 9))
          CHECK((clay::surface::evaluate(before, u, v) - clay::surface::evaluate(s, u, v)).norm() <=
                1e-12 * size);
    }
    REQUIRE(r.surface.points.rows() == before.points.rows());
    CHECK(r.surface.u.knots == before.u.knots);
    CHECK(r.surface.v.knots == before.v.knots);
    const InfluenceRegion region = influence_factors(before, hood_bound());
    CHECK(region.inside_count() > 10);
    CHECK(r.report.moved_vertices > 0);
    for (Eigen::Index row = 0; row < before.points.rows(); ++row)
      if (region.factors[static_cast<size_t>(row)] == 0)
        CHECK(rows_identical(r.surface.points, before.points, row));
    CHECK(r.report.locality == 0.0);
  }
}

TEST_CASE("lambda = 0 and the over-constrained class leave the surface bit-identical", "[style]") {
  const BSplineSurface s = hood();
  for (StyleMode mode : {StyleMode::Paper, StyleMode::Exact}) {
    StyleOptions options;
    options.mode = mode;
    options.lambda = 0;
    const StyleResult zero = style_deform(s, hood_bound(), hood_target(), options);
    CHECK(clay::surface::identical(zero.surface, s));
    options.lambda = 1;
    // A target beside the bound, completely outside it.
    const BSplineCurve outside =
        bezier({450, -150, 60}, {480, -50, 80}, {480, 50, 80}, {450, 150, 60});
    const StyleResult over = style_deform(s, hood_bound(), outside, options);
    CHECK(over.report.constraint_class == ConstraintClass::OverConstrained);
    CHECK(clay::surface::identical(over.surface, s));
    CHECK(over.report.message.find("over-constrained") != std::string::npos);
    // Half in, half out.
    const BSplineCurve partly =
        bezier({-60, -380, 60}, {-40, -200, 150}, {-40, 0, 150}, {-60, 100, 120});
    CHECK(style_deform(s, hood_bound(), partly, options).report.constraint_class ==
          ConstraintClass::UnderConstrained);
  }
}

TEST_CASE("mirror-symmetric input gives a mirror-symmetric result to 1e-12", "[style]") {
  const BSplineSurface s = hood();
  const double size = size_of(s);
  for (StyleMode mode : {StyleMode::Paper, StyleMode::Exact}) {
    for (bool smoothing : {true, false}) {
      StyleOptions options;
      options.mode = mode;
      options.smoothing = smoothing;
      const StyleResult r = style_deform(s, hood_bound(), hood_target(), options);
      CHECK(r.report.direction == KeyDirection::V);
      // The exact mode refines this net: mirror-symmetrically too.
      const auto& kv = r.surface.v.knots;
      for (size_t k = 0; k < kv.size(); ++k)
        CHECK_THAT(kv[k] + kv[kv.size() - 1 - k], WithinAbs(1.0, 1e-15));
      const int nu = r.surface.count_u(), nv = r.surface.count_v();
      double worst = 0;
      for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) {
          const Eigen::RowVector3d a = r.surface.points.row(i * nv + j);
          const Eigen::RowVector3d b = r.surface.points.row(i * nv + nv - 1 - j);
          worst = std::max(worst, (a - Eigen::RowVector3d(b.x(), -b.y(), b.z())).norm() / size);
        }
      INFO(worst);
      // The paper's mode is symmetric to rounding. The exact mode solves a thin-plate KKT system
      // whose conditioning grows with the refinement; its rounding (not the key points, which
      // come in mirrored pairs) leaves an asymmetry of about 2e-11 of the size here.
      CHECK(worst <= (mode == StyleMode::Paper ? 1e-12 : 1e-10));
      CHECK(r.report.max_displacement > 1);
    }
  }
}

TEST_CASE("exact mode: the hood passes through every key point and joins the parent with G1",
          "[style]") {
  const BSplineSurface s = hood(16, 16);
  const double size = size_of(s);
  StyleOptions options;
  options.mode = StyleMode::Exact;
  const StyleResult r = style_deform(s, hood_bound(), hood_target(), options);
  INFO(r.report.message);
  REQUIRE(std::ssize(r.report.key_points) >= 4);
  for (const KeyPoint& k : r.report.key_points) {
    REQUIRE(k.influenced);
    const auto p = clay::surface::closest_point(r.surface, k.point);  // independent of the report
    CHECK(p.distance <= 1e-6 * size);
  }
  CHECK(r.report.target_deviation <= 1e-6 * size);
  CHECK(r.report.conflicting_key_points.empty());
  CHECK(r.report.degrees_of_freedom > 0);
  // The target curve between key points: followed within curve_tolerance, or the message says not.
  const bool followed = r.report.target_curve_deviation <= options.curve_tolerance * size;
  CHECK(followed == (r.report.message.find("still missed") == std::string::npos));
  CHECK(r.report.rank == std::ssize(r.report.key_points));
  CHECK(normal_jump_along(s, r.surface, hood_bound()) <= 0.5);
  CHECK(r.report.boundary_tangent_angle <= 0.5);
  CHECK(r.report.locality == 0.0);
  // The paper's mode only approximates: its key-point deviation is far larger.
  options.mode = StyleMode::Paper;
  CHECK(style_deform(s, hood_bound(), hood_target(), options).report.target_deviation >
        1e-3 * size);
}

// The thin-plate fairness energy of docs/deform.md as a bilinear form, E(x, y) = sum over the
// knot-span cells of `net` and the 4 x 4 Gauss–Legendre points of each of
//   (x_uu . y_uu / a^4 + 2 x_uv . y_uv / (a^2 b^2) + x_vv . y_vv / b^4) |S_u x S_v| w,
// with a = |S_u|, b = |S_v| of `net` and x_uu... the second derivatives of the surface with
// `net`'s knots and weights and control points x — written from the definition with the
// library's point evaluation, not the solver's basis code. (No floor is needed on the hood.)
double thin_plate(const BSplineSurface& net, const Points3& x, const Points3& y) {
  const double node[] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                         0.8611363115940526};
  const double weight[] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                           0.3478548451374538};
  BSplineSurface sx = net, sy = net;
  sx.points = x;
  sy.points = y;
  const auto bu = clay::surface::breakpoints(net.u), bv = clay::surface::breakpoints(net.v);
  double sum = 0;
  for (size_t i = 0; i + 1 < bu.size(); ++i)
    for (size_t j = 0; j + 1 < bv.size(); ++j)
      for (int gi = 0; gi < 4; ++gi)
        for (int gj = 0; gj < 4; ++gj) {
          const double hu = bu[i + 1] - bu[i], hv = bv[j + 1] - bv[j];
          const double u = bu[i] + 0.5 * hu * (1 + node[gi]), v = bv[j] + 0.5 * hv * (1 + node[gj]);
          const auto m = clay::surface::derivatives(net, u, v, 1);
          const auto dx = clay::surface::derivatives(sx, u, v, 2);
          const auto dy = clay::surface::derivatives(sy, u, v, 2);
          const double a = m.du.norm(), b = m.dv.norm();
          const double density = dx.duu.dot(dy.duu) / std::pow(a, 4) +
                                 2 * dx.duv.dot(dy.duv) / (a * a * b * b) +
                                 dx.dvv.dot(dy.dvv) / std::pow(b, 4);
          sum += density * m.du.cross(m.dv).norm() * 0.25 * hu * hv * weight[gi] * weight[gj];
        }
  return sum;
}

TEST_CASE("exact mode: the displacement is the least thin-plate energy that meets the key points",
          "[style]") {
  // First-order optimality, checked from the definitions alone: with E the thin-plate energy of
  // the displacement field (thin_plate above) and B the key-point rows, any move z of the moved
  // vertices with B z = 0 leaves the key points met, so E(d, z) must vanish for all of them. B
  // is read off the surface by moving one control point at a time (linear in the points), not
  // from the basis code the solver uses. The energy is that of a surface, not of its net, so it
  // does not depend on how the net is spaced.
  const BSplineSurface s = hood(16, 16);
  StyleOptions options;
  options.mode = StyleMode::Exact;
  const StyleResult r = style_deform(s, hood_bound(), hood_target(), options);
  INFO(r.report.message);
  const BSplineSurface& net = r.refined_parent;
  const Points3 d = r.surface.points - net.points;
  std::vector<Eigen::Index> moved;
  for (Eigen::Index row = 0; row < d.rows(); ++row)
    if (!d.row(row).isZero(0)) moved.push_back(row);
  REQUIRE(moved.size() > 100);
  // The reported energy is E(d, d).
  const double energy = thin_plate(net, d, d);
  CHECK_THAT(r.report.fairness_energy, Catch::Matchers::WithinRel(energy, 1e-9));

  std::vector<const KeyPoint*> keys;
  for (const KeyPoint& k : r.report.key_points)
    if (k.influenced) keys.push_back(&k);
  const Eigen::Index nk = static_cast<Eigen::Index>(keys.size()),
                     nm = static_cast<Eigen::Index>(moved.size());
  Eigen::MatrixXd B(nk, nm);
  for (Eigen::Index c = 0; c < nm; ++c) {
    BSplineSurface unit = net;
    unit.points.row(moved[static_cast<size_t>(c)]).x() += 1.0;
    for (Eigen::Index k = 0; k < nk; ++k) {
      const KeyPoint& kp = *keys[static_cast<size_t>(k)];
      B(k, c) =
          (clay::surface::evaluate(unit, kp.u, kp.v) - clay::surface::evaluate(net, kp.u, kp.v))
              .x();
    }
  }
  // Random moves z of the moved vertices, projected onto null(B): z - B^T (B B^T)^-1 B z.
  std::srand(7);
  auto null_move = [&] {
    const Eigen::MatrixXd z = Eigen::MatrixXd::Random(nm, 3);
    Points3 out = Points3::Zero(d.rows(), 3);
    out(moved, Eigen::all) = z - B.transpose() * (B * B.transpose()).ldlt().solve(B * z);
    return out;
  };
  // The minimal-norm displacement through the same key points is not the least energy: the
  // check can fail.
  Points3 minimal_norm = Points3::Zero(d.rows(), 3);
  const Eigen::MatrixXd rhs = B * d(moved, Eigen::all);
  minimal_norm(moved, Eigen::all) = B.transpose() * (B * B.transpose()).ldlt().solve(rhs);
  const double energy_mn = thin_plate(net, minimal_norm, minimal_norm);
  double worst = 0, worst_mn = 0;
  for (int trial = 0; trial < 6; ++trial) {
    const Points3 z = null_move();
    const double ez = thin_plate(net, z, z);
    worst = std::max(worst, std::abs(thin_plate(net, d, z)) / std::sqrt(energy * ez));
    worst_mn =
        std::max(worst_mn, std::abs(thin_plate(net, minimal_norm, z)) / std::sqrt(energy_mn * ez));
  }
  INFO("stationarity " << worst << ", of the minimal-norm displacement " << worst_mn);
  CHECK(worst <= 1e-7);
  CHECK(worst_mn > 1e-3);
  CHECK(energy < energy_mn);
}

TEST_CASE("exact mode on a sail with uneven knots, with and without a bound curve", "[style]") {
  const BSplineSurface s = sail();
  const double size = size_of(s);
  // A target across the sail at mid height, 80-150 mm off its camber.
  const BSplineCurve target =
      bezier({500, 2200, 380}, {800, 2500, 450}, {1100, 2500, 450}, {1300, 2300, 300});
  const BSplineCurve bound = ellipse({900, 2400, 600}, 750, 900);
  StyleOptions options;
  options.mode = StyleMode::Exact;
  for (bool with_bound : {true, false}) {
    const StyleResult r =
        with_bound ? style_deform(s, bound, target, options) : style_deform(s, target, options);
    INFO((with_bound ? "with bound: " : "without: ") << r.report.message);
    REQUIRE(std::ssize(r.report.key_points) >= 2);
    CHECK(r.report.constraint_class != ConstraintClass::OverConstrained);
    for (const KeyPoint& k : r.report.key_points)
      if (k.influenced) {
        INFO((clay::surface::evaluate(r.surface, k.u, k.v) - k.point).norm()
             << " at " << k.u << " " << k.v << " D " << k.distance);
        CHECK(clay::surface::closest_point(r.surface, k.point).distance <= 1e-6 * size);
      }
    CHECK(r.report.target_deviation <= 1e-6 * size);
    CHECK(r.report.locality == 0.0);
    if (with_bound) CHECK(normal_jump_along(s, r.surface, bound) <= 0.5);
    CHECK(r.report.boundary_tangent_angle <= 0.5);
  }
}

TEST_CASE("exact mode refines a coarse net by knot insertion and reports conflicts without it",
          "[style]") {
  const BSplineSurface s = hood(6, 6);
  const double size = size_of(s);
  StyleOptions options;
  options.mode = StyleMode::Exact;
  options.key_points_per_row = 2;
  const StyleResult r = style_deform(s, hood_bound(), hood_target(), options);
  INFO(r.report.message);
  CHECK(r.report.knots_inserted > 0);
  CHECK(r.surface.u.degree == 3);
  CHECK(r.surface.v.degree == 3);
  CHECK(r.surface.count_u() * r.surface.count_v() > 36);
  CHECK(r.report.conflicting_key_points.empty());
  CHECK(r.report.target_deviation <= 1e-6 * size);
  // The refinement is exact: away from the bound the result equals the parent.
  for (double u : {0.02, 0.98})
    for (double v : {0.03, 0.5, 0.97})
      CHECK((clay::surface::evaluate(r.surface, u, v) - clay::surface::evaluate(s, u, v)).norm() <=
            1e-12 * size);

  options.max_refinements = 0;
  const StyleResult coarse = style_deform(s, hood_bound(), hood_target(), options);
  CHECK(coarse.report.knots_inserted == 0);
  CHECK(coarse.report.rank < std::ssize(coarse.report.key_points));
  CHECK_FALSE(coarse.report.conflicting_key_points.empty());
  CHECK(coarse.report.message.find("cannot be met") != std::string::npos);
}

TEST_CASE("style deformation errors name the object and the fix", "[style]") {
  using clay::ErrorCategory;
  using clay::test::error_of;
  const BSplineSurface s = hood();
  // An open bound curve.
  const BSplineCurve open =
      bezier({-300, -200, 150}, {0, -300, 150}, {300, -200, 150}, {300, 200, 150});
  auto [c1, m1] = error_of([&] { influence_factors(s, open); });
  CHECK(c1 == ErrorCategory::InvalidGeometry);
  CHECK(m1.find("closed") != std::string::npos);
  // A figure-eight bound crossing itself.
  Points3 p(7, 3);
  p << -300, 0, 150, -300, 250, 150, 300, -250, 150, 300, 250, 150, -300, -250, 150, -300, 0, 150,
      -300, 0, 150;
  const BSplineCurve eight =
      clay::surface::make_curve(3, {0, 0, 0, 0, 0.25, 0.5, 0.75, 1, 1, 1, 1}, p);
  auto [c2, m2] = error_of([&] { influence_factors(s, eight); });
  CHECK(c2 == ErrorCategory::InvalidGeometry);
  CHECK(m2.find("crosses itself") != std::string::npos);
  // Bad options.
  StyleOptions bad;
  bad.lambda = 1.5;
  auto [c3, m3] = error_of([&] { style_deform(s, hood_bound(), hood_target(), bad); });
  CHECK(c3 == ErrorCategory::InvalidArgument);
  CHECK(m3.find("lambda") != std::string::npos);
  bad = {};
  bad.curve_samples = 3;
  CHECK(error_of([&] { bad.validate(); }).second.find("curve_samples") != std::string::npos);
  bad = {};
  bad.boundary_rows = 7;
  CHECK(error_of([&] { bad.validate(); }).second.find("boundary_rows") != std::string::npos);
  // A region made for another net.
  const InfluenceRegion other = influence_factors(hood(8, 8), hood_bound());
  auto [c4, m4] = error_of([&] { style_deform(s, other, hood_target()); });
  CHECK(c4 == ErrorCategory::InvalidArgument);
  CHECK(m4.find("8 x 8") != std::string::npos);
  // A target with a NaN control point.
  BSplineCurve nan_target = hood_target();
  nan_target.points(1, 2) = std::nan("");
  auto [c5, m5] = error_of([&] { style_deform(s, hood_bound(), nan_target); });
  CHECK(c5 == ErrorCategory::InvalidGeometry);
  CHECK(m5.find("target curve") != std::string::npos);
}

TEST_CASE("StyleEditor: drags give the one-off results and reuse the exact factorization",
          "[style]") {
  const BSplineSurface s = hood(16, 16);
  const double size = size_of(s);
  for (StyleMode mode : {StyleMode::Paper, StyleMode::Exact}) {
    StyleOptions options;
    options.mode = mode;
    const InfluenceRegion region = influence_factors(s, hood_bound(), options);
    StyleEditor editor(s, region, options);
    for (double lift : {0.0, 3.0, 6.0, 9.0, 6.0}) {
      BSplineCurve target = hood_target();
      target.points.col(2).array() += lift;
      const StyleResult dragged = editor.update(target);
      const StyleResult once = style_deform(s, region, target, options);
      REQUIRE(dragged.surface.points.rows() == once.surface.points.rows());
      // Paper mode: the same up to the projection tolerance (the Newton starts differ). Exact
      // mode: the key points added where the target is missed may then differ too; both results
      // follow the target within curve_tolerance.
      const double agree = mode == StyleMode::Paper ? 1e-9 : options.curve_tolerance;
      CHECK((dragged.surface.points - once.surface.points).cwiseAbs().maxCoeff() <= agree * size);
      CHECK(std::ssize(dragged.report.key_points) == std::ssize(once.report.key_points));
      CHECK(dragged.report.knots_inserted == once.report.knots_inserted);
      if (mode == StyleMode::Exact) CHECK(dragged.report.target_deviation <= 1e-6 * size);
    }
  }
  CHECK_THROWS_AS(StyleEditor(hood(8, 8), influence_factors(s, hood_bound())), clay::Error);
}

TEST_CASE("report_curves off leaves the sampled figures unmeasured (NaN), the rest identical",
          "[style]") {
  const BSplineSurface s = hood(16, 16);
  StyleOptions options;
  const StyleResult full = style_deform(s, hood_bound(), hood_target(), options);
  options.report_curves = false;
  const StyleResult quick = style_deform(s, hood_bound(), hood_target(), options);
  CHECK(clay::surface::identical(full.surface, quick.surface));
  CHECK(std::isnan(quick.report.target_curve_deviation));
  CHECK(std::isnan(quick.report.boundary_tangent_angle));
  CHECK(std::isnan(quick.report.boundary_position_jump));
  CHECK(quick.report.target_deviation == full.report.target_deviation);
  CHECK(std::isfinite(full.report.boundary_tangent_angle));
  CHECK(full.report.target_curve_deviation >= full.report.target_deviation * 0.5);
}

TEST_CASE("exact mode: the target curve is measured densely and independently", "[style]") {
  // The report's target_curve_distance against 2001 samples of the target, each by a global
  // closest point on the result; inside the bound means the sample's closest point on the parent
  // lies in the projected bound (an independent winding-number test).
  const BSplineSurface s = hood(16, 16);
  const double size = size_of(s);
  StyleOptions options;
  options.mode = StyleMode::Exact;
  const StyleResult r = style_deform(s, hood_bound(), hood_target(), options);
  INFO(r.report.message);
  const auto polygon = influence_factors(s, hood_bound(), options).polygon;
  auto inside = [&](double u, double v) {
    double winding = 0;
    for (size_t k = 0; k < polygon.size(); ++k) {
      const Eigen::Vector2d a = polygon[k] - Eigen::Vector2d(u, v);
      const Eigen::Vector2d b = polygon[(k + 1) % polygon.size()] - Eigen::Vector2d(u, v);
      winding += std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
    }
    return std::abs(winding) > pi;
  };
  double independent = 0;
  for (double t : clay::surface::linspace(0, 1, 2001)) {
    const Eigen::Vector3d c = clay::surface::evaluate(hood_target(), t);
    const auto foot = clay::surface::closest_point(s, c);
    if (!inside(foot.u, foot.v)) continue;
    independent = std::max(independent, clay::surface::closest_point(r.surface, c).distance);
  }
  INFO("reported " << r.report.target_curve_distance << " mm, independent " << independent);
  CHECK(r.report.target_curve_distance <= 1.1 * independent + 1e-9 * size);
  CHECK(r.report.target_curve_distance >= 0.9 * independent);
  // The whole curve is met, not just the key points.
  CHECK(independent <= options.curve_tolerance * size);
  CHECK(r.report.summary.converged());

  // The mean curvature at the region's centre, by central differences of point evaluations,
  // lies in the reported range.
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  for (const auto& p : polygon) centre += p / static_cast<double>(polygon.size());
  const double h = 1e-4, u = centre.x(), v = centre.y();
  auto S = [&](double a, double b) { return clay::surface::evaluate(r.surface, a, b); };
  const Eigen::Vector3d su = (S(u + h, v) - S(u - h, v)) / (2 * h);
  const Eigen::Vector3d sv = (S(u, v + h) - S(u, v - h)) / (2 * h);
  const Eigen::Vector3d suu = (S(u + h, v) - 2 * S(u, v) + S(u - h, v)) / (h * h);
  const Eigen::Vector3d svv = (S(u, v + h) - 2 * S(u, v) + S(u, v - h)) / (h * h);
  const Eigen::Vector3d suv =
      (S(u + h, v + h) - S(u + h, v - h) - S(u - h, v + h) + S(u - h, v - h)) / (4 * h * h);
  const Eigen::Vector3d n = su.cross(sv).normalized();
  const double E = su.dot(su), F = su.dot(sv), G = sv.dot(sv);
  const double H = (E * svv.dot(n) - 2 * F * suv.dot(n) + G * suu.dot(n)) / (2 * (E * G - F * F));
  INFO("H = " << H << " in [" << r.report.mean_curvature_min << ", " << r.report.mean_curvature_max
              << "]");
  CHECK(H >= r.report.mean_curvature_min - 1e-6);
  CHECK(H <= r.report.mean_curvature_max + 1e-6);
  CHECK(r.report.mean_curvature_max > r.report.mean_curvature_min);
}

TEST_CASE("exact mode: net convergence refines until the shape settles, and says when it cannot",
          "[style]") {
  const BSplineSurface s = hood(16, 16);
  StyleOptions options;
  options.mode = StyleMode::Exact;
  // Convergence off (the default): the first net that meets the key points.
  const StyleResult coarse = style_deform(s, hood_bound(), hood_target(), options);
  INFO(coarse.report.message);
  CHECK(std::isnan(coarse.report.net_change));
  CHECK(coarse.report.summary.converged());
  options.net_convergence = 0.02;
  const StyleResult fine = style_deform(s, hood_bound(), hood_target(), options);
  INFO(fine.report.message);
  CHECK(fine.report.net_change <= 0.02);
  CHECK(fine.report.summary.converged());
  CHECK(fine.report.knots_inserted > coarse.report.knots_inserted);
  // The nets are nested and the key points the same, so the finer solve has less energy.
  CHECK(fine.report.fairness_energy < coarse.report.fairness_energy);
  // The shape moved by more on the way than in the last halving: the changes fall.
  double change = 0, moved = 0;
  for (double u : clay::surface::linspace(0.25, 0.75, 41))
    for (double v : clay::surface::linspace(0.25, 0.75, 41)) {
      const Eigen::Vector3d a = clay::surface::evaluate(coarse.surface, u, v);
      const Eigen::Vector3d b = clay::surface::evaluate(fine.surface, u, v);
      change = std::max(change, (b - a).norm());
      moved = std::max(moved, (b - clay::surface::evaluate(s, u, v)).norm());
    }
  INFO("coarse to fine " << change / moved << ", last halving " << fine.report.net_change);
  CHECK(change / moved > fine.report.net_change);
  // Not reachable within the rounds allowed: not converged, and the message says which figure.
  options.net_convergence = 1e-4;
  options.max_refinements = 3;
  const StyleResult stuck = style_deform(s, hood_bound(), hood_target(), options);
  CHECK_FALSE(stuck.report.summary.converged());
  CHECK(stuck.report.summary.message.find("net_convergence") != std::string::npos);
  // Best effort (the studio's calm default): the same rounds, the finest net's result kept and
  // its net_change reported, bit for bit the surface the failing run computed.
  options.net_convergence_best_effort = true;
  const StyleResult effort = style_deform(s, hood_bound(), hood_target(), options);
  INFO(effort.report.summary.message);
  CHECK(effort.report.summary.converged());
  CHECK(effort.report.net_change > 1e-4);
  CHECK(effort.report.net_change == stuck.report.net_change);
  CHECK(clay::surface::identical(effort.surface, stuck.surface));
  // Reachable: best effort changes nothing.
  options.net_convergence = 0.02;
  options.max_refinements = 6;
  const StyleResult reached = style_deform(s, hood_bound(), hood_target(), options);
  CHECK(reached.report.net_change == fine.report.net_change);
  CHECK(clay::surface::identical(reached.surface, fine.surface));
}

TEST_CASE("grid_waves counts the turns along a grid's rows and columns: sin of k periods, 2k",
          "[style]") {
  // sin(2 pi k x) on [0, 1] has 2k interior extrema, each a full swing of 1 or 2 from the last.
  for (int k = 1; k <= 5; ++k) {
    const int n = 200 * k + 1;
    Eigen::MatrixXd rows(3, n);
    for (int j = 0; j < n; ++j) rows.col(j).setConstant(std::sin(2 * M_PI * k * j / (n - 1.0)));
    CHECK(grid_waves(rows, 0.5) == 2 * k);
    CHECK(grid_waves(Eigen::MatrixXd(rows.transpose()), 0.5) == 2 * k);  // columns too
    // Ripples below the swing do not count: 0.01 * sin(60 pi x) on top changes nothing.
    Eigen::MatrixXd rippled = rows;
    for (int j = 0; j < n; ++j)
      rippled.col(j).array() += 0.01 * std::sin(60 * M_PI * j / (n - 1.0));
    CHECK(grid_waves(rippled, 0.5) == 2 * k);
  }
  // The ripples alone (10 periods: 20 turns) count when the swing asked is smaller than theirs.
  Eigen::MatrixXd ripples(1, 2001);
  for (int j = 0; j < 2001; ++j) ripples(0, j) = 0.01 * std::sin(20 * M_PI * j / 2000.0);
  CHECK(grid_waves(ripples, 0.005) == 20);
  CHECK(grid_waves(ripples, 0.5) == 0);
  // NaN cells (outside a region) cut a line into runs counted apart: two halves of sin(4 pi x)
  // cut at its middle zero, each with 2 turns.
  Eigen::MatrixXd cut(1, 401);
  for (int j = 0; j < 401; ++j) cut(0, j) = std::sin(4 * M_PI * j / 400.0);
  CHECK(grid_waves(cut, 0.5) == 4);
  cut(0, 200) = std::numeric_limits<double>::quiet_NaN();
  CHECK(grid_waves(cut, 0.5) == 2);
  CHECK(grid_waves(cut, 0) == 0);  // no swing: nothing counted
  CHECK(grid_waves(Eigen::MatrixXd::Zero(4, 4), 0.1) == 0);
}

TEST_CASE(
    "curvature_waves: a push rings on its first net, calm once converged, unmeasured without "
    "curves",
    "[style]") {
  const BSplineSurface s = hood(16, 16);
  StyleOptions options;
  options.mode = StyleMode::Exact;
  // On its first net the push rings (the change of mean curvature turns 7 times along a section;
  // Zebra shows beads along the bound); refined until a halving changes it by under 2 %, calm.
  const StyleResult first = style_deform(s, hood_bound(), hood_target(), options);
  options.net_convergence = 0.02;
  const StyleResult r = style_deform(s, hood_bound(), hood_target(), options);
  INFO(r.report.message << "; waves " << r.report.curvature_waves << ", on the first net "
                        << first.report.curvature_waves);
  CHECK(first.report.curvature_waves > curvature_waves_calm);
  // A push changes the curvature (a crest at least); calm, it turns no more than a crest and its
  // shoulders do.
  CHECK(r.report.curvature_waves >= 1);
  CHECK(r.report.curvature_waves <= curvature_waves_calm);
  options.report_curves = false;
  CHECK(style_deform(s, hood_bound(), hood_target(), options).report.curvature_waves == -1);
  // Paper mode measures it too.
  options.report_curves = true;
  options.mode = StyleMode::Paper;
  CHECK(style_deform(s, hood_bound(), hood_target(), options).report.curvature_waves >= 0);
}

TEST_CASE("exact mode with G2 at the bound: third-derivative energy, one more fixed layer",
          "[style]") {
  const BSplineSurface s = hood(16, 16);
  const double size = size_of(s);
  StyleOptions options;
  options.mode = StyleMode::Exact;
  options.continuity = BoundContinuity::G2;
  const StyleResult r = style_deform(s, hood_bound(), hood_target(), options);
  INFO(r.report.message);
  for (const KeyPoint& k : r.report.key_points)
    if (k.influenced)
      CHECK(clay::surface::closest_point(r.surface, k.point).distance <= 1e-6 * size);
  CHECK(r.report.locality == 0.0);
  CHECK(r.report.boundary_position_jump == 0.0);
  CHECK(r.report.boundary_tangent_angle == 0.0);
  CHECK(r.report.fairness_energy > 0);
  CHECK(to_string(BoundContinuity::G2) == "G2");
  // A quadratic parent has no third derivatives inside its spans: refused, naming the way out.
  auto bu = clay::surface::clamped_uniform_basis(2, 8);
  Points3 p(64, 3);
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) p.row(i * 8 + j) << 100.0 * i, 100.0 * j, 0.0;
  const BSplineSurface quadratic = clay::surface::make_surface(bu, bu, p);
  const auto [category, what] = clay::test::error_of([&] {
    style_deform(quadratic, bezier({200, 300, 0}, {300, 300, 40}, {400, 300, 40}, {500, 300, 0}),
                 options);
  });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK(what.find("elevate") != std::string::npos);
  CHECK(what.find("G2") != std::string::npos);
}

TEST_CASE("exact mode inserts only simple knots: the styled area stays curvature-continuous",
          "[style]") {
  // Inside the bound no knot of multiplicity above degree - 2 is introduced (a cubic stays C2 in
  // its parametrization), with and without net convergence.
  const BSplineSurface s = hood(16, 16);
  StyleOptions options;
  options.mode = StyleMode::Exact;
  for (double convergence : {0.0, 0.02}) {
    options.net_convergence = convergence;
    const StyleResult r = style_deform(s, hood_bound(), hood_target(), options);
    REQUIRE(r.report.knots_inserted > 0);
    for (const auto* pair : {&r.surface.u, &r.surface.v}) {
      const auto& parent = pair == &r.surface.u ? s.u : s.v;
      for (double t : clay::surface::breakpoints(*pair)) {
        if (t <= pair->knots.front() || t >= pair->knots.back()) continue;
        if (clay::surface::multiplicity(parent, t) > 0) continue;  // the parent's own
        CHECK(clay::surface::multiplicity(*pair, t) <= pair->degree - 2);
      }
    }
  }
}
