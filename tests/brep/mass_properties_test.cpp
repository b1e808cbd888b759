// Mass properties and their gradients (clay/brep/mass_properties.hpp): against the closed forms
// of a cube, a sphere and a cone frustum (and of their affine images), the volume against
// volume_mm3, and the gradients against the closed-form derivative of an affine map and against
// finite differences of the properties under a nonlinear move of every control point.
#include <catch2/catch.hpp>

#include <clay/brep/mass_properties.hpp>
#include <clay/brep/volume.hpp>

#include <cmath>
#include <functional>
#include <numbers>

#include "error_of.hpp"
#include "hand_models.hpp"
#include "occt/test_files.hpp"
#include "occt_test_models.hpp"

using clay::brep::MassProperties;
using clay::brep::Model;
using clay::surface::occt_reference::TestModel;
using Eigen::Matrix3d;
using Eigen::Vector3d;

using clay::test::mapped;

namespace {

Model read(TestModel model, const std::string& name) {
  return clay::test::read_test_model(model, clay::test::test_output("brep-mass", name));
}

/// Σ_f Σ_k ∂q/∂P_k · d(P_k) + Σ_v ∂q/∂V_v · d(V_v): a gradient's directional derivative along a
/// move of the points (control points and vertices alike).
double along(const clay::brep::PointGradients& g, const Model& m,
             const std::function<Vector3d(const Vector3d&)>& d) {
  double sum = 0;
  for (size_t f = 0; f < g.faces.size(); ++f)
    for (Eigen::Index k = 0; k < g.faces[f].rows(); ++k)
      sum += g.faces[f].row(k).dot(d(m.faces[f].surface.points.row(k).transpose()));
  for (size_t v = 0; v < m.vertices.size(); ++v)
    sum += g.vertices.row(static_cast<Eigen::Index>(v)).dot(d(m.vertices[v].point));
  return sum;
}

/// The 5-point central difference of q(h) at 0 (exact for a quartic).
double derivative(const std::function<double(double)>& q, double h) {
  return (8 * (q(h) - q(-h)) - (q(2 * h) - q(-2 * h))) / (12 * h);
}

/// Inertia about the centroid of a solid ball of radius r and of a frustum (radii R, r, height h,
/// axis z): the closed forms.
Matrix3d ball_inertia(double r) {
  return Matrix3d::Identity() * 0.4 * (4.0 / 3.0 * std::numbers::pi * r * r * r) * r * r;
}

/// The inertia's derivative along the affine move x -> x + ε A x: the second moments about the
/// centroid S' (from I = tr(S') 1 − S') move by tr(A) S' + A S' + S' Aᵀ, and I with them; each
/// entry of the gradients against it, within 1e-11 of the inertia.
void check_inertia_derivative(const clay::brep::MassPropertyGradients& g, const Model& m,
                              const Matrix3d& a, const Matrix3d& inertia) {
  const Matrix3d s = 0.5 * inertia.trace() * Matrix3d::Identity() - inertia;
  const Matrix3d ds = a.trace() * s + a * s + s * a.transpose();
  const Matrix3d di = ds.trace() * Matrix3d::Identity() - ds;
  const std::array<std::pair<int, int>, 6> entries{
      {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}}};
  const auto d = [&](const Vector3d& x) { return Vector3d(a * x); };
  for (size_t e = 0; e < 6; ++e)
    CHECK(along(g.inertia[e], m, d) ==
          Approx(di(entries[e].first, entries[e].second)).margin(1e-11 * inertia.norm()));
}

}  // namespace

TEST_CASE("mass_properties: a cube, its affine image and their closed forms") {
  const Model cube = clay::test::cube(10);
  const MassProperties p = clay::brep::mass_properties(cube);
  CHECK(p.volume_mm3 == Approx(1000).epsilon(1e-14));
  CHECK((p.centroid_mm - Vector3d(5, 5, 5)).norm() <= 1e-13);
  // a cube of side a: I = V a² / 6 about every axis, no products
  CHECK((p.inertia_mm5 - Matrix3d::Identity() * 1000 * 100 / 6).norm() <= 1e-10);
  // x -> A x + b: V det A, centroid A g + b, second moments about it det A · A S' Aᵀ
  Matrix3d a;
  a << 1.2, 0.3, -0.1, 0.05, 0.9, 0.2, -0.15, 0.1, 1.1;
  const Vector3d b(3, -2, 7);
  const MassProperties q = clay::brep::mass_properties(
      mapped(cube, [&](const Vector3d& x) { return Vector3d(a * x + b); }));
  CHECK(q.volume_mm3 == Approx(1000 * a.determinant()).epsilon(1e-13));
  CHECK((q.centroid_mm - (a * Vector3d(5, 5, 5) + b)).norm() <= 1e-12);
  const Matrix3d s = Matrix3d::Identity() * 1000 * 100 / 12;  // ∭ r rᵀ of the cube
  const Matrix3d s2 = a.determinant() * a * s * a.transpose();
  const Matrix3d expected = s2.trace() * Matrix3d::Identity() - s2;
  CHECK((q.inertia_mm5 - expected).norm() <= 1e-12 * expected.norm());
}

TEST_CASE("mass_properties: a sphere and a cone frustum (rational faces) against closed forms") {
  const Model sphere = read(TestModel::Sphere, "sphere-closed.step");
  const MassProperties p = clay::brep::mass_properties(sphere);
  const double v = 4.0 / 3.0 * std::numbers::pi * 1000;
  CHECK(p.volume_mm3 == Approx(v).epsilon(1e-12));
  CHECK(p.volume_mm3 == Approx(clay::brep::volume_mm3(sphere)).epsilon(1e-13));
  CHECK(p.centroid_mm.norm() <= 1e-11);
  CHECK((p.inertia_mm5 - ball_inertia(10)).norm() <= 1e-11 * ball_inertia(10).norm());

  const Model cone = read(TestModel::Cone, "cone-closed.step");
  const MassProperties c = clay::brep::mass_properties(cone);
  const double R = 10, r = 4, h = 15, pi = std::numbers::pi;
  CHECK(c.volume_mm3 == Approx(pi * h / 3 * (R * R + R * r + r * r)).epsilon(1e-12));
  // the frustum's centroid on its axis, from the wide end: h (R² + 2Rr + 3r²) / (4 (R² + Rr + r²))
  const double zbar = h * (R * R + 2 * R * r + 3 * r * r) / (4 * (R * R + R * r + r * r));
  CHECK(std::abs(c.centroid_mm.x()) <= 1e-11);
  CHECK(std::abs(c.centroid_mm.y()) <= 1e-11);
  CHECK(std::abs(c.centroid_mm.z() - zbar) <= 1e-11);
  // about the axis: π h (R⁵ − r⁵) / (10 (R − r)) (the integral of π ρ(z)⁴ / 2)
  CHECK(c.inertia_mm5(2, 2) ==
        Approx(pi * h * (std::pow(R, 5) - std::pow(r, 5)) / (10 * (R - r))).epsilon(1e-12));
  CHECK(std::abs(c.inertia_mm5(0, 1)) <= 1e-10 * c.inertia_mm5(2, 2));
}

TEST_CASE("mass_properties: two solids apart, each about its own point, put together") {
  // A box 20^3 at the origin and a ball r 5 at (50, 10, 10): the parallel-axis theorem.
  const Model two = read(TestModel::Separated, "separated.step");
  const double box = 8000, ball = 4.0 / 3.0 * std::numbers::pi * 125, v = box + ball;
  const Vector3d gb(10, 10, 10), gs(50, 10, 10);
  const Vector3d g = (box * gb + ball * gs) / v;
  Matrix3d inertia = Matrix3d::Identity() * (box * 400 / 6) + ball_inertia(5);
  for (const auto& [mass, at] : {std::pair{box, gb}, std::pair{ball, gs}}) {
    const Vector3d d = at - g;
    inertia += mass * (d.squaredNorm() * Matrix3d::Identity() - d * d.transpose());
  }
  const MassProperties p = clay::brep::mass_properties(two);
  CHECK(p.volume_mm3 == Approx(v).epsilon(1e-12));
  CHECK(p.volume_mm3 == Approx(clay::brep::volume_mm3(two)).epsilon(1e-14));
  CHECK((p.centroid_mm - g).norm() <= 1e-11 * 60);
  CHECK((p.inertia_mm5 - inertia).norm() <= 1e-11 * inertia.norm());
  // The gradients put together as the values: an affine move's derivative in closed form.
  Matrix3d a;
  a << 0.3, -0.2, 0.5, 0.1, -0.4, 0.25, 0.2, 0.6, 0.15;
  const auto d = [&](const Vector3d& x) { return Vector3d(a * x); };
  const auto grad = clay::brep::mass_property_gradients(two);
  CHECK(along(grad.volume, two, d) == Approx(a.trace() * v).epsilon(1e-11));
  for (int i = 0; i < 3; ++i)
    CHECK(along(grad.centroid[static_cast<size_t>(i)], two, d) ==
          Approx((a * g)[i]).margin(1e-11 * 60));
  check_inertia_derivative(grad, two, a, inertia);
}

TEST_CASE("mass_property_gradients: an affine move's derivative in closed form") {
  // A nonlinear move of the control points would open a trimmed model's edges (each carrier
  // moves its own way); an affine one keeps every model closed. Trimmed faces on planes,
  // cylinders and fillets; a rational sphere with a seam and poles.
  // And the sphere without its loops: the whole domain integrated, the reference point the mean
  // of the control points (no vertex left).
  const int which = GENERATE(0, 1, 2);
  Model model = which == 0 ? read(TestModel::FilletedBlock, "block-affine.step")
                           : read(TestModel::Sphere, "sphere-affine.step");
  if (which == 2) {
    for (auto& face : model.faces) face.loops.clear();
    model.edges.clear();
    model.vertices.clear();
  }
  const auto moved =
      mapped(model, [](const Vector3d& x) { return Vector3d(x + Vector3d(2, -1, 3)); });
  clay::brep::MassPropertyOptions unchecked;
  unchecked.validate = which != 2;  // a solid whose faces have no loops breaks an invariant
  const auto g = clay::brep::mass_property_gradients(moved, unchecked);
  if (which > 0)
    CHECK(g.value.volume_mm3 == Approx(4.0 / 3.0 * std::numbers::pi * 1000).epsilon(1e-12));
  Matrix3d a;
  a << 0.3, -0.2, 0.5, 0.1, -0.4, 0.25, 0.2, 0.6, 0.15;
  const auto d = [&](const Vector3d& x) { return Vector3d(a * x); };
  // d/dε of det(I + εA) V = tr(A) V; of the centroid (I + εA) g: A g; of S' : tr(A) S' + A S' + S'
  // Aᵀ
  const double v = g.value.volume_mm3;
  CHECK(along(g.volume, moved, d) == Approx(a.trace() * v).epsilon(1e-11));
  for (int i = 0; i < 3; ++i)
    CHECK(along(g.centroid[static_cast<size_t>(i)], moved, d) ==
          Approx((a * g.value.centroid_mm)[i]).margin(1e-11 * 100));  // 1e-11 of the size
  const Matrix3d i0 = g.value.inertia_mm5;
  check_inertia_derivative(g, moved, a, i0);
}

TEST_CASE("mass_property_gradients: central differences under a nonlinear move of the points") {
  const auto check = [](const Model& m, double h) {
    // every control point x -> x + ε w(x), a smooth field that keeps coincident points together
    const auto w = [](const Vector3d& x) {
      return Vector3d(0.01 * x.x() * x.x() + std::sin(0.1 * x.y()) + 0.3,
                      0.2 * std::cos(0.07 * x.z() + x.x() * 0.05) + 0.005 * x.y() * x.y(),
                      0.01 * x.x() * x.y() - 0.2 + 0.003 * x.z() * x.z());
    };
    const auto g = clay::brep::mass_property_gradients(m);
    auto at = [&](double e) {
      return clay::brep::mass_properties(mapped(
          m, [&](const Vector3d& x) { return Vector3d(x + e * w(x)); }, 1.0));
    };
    const double dv = derivative([&](double e) { return at(e).volume_mm3; }, h);
    CHECK(along(g.volume, m, w) == Approx(dv).epsilon(1e-10));
    for (int i = 0; i < 3; ++i) {
      const double dc = derivative([&](double e) { return at(e).centroid_mm[i]; }, h);
      CHECK(along(g.centroid[static_cast<size_t>(i)], m, w) == Approx(dc).margin(1e-9));
    }
    const double di = derivative([&](double e) { return at(e).inertia_mm5(0, 0); }, h);
    CHECK(along(g.inertia[0], m, w) == Approx(di).epsilon(1e-8));
    const double dxy = derivative([&](double e) { return at(e).inertia_mm5(0, 1); }, h);
    CHECK(along(g.inertia[3], m, w) == Approx(dxy).margin(1e-8 * std::abs(di) + 1e-6));
  };
  SECTION("a cube (planar faces)") { check(clay::test::cube(10), 1e-3); }
  SECTION("a sphere (rational faces, a seam, poles)") {
    check(read(TestModel::Sphere, "sphere-differences.step"), 1e-3);
  }
}

TEST_CASE("mass_properties: bad input is refused, named") {
  const Model cube = clay::test::cube(10);
  auto [category, message] =
      clay::test::error_of([&] { (void)clay::brep::mass_properties(cube, 3); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Catch::Matchers::Contains("body 3 does not exist"));
  Model sheet = cube;
  sheet.bodies[0].kind = clay::brep::BodyKind::Sheet;
  std::tie(category, message) =
      clay::test::error_of([&] { (void)clay::brep::mass_properties(sheet); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Catch::Matchers::Contains("no solid"));
  std::tie(category, message) =
      clay::test::error_of([&] { (void)clay::brep::mass_property_gradients(sheet, 0); });
  CHECK_THAT(message, Catch::Matchers::Contains("body 0 is not a solid"));
}

TEST_CASE("mass_property_gradients: options choose the body and whether to check the model") {
  const Model cube = clay::test::cube(10);
  clay::brep::MassPropertyOptions options;
  options.body = 0;
  const auto checked = clay::brep::mass_property_gradients(cube, options);
  CHECK(checked.value.volume_mm3 == Approx(1000).epsilon(1e-14));
  // Unchecked: the same figures on a valid model, and a torn one is measured, not refused.
  options.validate = false;
  CHECK(clay::brep::mass_property_gradients(cube, options).value.volume_mm3 ==
        checked.value.volume_mm3);
  Model torn = cube;
  torn.faces[1].surface.points.col(2).array() += 1e-3;  // the top lifted off its edges
  CHECK(clay::test::error_of([&] { (void)clay::brep::mass_property_gradients(torn); }).first ==
        clay::ErrorCategory::InvalidGeometry);
  CHECK(clay::brep::mass_property_gradients(torn, options).value.volume_mm3 ==
        Approx(1000 + 100 * 1e-3 / 3).epsilon(1e-12));  // the flux of (x - c) / 3 through the
                                                        // lifted top: 100 mm^2 x 1e-3 mm / 3
  // A solid squashed flat encloses nothing: its centroid is undefined, and said so.
  Model flat = cube;
  for (auto& face : flat.faces) face.surface.points.col(2).setZero();
  const auto [category, message] =
      clay::test::error_of([&] { (void)clay::brep::mass_property_gradients(flat, options); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(message, Catch::Matchers::Contains("centroid and inertia are undefined"));
  options.body = -1;
  CHECK_THAT(clay::test::error_of([&] {
               (void)clay::brep::mass_property_gradients(cube, options);
             }).second,
             Catch::Matchers::Contains("body -1 does not exist"));
}
