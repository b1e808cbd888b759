// The paper-figure example recipes (examples/recipes: sail, car_hood, bump, bottle, tongue; issue
// #8), each run with run_recipe and checked against an independent computation: the lattice
// rebuilt here from the recipe's own numbers (read with nlohmann-json, not the runner's parser)
// and applied pointwise with deform_point to the parent surface's points, closed forms (the
// bottle's radial pinch), the direct-manipulation targets, the style key points, and the
// continuity across shared edges.
#include <catch2/catch.hpp>

#include <clay/deform/direct_manipulation.hpp>
#include <clay/deform/lattice.hpp>
#include <clay/deform/style.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/projection.hpp>
#include <clay/surface/skin.hpp>

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <tuple>

using namespace clay::recipe;
namespace surface = clay::surface;
namespace deform = clay::deform;
namespace fs = std::filesystem;
using Catch::Matchers::WithinAbs;
using Json = nlohmann::json;

namespace {

fs::path recipe_file(const std::string& name) {
  return fs::path(CLAY_EXAMPLES_DIR) / "recipes" / (name + ".json");
}

Json recipe_json(const std::string& name) {
  std::ifstream in(recipe_file(name));
  return Json::parse(in);
}

RunResult run_example(const std::string& name) {
  return run_recipe(load_recipe(recipe_file(name)));
}

const StepReport& step(const RunResult& r, const std::string& path) {
  for (const auto& s : r.steps)
    if (s.path == path) return s;
  FAIL("no step " << path);
  return r.steps.front();
}

bool has_step(const RunResult& r, const std::string& path) {
  return std::any_of(r.steps.begin(), r.steps.end(),
                     [&](const StepReport& s) { return s.path == path; });
}

template <class T>
T figure(const StepReport& s, const std::string& key) {
  for (const auto& [k, v] : s.figures)
    if (k == key) {
      REQUIRE(std::holds_alternative<T>(v));
      return std::get<T>(v);
    }
  FAIL("step " << s.path << " has no figure " << key);
  return T{};
}

Eigen::Vector3d vec(const Json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

deform::Frame frame_of(const Json& f) {
  deform::Frame frame;
  frame.origin = vec(f.at("origin"));
  frame.s = vec(f.at("s"));
  frame.t = vec(f.at("t"));
  frame.u = vec(f.at("u"));
  return frame;
}

std::array<int, 3> ints3(const Json& j) {
  return {j.at(0).get<int>(), j.at(1).get<int>(), j.at(2).get<int>()};
}

/// docs/recipe.md "moves": start from the undisplaced lattice, then set ("to") or shift ("by").
template <class Lattice>
void apply_moves(Lattice& lattice, const Json& moves) {
  for (const auto& m : moves) {
    const auto [i, j, k] = ints3(m.at("index"));
    const Eigen::Index row = lattice.index(i, j, k);
    if (m.contains("to"))
      lattice.points.row(row) = vec(m.at("to")).transpose();
    else
      lattice.points.row(row) += vec(m.at("by")).transpose();
  }
}

deform::BezierLattice bezier_lattice_of(const Json& step) {
  deform::BezierLattice l =
      deform::make_bezier_lattice(frame_of(step.at("frame")), ints3(step.at("degrees")));
  apply_moves(l, step.at("moves"));
  return l;
}

deform::BSplineLattice bspline_lattice_of(const Json& step) {
  REQUIRE(step.at("knots") == "clamped");
  deform::BSplineLattice l = deform::make_bspline_lattice(
      frame_of(step.at("frame")), ints3(step.at("degrees")), ints3(step.at("cells")));
  if (step.contains("moves")) apply_moves(l, step.at("moves"));
  return l;
}

double diagonal(const surface::BSplineSurface& s) {
  const auto [lo, hi] = surface::control_box(s);
  return (hi - lo).norm();
}

/// Largest |result(u, v) - map(parent(u, v))| over `n` random parameters.
template <class Map>
double max_pointwise_gap(const surface::BSplineSurface& parent,
                         const surface::BSplineSurface& result, Map&& map, int n = 400,
                         unsigned seed = 8) {
  std::mt19937 rng(seed);
  const auto [u0, u1] = parent.u.domain();
  const auto [v0, v1] = parent.v.domain();
  std::uniform_real_distribution<double> du(u0, u1), dv(v0, v1);
  double gap = 0;
  for (int i = 0; i < n; ++i) {
    const double u = du(rng), v = dv(rng);
    gap = std::max(gap,
                   (surface::evaluate(result, u, v) - map(surface::evaluate(parent, u, v))).norm());
  }
  return gap;
}

void check_exact_composition(const StepReport& s) {
  INFO(s.path << ": " << s.message);
  CHECK(figure<std::string>(s, "composition") == "exact");
  CHECK(figure<bool>(s, "exact"));
  CHECK(figure<double>(s, "max_relative_deviation") <= 1e-12);
  CHECK(figure<bool>(s, "fold_free"));
}

}  // namespace

TEST_CASE(
    "example sail: fill of three curves, exact style step, Bezier billow as its certified light "
    "form, the exact composition on request",
    "[examples]") {
  const RunResult r = run_example("sail");
  Json j = recipe_json("sail");
  const auto& flat = r.surface("flat_sail");
  const auto& sail = r.surface("sail");
  const double size = diagonal(sail);

  // The style step, recomputed with the deform library from the recipe's numbers.
  const Json& draft = j.at("deformations").at("shape").at(0);
  deform::StyleOptions options;
  options.mode = deform::StyleMode::Exact;
  options.key_points_per_row = draft.at("key_points_per_row").get<int>();
  options.curve_tolerance = draft.at("curve_tolerance").get<double>();
  const deform::StyleResult styled =
      deform::style_deform(flat, r.curve("draft_bound"), r.curve("draft_line"), options);
  // The billow lattice rebuilt from the recipe: sail(u, v) = billow(styled(u, v)).
  const deform::BezierLattice billow = bezier_lattice_of(j.at("deformations").at("shape").at(1));
  const double gap = max_pointwise_gap(styled.surface, sail, [&](const Eigen::Vector3d& x) {
    return deform::deform_point(billow, x);
  });
  // Its exact composition is above the default budget (degree 15, 10,000 control points): the
  // step yields a certified bicubic of the same map, and the exact net is never built.
  const StepReport& lattice_step = step(r, "surfaces.sail.steps[1]");
  INFO(lattice_step.message);
  CHECK(figure<std::string>(lattice_step, "composition") == "light");
  CHECK(figure<bool>(lattice_step, "certified"));
  CHECK(figure<long long>(lattice_step, "degree_u") == 3);
  CHECK(figure<long long>(lattice_step, "control_points") < 10000);
  // The billow moves P_i0k and P_i1k alike, along y only: y = 1000 t + D(s, u) with D of degree
  // (2, 1), x and z linear. The lattice's highest monomial is s^2 u, total degree 3 (the
  // tensor-product rule's 2 + 1 + 1 = 4 counts an s^2 t u that is not there), so the cubic sail
  // composes to 3 x 3 = 9, not 12.
  CHECK(figure<long long>(lattice_step, "exact_degree_u") == 9);
  CHECK(figure<long long>(lattice_step, "exact_degree_v") == 9);
  CHECK(figure<long long>(lattice_step, "exact_control_points") > 10000);
  const double certified = figure<double>(lattice_step, "max_deviation_mm");
  INFO("pointwise gap " << gap << " mm on a " << size << " mm sail, certified " << certified);
  CHECK(gap <= certified + 1e-12 * size);
  CHECK(certified <= figure<double>(lattice_step, "tolerance_mm"));
  // The input was exact, so the ledger holds this step's bound alone.
  CHECK(figure<double>(lattice_step, "accumulated_bound_mm") == certified);
  CHECK(!has_step(r, "surfaces.sail.composition.budget"));  // already light
  CHECK_THAT(figure<double>(lattice_step, "volume_ratio_min"),
             WithinAbs(1.0, 1e-12));  // a pure shear

  // The exact composition on request ("budget": "none"): exact to rounding, its size the one
  // the light step predicted, and the light form within its certified bound of it.
  j["composition"]["budget"] = "none";
  const RunResult exact = run_recipe(parse_recipe(j.dump()));
  const StepReport& exact_step = step(exact, "surfaces.sail.steps[1]");
  check_exact_composition(exact_step);
  CHECK(figure<long long>(exact_step, "degree_u") == 9);
  // The prediction counts the knots the styled net's multiplicities say; knot removal also takes
  // out those where the net is smoother than that (where the style step refined but moved
  // nothing), so it is an upper bound.
  CHECK(figure<long long>(exact_step, "control_points") <=
        figure<long long>(lattice_step, "exact_control_points"));
  CHECK(figure<long long>(exact_step, "control_points") > 10000);
  const auto& reference = exact.surface("sail");
  double light_gap = 0;
  for (double u : surface::linspace(0, 1, 61))
    for (double v : surface::linspace(0, 1, 61))
      light_gap = std::max(
          light_gap, (surface::evaluate(sail, u, v) - surface::evaluate(reference, u, v)).norm());
  INFO("light form against the exact composition: " << light_gap << " mm");
  CHECK(light_gap <= certified + 1e-9 * size);
  CHECK(light_gap > 0);

  // The report: the style step meets its key points.
  const StepReport& style_step = step(r, "surfaces.sail.steps[0]");
  CHECK(figure<std::string>(style_step, "mode") == "exact");
  CHECK(figure<double>(style_step, "locality") == 0.0);
  CHECK(figure<long long>(style_step, "key_points") == std::ssize(styled.report.key_points));
  for (const auto& k : styled.report.key_points)
    if (k.influenced)
      CHECK(surface::closest_point(styled.surface, k.point).distance <= 1e-9 * size);
  // Below and above the bound (an ellipse over z = 500 .. 4100 mm) the style step changed nothing.
  int away = 0;
  for (double u : surface::linspace(0, 1, 41))
    for (double v : surface::linspace(0, 1, 11)) {
      const Eigen::Vector3d p = surface::evaluate(flat, u, v);
      if (p.z() > 200 && p.z() < 4400) continue;
      CHECK((surface::evaluate(styled.surface, u, v) - p).norm() <= 1e-9 * size);
      ++away;
    }
  CHECK(away > 50);

  // The luff lies on the lattice face s = 0 whose control points stay: it stays on the mast (x = y
  // = 0), within the light form's certified bound.
  for (double u : surface::linspace(0, 1, 21)) {
    const Eigen::Vector3d p = surface::evaluate(sail, u, 0.0);
    CHECK_THAT(p.x(), WithinAbs(0.0, certified + 1e-9 * size));
    CHECK_THAT(p.y(), WithinAbs(0.0, certified + 1e-9 * size));
  }
  // The billow is there: the middle of the sail moved about 100 mm to leeward.
  const Eigen::Vector3d mid =
      surface::evaluate(sail, 0.6, 0.5) - surface::evaluate(styled.surface, 0.6, 0.5);
  CHECK(mid.y() > 50.0);

  // A replay gives the same surface bit for bit (the ctest "recipe: sail" also compares the STEP
  // files of two `clayform run`s byte for byte).
  CHECK(surface::identical(run_example("sail").surface("sail"), sail));
}

TEST_CASE("example car hood: skinned hood, crease by bound and target, paper and exact modes",
          "[examples]") {
  const RunResult r = run_example("car_hood");
  const auto& hood = r.surface("hood");
  const auto& exact = r.surface("hood_exact");
  const auto& paper = r.surface("hood_paper");
  const double size = diagonal(hood);
  CHECK(hood.u.degree == 3);
  CHECK(hood.v.count() == 5);  // through five sections

  // Key points found independently on the parent: the exact mode passes through every
  // influenced one, the paper's forces only approach them.
  deform::StyleOptions options;
  const deform::InfluenceRegion region =
      deform::influence_factors(hood, r.curve("crease_bound"), options);
  const deform::KeyPoints keys = deform::key_points(hood, region, r.curve("crease"), options);
  REQUIRE(keys.points.size() >= 2);
  double paper_miss = 0;
  for (const auto& k : keys.points) {
    if (!k.influenced) continue;
    CHECK(surface::closest_point(exact, k.point).distance <= 1e-6 * size);
    paper_miss = std::max(paper_miss, surface::closest_point(paper, k.point).distance);
  }
  CHECK(paper_miss > 1.0);  // mm: the paper mode approximates

  // Away from the bound (an ellipse 700 x 500 mm about the origin) the exact result equals the
  // parent: its two fixed layers keep the surface around the bound as it was.
  for (double u : surface::linspace(0, 1, 25))
    for (double v : surface::linspace(0, 1, 17)) {
      const Eigen::Vector3d p = surface::evaluate(hood, u, v);
      if (std::hypot(p.x() / 350.0, p.y() / 250.0) < 1.8) continue;
      CHECK((surface::evaluate(exact, u, v) - p).norm() <= 1e-9 * size);
    }
  // The paper mode moves only the vertices whose Greville point lies inside the bound (eq. 2):
  // every other control point keeps its coordinates bit for bit (same knots).
  REQUIRE(paper.u.knots == hood.u.knots);
  REQUIRE(paper.v.knots == hood.v.knots);
  const auto xi = surface::greville_abscissae(hood.u), eta = surface::greville_abscissae(hood.v);
  int outside = 0;
  for (std::size_t a = 0; a < xi.size(); ++a)
    for (std::size_t b = 0; b < eta.size(); ++b) {
      const Eigen::Vector3d p = surface::evaluate(hood, xi[a], eta[b]);
      if (std::hypot(p.x() / 350.0, p.y() / 250.0) < 1.05) continue;
      const Eigen::Index row = static_cast<Eigen::Index>(a * eta.size() + b);
      CHECK(paper.points.row(row) == hood.points.row(row));
      ++outside;
    }
  CHECK(outside > 40);

  const StepReport& e = step(r, "surfaces.hood_exact.steps[0]");
  const StepReport& q = step(r, "surfaces.hood_paper.steps[0]");
  CHECK(figure<std::string>(e, "mode") == "exact");
  CHECK(figure<std::string>(q, "mode") == "paper");
  CHECK(figure<double>(e, "target_deviation") <= 1e-6 * size);
  CHECK(figure<double>(q, "target_deviation") > 1.0);
  CHECK(figure<double>(e, "locality") == 0.0);
  CHECK(figure<double>(q, "locality") == 0.0);
  CHECK(figure<double>(e, "boundary_tangent_angle") <= 0.5);
}

TEST_CASE("example bump: direct manipulation to a flat top, B-spline lattice composed exactly",
          "[examples]") {
  const RunResult r = run_example("bump");
  const Json j = recipe_json("bump");
  const auto& sheet = r.surface("sheet");
  const auto& bump = r.surface("bump");
  const double size = diagonal(bump);
  const Json& dm = j.at("deformations").at("flat_top").at(0);

  // Every selected point of the sheet went where it was asked, 40 mm up.
  for (const auto& m : dm.at("moves")) {
    const double u = m.at("surface_point").at(0).get<double>(),
                 v = m.at("surface_point").at(1).get<double>();
    const Eigen::Vector3d p = surface::evaluate(bump, u, v);
    CHECK((p - vec(m.at("to"))).norm() <= 1e-10);
    CHECK_THAT(p.z(), WithinAbs(40.0, 1e-10));
  }
  // Fig. 1(b): the top is flat between them too. The 5 x 5 points span the lattice's two middle
  // cells in s and t, whose surface depends only on the 5 x 5 free control columns: the 25
  // interpolation conditions fix them, and equal heights reproduce the plane z = 40 exactly.
  for (double u : surface::linspace(0.35, 0.65, 31))
    for (double v : surface::linspace(0.35, 0.65, 31))
      CHECK_THAT(surface::evaluate(bump, u, v).z(), WithinAbs(40.0, 1e-9));

  // The lattice solved again with the deform library from the recipe's numbers, applied pointwise.
  const deform::BSplineLattice lattice = bspline_lattice_of(dm.at("lattice"));
  std::vector<deform::PointMove> moves;
  for (const auto& m : dm.at("moves"))
    moves.push_back({surface::evaluate(sheet, m.at("surface_point").at(0).get<double>(),
                                       m.at("surface_point").at(1).get<double>()),
                     vec(m.at("to"))});
  deform::DirectManipulationOptions options;
  options.locked.assign(static_cast<std::size_t>(lattice.points.rows()), false);
  for (const auto& ix : dm.at("locked")) {
    const auto [a, b, c] = ints3(ix);
    options.locked[static_cast<std::size_t>(lattice.index(a, b, c))] = true;
  }
  const auto solved = deform::manipulate(lattice, moves, options);
  REQUIRE(solved.report.feasible);
  const double gap = max_pointwise_gap(sheet, bump, [&](const Eigen::Vector3d& x) {
    return deform::deform_point(solved.lattice, x);
  });
  INFO("pointwise gap " << gap << " mm");
  CHECK(gap <= 1e-12 * size);

  // The border planes are locked: the sheet's edges stay where they were.
  for (double t : surface::linspace(0, 1, 11))
    for (const auto& [u, v] :
         {std::pair{t, 0.0}, std::pair{t, 1.0}, std::pair{0.0, t}, std::pair{1.0, t}})
      CHECK((surface::evaluate(bump, u, v) - surface::evaluate(sheet, u, v)).norm() <=
            1e-12 * size);

  const StepReport& s = step(r, "surfaces.bump.steps[0]");
  CHECK(figure<bool>(s, "feasible"));
  CHECK(figure<long long>(s, "requested") == 25);
  CHECK(figure<double>(s, "achieved_max_error") <= 1e-10);
  check_exact_composition(s);
  CHECK(figure<long long>(s, "degree_u") == 3);  // an axis-aligned sheet: 3 x 1
}

TEST_CASE("example bottle: revolved body pinched by a Bezier lattice stays rational and round",
          "[examples]") {
  const RunResult r = run_example("bottle");
  const Json j = recipe_json("bottle");
  const auto& body = r.surface("body");
  const auto& waist = r.surface("waist");
  const double size = diagonal(body);
  CHECK(waist.is_rational());
  CHECK((waist.weights.array() != 1.0).any());

  // Closed form: plane k of the (1, 1, n) lattice scales the radius by f_k, so the body becomes
  // r(z) = r0 f(w), f(w) = sum_k B_k^n(w) f_k, w = (z - 60) / 110; z and the angle stay.
  const Json& pinch = j.at("deformations").at("pinch").at(0);
  const int n = pinch.at("degrees").at(2).get<int>();
  std::vector<double> f(static_cast<std::size_t>(n + 1), 1.0);
  for (const auto& m : pinch.at("moves")) {
    const auto [i, jj, k] = ints3(m.at("index"));
    f[static_cast<std::size_t>(k)] = m.at("to").at(0).get<double>() / (-40.0 + 80.0 * i);
    (void)jj;
  }
  const auto radial = [&](const Eigen::Vector3d& x) {
    const double w = (x.z() - 60.0) / 110.0;
    double scale = 0;
    for (int k = 0; k <= n; ++k)
      scale += std::tgamma(n + 1.0) / (std::tgamma(k + 1.0) * std::tgamma(n - k + 1.0)) *
               std::pow(w, k) * std::pow(1 - w, n - k) * f[static_cast<std::size_t>(k)];
    return Eigen::Vector3d(scale * x.x(), scale * x.y(), x.z());
  };
  const double gap = max_pointwise_gap(body, waist, radial);
  INFO("closed-form gap " << gap << " mm");
  CHECK(gap <= 1e-12 * size);
  // And against the lattice rebuilt from the recipe, pointwise.
  const deform::BezierLattice lattice = bezier_lattice_of(pinch);
  CHECK(max_pointwise_gap(body, waist, [&](const Eigen::Vector3d& x) {
          return deform::deform_point(lattice, x);
        }) <= 1e-12 * size);
  // The waist is pinched: radius 33 mm -> 33 f(1/2) at mid-height.
  const Eigen::Vector3d mid = surface::evaluate(waist, 0.3, 0.5);
  CHECK_THAT(std::hypot(mid.x(), mid.y()),
             WithinAbs(radial(surface::evaluate(body, 0.3, 0.5)).head<2>().norm(), 1e-9));
  CHECK(std::hypot(mid.x(), mid.y()) < 30.0);

  // Base and neck lie outside the lattice and are exported untouched; the pinched body still meets
  // them with the same tangent (the lattice's two end planes stay: C1 with the space outside).
  const auto& base = r.surface("base");
  const auto& neck = r.surface("neck");
  for (double u : surface::linspace(0, 1, 17)) {
    const auto b = surface::derivatives(base, u, 1.0, 1),
               w0 = surface::derivatives(waist, u, 0.0, 1);
    const auto w1 = surface::derivatives(waist, u, 1.0, 1),
               k = surface::derivatives(neck, u, 0.0, 1);
    CHECK((b.point - w0.point).norm() <= 1e-12 * size);
    CHECK((w1.point - k.point).norm() <= 1e-12 * size);
    CHECK((b.dv.normalized() - w0.dv.normalized()).norm() <= 1e-9);
    CHECK((w1.dv.normalized() - k.dv.normalized()).norm() <= 1e-9);
  }
  const StepReport& s = step(r, "surfaces.waist.steps[0]");
  check_exact_composition(s);
  // The pinch scales x and y by one degree-6 profile of u: x = (−40 + 80 s) g(u), y alike, z
  // linear. Its highest monomials are s u^6 and t u^6 (no s t term), total degree 7, so around
  // the axis (rational circle, degree 2, W^7 in the homogeneous form) 2 x 7 = 14, not the
  // tensor-product rule's 2 x (1 + 1 + 6) = 16.
  CHECK(figure<long long>(s, "degree_u") == 14);
  CHECK(figure<long long>(s, "degree_v") == 6);  // 1 x 6 along the straight profile
}

TEST_CASE("example tongue: one lattice over two C1 bicubic patches keeps them C1", "[examples]") {
  const RunResult r = run_example("tongue");
  const Json j = recipe_json("tongue");
  const auto& left = r.surface("left");
  const auto& right = r.surface("right");
  const auto& lt = r.surface("left_tongue");
  const auto& rt = r.surface("right_tongue");
  const double size = std::max(diagonal(lt), diagonal(rt));

  // The parents are C1 across x = 300 (the recipe's premise).
  for (double v : surface::linspace(0, 1, 9)) {
    const auto a = surface::derivatives(left, 1.0, v, 1),
               b = surface::derivatives(right, 0.0, v, 1);
    REQUIRE((a.point - b.point).norm() <= 1e-12 * size);
    REQUIRE((a.du - b.du).norm() <= 1e-12 * a.du.norm());
  }
  // Each deformed patch is the rebuilt lattice applied pointwise to its parent.
  const deform::BSplineLattice lattice =
      bspline_lattice_of(j.at("deformations").at("tongue").at(0));
  const auto map = [&](const Eigen::Vector3d& x) { return deform::deform_point(lattice, x); };
  CHECK(max_pointwise_gap(left, lt, map) <= 1e-12 * size);
  CHECK(max_pointwise_gap(right, rt, map) <= 1e-12 * size);

  // The paper's point: the deformed patches still meet and stay tangent-continuous (here even C1
  // in the parameters) across the shared edge.
  double position = 0, tangent = 0;
  for (double v : surface::linspace(0, 1, 41)) {
    const auto a = surface::derivatives(lt, 1.0, v, 1), b = surface::derivatives(rt, 0.0, v, 1);
    position = std::max(position, (a.point - b.point).norm());
    tangent = std::max(tangent, (a.du - b.du).norm() / a.du.norm());
  }
  INFO("edge: position gap " << position << " mm, cross-derivative gap " << tangent
                             << " (relative)");
  CHECK(position <= 1e-9 * size);
  CHECK(tangent <= 1e-9);
  // The tongue is there, straddling the edge: the middle of the edge rose by more than 60 mm.
  CHECK(surface::evaluate(lt, 1.0, 0.5).z() - surface::evaluate(left, 1.0, 0.5).z() > 60.0);

  for (const char* path : {"surfaces.left_tongue.steps[0]", "surfaces.right_tongue.steps[0]"})
    check_exact_composition(step(r, path));
}

// Regression (style exact mode): bounds whose key points were held almost only by fixed vertices
// (free share ~1e-4) passed the rank test and were met by moving the free vertices metres away,
// a net 1e4-1e7 mm across that no lattice contained. Such nets are now refined first: the key
// points are met with displacements of the order of their distances.
TEST_CASE("example sail: a bound close around the target no longer blows the net up", "[recipe]") {
  std::ifstream in(std::string(CLAY_EXAMPLES_DIR) + "/recipes/sail.json");
  nlohmann::ordered_json r = nlohmann::ordered_json::parse(in);
  const double w = std::sqrt(0.5);
  for (const auto& [c, a, b] : {std::tuple{Eigen::Vector3d(650, 600, 2300), 650.0, 1500.0},
                                std::tuple{Eigen::Vector3d(600, 600, 2300), 500.0, 1300.0}}) {
    nlohmann::ordered_json pts = nlohmann::ordered_json::array();
    for (const auto& [s, t] : std::vector<std::pair<double, double>>{
             {1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0}, {-1, -1}, {0, -1}, {1, -1}, {1, 0}})
      pts.push_back({c.x() + s * a, c.y(), c.z() + t * b});
    r["curves"]["draft_bound"] = {{"bspline",
                                   {{"degree", 2},
                                    {"knots", {0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1}},
                                    {"points", pts},
                                    {"weights", {1, w, 1, w, 1, w, 1, w, 1}}}}};
    r["deformations"]["shape"][0]["key_points_per_row"] = 1;
    const auto result = clay::recipe::run_recipe(clay::recipe::parse_recipe(r.dump()));
    double displacement = -1, target = -1, locality = -1;
    for (const auto& step : result.steps)
      if (step.kind == "style")
        for (const auto& [name, value] : step.figures) {
          if (name == "max_displacement") displacement = std::get<double>(value);
          if (name == "target_deviation") target = std::get<double>(value);
          if (name == "locality") locality = std::get<double>(value);
        }
    CHECK(displacement > 0);
    CHECK(displacement < 500);  // the draft line lies ~300 mm off the flat sail
    CHECK(target < 1e-6);
    CHECK(locality == 0);
  }
}

// Regression (style exact mode): key points added where the target curve is missed could make the
// key-point rows nearly dependent on a coarse net (the rank test passes) and were met by winding
// the net up: with curve_tolerance 1e-3 the sail's control points moved up to 307 m. Such a solve
// now refines the net (or takes the added key points back): the surface moves by the order of the
// draft line's distance, and the target curve is met within the tolerance.
TEST_CASE("example sail: key points added along the target do not wind the net up", "[recipe]") {
  std::ifstream in(std::string(CLAY_EXAMPLES_DIR) + "/recipes/sail.json");
  nlohmann::ordered_json r = nlohmann::ordered_json::parse(in);
  auto& shape = r["deformations"]["shape"];
  shape.erase(1);  // the style step alone
  shape[0]["curve_tolerance"] = 1e-3;
  const auto result = clay::recipe::run_recipe(clay::recipe::parse_recipe(r.dump()));
  REQUIRE(result.stages.size() == 1);
  const auto& before = result.stages[0].before;
  const auto& after = result.stages[0].after;
  // The size the tolerance is relative to: the diagonal of the parent's control-point box.
  const double size =
      (before.points.colwise().maxCoeff() - before.points.colwise().minCoeff()).norm();
  // The surface moves by the order of the draft line's distance from the flat sail (~330 mm).
  double moved = 0;
  for (double u : surface::linspace(0, 1, 61))
    for (double v : surface::linspace(0, 1, 61))
      moved = std::max(moved,
                       (surface::evaluate(after, u, v) - surface::evaluate(before, u, v)).norm());
  INFO("largest move of the surface " << moved << " mm");
  CHECK(moved < 500);
  // Every sample of the draft line is on the styled sail within curve_tolerance x size (λ = 1,
  // the line inside the bound), by closest points on the result.
  const auto& line = result.curve("draft_line");
  double miss = 0;
  for (double t : surface::linspace(0, 1, 101))
    miss = std::max(miss, surface::closest_point(after, surface::evaluate(line, t)).distance);
  INFO("draft line missed by " << miss << " mm (" << miss / size << " of the size " << size
                               << " mm)");
  CHECK(miss <= 1e-3 * size);
}

// Release only ([release-only]): sanitized, the example takes 8 minutes, more than a test may; each
// of its steps runs sanitized in its own tests (the exact style to a converged net, the rebuild,
// the lattice's light form, the class-A export).
TEST_CASE(
    "example fender: strokes, a constrained door cut, a snapped fill, exact flare, lattice as a "
    "certified light form, exported for a class-A receiver",
    "[examples][release-only]") {
  const RunResult r = run_example("fender");
  const Json j = recipe_json("fender");
  const auto& panel = r.surface("panel");
  const auto& fender = r.surface("fender");
  const double size = diagonal(fender);

  // The door cut: a cubic in the plane y = 0 from (1000, 0, 0) to (960, 0, 420), leaving the
  // rocker vertically (tangent to the sill) and meeting the shoulder level (tangent to the header).
  const auto& cut = r.curve("rear.cut");
  for (Eigen::Index i = 0; i < cut.points.rows(); ++i) CHECK(std::abs(cut.points(i, 1)) < 1e-9);
  CHECK((surface::evaluate(cut, 0.0) - Eigen::Vector3d(1000, 0, 0)).norm() < 1e-9);
  CHECK((surface::evaluate(cut, 1.0) - Eigen::Vector3d(960, 0, 420)).norm() < 1e-9);
  const Eigen::Vector3d t0 = surface::derivatives(cut, 0.0, 1).d1.normalized();
  const Eigen::Vector3d t1 = surface::derivatives(cut, 1.0, 1).d1.normalized();
  CHECK(std::abs(std::abs(t0.z()) - 1) < 1e-9);
  CHECK(std::abs(std::abs(t1.x()) - 1) < 1e-9);

  // The fill: the strokes' ends, up to ~2.5 mm apart, snapped to their midpoints; the sliver of the
  // rocker's and shoulder's knot union merged; every curve within the snap of the panel.
  const StepReport& fill = step(r, "surfaces.panel");
  const double snapped = figure<double>(fill, "snapped_mm");
  CHECK(snapped > 0.5);
  CHECK(snapped <= 1.5);  // half of gap_tolerance 3
  CHECK(surface::smallest_span_ratio(panel.u) >= 0.05);
  CHECK(surface::smallest_span_ratio(panel.v) >= 0.05);
  for (const char* name : {"rocker", "shoulder", "front", "rear.cut"}) {
    double worst = 0;
    for (double t : surface::linspace(0, 1, 101))
      worst = std::max(worst,
                       surface::closest_point(panel, surface::evaluate(r.curve(name), t)).distance);
    INFO(name << " " << worst << " mm from the panel");
    CHECK(worst <= snapped + 0.01);
  }
  // The bound was drawn 60 mm beside the panel and projected onto it.
  for (double t : surface::linspace(0, 1, 201))
    CHECK(surface::closest_point(panel, surface::evaluate(r.curve("bound"), t)).distance <= 0.01);

  // The flare on a converged net: the whole target line lies on the recipe's exact styled
  // surface within curve_tolerance x size (closest points, independent of the solver), the net
  // changed by less than net_convergence at its last halving, and nothing moved outside the
  // bound.
  const Json& flare = j.at("deformations").at("flare").at(0);
  const auto& styled = r.surface("styled");
  const double styled_size = diagonal(styled);
  double miss = 0;
  for (double t : surface::linspace(0, 1, 401))
    miss = std::max(
        miss, surface::closest_point(styled, surface::evaluate(r.curve("flare_line"), t)).distance);
  INFO("target line missed by " << miss << " mm");
  CHECK(miss <= flare.at("curve_tolerance").get<double>() * styled_size * 1.01);
  const StepReport& style_step = step(r, "surfaces.styled.steps[0]");
  CHECK(figure<double>(style_step, "locality") == 0.0);
  CHECK(figure<double>(style_step, "target_curve_distance") <= miss * 1.01 + 1e-9);
  CHECK(figure<double>(style_step, "net_change") < flare.at("net_convergence").get<double>());
  CHECK(figure<double>(style_step, "net_change") > 0);
  int away = 0;
  for (double u : surface::linspace(0, 1, 41))
    for (double v : surface::linspace(0, 1, 11)) {
      const Eigen::Vector3d p = surface::evaluate(panel, u, v);
      if (p.x() > 80 && p.x() < 880 && p.z() > 20 && p.z() < 390) continue;  // near the bound
      CHECK((surface::evaluate(styled, u, v) - p).norm() <= 1e-9 * size);
      ++away;
    }
  CHECK(away > 100);

  // The rebuild: a net far lighter than the converged one, within its certified bound of it
  // pointwise (the same parameters: a rebuild keeps the domain).
  const auto& styled_net = r.surface("styled_net");
  const StepReport& rebuild = step(r, "surfaces.styled_net");
  const double rebuilt = figure<double>(rebuild, "certified_bound_mm");
  CHECK(rebuilt <= figure<double>(rebuild, "tolerance_mm"));
  CHECK(styled_net.points.rows() * 10 < styled.points.rows());
  const double rebuild_gap =
      max_pointwise_gap(styled, styled_net, [](const Eigen::Vector3d& x) { return x; });
  INFO("rebuild: pointwise gap " << rebuild_gap << " mm, certified " << rebuilt << " mm");
  CHECK(rebuild_gap <= rebuilt + 1e-12 * size);
  // The styled net (177,996 control points) is not a final surface: no light copy of it.
  CHECK_FALSE(has_step(r, "surfaces.styled.composition.budget"));

  // The nose lattice rebuilt from the recipe: its exact composition is above the default budget,
  // so the step is its light form, fender(u, v) = nose(styled_net(u, v)) within its certified
  // bound.
  const deform::BezierLattice nose = bezier_lattice_of(j.at("deformations").at("nose").at(0));
  const auto nosed = [&](const Eigen::Vector3d& x) { return deform::deform_point(nose, x); };
  const double gap = max_pointwise_gap(styled_net, fender, nosed);
  const StepReport& light = step(r, "surfaces.fender.steps[0]");
  const double certified = figure<double>(light, "max_deviation_mm");
  INFO("pointwise gap " << gap << " mm, certified " << certified << " mm");
  CHECK(figure<std::string>(light, "composition") == "light");
  CHECK(figure<bool>(light, "certified"));
  CHECK(figure<long long>(light, "degree_u") == 3);
  CHECK(figure<long long>(light, "control_points") < 10000);
  CHECK(figure<long long>(light, "exact_control_points") > 10000);
  CHECK(gap <= certified + 1e-12 * size);
  CHECK(certified <= figure<double>(light, "tolerance_mm"));
  CHECK_FALSE(has_step(r, "surfaces.fender.composition.budget"));
  // The ledger: the rebuild's bound carried through the lattice (times its Lipschitz bound) plus
  // the light form's own; the fender is within it of the all-exact reference nose(styled(u, v)).
  const double accumulated = figure<double>(light, "accumulated_bound_mm");
  CHECK(figure<double>(rebuild, "accumulated_bound_mm") == rebuilt);
  CHECK(accumulated >= certified + rebuilt);  // this lattice stretches: sup |D'| >= 1
  const double reference_gap = max_pointwise_gap(styled, fender, nosed);
  INFO("fender against nose(styled): " << reference_gap << " mm, ledger " << accumulated);
  CHECK(reference_gap <= accumulated + 1e-12 * size);
  // The nose is wrapped inward: the front edge moved about 25 mm to -y, the rear edge not at all.
  CHECK((surface::evaluate(fender, 0, 0.5) - surface::evaluate(panel, 0, 0.5)).y() < -20);
  CHECK(std::abs((surface::evaluate(fender, 1, 0.5) - surface::evaluate(panel, 1, 0.5)).y()) <
        certified + rebuilt + 1.0);

  // The export, for a class-A receiver: a quintic of at most 32 x 32 control points (a net a
  // stylist edits), certified within its bound of the fender, and within the export's bound (the
  // ledger plus that fit) of the all-exact reference nose(styled(u, v)).
  REQUIRE(r.exports.size() == 1);
  const ExportResult& out = r.exports.front();
  CHECK(out.profile == "class_a");
  REQUIRE(out.surfaces.size() == 1);
  const surface::BSplineSurface& written = out.surfaces.front();
  CHECK(written.u.degree == 5);
  CHECK(written.v.degree == 5);
  CHECK(written.count_u() <= 32);
  CHECK(written.count_v() <= 32);
  const double fitted = out.bounds_mm.front() - accumulated;
  CHECK(fitted > 0);
  CHECK(fitted <= figure<double>(light, "tolerance_mm") * 1.01);  // the recipe's tolerance
  const double class_a_gap =
      max_pointwise_gap(fender, written, [](const Eigen::Vector3d& x) { return x; });
  INFO("class A: " << written.count_u() << " x " << written.count_v() << ", gap " << class_a_gap
                   << " mm, certified " << fitted << " mm");
  CHECK(class_a_gap <= fitted + 1e-12 * size);
  CHECK(max_pointwise_gap(styled, written, nosed) <= out.bounds_mm.front() + 1e-12 * size);
  // (Replay determinism is checked on the lighter examples: this run takes half a minute.)
}

TEST_CASE(
    "example tank: a studio session's fill, exact style and (3, 3, 1) lattice under the default "
    "budget: a certified light form instead of an exact net of hundreds of thousands of points",
    "[examples]") {
  const RunResult r = run_example("tank");
  const Json j = recipe_json("tank");
  CHECK_FALSE(j.contains("composition"));  // every composition setting at its default
  const auto& styled = r.surface("styled");
  const auto& tank = r.surface("tank");
  const double size = diagonal(tank);
  const StepReport& lattice_step = step(r, "surfaces.tank.steps[0]");
  INFO(lattice_step.message);
  CHECK(figure<std::string>(lattice_step, "composition") == "light");
  // The lattice's exact composition: every local coordinate of the fill is bicubic, so
  // 3 x 3 + 3 x 3 + 1 x 3 = 21 at most; above the budget's degree 15 and far above its net.
  CHECK(figure<long long>(lattice_step, "exact_degree_u") > 15);
  CHECK(figure<long long>(lattice_step, "exact_degree_u") <= 21);
  CHECK(figure<long long>(lattice_step, "exact_control_points") > 100000);
  CHECK(figure<long long>(lattice_step, "degree_u") == 3);
  CHECK(figure<long long>(lattice_step, "degree_v") == 3);
  CHECK(figure<long long>(lattice_step, "control_points") <= 10000);
  CHECK(tank.points.rows() == figure<long long>(lattice_step, "control_points"));
  CHECK(figure<bool>(lattice_step, "certified"));
  const double bound = figure<double>(lattice_step, "max_deviation_mm");
  CHECK(bound <= figure<double>(lattice_step, "tolerance_mm"));
  // The style result is exact, so the ledger is the light form's own bound.
  CHECK(figure<double>(lattice_step, "accumulated_bound_mm") == bound);
  // Independently: tank(u, v) against the lattice applied to styled(u, v), at random parameters.
  const deform::BezierLattice knees = bezier_lattice_of(j.at("deformations").at("knees").at(0));
  const double gap = max_pointwise_gap(
      styled, tank, [&](const Eigen::Vector3d& x) { return deform::deform_point(knees, x); }, 3000);
  INFO("pointwise gap " << gap << " mm, certified " << bound << " mm on a " << size << " mm tank");
  CHECK(gap <= bound + 1e-12 * size);
  CHECK(gap > bound / 20);  // the bound is not loose by orders of magnitude
  CHECK(!has_step(r, "surfaces.tank.composition.budget"));
}
