// Extended lattices (Coquillart 1990): freezing inverts the rest shape, re-evaluation follows
// eq. (1) at the frozen parameters (checked by an independent de Casteljau evaluation), outside
// points stay put, degenerate chunks and Newton failures are handled, every error path.
#include <catch2/catch.hpp>

#include <clay/deform.hpp>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "error_of.hpp"

using namespace clay::deform;
using Catch::Matchers::Contains;
using clay::ErrorCategory;
using clay::test::error_of;
using Vec3 = Eigen::Vector3d;

static_assert(PointDeformation<ExtendedLattice>);

namespace {

/// Coquillart eq. (1) by de Casteljau's algorithm (in w, then v, then u): independent of the
/// Bernstein sums in the library.
Vec3 de_casteljau(const Points3& control, const Chunk& chunk, const Vec3& uvw) {
  std::array<Vec3, 64> p;
  for (size_t e = 0; e < 64; ++e) p[e] = control.row(chunk[e]).transpose();
  auto reduce = [](Vec3* q, int stride, double t) {  // 4 points at q, q + stride, ...
    Vec3 a[4] = {q[0], q[stride], q[2 * stride], q[3 * stride]};
    for (int level = 1; level < 4; ++level)
      for (int i = 0; i < 4 - level; ++i) a[i] = (1 - t) * a[i] + t * a[i + 1];
    return a[0];
  };
  std::array<Vec3, 16> w;
  for (int ij = 0; ij < 16; ++ij)
    w[static_cast<size_t>(ij)] = reduce(&p[static_cast<size_t>(ij * 4)], 1, uvw[2]);
  std::array<Vec3, 4> v;
  for (int i = 0; i < 4; ++i)
    v[static_cast<size_t>(i)] = reduce(&w[static_cast<size_t>(i * 4)], 1, uvw[1]);
  return reduce(v.data(), 1, uvw[0]);
}

/// A skewed cylinder far from the origin, with merged axis points.
CylinderSpec cylinder() {
  CylinderSpec s;
  s.origin = Vec3(120, -40, 75);
  s.axis = Vec3(0.2, -0.3, 1.0);
  s.reference = Vec3(1, 0.5, 0);
  s.radius = 30;
  s.height = 45;
  s.sectors = 12;
  s.rings = 2;
  s.layers = 2;
  return s;
}

/// The cylinder's frame, computed here: e1 (angle 0), e2, e3 (axis).
struct Cyl {
  Vec3 o, e1, e2, e3;
  explicit Cyl(const CylinderSpec& s) : o(s.origin) {
    e3 = s.axis / s.axis.norm();
    e1 = s.reference - s.reference.dot(e3) * e3;
    e1 /= e1.norm();
    e2 = e3.cross(e1);
  }
  Vec3 at(double rho, double angle, double z) const {
    return o + z * e3 + rho * (std::cos(angle) * e1 + std::sin(angle) * e2);
  }
};

/// Points inside the cylinder: random (area-uniform), exactly on the axis (ends included), on
/// the welded seam (angle 0), on the other sector boundaries, on the end discs and the mantle.
Points3 cylinder_points(const CylinderSpec& s, std::mt19937& rng, int random_count) {
  const Cyl c(s);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<Vec3> p;
  for (int n = 0; n < random_count; ++n)
    p.push_back(c.at(s.radius * std::sqrt(unit(rng)), 2 * std::numbers::pi * unit(rng),
                     s.height * unit(rng)));
  for (int n = 0; n <= 40; ++n) p.push_back(c.at(0, 0, s.height * n / 40));  // axis
  for (int n = 0; n <= 40; ++n)
    p.push_back(c.at(s.radius * unit(rng), 0, s.height * unit(rng)));  // seam
  for (int n = 0; n < 60; ++n)                                         // sector faces
    p.push_back(c.at(s.radius * unit(rng), 2 * std::numbers::pi * (n % s.sectors) / s.sectors,
                     s.height * unit(rng)));
  for (int n = 0; n < 40; ++n)  // end discs
    p.push_back(c.at(s.radius * std::sqrt(unit(rng)), 2 * std::numbers::pi * unit(rng),
                     n % 2 ? s.height : 0.0));
  for (int n = 0; n < 40; ++n)  // mantle
    p.push_back(c.at(s.radius, 2 * std::numbers::pi * unit(rng), s.height * unit(rng)));
  p.push_back(c.at(1e-9, 0.3, 10));  // a hair off the axis
  Points3 out(static_cast<Eigen::Index>(p.size()), 3);
  for (size_t r = 0; r < p.size(); ++r) out.row(static_cast<Eigen::Index>(r)) = p[r].transpose();
  return out;
}

double size_of(const Points3& p) {
  return (p.colwise().maxCoeff() - p.colwise().minCoeff()).norm();
}

/// One chunk whose control point (i, j, k) is f(i / 3, j / 3, k / 3).
template <class F>
ExtendedLattice one_chunk(F f) {
  ExtendedLattice L;
  L.rest.resize(64, 3);
  L.chunks.resize(1);
  for (int e = 0; e < 64; ++e) {
    L.rest.row(e) = f((e / 16) / 3.0, (e / 4 % 4) / 3.0, (e % 4) / 3.0).transpose();
    L.chunks[0][static_cast<size_t>(e)] = e;
  }
  L.points = L.rest;
  return L;
}

/// `n` points of the rest shape at random parameters of random chunks.
Points3 rest_samples(const ExtendedLattice& L, std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> unit(0, 1);
  std::uniform_int_distribution<size_t> pick(0, L.chunks.size() - 1);
  Points3 p(n, 3);
  for (int r = 0; r < n; ++r)
    p.row(r) = de_casteljau(L.rest, L.chunks[pick(rng)], Vec3(unit(rng), unit(rng), unit(rng)))
                   .transpose();
  return p;
}

/// Largest |rest map(uvw) − x| (de Casteljau) and |evaluate − x| over the frozen points, and
/// the largest distance of a frozen (u, v, w) outside [0, 1]^3.
struct Identity {
  double rest_map = 0, evaluated = 0, outside_cube = 0;
};

Identity identity_errors(const ExtendedLattice& L, const Points3& p, const FrozenPoints& f) {
  Identity id;
  const Points3 back = evaluate(L, f);
  for (Eigen::Index r = 0; r < p.rows(); ++r) {
    const FrozenPoint& q = f.points[static_cast<size_t>(r)];
    REQUIRE(q.chunk >= 0);
    const Vec3 x = p.row(r).transpose();
    id.rest_map =
        std::max(id.rest_map,
                 (de_casteljau(L.rest, L.chunks[static_cast<size_t>(q.chunk)], q.uvw) - x).norm());
    id.evaluated = std::max(id.evaluated, (back.row(r) - p.row(r)).norm());
    for (int d = 0; d < 3; ++d)
      id.outside_cube = std::max({id.outside_cube, -q.uvw[d], q.uvw[d] - 1});
  }
  return id;
}

/// Every control point moved by up to `amount` mm at random.
ExtendedLattice displaced(ExtendedLattice L, std::mt19937& rng, double amount) {
  std::uniform_real_distribution<double> c(-amount, amount);
  for (Eigen::Index r = 0; r < L.points.rows(); ++r)
    L.points.row(r) += Eigen::RowVector3d(c(rng), c(rng), c(rng));
  return L;
}

}  // namespace

TEST_CASE("a cylindrical lattice welds its seam and merges its axis points", "[deform]") {
  const CylinderSpec s = cylinder();
  const ExtendedLattice L = make_cylindrical_lattice(s);
  const int nI = 3 * s.rings + 1, nJ = 3 * s.sectors, nK = 3 * s.layers + 1;
  CHECK(L.rest.rows() == nK + (nI - 1) * nJ * nK);  // one axis row per height
  CHECK(L.chunks.size() == static_cast<size_t>(s.rings * s.sectors * s.layers));
  CHECK(problems(L).empty());
  const Cyl c(s);
  for (int k = 0; k < nK; ++k) {
    CHECK(cylindrical_index(s, 0, 5, k) == k);
    CHECK((L.rest.row(k).transpose() - c.at(0, 0, s.height * k / (nK - 1))).norm() < 1e-12);
    // The seam: angular index 3 sectors is angular index 0.
    CHECK(cylindrical_index(s, 4, nJ, k) == cylindrical_index(s, 4, 0, k));
    CHECK(cylindrical_index(s, 4, -1, k) == cylindrical_index(s, 4, nJ - 1, k));
  }
  // Corner control points (angular multiple of 3) lie on the circle of their radius.
  for (int j = 0; j < nJ; j += 3) {
    const Vec3 p = L.rest.row(cylindrical_index(s, nI - 1, j, 0)).transpose();
    CHECK_THAT((p - c.o).norm(), Catch::Matchers::WithinAbs(s.radius, 1e-12));
  }
  // The last sector's v = 1 face is the first sector's v = 0 face (same rows).
  const Chunk& last = L.chunks[static_cast<size_t>((0 * s.sectors + s.sectors - 1) * s.layers)];
  const Chunk& first = L.chunks[0];
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k)
      CHECK(last[static_cast<size_t>((i * 4 + 3) * 4 + k)] ==
            first[static_cast<size_t>((i * 4 + 0) * 4 + k)]);
  // A tube (inner radius > 0) merges nothing.
  CylinderSpec tube = s;
  tube.inner_radius = 10;
  CHECK(make_cylindrical_lattice(tube).rest.rows() == nI * nJ * nK);
}

TEST_CASE("freezing then re-evaluating an undisplaced cylindrical lattice returns every point",
          "[deform]") {
  std::mt19937 rng(61);
  const CylinderSpec s = cylinder();
  const ExtendedLattice L = make_cylindrical_lattice(s);
  const Points3 p = cylinder_points(s, rng, 3000);
  for (int threads : {1, 2}) {
    FreezeOptions o;
    o.threads = threads;
    const FrozenPoints f = freeze(L, p, o);
    INFO(f.report.brief());
    CHECK(f.report.summary.converged());
    CHECK(f.report.inside == p.rows());
    CHECK(f.report.outside == 0);
    const Identity id = identity_errors(L, p, f);
    INFO("rest map " << id.rest_map << " mm, evaluate " << id.evaluated << " mm, outside the cube "
                     << id.outside_cube << ", lattice size " << size_of(L.rest) << " mm");
    CHECK(id.rest_map < 1e-9);
    CHECK(id.evaluated < 1e-9);
    CHECK(id.evaluated < 1e-14 * size_of(L.rest));  // Newton polished to rounding (~1e-15)
    CHECK(id.outside_cube <= 1e-9);
    CHECK(f.report.summary.final_residual < 1e-12 * size_of(L.rest));
  }
  // Points on the axis are in an innermost chunk (the degenerate ones), at u = 0.
  const FrozenPoints f = freeze(L, p.middleRows(3000, 41));
  for (const FrozenPoint& q : f.points) {
    REQUIRE(q.chunk >= 0);
    CHECK((q.chunk / s.layers) / s.sectors == 0);  // ring 0
    CHECK(std::abs(q.uvw[0]) < 1e-9);
  }
}

TEST_CASE("a displaced extended lattice deforms like de Casteljau at the frozen parameters",
          "[deform]") {
  std::mt19937 rng(62);
  const CylinderSpec s = cylinder();
  const ExtendedLattice L = displaced(make_cylindrical_lattice(s), rng, 4.0);
  const Points3 p = cylinder_points(s, rng, 2000);
  const FrozenPoints f = freeze(L, p);  // freezing reads the rest shape only
  const Points3 moved = evaluate(L, f);
  double worst = 0;
  for (Eigen::Index r = 0; r < p.rows(); ++r) {
    const FrozenPoint& q = f.points[static_cast<size_t>(r)];
    REQUIRE(q.chunk >= 0);
    worst = std::max(worst, (moved.row(r).transpose() -
                             de_casteljau(L.points, L.chunks[static_cast<size_t>(q.chunk)], q.uvw))
                                .norm());
  }
  INFO("largest difference to de Casteljau " << worst << " mm");
  CHECK(worst < 1e-12 * size_of(L.points));
  // The one-off functions freeze and evaluate the same way.
  CHECK(deform_points(L, p, DeformOptions{2}) == moved);
  CHECK(deform_points(L, p, DeformOptions{1}) == moved);
  for (Eigen::Index r = 0; r < 20; ++r)
    CHECK(deform_point(L, p.row(r).transpose()) == moved.row(r).transpose());
  // C0 by construction: the displaced seam and axis agree between the chunks that share them.
  std::uniform_real_distribution<double> unit(0, 1);
  for (int n = 0; n < 50; ++n) {
    const double u = unit(rng), w = unit(rng), v = unit(rng);
    const Chunk& first = L.chunks[0];
    const Chunk& last = L.chunks[static_cast<size_t>((s.sectors - 1) * s.layers)];
    CHECK((chunk_point(L.points, first, Vec3(u, 0, w)) - chunk_point(L.points, last, Vec3(u, 1, w)))
              .norm() < 1e-12);
    const Chunk& other = L.chunks[static_cast<size_t>(5 * s.layers)];
    CHECK((chunk_point(L.points, first, Vec3(0, v, w)) -
           chunk_point(L.points, other, Vec3(0, unit(rng), w)))
              .norm() < 1e-12);
  }
}

TEST_CASE("points outside an extended lattice come back bit-identical", "[deform]") {
  std::mt19937 rng(63);
  const CylinderSpec s = cylinder();
  const ExtendedLattice L = displaced(make_cylindrical_lattice(s), rng, 4.0);
  const Cyl c(s);
  std::uniform_real_distribution<double> unit(0, 1);
  Points3 p(300, 3);
  for (Eigen::Index r = 0; r < 300; ++r) {
    const double angle = 2 * std::numbers::pi * unit(rng);
    if (r % 3 == 0)
      p.row(r) = c.at(s.radius * (1.001 + unit(rng)), angle, s.height * unit(rng)).transpose();
    else if (r % 3 == 1)
      p.row(r) = c.at(s.radius * unit(rng), angle, -1e-6 - 20 * unit(rng)).transpose();
    else
      p.row(r) =
          c.at(s.radius * unit(rng), angle, s.height * (1 + 1e-7) + 20 * unit(rng)).transpose();
  }
  p.row(0) << 1e6, -1e6, 3e5;  // far away, outside the candidate grid
  const FrozenPoints f = freeze(L, p);
  CHECK(f.report.outside == 300);
  CHECK(f.report.inside == 0);
  for (const FrozenPoint& q : f.points) CHECK(q.chunk == outside_chunk);
  CHECK(evaluate(L, f) == p);
  CHECK(deform_points(L, p) == p);
}

TEST_CASE("a prismatic lattice lofted from planar curves is the identity when undisplaced",
          "[deform]") {
  std::mt19937 rng(64);
  PrismSpec s;
  s.origin = Vec3(-30, 12, 200);
  s.x_axis = Vec3(1, 0.2, 0);
  s.y_axis = Vec3(0.1, 1, 0.3);
  s.extrusion = Vec3(2, -3, 15);
  s.layers = 2;
  // An S-like middle curve (two cubic segments) and two offsets (Coquillart's "S" lattice: a
  // loft on three curves, two of them offsets of the middle one).
  const std::vector<Eigen::Vector2d> middle = {{0, 0},   {10, 8},  {20, 8}, {30, 0},
                                               {40, -8}, {50, -8}, {60, 0}};
  for (double offset : {-6.0, 0.0, 6.0}) {
    std::vector<Eigen::Vector2d> c = middle;
    for (auto& q : c) q.y() += offset;
    s.sections.push_back(c);
  }
  const ExtendedLattice L = make_prismatic_lattice(s);
  CHECK(L.chunks.size() == 2u * 2u * 2u);
  CHECK(L.rest.rows() == 7 * 7 * 7);  // nothing coincides: no welding
  const Points3 p = rest_samples(L, rng, 1500);
  const FrozenPoints f = freeze(L, p);
  INFO(f.report.brief());
  CHECK(f.report.inside == p.rows());
  const Identity id = identity_errors(L, p, f);
  INFO("rest map " << id.rest_map << ", evaluate " << id.evaluated);
  CHECK(id.rest_map < 1e-14 * size_of(L.rest));
  CHECK(id.evaluated < 1e-14 * size_of(L.rest));
  CHECK(id.outside_cube <= 1e-9);

  // Closed sections (an annulus of four arcs each): the seam is welded.
  PrismSpec ring;
  ring.extrusion = Vec3(0, 0, 5);
  for (double radius : {10.0, 20.0}) {
    std::vector<Eigen::Vector2d> c;
    const double kappa = 4.0 / 3.0 * std::tan(std::numbers::pi / 8);
    for (int q = 0; q < 4; ++q) {
      const double a = q * std::numbers::pi / 2, b = a + std::numbers::pi / 2;
      c.push_back(radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
      c.push_back(radius * (Eigen::Vector2d(std::cos(a), std::sin(a)) +
                            kappa * Eigen::Vector2d(-std::sin(a), std::cos(a))));
      c.push_back(radius * (Eigen::Vector2d(std::cos(b), std::sin(b)) -
                            kappa * Eigen::Vector2d(-std::sin(b), std::cos(b))));
    }
    c.push_back(c.front());
    ring.sections.push_back(c);
  }
  const ExtendedLattice R = make_prismatic_lattice(ring);
  CHECK(R.rest.rows() == 4 * 12 * 4);  // 13 columns, the last welded to the first
  CHECK(R.chunks[3][(2 * 4 + 3) * 4 + 1] == R.chunks[0][(2 * 4 + 0) * 4 + 1]);
  const Points3 q = rest_samples(R, rng, 500);
  const FrozenPoints g = freeze(R, q);
  CHECK(g.report.inside == q.rows());
  CHECK(identity_errors(R, q, g).evaluated < 1e-14 * size_of(R.rest));
}

TEST_CASE("degenerate chunks do not crash and use the pseudo-inverse", "[deform]") {
  std::mt19937 rng(65);
  // det J = 0 exactly at the start (0.5, 0.5, 0.5): x(u) = 3u − 6u^2 + 4u^3 (control values 0, 1,
  // 0, 1) is monotone with x'(1/2) = 0. The chunk is injective, Newton's first step needs J+.
  const ExtendedLattice S = one_chunk([](double a, double b, double c) {
    const int i = static_cast<int>(std::lround(3 * a));
    return Vec3(10.0 * (i % 2), 7 * b + 2 * c, 5 * c);
  });
  const Points3 p = rest_samples(S, rng, 400);
  const FrozenPoints f = freeze(S, p);
  INFO(f.report.brief());
  CHECK(f.report.pseudo_inverse_steps > 0);
  CHECK(f.report.unresolved == 0);
  CHECK(f.report.inside == p.rows());
  const Identity id = identity_errors(S, p, f);
  CHECK(id.rest_map < 1e-9);
  CHECK(id.evaluated < 1e-9);

  // A flat chunk (zero thickness along w): points of its plane are found (w is then arbitrary),
  // points off it are outside.
  const ExtendedLattice F =
      one_chunk([](double a, double b, double) { return Vec3(10 * a + b * b, 8 * b, 0); });
  Points3 q(4, 3);
  q << 5, 4, 0, 2, 7, 0, 5, 4, 1e-3, 5, 4, -2;
  const FrozenPoints g = freeze(F, q);
  INFO(g.report.brief());
  CHECK(g.report.pseudo_inverse_steps > 0);
  CHECK(g.points[0].chunk == 0);
  CHECK(g.points[1].chunk == 0);
  CHECK(g.points[2].chunk == outside_chunk);
  CHECK(g.points[3].chunk == outside_chunk);
  CHECK((evaluate(F, g) - q).norm() < 1e-9);

  // A chunk collapsed to a segment (u and v collapsed): its points are still found.
  const ExtendedLattice N = one_chunk([](double, double, double c) { return Vec3(0, 0, 9 * c); });
  Points3 r(2, 3);
  r << 0, 0, 4.5, 0, 0, 9;
  const FrozenPoints h = freeze(N, r);
  CHECK(h.report.inside == 2);
  CHECK((evaluate(N, h) - r).norm() < 1e-9);
}

TEST_CASE("a strongly twisted chunk needs subdivision and the report counts it", "[deform]") {
  std::mt19937 rng(66);
  // Layers rotated by up to 6 rad about the w axis: Newton from the centre jumps out of
  // [-1, 2]^3 for some points; restarting from sub-chunk centres finds them.
  const ExtendedLattice T = one_chunk([](double a, double b, double c) {
    const double x = 10 * (2 * a - 1), y = 10 * (2 * b - 1), t = 6 * c;
    return Vec3(std::cos(t) * x - std::sin(t) * y, std::sin(t) * x + std::cos(t) * y, 2 * c);
  });
  const Points3 p = rest_samples(T, rng, 1000);
  const FrozenPoints f = freeze(T, p);
  INFO(f.report.brief());
  CHECK(f.report.summary.converged());
  CHECK(f.report.inside == p.rows());
  CHECK(f.report.subdivided > 0);
  CHECK(f.report.splits >= f.report.subdivided);
  const Identity id = identity_errors(T, p, f);
  CHECK(id.rest_map < 1e-9);
  CHECK(id.evaluated < 1e-9);
  // Without subdivision those points stay unresolved, unchanged, and the freeze says so.
  FreezeOptions o;
  o.max_subdivision_depth = 0;
  const FrozenPoints g = freeze(T, p, o);
  CHECK(g.report.unresolved == f.report.subdivided);
  CHECK(g.report.summary.termination == clay::Termination::NotConverged);
  CHECK_THAT(g.report.summary.message, Contains("max_subdivision_depth"));
  const Points3 moved = evaluate(displaced(T, rng, 1.0), g);
  for (Eigen::Index r = 0; r < p.rows(); ++r)
    if (g.points[static_cast<size_t>(r)].chunk == unresolved_chunk) CHECK(moved.row(r) == p.row(r));
}

TEST_CASE("welding coincident points joins two chunks into a composite lattice", "[deform]") {
  // Two unit boxes side by side, built separately: 128 rows, 16 of them duplicated.
  auto box = [](double x0) {
    return one_chunk(
        [x0](double a, double b, double c) { return Vec3(x0 + 10 * a, 10 * b, 10 * c); });
  };
  ExtendedLattice A = box(0), B = box(10);
  ExtendedLattice C;
  C.rest.resize(128, 3);
  C.rest << A.rest, B.rest;
  C.points = C.rest;
  C.chunks = {A.chunks[0], B.chunks[0]};
  for (int& e : C.chunks[1]) e += 64;
  const ExtendedLattice W = merge_coincident_points(C, 1e-9);
  CHECK(W.rest.rows() == 112);
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 4; ++k)
      CHECK(W.chunks[0][static_cast<size_t>((3 * 4 + j) * 4 + k)] ==
            W.chunks[1][static_cast<size_t>((0 * 4 + j) * 4 + k)]);
  for (size_t c = 0; c < 2; ++c)
    for (int e = 0; e < 64; ++e)
      CHECK(W.rest.row(W.chunks[c][static_cast<size_t>(e)]) ==
            C.rest.row(C.chunks[c][static_cast<size_t>(e)]));
  // Moving a welded point moves both chunks' shared face alike.
  ExtendedLattice M = W;
  M.points.row(W.chunks[0][(3 * 4 + 1) * 4 + 2]) += Eigen::RowVector3d(1, 2, 3);
  CHECK((chunk_point(M.points, M.chunks[0], Vec3(1, 0.4, 0.6)) -
         chunk_point(M.points, M.chunks[1], Vec3(0, 0.4, 0.6)))
            .norm() < 1e-14);
  CHECK(merge_coincident_points(C, 0).rest.rows() == 112);  // exact duplicates
}

TEST_CASE("extended lattice errors name the culprit and the fix", "[deform]") {
  const ExtendedLattice good = make_cylindrical_lattice(cylinder());
  const Points3 p = Points3::Zero(2, 3);
  {
    ExtendedLattice L = good;
    L.chunks[3][(1 * 4 + 2) * 4 + 3] = static_cast<int>(L.rest.rows());
    const auto [category, what] = error_of([&] { freeze(L, p); });
    CHECK(category == ErrorCategory::InvalidGeometry);
    CHECK_THAT(what, Contains("chunk 3 control point (1, 2, 3)") && Contains("outside [0, "));
    L.chunks[3][0] = -1;
    CHECK_THAT(error_of([&] { validate(L); }).second, Contains("index -1"));
  }
  {
    ExtendedLattice L = good;
    L.rest(7, 1) = std::numeric_limits<double>::quiet_NaN();
    CHECK_THAT(error_of([&] { evaluate(L, FrozenPoints{}); }).second,
               Contains("rest control point row 7"));
    L = good;
    L.points(9, 2) = std::numeric_limits<double>::infinity();
    CHECK_THAT(error_of([&] { deform_points(L, p); }).second,
               Contains("current control point row 9"));
    L = good;
    L.points.conservativeResize(L.points.rows() - 1, 3);
    CHECK_THAT(error_of([&] { validate(L); }).second, Contains("current ones"));
    L = good;
    L.chunks.clear();
    CHECK_THAT(error_of([&] { validate(L); }).second, Contains("no chunks"));
    const ExtendedLattice Z = one_chunk([](double, double, double) { return Vec3(1, 2, 3); });
    CHECK_THAT(error_of([&] { validate(Z); }).second, Contains("zero extent"));
  }
  {
    Points3 q = p;
    q(1, 0) = std::numeric_limits<double>::quiet_NaN();
    const auto [category, what] = error_of([&] { freeze(good, q); });
    CHECK(category == ErrorCategory::InvalidGeometry);
    CHECK_THAT(what, Contains("point row 1"));
  }
  {
    // Freeze, then edit the lattice (not only move it): evaluate refuses.
    const FrozenPoints f = freeze(good, p);
    ExtendedLattice L = good;
    L.chunks.pop_back();
    const auto [category, what] = error_of([&] { evaluate(L, f); });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Contains("freeze again"));
  }
  {
    auto option = [&](auto set) {
      FreezeOptions o;
      set(o);
      return error_of([&] { freeze(good, p, o); });
    };
    CHECK_THAT(option([](FreezeOptions& o) { o.newton_tolerance = 0; }).second,
               Contains("FreezeOptions::newton_tolerance = 0"));
    CHECK_THAT(option([](FreezeOptions& o) { o.parameter_tolerance = -1; }).second,
               Contains("parameter_tolerance = -1"));
    CHECK_THAT(option([](FreezeOptions& o) { o.pseudo_inverse_threshold = 0.5; }).second,
               Contains("pseudo_inverse_threshold = 0.5"));
    CHECK_THAT(option([](FreezeOptions& o) { o.max_iterations = 0; }).second,
               Contains("max_iterations = 0"));
    CHECK_THAT(option([](FreezeOptions& o) { o.max_subdivision_depth = 11; }).second,
               Contains("max_subdivision_depth = 11"));
    const auto [category, what] = option([](FreezeOptions& o) { o.threads = -2; });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Contains("FreezeOptions::threads = -2"));
    CHECK_THAT(error_of([&] { evaluate(good, freeze(good, p), DeformOptions{-1}); }).second,
               Contains("DeformOptions::threads = -1"));
  }
  {
    auto spec = [](auto set) {
      CylinderSpec s = cylinder();
      set(s);
      return error_of([&] { make_cylindrical_lattice(s); });
    };
    const auto [category, what] = spec([](CylinderSpec& s) { s.sectors = 2; });
    CHECK(category == ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Contains("CylinderSpec::sectors = 2") && Contains("3 <= sectors"));
    CHECK_THAT(spec([](CylinderSpec& s) { s.radius = 0; }).second,
               Contains("CylinderSpec::radius = 0"));
    CHECK_THAT(spec([](CylinderSpec& s) { s.inner_radius = 30; }).second,
               Contains("inner_radius < radius"));
    CHECK_THAT(spec([](CylinderSpec& s) { s.height = -1; }).second,
               Contains("CylinderSpec::height = -1"));
    CHECK_THAT(spec([](CylinderSpec& s) { s.axis = Vec3::Zero(); }).second,
               Contains("CylinderSpec::axis"));
    CHECK_THAT(spec([](CylinderSpec& s) { s.reference = s.axis; }).second,
               Contains("not parallel to the axis"));
    CHECK_THAT(spec([](CylinderSpec& s) { s.rings = 0; }).second,
               Contains("CylinderSpec::rings = 0"));
    CHECK_THAT(spec([](CylinderSpec& s) { s.layers = 2000; }).second, Contains("layers <= 1024"));
    CHECK_THAT(spec([](CylinderSpec& s) { s.sectors = s.rings = s.layers = 1000; }).second,
               Contains("1000000 chunks"));
    CHECK_THAT(spec([](CylinderSpec& s) { s.origin.x() = std::nan(""); }).second,
               Contains("CylinderSpec::origin"));
    const auto [c2, w2] = error_of([] { cylindrical_index(cylinder(), 7, 0, 0); });
    CHECK(c2 == ErrorCategory::OutOfDomain);
    CHECK_THAT(w2, Contains("radial <= 6"));
  }
  {
    PrismSpec s;
    s.sections = {{{0, 0}, {1, 0}, {2, 0}, {3, 0}}, {{0, 1}, {1, 1}, {2, 1}, {3, 1}}};
    CHECK(make_prismatic_lattice(s).chunks.size() == 1);
    auto spec = [&](auto set) {
      PrismSpec t = s;
      set(t);
      return error_of([&] { make_prismatic_lattice(t); });
    };
    CHECK_THAT(spec([](PrismSpec& t) { t.sections.pop_back(); }).second,
               Contains("sections.size() = 1"));
    CHECK_THAT(spec([](PrismSpec& t) { t.sections[1].pop_back(); }).second,
               Contains("sections[1].size() = 3"));
    CHECK_THAT(spec([](PrismSpec& t) {
                 t.sections[1].push_back({4, 1});
                 t.sections[1].push_back({5, 1});
                 t.sections[1].push_back({6, 1});
               }).second,
               Contains("every section alike"));
    CHECK_THAT(spec([](PrismSpec& t) { t.sections[0][2].y() = std::nan(""); }).second,
               Contains("sections[0][2]"));
    CHECK_THAT(spec([](PrismSpec& t) { t.extrusion = Vec3(1, 1, 0); }).second,
               Contains("off the plane"));
    CHECK_THAT(spec([](PrismSpec& t) { t.y_axis = 2 * t.x_axis; }).second,
               Contains("not parallel to x_axis"));
    CHECK_THAT(spec([](PrismSpec& t) { t.x_axis = Vec3::Zero(); }).second,
               Contains("PrismSpec::x_axis"));
    CHECK_THAT(spec([](PrismSpec& t) { t.layers = 0; }).second, Contains("PrismSpec::layers = 0"));
  }
  CHECK_THAT(error_of([&] { merge_coincident_points(good, -1); }).second,
             Contains("tolerance = -1"));
}

TEST_CASE("the docs snippet pushes the axis of a cylindrical lattice up", "[deform]") {
  CylinderSpec spec;
  spec.radius = 30;
  spec.height = 20;
  spec.sectors = 12;
  spec.rings = 2;
  spec.layers = 1;
  ExtendedLattice lattice = make_cylindrical_lattice(spec);
  Points3 points(3, 3);
  points << 0, 0, 10, 29.9, 0, 0, 40, 0, 10;  // on the axis, at the rim's foot, outside
  const FrozenPoints frozen = freeze(lattice, points);
  for (int k = 0; k <= 3; ++k)
    lattice.points.row(cylindrical_index(spec, 0, 0, k)) += Eigen::RowVector3d(0, 0, 8);
  const Points3 out = evaluate(lattice, frozen);
  // The axis moves by 8 (all its control points did: partition of unity in w); the rim's outer
  // ring of control points did not move and the point outside stays.
  CHECK((out.row(0) - Eigen::RowVector3d(0, 0, 18)).norm() < 1e-12);
  CHECK(out.row(2) == points.row(2));
  // Radius 29.9 lies in ring 1, whose chunks do not use the axis rows: unchanged to rounding.
  CHECK((out.row(1) - points.row(1)).norm() < 1e-12);
  CHECK_THAT(frozen.report.brief(), Contains("2 inside, 1 outside, 0 unresolved"));
}
