// Surfaces built to meet keep meeting through a recipe's refits (issue #38 step 3): a panel and
// its mirror, tangent (G2) across the mirror plane, each deformed by the same non-affine lattice
// and refitted alone, follow their shared side (recipe_run: shared_sides), checked between the
// two results at points the refits never sampled.
#include <catch2/catch.hpp>

#include <clay/recipe/recipe.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

using namespace clay::recipe;
namespace surface = clay::surface;

namespace {

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

/// A bicubic panel 100 x 100 mm over x in [0, 100], flat across x = 0 (its first two rows of
/// control points at one height): its mirror in x = 0 meets it tangentially, and with the same
/// curvature (a reflection keeps it), so G2.
std::string panel_json() {
  const std::vector<double> knots{0, 0, 0, 0, 0.3, 0.55, 1, 1, 1, 1};
  const auto xi = surface::greville_abscissae({3, knots});
  std::string points = "[";
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      const double x = 100 * xi[static_cast<std::size_t>(i)],
                   y = 100 * xi[static_cast<std::size_t>(j)];
      const double xz = i == 1 ? 0 : x;  // row 1 at row 0's height: flat across x = 0
      const double z = 12 * std::cos(0.02 * xz) * std::sin(0.029 * y + 0.3);
      points +=
          std::string(i + j ? "," : "") + "[" + number(x) + "," + number(y) + "," + number(z) + "]";
    }
  std::string k = "[";
  for (std::size_t n = 0; n < knots.size(); ++n) k += (n ? "," : "") + number(knots[n]);
  k += "]";
  return R"({"bspline": {"degrees": [3, 3], "knots_u": )" + k + R"(, "knots_v": )" + k +
         R"(, "points": )" + points + "]}}";
}

std::string recipe(const std::string& edges) {
  const std::string composition =
      R"(, "composition": {"tolerance_mm": 0.3, "budget": {"max_degree": 4})" + edges + "}";
  return R"({"format": "clayform.recipe", "version": 1, "name": "halves",
    "surfaces": {"panel": )" +
         panel_json() + R"(,
      "other": {"mirror": {"surface": "panel", "plane": {"origin": [0, 0, 0], "normal": [1, 0, 0]}}},
      "a": {"deform": {"surface": "panel", "deformation": "bulge")" +
         composition + R"(}},
      "b": {"deform": {"surface": "other", "deformation": "bulge")" +
         composition + R"(}}},
    "deformations": {"bulge": [{"kind": "bezier_lattice", "name": "bulge",
      "frame": {"origin": [-110, -10, -20], "s": [220, 0, 0], "t": [0, 120, 0], "u": [0, 0, 60]},
      "degrees": [2, 2, 1],
      "moves": [{"index": [1, 1, 1], "by": [25, -12, 40]}, {"index": [2, 0, 0], "by": [14, -13, -12]}]}]}})";
}

/// The largest gap (mm) and normal angle (deg, up to orientation) between a(0, v) and b(1, v)
/// (the mirror reverses u), at 401 v between the refits' samples.
std::pair<double, double> join(const surface::BSplineSurface& a, const surface::BSplineSurface& b) {
  std::pair<double, double> w{0, 0};
  for (int k = 0; k <= 400; ++k) {
    const double v = (k + 0.31) / 401.3;
    const auto da = surface::derivatives(a, 0, v, 1), db = surface::derivatives(b, 1, v, 1);
    const Eigen::Vector3d na = da.du.cross(da.dv), nb = db.du.cross(db.dv);
    w.first = std::max(w.first, (da.point - db.point).norm());
    w.second = std::max(
        w.second, std::atan2(na.cross(nb).norm(), std::abs(na.dot(nb))) * 180 / std::numbers::pi);
  }
  return w;
}

}  // namespace

TEST_CASE("a panel and its mirror refitted through a lattice keep their tangent join",
          "[recipe][shared]") {
  // the source: the halves meet exactly and tangentially
  const auto source = run_recipe(parse_recipe(recipe("")));
  const auto [gap0, angle0] = join(source.surface("panel"), source.surface("other"));
  REQUIRE(gap0 <= 1e-12);
  REQUIRE(angle0 <= 1e-9);
  // refitted with their shared side (the default edges, 0.0005 mm and 0.008 deg per surface)
  const auto [gap, angle] = join(source.surface("a"), source.surface("b"));
  // refitted alone ("edges": "alone")
  const auto alone = run_recipe(parse_recipe(recipe(R"(, "edges": "alone")")));
  const auto [gap_alone, angle_alone] = join(alone.surface("a"), alone.surface("b"));
  INFO("matched: " << gap << " mm, " << angle << " deg; alone: " << gap_alone << " mm, "
                   << angle_alone << " deg");
  CHECK(gap <= 2 * 0.0005);
  CHECK(angle <= 2 * 0.008);
  CHECK(angle_alone > 2 * 0.008);  // following the shared side is what keeps the join
}
