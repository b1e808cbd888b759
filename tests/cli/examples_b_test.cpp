// Example recipes of set B (issue #8; docs/recipe.md § Examples): each recipe in
// examples/recipes/ is loaded and run, and its deformed surfaces are checked against an independent
// computation — the deformation rebuilt here from the same numbers with the deform library (or by
// the closed forms of Barr's taper, twist and bend), applied pointwise to the run's own parent
// surface at random parameters — within the tolerance the refit reports. Lattices are checked
// fold-free by their Jacobian (Sederberg–Parry §4), extended lattices leave outside points alone.
#include <catch2/catch.hpp>

#include <clay/deform.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

using namespace clay::recipe;
using Catch::Matchers::WithinAbs;

namespace {

using namespace clay::deform;
namespace surface = clay::surface;
using V3 = Eigen::Vector3d;
using R3 = Eigen::RowVector3d;

inline constexpr double pi = 3.14159265358979323846;

// The rebuilt deformations: the same numbers as examples/recipes/tools/make_recipes.py, built here
// with the deform library's own constructors (not read from the recipes).

// ---- handset (Sederberg–Parry figs. 14-16) ----
// Local C1 Bézier lattice (3, 2, 2) over one end of the bar, x in [40, 110] or [-110, -40].
// end = +1: mouthpiece (x > 0, the bar crosses the s_min face, planes i = 0, 1 stay), end = -1:
// earpiece (the s_max face, planes i = 2, 3 stay).
inline BezierLattice end_lattice(int end, double drop, double widen) {
  Frame f;
  f.origin = end > 0 ? V3(40, -32, -20) : V3(-110, -32, -20);
  f.s = {70, 0, 0};
  f.t = {0, 64, 0};
  f.u = {0, 0, 40};
  BezierLattice l = make_bezier_lattice(f, {3, 2, 2});
  // The two free planes: far from the crossed face.
  const int far_i = end > 0 ? 3 : 0, mid_i = end > 0 ? 2 : 1;
  const double sy[3] = {-1, 0, 1};
  const double dz_far[3] = {-drop, -0.5 * drop, 0.0};  // k = 0 (bottom), 1, 2 (top)
  for (int j = 0; j <= 2; ++j)
    for (int k = 0; k <= 2; ++k) {
      l.points.row(l.index(far_i, j, k)) += R3(-end * 0.1 * drop, sy[j] * 32 * widen, dz_far[k]);
      l.points.row(l.index(mid_i, j, k)) += R3(0, sy[j] * 32 * 0.5 * widen, 0.5 * dz_far[k]);
    }
  return l;
}

inline BSplineLattice arch() {
  Frame f;
  f.origin = {-125, -45, -50};
  f.s = {250, 0, 0};
  f.t = {0, 90, 0};
  f.u = {0, 0, 80};
  BSplineLattice l = make_bspline_lattice(f, {3, 1, 1}, {2, 1, 1});
  const double lift[5] = {0, 10, 16, 10, 0};
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k) l.points.row(l.index(i, j, k)) += R3(0, 0, lift[i]);
  return l;
}

inline DeformationStack handset_stack() {
  DeformationStack s;
  s.steps.push_back({end_lattice(+1, 30, 0.2), "mouthpiece", true});
  s.steps.push_back({end_lattice(-1, 26, 0.3), "earpiece", true});
  s.steps.push_back({arch(), "arch", true});
  return s;
}

// ---- sandpie (Coquillart fig. 6) ----
inline CylinderSpec pie_spec() {
  CylinderSpec c;
  c.origin = {0, 0, -5};
  c.radius = 40;
  c.height = 10;
  c.sectors = 12;
  c.rings = 2;
  c.layers = 1;
  return c;
}
inline ExtendedLattice sandpie_lattice() {
  const CylinderSpec c = pie_spec();
  ExtendedLattice l = make_cylindrical_lattice(c);
  // The axis and the intermediate cylinders (radial 0..4) lifted: a mound with sloping sides.
  const double h = 14;
  for (int k = 0; k <= 3; ++k) {
    l.points.row(cylindrical_index(c, 0, 0, k)) += R3(0, 0, h);
    for (int r = 1; r <= 4; ++r)
      for (int a = 0; a < 36; ++a) l.points.row(cylindrical_index(c, r, a, k)) += R3(0, 0, h);
  }
  // Flutes: every second sector boundary of the radial-4 cylinder pulled towards the axis.
  for (int a = 0; a < 36; a += 6) {
    const double t = 2 * pi * a / 36.0;
    for (int k = 0; k <= 3; ++k)
      l.points.row(cylindrical_index(c, 4, a, k)) += R3(-5 * std::cos(t), -5 * std::sin(t), 0);
  }
  return l;
}

// ---- cushion (Coquillart fig. 10) ----
inline CylinderSpec cushion_spec() {
  CylinderSpec c;
  c.origin = {0, 0, -20};
  c.radius = 64;
  c.height = 40;
  c.sectors = 12;
  c.rings = 2;
  c.layers = 1;
  return c;
}
inline ExtendedLattice cushion_lattice() {
  const CylinderSpec c = cushion_spec();
  ExtendedLattice l = make_cylindrical_lattice(c);
  // The axis points pulled in: a button hollow on both faces.
  l.points.row(cylindrical_index(c, 0, 0, 3)) += R3(0, 0, -12);
  l.points.row(cylindrical_index(c, 0, 0, 2)) += R3(0, 0, -4);
  l.points.row(cylindrical_index(c, 0, 0, 0)) += R3(0, 0, 12);
  l.points.row(cylindrical_index(c, 0, 0, 1)) += R3(0, 0, 4);
  // Folds: the intermediate cylinder (radial 3) at every second sector boundary pinched.
  for (int a = 0; a < 36; a += 6) {
    l.points.row(cylindrical_index(c, 3, a, 3)) += R3(0, 0, -7);
    l.points.row(cylindrical_index(c, 3, a, 0)) += R3(0, 0, 7);
  }
  return l;
}

// ---- S (Coquillart fig. 8) ----
// Arc of radius r about c from angle a0 to a1 (degrees) as `n` cubic Bézier segments, appended
// (without the first point when `skip_first`).
inline void arc(std::vector<Eigen::Vector2d>& out, Eigen::Vector2d c, double r, double a0,
                double a1, int n, bool skip_first) {
  const double d = (a1 - a0) / n * pi / 180, h = 4.0 / 3.0 * std::tan(std::abs(d) / 4) * r;
  for (int s = 0; s < n; ++s) {
    const double t0 = a0 * pi / 180 + s * d, t1 = t0 + d;
    const Eigen::Vector2d p0 = c + r * Eigen::Vector2d(std::cos(t0), std::sin(t0));
    const Eigen::Vector2d p3 = c + r * Eigen::Vector2d(std::cos(t1), std::sin(t1));
    const double sg = d > 0 ? 1 : -1;
    const Eigen::Vector2d p1 = p0 + sg * h * Eigen::Vector2d(-std::sin(t0), std::cos(t0));
    const Eigen::Vector2d p2 = p3 - sg * h * Eigen::Vector2d(-std::sin(t1), std::cos(t1));
    if (s == 0 && !skip_first) out.push_back(p0);
    out.push_back(p1);
    out.push_back(p2);
    out.push_back(p3);
  }
}
inline constexpr double s_radius = 15, s_half_width = 5;
// offset > 0: to the left of the stroke.
inline std::vector<Eigen::Vector2d> s_section(double offset) {
  std::vector<Eigen::Vector2d> pts;
  arc(pts, {0, s_radius}, s_radius - offset, 30, 270, 4, false);   // upper bowl, counter-clockwise
  arc(pts, {0, -s_radius}, s_radius + offset, 90, -150, 4, true);  // lower bowl, clockwise
  return pts;
}
inline PrismSpec s_spec() {
  PrismSpec p;
  p.origin = {0, 0, -6};
  p.extrusion = {0, 0, 12};
  p.sections = {s_section(s_half_width), s_section(0), s_section(-s_half_width)};
  p.layers = 1;
  return p;
}
inline int s_row(int i, int j, int k) { return (i * 25 + j) * 4 + k; }
inline ExtendedLattice s_lattice() {
  ExtendedLattice l = make_prismatic_lattice(s_spec());
  for (int i = 2; i <= 4; ++i)
    for (int j = 2; j <= 22; ++j)
      for (int k = 1; k <= 3; ++k) l.points.row(s_row(i, j, k)) += R3(0, 0, -4);
  return l;
}

RunResult run_example(const std::string& name) {
  return run_recipe(
      load_recipe(std::filesystem::path(CLAY_EXAMPLES_DIR) / "recipes" / (name + ".json")));
}

const StepReport& step_at(const RunResult& r, const std::string& path) {
  for (const auto& s : r.steps)
    if (s.path == path) return s;
  FAIL("no step " << path);
  throw;  // unreachable
}

template <class T>
T figure(const StepReport& s, const std::string& name) {
  for (const auto& [key, value] : s.figures)
    if (key == name) {
      REQUIRE(std::holds_alternative<T>(value));
      return std::get<T>(value);
    }
  FAIL("step " << s.path << " has no figure " << name);
  throw;  // unreachable
}

/// Largest |result(u, v) - want(parent(u, v))| at n random parameters of the parent's domain
/// where `keep(x)` holds (x the parent's point), and how many were kept.
struct Check {
  double worst = 0;
  int count = 0;
};
Check compare(const surface::BSplineSurface& parent, const surface::BSplineSurface& result,
              const std::function<V3(const V3&)>& want, int n,
              const std::function<bool(const V3&)>& keep = {}) {
  std::mt19937 rng(8);
  const auto [u0, u1] = parent.u.domain();
  const auto [v0, v1] = parent.v.domain();
  std::uniform_real_distribution<double> U(u0, u1), V(v0, v1);
  Check c;
  for (int k = 0; k < n; ++k) {
    const double u = U(rng), v = V(rng);
    const V3 x = surface::evaluate(parent, u, v);
    if (keep && !keep(x)) continue;
    c.worst = std::max(c.worst, (surface::evaluate(result, u, v) - want(x)).norm());
    ++c.count;
  }
  return c;
}

}  // namespace

TEST_CASE("example handset: local C1 lattices then a global bend, against the pointwise stack",
          "[recipe][examples]") {
  const RunResult r = run_example("handset");
  const DeformationStack stack = handset_stack();
  // The local lattices move interior planes only: C1 with the bar across the face it crosses.
  const FaceContinuity mouth_face[] = {{Face::SMin, 1}};
  const FaceContinuity ear_face[] = {{Face::SMax, 1}};
  const auto& mouth = std::get<BezierLattice>(stack.steps[0].deformation);
  const auto& ear = std::get<BezierLattice>(stack.steps[1].deformation);
  CHECK(with_continuity(mouth, mouth_face).points == mouth.points);
  CHECK(with_continuity(ear, ear_face).points == ear.points);
  double bounds = 0, sampled = 0;
  for (int i = 0; i < 3; ++i) {
    const StepReport& s = step_at(r, "surfaces.handset.steps[" + std::to_string(i) + "]");
    CHECK(figure<std::string>(s, "composition") == "refit");
    CHECK(figure<bool>(s, "certified"));
    CHECK(figure<double>(s, "max_deviation_mm") <= figure<double>(s, "tolerance_mm"));
    bounds += figure<double>(s, "max_deviation_mm");
    sampled += figure<double>(s, "sampled_max_mm");
    // Fold-free, independently: the Jacobian of the lattice rebuilt here.
    const JacobianBounds j = std::visit(
        [](const auto& d) -> JacobianBounds {
          if constexpr (std::is_same_v<std::decay_t<decltype(d)>, BezierLattice> ||
                        std::is_same_v<std::decay_t<decltype(d)>, BSplineLattice>)
            return jacobian_bounds(d);
          else
            return {};
        },
        stack.steps[static_cast<size_t>(i)].deformation);
    CHECK(j.fold_free);
    CHECK(figure<bool>(s, "fold_free"));
    CHECK_THAT(figure<double>(s, "volume_ratio_min"), WithinAbs(j.min, 1e-12));
    CHECK_THAT(figure<double>(s, "volume_ratio_max"), WithinAbs(j.max, 1e-12));
  }
  const surface::BSplineSurface& bar = r.surface("bar");
  const surface::BSplineSurface& handset = r.surface("handset");
  CHECK(handset.u.degree == 3);
  CHECK(handset.v.degree == 3);
  // Each refit's bound is its own; the later lattices stretch it by at most their Lipschitz
  // constant (about 1.5 here), so the whole stack is within 1.5 x the sum of the bounds.
  const Check all = compare(
      bar, handset, [&](const V3& x) { return deform_point(stack, x); }, 400);
  CHECK(all.worst <= 1.5 * bounds);
  // The certified bounds are loose near the local lattices' faces (first-order cells); the refit
  // also samples every cell on a grid four times denser than its fit, and random parameters find
  // no larger deviation than those samples (same stretch allowance): a check at the 0.05 mm level.
  CHECK(all.worst <= 1.5 * sampled);
  // Between the local lattices only the global bend acts.
  const Check middle = compare(
      bar, handset, [&](const V3& x) { return deform_point(arch(), x); }, 400,
      [](const V3& x) { return std::abs(x.x()) < 39; });
  CHECK(middle.count > 50);
  CHECK(middle.worst <= 1.5 * bounds);
}

TEST_CASE("example sandpie: cylindrical extended lattice, mound and outside sheet",
          "[recipe][examples]") {
  const RunResult r = run_example("sandpie");
  const StepReport& s = step_at(r, "surfaces.sandpie.steps[0]");
  CHECK(figure<std::string>(s, "composition") == "refit");
  CHECK_FALSE(figure<bool>(s, "certified"));  // extended lattices are sampled, not certified
  const double tolerance = figure<double>(s, "tolerance_mm");
  const ExtendedLattice lattice = sandpie_lattice();
  const surface::BSplineSurface& sheet = r.surface("sheet");
  const surface::BSplineSurface& pie = r.surface("sandpie");
  const Check all = compare(
      sheet, pie, [&](const V3& x) { return deform_point(lattice, x); }, 300);
  CHECK(all.worst <= tolerance);
  // Outside the cylinder (radius 40 mm) the sheet stays where it was.
  const Check outside = compare(
      sheet, pie, [](const V3& x) { return x; }, 300,
      [](const V3& x) { return x.head<2>().norm() > 40.5; });
  CHECK(outside.count > 100);
  CHECK(outside.worst <= tolerance);
  // Closed form: in the inner ring every control point moved by (0, 0, 14), so the top is flat.
  const Check top = compare(
      sheet, pie, [](const V3& x) { return V3(x + V3(0, 0, 14)); }, 300,
      [](const V3& x) { return x.head<2>().norm() < 19.5; });
  CHECK(top.count > 10);
  CHECK(top.worst <= tolerance);
}

TEST_CASE("example cushion: hollow on the axis and folds, against the pointwise lattice",
          "[recipe][examples]") {
  const RunResult r = run_example("cushion");
  const StepReport& s = step_at(r, "surfaces.cushion.steps[0]");
  CHECK(figure<std::string>(s, "composition") == "refit");
  CHECK_FALSE(figure<bool>(s, "certified"));
  const double tolerance = figure<double>(s, "tolerance_mm");
  const ExtendedLattice lattice = cushion_lattice();
  const surface::BSplineSurface& parent = r.surface("cushion_parent");
  const surface::BSplineSurface& cushion = r.surface("cushion");
  const Check all = compare(
      parent, cushion, [&](const V3& x) { return deform_point(lattice, x); }, 300);
  CHECK(all.worst <= tolerance);
  // Closed form on the axis (u = 0 of the inner ring: only the axis points act): the top pole at
  // height 14 mm, w = 34/40, moves by sum_k B_k(w) dz_k with dz = (12, 4, -4, -12).
  const double w = 34.0 / 40.0, b[4] = {std::pow(1 - w, 3), 3 * w * std::pow(1 - w, 2),
                                        3 * w * w * (1 - w), w * w * w};
  const double top = 14 + 12 * b[0] + 4 * b[1] - 4 * b[2] - 12 * b[3];
  int poles = 0;
  for (double u : {parent.u.domain().first, parent.u.domain().second})
    for (double v : {parent.v.domain().first, parent.v.domain().second}) {
      const V3 x = surface::evaluate(parent, u, v);
      if (x.head<2>().norm() < 1e-9 && x.z() > 0) {
        ++poles;
        const V3 y = surface::evaluate(cushion, u, v);
        CHECK_THAT(y.x(), WithinAbs(0, tolerance));
        CHECK_THAT(y.y(), WithinAbs(0, tolerance));
        CHECK_THAT(y.z(), WithinAbs(top, tolerance));
      }
    }
  CHECK(poles > 0);
}

TEST_CASE("example s_letter: prismatic lattice lofted on an S, groove depth and outside sheet",
          "[recipe][examples]") {
  const RunResult r = run_example("s_letter");
  const StepReport& s = step_at(r, "surfaces.engraved.steps[0]");
  CHECK(figure<std::string>(s, "composition") == "refit");
  CHECK_FALSE(figure<bool>(s, "certified"));
  const double tolerance = figure<double>(s, "tolerance_mm");
  const ExtendedLattice lattice = s_lattice();
  REQUIRE(lattice.rest.rows() == 7 * 25 * 4);  // no welded points: rows as the recipe's moves say
  const surface::BSplineSurface& sheet = r.surface("sheet");
  const surface::BSplineSurface& engraved = r.surface("engraved");
  const Check all = compare(
      sheet, engraved, [&](const V3& x) { return deform_point(lattice, x); }, 300);
  CHECK(all.worst <= tolerance);
  // Points the lattice leaves alone (outside the band, or where nothing moved) stay.
  const Check still = compare(
      sheet, engraved, [](const V3& x) { return x; }, 300,
      [&](const V3& x) { return deform_point(lattice, x) == x; });
  CHECK(still.count > 100);
  CHECK(still.worst <= tolerance);
  // Closed form: the S's centre (0, 0, 0) is on the middle section at mid-height, w = 1/2; the
  // rows i = 2..4 and layers k = 1..3 moved by -4 mm: depth 4 (1 - (1 - w)^3) = 3.5 mm.
  const V3 centre = surface::evaluate(engraved, 0.5, 0.5);
  CHECK_THAT(centre.z(), WithinAbs(-3.5, tolerance));
}

TEST_CASE("example superellipsoid_taper_twist: exact taper, certified twist, closed forms",
          "[recipe][examples]") {
  const RunResult r = run_example("superellipsoid_taper_twist");
  const StepReport& taper = step_at(r, "surfaces.twisted.steps[0]");
  const StepReport& twist = step_at(r, "surfaces.twisted.steps[1]");
  CHECK(figure<std::string>(taper, "composition") == "exact");
  CHECK(figure<double>(taper, "max_relative_deviation") <= 1e-12);
  CHECK(figure<std::string>(twist, "composition") == "refit");
  CHECK(figure<bool>(twist, "certified"));
  const double bound = figure<double>(twist, "max_deviation_mm");
  CHECK(bound <= figure<double>(twist, "tolerance_mm"));
  // Güdükbay–Özgüç §3.1.1-2 written out: r = 1 - 0.006 z, theta = 0.0131 z about z.
  const auto closed_form = [](const V3& x) {
    const double rr = 1 - 0.006 * x.z(), th = 0.0131 * x.z();
    const double X = rr * x.x(), Y = rr * x.y();
    return V3(X * std::cos(th) - Y * std::sin(th), X * std::sin(th) + Y * std::cos(th), x.z());
  };
  const Check all = compare(r.surface("post"), r.surface("twisted"), closed_form, 400);
  CHECK(all.worst <= bound + 1e-9 * 150);
}

TEST_CASE("example superellipsoid_bend: exact taper, certified bend with a region, closed forms",
          "[recipe][examples]") {
  const RunResult r = run_example("superellipsoid_bend");
  const StepReport& taper = step_at(r, "surfaces.bent.steps[0]");
  const StepReport& bend = step_at(r, "surfaces.bent.steps[1]");
  CHECK(figure<std::string>(taper, "composition") == "exact");
  CHECK(figure<double>(taper, "max_relative_deviation") <= 1e-12);
  CHECK(figure<std::string>(bend, "composition") == "refit");
  CHECK(figure<bool>(bend, "certified"));
  const double bound = figure<double>(bend, "max_deviation_mm");
  CHECK(bound <= figure<double>(bend, "tolerance_mm"));
  // Taper along y, r = 1 - 0.004 y, then Barr's bend (Güdükbay–Özgüç §3.1.3) written out:
  // region y in [-40, 40], y0 = 0, k = (pi / 2) / 80.
  const double k = (pi / 2) / 80, y_min = -40, y_max = 40;
  const auto closed_form = [&](const V3& p) {
    const double rr = 1 - 0.004 * p.y();
    const double x = rr * p.x(), y = p.y(), z = rr * p.z();
    const double yh = std::clamp(y, y_min, y_max), th = k * yh;
    return V3(x, -std::sin(th) * (z - 1 / k) + std::cos(th) * (y - yh),
              std::cos(th) * (z - 1 / k) + 1 / k + std::sin(th) * (y - yh));
  };
  const Check all = compare(r.surface("beam"), r.surface("bent"), closed_form, 400);
  CHECK(all.worst <= bound + 1e-9 * 150);
  // The end beyond y_max moves rigidly with the region's end, turned by 90 degrees.
  const Check tip = compare(r.surface("beam"), r.surface("bent"), closed_form, 400,
                            [](const V3& p) { return p.y() > 45; });
  CHECK(tip.count > 10);
  CHECK(tip.worst <= bound + 1e-9 * 150);
}
