#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/sketch/fit.hpp>
#include <clay/sketch/stroke.hpp>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "error_of.hpp"

using namespace clay::sketch;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;

namespace {

/// A gentle arc of `count` points (no corner, not closed).
Stroke arc(int count) {
  Stroke s;
  s.points.resize(count, 3);
  for (int i = 0; i < count; ++i) {
    const double a = 1.5 * i / (count - 1);
    s.points.row(i) << 50 * std::cos(a), 50 * std::sin(a), 0.1 * i;
  }
  return s;
}

std::pair<clay::ErrorCategory, std::string> fit_error(const Stroke& s, const FitOptions& o = {}) {
  return clay::test::error_of([&] { fit_stroke(s, o); });
}

}  // namespace

TEST_CASE("an empty stroke is refused", "[stroke]") {
  const auto [category, what] = fit_error(Stroke{});
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("stroke: is empty; a stroke needs at least 2 points"));
}

TEST_CASE("a single-point stroke is refused", "[stroke]") {
  Stroke s;
  s.points.resize(1, 3);
  s.points << 1, 2, 3;
  const auto [category, what] = fit_error(s);
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("has a single point"));
}

TEST_CASE("a NaN coordinate is refused, naming the point", "[stroke]") {
  Stroke s = arc(20);
  s.points(7, 1) = std::numeric_limits<double>::quiet_NaN();
  const auto [category, what] = fit_error(s);
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("stroke: point 7 has a non-finite coordinate"));
}

TEST_CASE("an infinite coordinate is refused, naming the point", "[stroke]") {
  Stroke s = arc(20);
  s.points(19, 2) = -std::numeric_limits<double>::infinity();
  const auto [category, what] = fit_error(s);
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("point 19 has a non-finite coordinate"));
}

TEST_CASE("repeated consecutive points are refused, naming them, unless dropped on request",
          "[stroke]") {
  Stroke s = arc(20);
  s.points.row(5) = s.points.row(4);
  const auto [category, what] = fit_error(s);
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("points 4 and 5 are at the same place"));
  CHECK_THAT(what, Contains("drop_duplicates"));
  FitOptions o;
  o.drop_duplicates = true;
  const StrokeFit fit = fit_stroke(s, o);
  REQUIRE(fit.curves.size() == 1);
  CHECK(fit.summary.converged());
  CHECK(fit.curves[0].last_point == 18);  // 19 distinct points
}

TEST_CASE("points that project onto one point of the stroke's plane are repeated points",
          "[stroke]") {
  Stroke s = arc(10);
  s.plane = SketchPlane{};  // the xy plane
  s.points.row(3) = s.points.row(2);
  s.points(3, 2) += 5.0;  // straight above point 2
  const auto [category, what] = fit_error(s);
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("points 2 and 3 project onto the same place of its plane"));
}

TEST_CASE("a zero-length stroke is refused", "[stroke]") {
  Stroke s;
  s.points.resize(5, 3);
  for (int i = 0; i < 5; ++i) s.points.row(i) << 4, 5, 6;
  const auto [category, what] = fit_error(s);
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("stroke: has zero length: all 5 points are at the same place"));
  FitOptions o;
  o.drop_duplicates = true;  // dropping does not make it a stroke
  CHECK_THAT(fit_error(s, o).second, Contains("zero length"));
}

TEST_CASE("a stroke with an invalid plane is refused, naming the plane", "[stroke]") {
  Stroke s = arc(10);
  SketchPlane p;
  p.y_axis = Eigen::Vector3d(0.5, 1, 0);
  s.plane = p;
  const auto [category, what] = fit_error(s);
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(what, Contains("stroke plane: y axis has length"));
}

TEST_CASE("bad fit options are refused, naming the field, its value and the rule", "[stroke]") {
  const std::vector<std::pair<std::string, std::function<void(FitOptions&)>>> cases = {
      {"FitOptions::tolerance_mm = 0 must be a positive distance",
       [](FitOptions& o) { o.tolerance_mm = 0; }},
      {"FitOptions::tolerance_mm = nan", [](FitOptions& o) { o.tolerance_mm = std::nan(""); }},
      {"FitOptions::degree = 1 must be in [2, 9]", [](FitOptions& o) { o.degree = 1; }},
      {"FitOptions::degree = 10", [](FitOptions& o) { o.degree = 10; }},
      {"FitOptions::fairness = -1 must be finite and >= 0", [](FitOptions& o) { o.fairness = -1; }},
      {"FitOptions::fairness_reductions = -1", [](FitOptions& o) { o.fairness_reductions = -1; }},
      {"FitOptions::max_control_points = 5 must be >= 2 * degree (6)",
       [](FitOptions& o) { o.max_control_points = 5; }},
      {"FitOptions::max_iterations = 0 must be >= 1", [](FitOptions& o) { o.max_iterations = 0; }},
      {"FitOptions::corner_angle = 0 must be in (0, 180]",
       [](FitOptions& o) { o.corner_angle = 0; }},
      {"FitOptions::corner_angle = 181", [](FitOptions& o) { o.corner_angle = 181; }},
      {"FitOptions::corner_window = -1", [](FitOptions& o) { o.corner_window = -1; }},
      {"FitOptions::closing_ratio = 0.7 must be in [0, 0.5]",
       [](FitOptions& o) { o.closing_ratio = 0.7; }},
      {"FitOptions::end_samples = 0 must be >= 1", [](FitOptions& o) { o.end_samples = 0; }},
  };
  const Stroke s = arc(20);
  for (const auto& [message, spoil] : cases) {
    FitOptions o;
    spoil(o);
    const auto [category, what] = fit_error(s, o);
    CHECK(category == clay::ErrorCategory::InvalidArgument);
    CHECK_THAT(what, Contains(message));
  }
}

TEST_CASE("stroke length is the polyline's, in the plane when there is one", "[stroke]") {
  Stroke s;
  s.points.resize(3, 3);
  s.points << 0, 0, 0, 3, 4, 0, 3, 4, 12;
  CHECK_THAT(length(s), WithinAbs(17.0, 1e-14));
  s.plane = SketchPlane{};
  s.points(2, 0) = 6.0;  // (3, 4) -> (6, 4) in the plane, z ignored
  CHECK_THAT(length(s), WithinAbs(8.0, 1e-14));
}

TEST_CASE("a two-point stroke gives a straight cubic through both points", "[stroke]") {
  Stroke s;
  s.points.resize(2, 3);
  s.points << 0, 0, 0, 30, 40, 0;
  const StrokeFit fit = fit_stroke(s);
  REQUIRE(fit.curves.size() == 1);
  const auto& c = fit.curves[0].curve;
  CHECK(c.basis.degree == 3);
  CHECK(c.points.row(0) == s.points.row(0));
  CHECK(c.points.row(c.points.rows() - 1) == s.points.row(1));
  // Fairness makes it the straight segment: every control point on the line.
  for (Eigen::Index i = 0; i < c.points.rows(); ++i)
    CHECK(std::abs(c.points(i, 0) * 40 - c.points(i, 1) * 30) < 1e-9);
}
