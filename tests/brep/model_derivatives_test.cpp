// A model's exact Jacobian with respect to lattice points, its mass properties' gradients and
// moves that keep them (clay/deform/model_derivatives.hpp), on parts built by OpenCASCADE and
// read from STEP: the matrices against central differences of the pointwise FFD and of the mass
// properties, against deform_model, and against the closed forms of solids under affine lattices.
#include <catch2/catch.hpp>

#include <clay/brep/volume.hpp>
#include <clay/deform/model_deformation.hpp>
#include <clay/deform/model_derivatives.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/surface/evaluate.hpp>

#include <Eigen/Dense>

#include <cmath>
#include <filesystem>
#include <functional>
#include <numbers>
#include <random>

#include "error_of.hpp"
#include "hand_models.hpp"
#include "occt/test_files.hpp"
#include "occt_test_models.hpp"

using namespace clay::deform;
using clay::brep::Model;
using clay::surface::occt_reference::TestModel;
using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

Model read(TestModel model, const std::string& name) {
  return clay::test::read_test_model(model, clay::test::test_output("brep-derivatives", name));
}

/// `lattice` with every point moved by a normal deviate of `sigma` mm.
template <class Lattice>
Lattice shaken(Lattice lattice, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> d(0, sigma);
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r)
    for (int c = 0; c < 3; ++c) lattice.points(r, c) += d(rng);
  return lattice;
}

/// The 5-point central difference of q at 0 (exact for a quartic).
double derivative(const std::function<double(double)>& q, double h) {
  return (8 * (q(h) - q(-h)) - (q(2 * h) - q(-2 * h))) / (12 * h);
}

double dot(const Points3& a, const Points3& b) { return a.cwiseProduct(b).sum(); }

}  // namespace

TEST_CASE(
    "model_jacobian: a filleted block under a moved Bézier lattice, exact and fixed in form") {
  const Model block = read(TestModel::FilletedBlock, "block-form.step");
  const BezierLattice lattice = make_bezier_lattice(frame_around(block, 0.1), {2, 2, 1});
  const BezierLattice moved = shaken(lattice, 1.5, 3);
  const ModelJacobian at_identity = model_jacobian(lattice, block);
  const ModelJacobian j = model_jacobian(moved, block);
  // The form and the matrices do not depend on the points (deform_model's identity keeps the
  // faces as they are: the counts would differ there).
  REQUIRE(j.model.faces.size() == block.faces.size());
  for (size_t f = 0; f < j.faces.size(); ++f) {
    CHECK(j.faces[f].rows() == at_identity.faces[f].rows());
    CHECK((Eigen::MatrixXd(j.faces[f]) - Eigen::MatrixXd(at_identity.faces[f])).norm() == 0);
  }
  // The model at other points is the Jacobian's product: deformed_model from the identity's
  // Jacobian is the moved one's model.
  const Model again = deformed_model(at_identity, moved.points);
  double worst = 0;
  for (size_t f = 0; f < j.model.faces.size(); ++f)
    worst =
        std::max(worst, (again.faces[f].surface.points - j.model.faces[f].surface.points).norm());
  CHECK(worst <= 1e-12);
  // Each face is the pointwise FFD of the original, at random (u, v) over its whole surface.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0, 1);
  double deviation = 0;
  for (size_t f = 0; f < block.faces.size(); ++f) {
    const auto& s = block.faces[f].surface;
    for (int k = 0; k < 20; ++k) {
      const double u = s.u.domain().first + unit(rng) * (s.u.domain().second - s.u.domain().first);
      const double v = s.v.domain().first + unit(rng) * (s.v.domain().second - s.v.domain().first);
      const Vector3d expected = deform_point(moved, clay::surface::evaluate(s, u, v));
      deviation = std::max(
          deviation, (clay::surface::evaluate(j.model.faces[f].surface, u, v) - expected).norm());
    }
  }
  CHECK(deviation <= 1e-11 * 80);
  // The vertices are the FFD of the originals; the model is valid (its gaps within tolerance).
  for (size_t v = 0; v < block.vertices.size(); ++v)
    CHECK((j.model.vertices[v].point - deform_point(moved, block.vertices[v].point)).norm() <=
          1e-12 * 80);
  CHECK(clay::brep::problems(j.model).empty());
  // The same volume as deform_model's (its own composition, in its lightest form).
  DeformationStack stack;
  stack.steps.push_back({moved, "moved", true});
  const auto reference = deform_model(stack, block);
  CHECK(clay::brep::volume_mm3(j.model) ==
        Approx(reference.report.volume_after_mm3).epsilon(1e-12));
}

TEST_CASE("face_point_jacobian: central differences of the pointwise FFD, every lattice point") {
  const Model block = read(TestModel::FilletedBlock, "block-points.step");
  const BezierLattice lattice =
      shaken(make_bezier_lattice(frame_around(block, 0.1), {2, 2, 1}), 1, 5);
  const ModelJacobian j = model_jacobian(lattice, block);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> unit(0, 1);
  double worst = 0, largest = 0;
  for (int f : {0, 3, 7, static_cast<int>(block.faces.size()) - 1}) {
    const auto& s = block.faces[static_cast<size_t>(f)].surface;
    std::vector<Vector2d> uv;
    for (int k = 0; k < 5; ++k)
      uv.emplace_back(s.u.domain().first + unit(rng) * (s.u.domain().second - s.u.domain().first),
                      s.v.domain().first + unit(rng) * (s.v.domain().second - s.v.domain().first));
    const Eigen::MatrixXd jac(face_point_jacobian(j, f, uv));
    for (size_t i = 0; i < uv.size(); ++i) {
      const Vector3d x = clay::surface::evaluate(s, uv[i].x(), uv[i].y());
      for (Eigen::Index point = 0; point < lattice.points.rows(); ++point) {
        // The map is linear in the points: a central difference with h = 1 mm is exact to
        // rounding, every coordinate the same.
        BezierLattice plus = lattice, minus = lattice;
        plus.points(point, 1) += 1;
        minus.points(point, 1) -= 1;
        const Vector3d d = (deform_point(plus, x) - deform_point(minus, x)) / 2;
        worst = std::max(worst, std::abs(d.y() - jac(static_cast<Eigen::Index>(i), point)));
        worst = std::max(worst, std::abs(d.x()) + std::abs(d.z()));
        largest = std::max(largest, std::abs(d.y()));
      }
    }
  }
  CHECK(largest > 0.1);
  CHECK(worst <= 1e-10 * largest);
  // A (u, v) outside the face is refused, named.
  const auto [category, message] =
      clay::test::error_of([&] { (void)face_point_jacobian(j, 0, {Vector2d(-1e9, 0)}); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Catch::Matchers::Contains("is outside face 0's domain"));
}

TEST_CASE("mass_property_gradients: a real part's volume and centroid against differences") {
  const Model block = read(TestModel::FilletedBlock, "block-mass.step");
  const BezierLattice lattice =
      shaken(make_bezier_lattice(frame_around(block, 0.1), {2, 2, 1}), 0.8, 11);
  const ModelJacobian j = model_jacobian(lattice, block);
  const LatticeMassGradients g = mass_property_gradients(j);
  CHECK(g.value.volume_mm3 == Approx(clay::brep::volume_mm3(j.model)).epsilon(1e-13));
  std::mt19937 rng(13);
  std::normal_distribution<double> normal(0, 1);
  Points3 direction(lattice.points.rows(), 3);
  for (Eigen::Index r = 0; r < direction.rows(); ++r)
    for (int c = 0; c < 3; ++c) direction(r, c) = normal(rng);
  auto at = [&](double h) {
    return clay::brep::mass_properties(deformed_model(j, lattice.points + h * direction));
  };
  // The volume is a cubic in the points: the 5-point difference is exact (to rounding).
  const double dv = derivative([&](double h) { return at(h).volume_mm3; }, 0.05);
  CHECK(dot(g.volume, direction) == Approx(dv).epsilon(1e-10));
  for (int i = 0; i < 3; ++i) {
    const double dc = derivative([&](double h) { return at(h).centroid_mm[i]; }, 0.01);
    CHECK(dot(g.centroid[static_cast<size_t>(i)], direction) == Approx(dc).epsilon(1e-9));
  }
  const double di = derivative([&](double h) { return at(h).inertia_mm5(2, 2); }, 0.01);
  CHECK(dot(g.inertia[2], direction) == Approx(di).epsilon(1e-9));
  // One lattice point's coordinate at a time.
  for (const auto& [point, axis] : {std::pair{0, 0}, std::pair{4, 2}, std::pair{13, 1}}) {
    Points3 unit_move = Points3::Zero(lattice.points.rows(), 3);
    unit_move(point, axis) = 1;
    const double d = derivative(
        [&](double h) {
          return clay::brep::volume_mm3(deformed_model(j, lattice.points + h * unit_move));
        },
        0.05);
    CHECK(g.volume(point, axis) == Approx(d).epsilon(1e-10));
  }
}

TEST_CASE("mass_property_gradients: solids under an affine lattice against closed forms") {
  // x -> o + A (x - o) + b through a trilinear lattice; moving its points along A0 (x - o) changes
  // the volume by det A tr(A⁻¹ A0) V0 and the centroid by A0 (g0 - o).
  const TestModel which = GENERATE(TestModel::Sphere, TestModel::Cone, TestModel::FilletedBlock);
  const Model solid = read(which, "solid" + std::to_string(static_cast<int>(which)) + ".step");
  const BezierLattice lattice = make_bezier_lattice(frame_around(solid, 0.1), {1, 1, 1});
  const Vector3d o = lattice.frame.origin;
  Matrix3d a, a0;
  a << 1.1, 0.2, 0.0, -0.1, 0.95, 0.15, 0.05, 0.0, 1.2;
  a0 << 0.3, -0.1, 0.2, 0.4, -0.2, 0.1, 0.0, 0.25, 0.5;
  const Vector3d b(1, 2, -3);
  BezierLattice mapped = lattice;
  Points3 direction(lattice.points.rows(), 3);
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r) {
    const Vector3d x = lattice.points.row(r).transpose() - o;
    mapped.points.row(r) = (o + a * x + b).transpose();
    direction.row(r) = (a0 * x).transpose();
  }
  const auto v0 = clay::brep::mass_properties(solid);
  const LatticeMassGradients g = mass_property_gradients(model_jacobian(mapped, solid));
  CHECK(g.value.volume_mm3 == Approx(a.determinant() * v0.volume_mm3).epsilon(1e-12));
  CHECK(dot(g.volume, direction) ==
        Approx(a.determinant() * (a.inverse() * a0).trace() * v0.volume_mm3).epsilon(1e-11));
  const Vector3d dg = a0 * (v0.centroid_mm - o);
  for (int i = 0; i < 3; ++i)
    CHECK(dot(g.centroid[static_cast<size_t>(i)], direction) ==
          Approx(dg[i]).margin(1e-11 * dg.norm()));
}

TEST_CASE("keep_properties: 100 random drags of a real solid keep its volume to 1e-12") {
  const Model block = read(TestModel::FilletedBlock, "block-keep.step");
  const BezierLattice lattice = make_bezier_lattice(frame_around(block, 0.1), {2, 2, 1});
  const ModelJacobian j = model_jacobian(lattice, block);
  const double v0 = clay::brep::volume_mm3(j.model);
  std::mt19937 rng(17);
  std::uniform_int_distribution<int> pick(0, static_cast<int>(lattice.points.rows()) - 1);
  std::normal_distribution<double> normal(0, 1.0);
  Points3 points = lattice.points;
  KeptProperties keep;
  keep.volume_mm3 = v0;
  double worst = 0;
  int steps = 0, largest_steps = 0;
  for (int drag = 0; drag < 100; ++drag) {
    const int point = pick(rng);
    Points3 moved = points;
    moved.row(point) += Eigen::RowVector3d(normal(rng), normal(rng), normal(rng));
    keep.held = {point};  // the dragged point stays under the cursor
    const KeptMove kept = keep_properties(j, moved, keep);
    CHECK(kept.points.row(point) == moved.row(point));
    // measured by volume_mm3 (its own rule), not by the correction's
    const double v = clay::brep::volume_mm3(deformed_model(j, kept.points));
    worst = std::max(worst, std::abs(v - v0) / v0);
    steps += kept.iterations;
    largest_steps = std::max(largest_steps, kept.iterations);
    points = kept.points;
  }
  INFO("Newton steps " << steps << " in all, at most " << largest_steps << " per drag");
  CHECK(worst <= 1e-12);
  // And by deform_model's own composition of the final lattice.
  BezierLattice final_lattice = lattice;
  final_lattice.points = points;
  DeformationStack stack;
  stack.steps.push_back({final_lattice, "kept", true});
  CHECK(deform_model(stack, block).report.volume_after_mm3 == Approx(v0).epsilon(1e-12));
}

TEST_CASE("keep_properties: the centroid with the volume, and bad requests refused") {
  const Model sphere = read(TestModel::Sphere, "sphere-keep.step");
  // The knot plane z = 0 through the centre: the sphere meets it along its equator, a knot line,
  // where a B-spline lattice composes exactly.
  Frame frame;
  frame.origin = {-25, -25, -25};
  frame.s = {50, 0, 0};
  frame.t = {0, 50, 0};
  frame.u = {0, 0, 50};
  const BSplineLattice lattice = make_bspline_lattice(frame, {2, 2, 2}, {1, 1, 2});
  const ModelJacobian j = model_jacobian(lattice, sphere);
  const auto before = clay::brep::mass_properties(j.model);
  Points3 moved = lattice.points;
  moved.row(lattice.index(2, 2, 3)) += Eigen::RowVector3d(2, 1, -1);
  KeptProperties keep;
  keep.volume_mm3 = before.volume_mm3;
  keep.centroid_mm = before.centroid_mm;
  keep.held = {static_cast<int>(lattice.index(2, 2, 3))};
  const KeptMove kept = keep_properties(j, moved, keep);
  const auto after = clay::brep::mass_properties(deformed_model(j, kept.points));
  CHECK(std::abs(after.volume_mm3 / before.volume_mm3 - 1) <= 1e-12);
  CHECK((after.centroid_mm - before.centroid_mm).norm() <= 1e-11);
  CHECK((kept.points - moved).norm() > 1e-3);  // it did correct

  using clay::ErrorCategory;
  CHECK(clay::test::error_of([&] { (void)keep_properties(j, moved, KeptProperties{}); }).second ==
        "invalid argument: keep_properties: nothing to keep; give a volume, a centroid, an area, "
        "fixed faces or symmetry planes");
  KeptProperties all = keep;
  all.held.clear();
  for (int p = 0; p < static_cast<int>(lattice.points.rows()); ++p) all.held.push_back(p);
  const auto [category, message] =
      clay::test::error_of([&] { (void)keep_properties(j, moved, all); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Catch::Matchers::Contains("hold fewer points"));
  KeptProperties nothing = keep;
  nothing.volume_mm3 = 0;
  CHECK_THAT(clay::test::error_of([&] { (void)keep_properties(j, moved, nothing); }).second,
             Catch::Matchers::Contains("the volume to keep is 0 mm^3"));
  KeptProperties wrong = keep;
  wrong.held = {999};
  CHECK_THAT(clay::test::error_of([&] { (void)keep_properties(j, moved, wrong); }).second,
             Catch::Matchers::Contains("held point 999 does not exist; the lattice has 36 points"));
  CHECK_THAT(
      clay::test::error_of([&] { (void)deformed_model(j, Points3::Zero(3, 3)); }).second,
      Catch::Matchers::Contains("3 lattice points given, but the Jacobian was taken for 36"));
}

TEST_CASE("keep_properties: a symmetry plane and the volume, checked by the pointwise FFD") {
  // The sphere in a lattice symmetric about x = 0: a point dragged (held), its mirror follows,
  // the volume is kept; the FFD of the corrected lattice commutes with the reflection at random
  // points (F(R x) = R F(x), the pointwise deform_point, not the Jacobian), so the sphere's
  // centroid stays on the plane.
  const Model sphere = read(TestModel::Sphere, "sphere-symmetry.step");
  Frame frame;
  frame.origin = {-25, -25, -25};
  frame.s = {50, 0, 0};
  frame.t = {0, 50, 0};
  frame.u = {0, 0, 50};
  BezierLattice lattice = make_bezier_lattice(frame, {2, 2, 2});
  const ModelJacobian j = model_jacobian(lattice, sphere);
  const auto before = clay::brep::mass_properties(j.model);
  const int dragged = static_cast<int>(lattice.index(2, 1, 2));
  Points3 moved = lattice.points;
  moved.row(dragged) += Eigen::RowVector3d(3, 2, -1.5);
  KeptProperties keep;
  keep.volume_mm3 = before.volume_mm3;
  keep.symmetry_planes = {SymmetryPlane{Vector3d::Zero(), Vector3d(2, 0, 0)}};
  keep.held = {dragged};
  const KeptMove kept = keep_properties(j, moved, keep);
  CHECK(kept.points.row(dragged) == moved.row(dragged));
  CHECK(kept.linear_error_mm <= 1e-12);
  const int mirror = static_cast<int>(lattice.index(0, 1, 2));
  const auto after = clay::brep::mass_properties(deformed_model(j, kept.points));
  CHECK(std::abs(after.volume_mm3 / before.volume_mm3 - 1) <= 1e-12);
  CHECK(std::abs(after.centroid_mm.x()) <= 1e-10);
  lattice.points = kept.points;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> in(-24, 24);
  const Eigen::Matrix3d reflect = Eigen::Vector3d(-1, 1, 1).asDiagonal();
  for (int k = 0; k < 50; ++k) {
    const Vector3d x(in(rng), in(rng), in(rng));
    CHECK((deform_point(lattice, reflect * x) - reflect * deform_point(lattice, x)).norm() <=
          1e-12 * 50);
  }
  // the mirror point sits where the dragged one's reflection does
  CHECK((kept.points.row(mirror) - kept.points.row(dragged) * reflect).norm() <= 1e-12 * 50);
  // The centroid kept too: its x cannot move under mirrored moves of a symmetric part (its
  // projected gradient vanishes), so it leaves the Newton system, still checked; y and z are
  // corrected. A target off the plane cannot be reached: refused, naming the component.
  KeptProperties centred = keep;
  centred.centroid_mm = before.centroid_mm;
  const KeptMove both = keep_properties(j, moved, centred);
  const auto measured = clay::brep::mass_properties(deformed_model(j, both.points));
  CHECK((measured.centroid_mm - before.centroid_mm).norm() <= 1e-11);
  CHECK(std::abs(measured.volume_mm3 / before.volume_mm3 - 1) <= 1e-12);
  KeptProperties aside = centred;
  aside.centroid_mm = before.centroid_mm + Vector3d(1, 0, 0);
  CHECK_THAT(clay::test::error_of([&] { (void)keep_properties(j, moved, aside); }).second,
             Catch::Matchers::Contains("hold the centroid x where it is"));
  // An unsymmetric lattice is refused, named.
  KeptProperties off = keep;
  off.symmetry_planes = {SymmetryPlane{Vector3d(1, 0, 0), Vector3d(1, 0, 0)}};
  CHECK_THAT(clay::test::error_of([&] { (void)keep_properties(j, moved, off); }).second,
             Catch::Matchers::Contains("has no mirror image across symmetry plane 0"));
}

TEST_CASE("keep_properties: a fixed face stays put exactly while the volume is kept") {
  // The filleted block's bottom face fixed, a top lattice point dragged: the bottom face's
  // control points (deformed_model, the Jacobian's own composition) where they were to 1e-12 of
  // the size, the volume by volume_mm3 to 1e-12. Holding the points above and below the face at
  // once (both dragged) cannot keep it: refused, named.
  const Model block = read(TestModel::FilletedBlock, "block-fixed.step");
  const BezierLattice lattice = make_bezier_lattice(frame_around(block, 0.1), {2, 2, 1});
  const ModelJacobian j = model_jacobian(lattice, block);
  int bottom = 0;
  double lowest = 1e300;
  for (std::size_t f = 0; f < j.model.faces.size(); ++f) {
    const double z = j.model.faces[f].surface.points.col(2).maxCoeff();
    if (z < lowest) {
      lowest = z;
      bottom = static_cast<int>(f);
    }
  }
  const double v0 = clay::brep::volume_mm3(j.model);
  const int top = static_cast<int>(lattice.index(1, 1, 1));
  Points3 moved = lattice.points;
  moved.row(top) += Eigen::RowVector3d(2, -1, 4);
  KeptProperties keep;
  keep.volume_mm3 = v0;
  keep.fixed_faces = {bottom};
  keep.held = {top};
  const KeptMove kept = keep_properties(j, moved, keep);
  const Model after = deformed_model(j, kept.points);
  const double size = 80;
  CHECK((after.faces[static_cast<std::size_t>(bottom)].surface.points -
         j.model.faces[static_cast<std::size_t>(bottom)].surface.points)
            .cwiseAbs()
            .maxCoeff() <= 1e-12 * size);
  CHECK(kept.linear_error_mm <= 1e-12 * size);
  CHECK(std::abs(clay::brep::volume_mm3(after) / v0 - 1) <= 1e-12);
  CHECK((kept.points - moved).norm() > 1e-3);  // the bottom layer and the volume corrected it
  KeptProperties both = keep;
  const int below = static_cast<int>(lattice.index(1, 1, 0));
  moved.row(below) += Eigen::RowVector3d(0, 0, 1);
  both.held = {top, below};
  CHECK_THAT(clay::test::error_of([&] { (void)keep_properties(j, moved, both); }).second,
             Catch::Matchers::Contains("move a fixed face or break a symmetry plane"));
  KeptProperties missing = keep;
  missing.fixed_faces = {999};
  CHECK_THAT(clay::test::error_of([&] { (void)keep_properties(j, moved, missing); }).second,
             Catch::Matchers::Contains("fixed face 999 does not exist"));
}

TEST_CASE("keep_properties: the area kept, measured by surface_area") {
  const Model sphere = read(TestModel::Sphere, "sphere-area.step");
  const BezierLattice lattice = make_bezier_lattice(frame_around(sphere, 0.2), {2, 2, 2});
  const ModelJacobian j = model_jacobian(lattice, sphere);
  const double a0 = clay::brep::surface_area(j.model).area_mm2;
  const int dragged = static_cast<int>(lattice.index(2, 2, 1));
  Points3 moved = lattice.points;
  moved.row(dragged) += Eigen::RowVector3d(4, 3, 1);
  KeptProperties keep;
  keep.area_mm2 = a0;
  keep.held = {dragged};
  const KeptMove kept = keep_properties(j, moved, keep);
  const auto after = clay::brep::surface_area(deformed_model(j, kept.points));
  CHECK(std::abs(after.area_mm2 / a0 - 1) <= 1e-12);
  CHECK(kept.area_error <= 1e-13);
  CHECK(clay::brep::surface_area(deformed_model(j, moved)).area_mm2 > a0 * (1 + 1e-3));
}

TEST_CASE("model_jacobian: a face crossing the lattice's boundary is refused, named") {
  const Model block = read(TestModel::FilletedBlock, "block-boundary.step");
  Frame frame = frame_around(block, 0.1);
  frame.s *= 0.5;  // half the block sticks out along x
  const auto [category, message] = clay::test::error_of([&] {
    (void)model_jacobian(make_bezier_lattice(frame, {1, 1, 1}), block);
  });
  CHECK(category == clay::ErrorCategory::OutOfDomain);
  CHECK_THAT(message, Catch::Matchers::StartsWith("out of domain: model_jacobian: face "));
}

TEST_CASE("mass_property_gradients: real exporters' files with gaps, against differences") {
  // CATIA's bolt (7 faces, edges open by up to 5e-5 mm), SolidWorks' plate with holes (30
  // faces) and AutoCAD's two solids with voids (76 faces, gaps up to 0.01 mm): the gradient is the
  // derivative of the figure as computed, gaps and all, so a translation of the lattice changes
  // nothing, a scaling about a point changes the volume by 3 V, and the 5-point difference along a
  // random move agrees to 1e-10.
  const std::string file =
      GENERATE(std::string("catia_v5r13_xr2_bolt_ap214.stp"),
               std::string("solidworks2018_base_interface_plate_holes_ap214.STEP"),
               std::string("autocad2000i_k1_brep_with_voids_ap203.stp"));
  const Model m = clay::brep::flattened(
      clay::brep::read_model(std::filesystem::path(CLAY_TEST_CAD_DIR) / file).model);
  const Frame frame = frame_around(m, 0.1);
  BezierLattice lattice = make_bezier_lattice(frame, {2, 2, 2});
  std::mt19937 rng(1);
  std::normal_distribution<double> normal(0, 1);
  const Eigen::RowVector3d size(frame.s.norm(), frame.t.norm(), frame.u.norm());
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r)
    for (int c = 0; c < 3; ++c) lattice.points(r, c) += 0.02 * size[c] * normal(rng);
  const ModelJacobian j = model_jacobian(lattice, m);
  const LatticeMassGradients g = mass_property_gradients(j);
  INFO(file << ": " << m.faces.size() << " faces, volume " << g.value.volume_mm3);
  const Eigen::RowVector3d sum = g.volume.colwise().sum();
  CHECK(sum.norm() <= 1e-12 * g.volume.cwiseAbs().sum());
  const Eigen::RowVector3d middle = lattice.points.colwise().mean();
  const Points3 scaling = lattice.points.rowwise() - middle;
  CHECK(dot(g.volume, scaling) == Approx(3 * g.value.volume_mm3).epsilon(1e-12));
  Points3 direction(lattice.points.rows(), 3);
  for (Eigen::Index r = 0; r < direction.rows(); ++r)
    for (int c = 0; c < 3; ++c) direction(r, c) = size[c] * normal(rng);
  const double dv = derivative(
      [&](double h) {
        return clay::brep::mass_properties(deformed_model(j, lattice.points + h * direction))
            .volume_mm3;
      },
      1e-3);
  CHECK(dot(g.volume, direction) == Approx(dv).epsilon(1e-10));
}
