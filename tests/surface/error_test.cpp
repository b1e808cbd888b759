#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/occt/fill.hpp>
#include <clay/summary.hpp>
#include <clay/surface/projection.hpp>
#include <clay/surface/skin.hpp>

#include <limits>
#include <string>

TEST_CASE("clay::Error carries category and message", "[error]") {
  const clay::Error e(clay::ErrorCategory::DegreeLimit, "surface 'hood': degree 30 exceeds 25");
  CHECK(e.category() == clay::ErrorCategory::DegreeLimit);
  CHECK(e.message() == "surface 'hood': degree 30 exceeds 25");
  CHECK(std::string(e.what()) == "degree limit: surface 'hood': degree 30 exceeds 25");
  CHECK(clay::to_string(clay::ErrorCategory::InvalidGeometry) == "invalid geometry");
  CHECK(clay::to_string(clay::ErrorCategory::Io) == "i/o");
  CHECK(clay::to_string(clay::ErrorCategory::ToleranceNotMet) == "tolerance not met");
}

TEST_CASE("Summary::brief states the outcome in one line", "[error]") {
  clay::Summary s;
  s.termination = clay::Termination::Converged;
  s.iterations = 4;
  s.initial_residual = 0.11;
  s.final_residual = 3.2e-13;
  s.message = "foot point found";
  CHECK(s.converged());
  CHECK(s.brief() == "converged in 4 iterations, residual 3.2e-13 (from 0.11): foot point found");
  s.termination = clay::Termination::NotConverged;
  s.message.clear();
  CHECK_FALSE(s.converged());
  CHECK(s.brief() == "not converged in 4 iterations, residual 3.2e-13 (from 0.11)");
}

#include <clay/surface/build_report.hpp>

TEST_CASE("BuildReport describes a surface in one line", "[error]") {
  using namespace clay::surface;
  Points3 p(4, 3);
  p << 0, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0;
  const BSplineSurface s =
      make_surface(clamped_uniform_basis(1, 2), clamped_uniform_basis(1, 2), p);
  BuildReport r = describe(s, "bilinear");
  r.exact = true;
  r.max_deviation_mm = 0.0;
  r.samples = 9;
  CHECK(r.count_u == 2);
  CHECK_FALSE(r.rational);
  CHECK(r.brief() ==
        "bilinear: degree (1, 1), 2 x 2 control points, polynomial, exact (max deviation 0 mm on 9 "
        "samples)");
}

TEST_CASE("surface Options structs list every bad field, not only the first") {
  clay::surface::LoftOptions loft;
  loft.degree = 0;
  loft.relative_tolerance = 1;
  CHECK(loft.problems().size() == 2);
  clay::surface::SweepOptions sweep;
  sweep.sections = 1;
  sweep.max_sections = 1;
  sweep.twist_degrees = std::numeric_limits<double>::infinity();
  CHECK(sweep.problems().size() == 3);
  clay::surface::NSidedFillOptions fill;
  fill.degree = 1;
  fill.iterations = 0;
  fill.samples_per_curve = 1;
  CHECK(fill.problems().size() == 3);
  clay::surface::ProjectionOptions projection;
  projection.starts = 0;
  projection.max_iterations = 0;
  CHECK(projection.problems().size() == 2);
  try {
    projection.validate();
    FAIL("no error");
  } catch (const clay::Error& e) {
    CHECK(e.category() == clay::ErrorCategory::InvalidArgument);
    CHECK(std::string(e.what()).find("starts") != std::string::npos);
    CHECK(std::string(e.what()).find("max_iterations") != std::string::npos);
  }
}
