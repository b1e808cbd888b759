// deform_model (clay/deform/model_deformation.hpp) on whole models built by OpenCASCADE and read
// from STEP: the deformed model is valid for brep::problems and for BRepCheck, has the same
// counts, keeps its pcurves bit for bit, and each face equals the pointwise deformation of the
// original inside its trims; a uniform scale changes the volume by its determinant; faces a
// local lattice leaves alone are kept bit for bit.
#include <catch2/catch.hpp>

#include <clay/brep/volume.hpp>
#include <clay/deform/model_deformation.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/surface/evaluate.hpp>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "error_of.hpp"
#include "hand_models.hpp"
#include "occt/test_files.hpp"
#include "occt_test_models.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using clay::brep::Model;
using clay::deform::DeformationStack;
using clay::surface::occt_reference::TestModel;
using clay::test::trilinear;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

fs::path output(const std::string& name) { return clay::test::test_output("brep-deform", name); }

Model read(TestModel model, const std::string& name) {
  return clay::test::read_test_model(model, output(name));
}

/// The loops of a face as polygons in (u, v), 64 points per coedge.
std::vector<std::vector<Vector2d>> polygons(const Model& m, const clay::brep::Face& face) {
  std::vector<std::vector<Vector2d>> out;
  for (const auto& loop : face.loops) {
    auto& poly = out.emplace_back();
    for (const auto& co : loop.coedges) {
      const auto& e = m.edges[static_cast<size_t>(co.edge)];
      for (int k = 0; k < 64; ++k) {
        const double w = k / 64.0;
        const double t = co.same_sense ? e.t0 + (e.t1 - e.t0) * w : e.t1 - (e.t1 - e.t0) * w;
        poly.push_back(clay::surface::evaluate(co.pcurve, t).head<2>());
      }
    }
  }
  return out;
}

/// Even-odd rule over every loop.
bool inside(const std::vector<std::vector<Vector2d>>& loops, const Vector2d& p) {
  bool in = false;
  for (const auto& poly : loops)
    for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++)
      if ((poly[i].y() > p.y()) != (poly[j].y() > p.y()) &&
          p.x() <
              (poly[j].x() - poly[i].x()) * (p.y() - poly[i].y()) / (poly[j].y() - poly[i].y()) +
                  poly[i].x())
        in = !in;
  return in;
}

/// The largest distance, over `per_face` random parameters inside each face's trims, between
/// the deformed face and the pointwise deformation of the original face.
double max_pointwise_deviation(const DeformationStack& stack, const Model& before,
                               const Model& after, int per_face, int& samples) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(0, 1);
  double worst = 0;
  samples = 0;
  for (size_t f = 0; f < before.faces.size(); ++f) {
    const auto& face = before.faces[f];
    const auto loops = polygons(before, face);
    const auto [u0, u1] = face.surface.u.domain();
    const auto [v0, v1] = face.surface.v.domain();
    for (int found = 0, tries = 0; found < per_face && tries < 100 * per_face; ++tries) {
      const Vector2d uv(u0 + (u1 - u0) * unit(rng), v0 + (v1 - v0) * unit(rng));
      if (!face.loops.empty() && !inside(loops, uv)) continue;
      ++found;
      ++samples;
      const Vector3d expected =
          clay::deform::deform_point(stack, clay::surface::evaluate(face.surface, uv.x(), uv.y()));
      worst = std::max(
          worst,
          (clay::surface::evaluate(after.faces[f].surface, uv.x(), uv.y()) - expected).norm());
    }
  }
  return worst;
}

/// The undisplaced trilinear lattice on [-20, 20]^3.
clay::deform::BezierLattice around_origin() {
  clay::deform::Frame frame;
  frame.origin = {-20, -20, -20};
  frame.s = {40, 0, 0};
  frame.t = {0, 40, 0};
  frame.u = {0, 0, 40};
  return clay::deform::make_bezier_lattice(frame, {1, 1, 1});
}

}  // namespace

TEST_CASE("deform_model: a filleted block with holes through a trilinear lattice, exactly") {
  const Model block = read(TestModel::FilletedBlock, "block.step");
  const DeformationStack stack = trilinear({-5, -5, -5}, {65, 45, 25}, {6, 4, 5});
  const auto result = clay::deform::deform_model(stack, block);
  const auto& r = result.report;
  INFO(r.brief());
  CHECK(r.counts == clay::brep::counts(block));
  CHECK(r.faces_exact == 17);
  CHECK(r.faces_refit == 0);
  CHECK(r.edges_refit == 0);
  CHECK(r.max_certified_bound_mm == 0);
  // Green's-theorem volumes against the Jacobian's coefficient bounds (independent computations).
  REQUIRE(r.volume_ratio_bounded);
  const double ratio = r.volume_after_mm3 / r.volume_before_mm3;
  CHECK(ratio >= r.volume_ratio_min);
  CHECK(ratio <= r.volume_ratio_max);
  CHECK(r.volume_ratio_max > 1);  // the raised corner grows the block
  const double size = 75;         // the block's diagonal is 74.8 mm
  CHECK(r.max_edge_gap_mm <= 1e-9 * size);
  CHECK(r.max_deviation_mm <= 1e-12 * size);
  // Pcurves kept bit for bit.
  int kept = 0, coedges = 0;
  for (size_t f = 0; f < block.faces.size(); ++f)
    for (size_t l = 0; l < block.faces[f].loops.size(); ++l)
      for (size_t c = 0; c < block.faces[f].loops[l].coedges.size(); ++c) {
        ++coedges;
        kept += clay::surface::identical(block.faces[f].loops[l].coedges[c].pcurve,
                                         result.model.faces[f].loops[l].coedges[c].pcurve);
      }
  CHECK(kept == coedges);
  // Each face is the pointwise deformation of the original inside its trims.
  int samples = 0;
  const double deviation = max_pointwise_deviation(stack, block, result.model, 1000, samples);
  CHECK(samples >= 17 * 1000);
  CHECK(deviation <= 1e-12 * size);
  // OpenCASCADE finds it valid, in memory and read back from STEP, with the same counts.
  const auto check = clay::brep::check_model(result.model);
  INFO(check.brief());
  CHECK(check.valid);
  const fs::path written = output("block-deformed.step");
  clay::brep::write_model(result.model, written);
  const auto facts = clay::surface::occt_reference::facts_of_file(written);
  CHECK(facts.valid);
  CHECK(facts.solids == 1);
  CHECK(facts.faces == 17);
  CHECK(facts.edges == clay::brep::counts(block).edges);
  CHECK(std::abs(facts.volume - r.volume_after_mm3) <= 1e-6 * r.volume_after_mm3);
}

TEST_CASE("deform_model: a loft with trimmed holes (B-spline faces) through a lattice, exactly") {
  const fs::path file = output("loft.step");
  const Model loft = clay::test::read_test_model(TestModel::LoftWithHoles, file);
  // Read as OpenCASCADE reads it: one solid, a B-spline side face holding four holes.
  const auto facts = clay::surface::occt_reference::facts_of_file(file);
  const auto counts = clay::brep::counts(loft);
  CHECK(counts.solids == 1);
  CHECK(counts.faces == facts.faces);
  CHECK(counts.edges == facts.edges);
  CHECK(counts.inner_loops >= 4);
  CHECK(clay::brep::problems(loft).empty());
  CHECK(std::abs(clay::brep::volume_mm3(loft) - facts.volume) <= 1e-6 * facts.volume);
  const DeformationStack stack = trilinear({-40, -25, -5}, {40, 25, 65}, {5, -4, 6});
  const auto result = clay::deform::deform_model(stack, loft);
  const auto& r = result.report;
  INFO(r.brief());
  CHECK(r.counts == counts);
  CHECK(r.faces_exact == counts.faces);
  CHECK(r.faces_refit == 0);
  const double size = 100;  // the loft's box is 60 x 30 x 60 mm (diagonal 90)
  CHECK(r.max_deviation_mm <= 1e-12 * size);
  int samples = 0;
  const double deviation = max_pointwise_deviation(stack, loft, result.model, 1000, samples);
  CHECK(samples >= counts.faces * 1000);
  CHECK(deviation <= 1e-12 * size);
  CHECK(clay::brep::problems(result.model).empty());
  REQUIRE(r.volume_ratio_bounded);
  const double ratio = r.volume_after_mm3 / r.volume_before_mm3;
  CHECK(ratio >= r.volume_ratio_min);
  CHECK(ratio <= r.volume_ratio_max);
  const auto check = clay::brep::check_model(result.model);
  INFO(check.brief());
  CHECK(check.valid);
  // Written and read back by OpenCASCADE: valid, the same counts, its volume agrees with ours.
  const fs::path written = output("loft-deformed.step");
  clay::brep::write_model(result.model, written);
  const auto after = clay::surface::occt_reference::facts_of_file(written);
  CHECK(after.valid);
  CHECK(after.faces == counts.faces);
  CHECK(after.edges == counts.edges);
  CHECK(std::abs(after.volume - r.volume_after_mm3) <= 1e-6 * r.volume_after_mm3);
}

TEST_CASE("deform_model: a uniform scale changes the volume by its determinant") {
  const Model sphere = read(TestModel::Sphere, "sphere.step");
  // The lattice [-20, 20]^3 scaled by 1.1 about the origin: an affine map of determinant 1.331.
  auto lattice = around_origin();
  lattice.points *= 1.1;
  DeformationStack stack;
  stack.steps.push_back({lattice, "scale", true});
  const auto result = clay::deform::deform_model(stack, sphere);
  INFO(result.report.brief());
  CHECK(std::abs(result.report.volume_after_mm3 / result.report.volume_before_mm3 - 1.331) <=
        1e-9 * 1.331);
  // The Jacobian's bounds are the determinant itself (a constant), widened to 1 outside.
  CHECK(result.report.volume_ratio_bounded);
  CHECK(result.report.volume_ratio_min == 1);
  CHECK(std::abs(result.report.volume_ratio_max - 1.331) <= 1e-12);
  // An affine lattice keeps every degree.
  for (size_t f = 0; f < sphere.faces.size(); ++f) {
    CHECK(result.model.faces[f].surface.u.degree == sphere.faces[f].surface.u.degree);
    CHECK(result.model.faces[f].surface.v.degree == sphere.faces[f].surface.v.degree);
  }
  CHECK(clay::brep::check_model(result.model).valid);
}

TEST_CASE("frame_around: a lattice around a model or its faces, grown by a margin") {
  const Model sphere = read(TestModel::Sphere, "sphere.step");
  const clay::brep::Box box = clay::brep::control_box(sphere);
  // The control box holds every mesh-free sample of every face (convex hull property).
  for (const auto& f : sphere.faces)
    for (double u : {0.0, 0.37, 1.0})
      for (double v : {0.0, 0.61, 1.0}) {
        const auto [u0, u1] = f.surface.u.domain();
        const auto [v0, v1] = f.surface.v.domain();
        const Vector3d p =
            clay::surface::evaluate(f.surface, u0 + u * (u1 - u0), v0 + v * (v1 - v0));
        CHECK((p.array() >= box.lo.array() - 1e-12).all());
        CHECK((p.array() <= box.hi.array() + 1e-12).all());
      }
  const clay::deform::Frame frame = clay::deform::frame_around(sphere, 0.1);
  const Vector3d extent = box.hi - box.lo;
  CHECK((frame.origin - (box.lo - 0.1 * extent)).norm() <= 1e-12 * extent.norm());
  CHECK(std::abs(frame.s.x() - 1.2 * extent.x()) <= 1e-12 * extent.norm());
  CHECK(frame.s.y() == 0);
  CHECK(std::abs(frame.u.z() - 1.2 * extent.z()) <= 1e-12 * extent.norm());
  // A lattice around it, moved affinely (a stretch by 1.2 along x): the volume by 1.2 exactly.
  auto lattice = clay::deform::make_bezier_lattice(frame, {1, 1, 1});
  for (Eigen::Index r = 0; r < lattice.points.rows(); ++r)
    lattice.points(r, 0) = frame.origin.x() + 1.2 * (lattice.points(r, 0) - frame.origin.x());
  DeformationStack stack;
  stack.steps.push_back({lattice, "stretch", true});
  const auto stretched = clay::deform::deform_model(stack, sphere);
  CHECK(std::abs(clay::brep::volume_mm3(stretched.model) / clay::brep::volume_mm3(sphere) - 1.2) <=
        1e-9 * 1.2);
  // A flat selection (one planar face of a block) still gets a lattice with volume.
  const Model block = read(TestModel::FilletedBlock, "block-frame.step");
  int planar = -1;
  for (std::size_t f = 0; f < block.faces.size() && planar < 0; ++f) {
    const clay::brep::Box b = clay::brep::control_box(block, {static_cast<int>(f)});
    if ((b.hi - b.lo).minCoeff() == 0) planar = static_cast<int>(f);
  }
  REQUIRE(planar >= 0);
  CHECK(std::abs(clay::deform::frame_around(block, 0.05, {planar}).volume()) > 0);
  // Errors name the argument and the rule.
  const auto [margin_category, margin_message] =
      clay::test::error_of([&] { (void)clay::deform::frame_around(sphere, 0.0); });
  CHECK(margin_category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(margin_message, Contains("margin 0 must lie in (0, 10]"));
  const auto [face_category, face_message] =
      clay::test::error_of([&] { (void)clay::brep::control_box(sphere, {99}); });
  CHECK(face_category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(face_message, Contains("face 99 does not exist"));
  CHECK(clay::test::error_of([&] { (void)clay::brep::control_box(Model{}); }).first ==
        clay::ErrorCategory::InvalidArgument);
}

TEST_CASE("deform_model: trimmed faces on carriers larger than the lattice compose exactly") {
  // Issue #39 item 7: "face 42: cannot be composed exactly: out of domain". The cube [0, 10]^3
  // with each face's plane carried on three times its size (u, v in [-1, 2], the trims on
  // [0, 1]^2): the lattice [-1, 11]^3 holds every trim, not the carriers. Each face is composed
  // on the box of its pcurves (surface::restricted: the same (u, v)), exactly.
  Model cube = clay::test::cube(10);
  for (auto& face : cube.faces) {
    const auto& p = face.surface.points;  // bilinear: rows (0,0), (0,1), (1,0), (1,1)
    const Vector3d o = p.row(0).transpose();
    const Vector3d e1 = p.row(2).transpose() - o, e2 = p.row(1).transpose() - o;
    clay::surface::Points3 big(4, 3);
    big.row(0) = (o - e1 - e2).transpose();
    big.row(1) = (o - e1 + 2 * e2).transpose();
    big.row(2) = (o + 2 * e1 - e2).transpose();
    big.row(3) = (o + 2 * e1 + 2 * e2).transpose();
    face.surface = clay::surface::make_surface({1, {-1, -1, 2, 2}}, {1, {-1, -1, 2, 2}}, big);
  }
  REQUIRE(clay::brep::problems(cube).empty());
  const auto stack = trilinear({-1, -1, -1}, {11, 11, 11}, {1.5, -1, 2});
  const auto result = clay::deform::deform_model(stack, cube);
  INFO(result.report.brief());
  CHECK(result.report.faces_restricted == 6);
  CHECK(result.report.faces_exact == 6);
  CHECK(clay::brep::problems(result.model).empty());
  CHECK_THAT(result.report.brief(), Contains("6 faces composed on the part of their surface"));
  // Each face at the same (u, v) inside its trims is the lattice's map of the original point.
  const auto& lattice = std::get<clay::deform::BezierLattice>(stack.steps[0].deformation);
  double worst = 0;
  for (std::size_t f = 0; f < cube.faces.size(); ++f)
    for (double u : {0.0, 0.3, 1.0})
      for (double v : {0.0, 0.8, 1.0}) {
        const Vector3d expected = clay::deform::deform_point(
            lattice, clay::surface::evaluate(cube.faces[f].surface, u, v));
        worst = std::max(
            worst,
            (clay::surface::evaluate(result.model.faces[f].surface, u, v) - expected).norm());
      }
  CHECK(worst <= 1e-12 * 10);
  CHECK(clay::brep::check_model(result.model).valid);
}

TEST_CASE("deform_model: faces a local lattice leaves alone are kept bit for bit") {
  const Model pair = read(TestModel::Separated, "pair.step");
  // Around the sphere only (centre (50, 10, 10), r 5).
  const DeformationStack stack = trilinear({43, 3, 3}, {57, 17, 17}, {2, -1, 3});
  const auto result = clay::deform::deform_model(stack, pair);
  INFO(result.report.brief());
  CHECK(result.report.faces_untouched == 6);  // the box
  CHECK(result.report.faces_exact == 1);      // the sphere
  int identical = 0;
  for (size_t f = 0; f < pair.faces.size(); ++f)
    identical += clay::surface::identical(pair.faces[f].surface, result.model.faces[f].surface);
  CHECK(identical == 6);
  for (size_t e = 0; e < pair.edges.size(); ++e)
    if (!pair.edges[e].degenerate && pair.edges[e].curve.points.col(0).maxCoeff() < 30)
      CHECK(clay::surface::identical(pair.edges[e].curve, result.model.edges[e].curve));
  CHECK(clay::brep::check_model(result.model).valid);
  // ... and keep their type: the box's faces are still planes, in the model and in the file;
  // the deformed sphere is a sphere no more.
  int planes = 0, spheres = 0;
  for (const auto& face : result.model.faces) {
    planes += face.elementary && face.elementary->kind == clay::brep::ElementaryKind::Plane;
    spheres += face.elementary && face.elementary->kind == clay::brep::ElementaryKind::Sphere;
  }
  CHECK(planes == 6);
  CHECK(spheres == 0);
  const fs::path file = output("pair-deformed.step");
  CHECK(clay::brep::write_model(result.model, file).valid);
  const auto facts = clay::surface::occt_reference::facts_of_file(file);
  CHECK(facts.planes == 6);
  CHECK(facts.other_surfaces == 1);
}

TEST_CASE("deform_model: a mirroring lattice reverses the solid's faces") {
  const Model sphere = read(TestModel::Sphere, "sphere-mirror.step");
  auto lattice = around_origin();
  lattice.points.col(0) *= -1;  // x -> -x
  DeformationStack stack;
  stack.steps.push_back({lattice, "mirror", true});
  const auto result = clay::deform::deform_model(stack, sphere);
  CHECK(result.report.solids_reversed == 1);
  CHECK(result.report.volume_after_mm3 == Approx(result.report.volume_before_mm3).epsilon(1e-12));
  CHECK(clay::brep::check_model(result.model).valid);
}

TEST_CASE("deform_model: a model leaving the lattice is refused, naming the face") {
  const Model block = read(TestModel::FilletedBlock, "block-leaves.step");
  // The lattice holds only the left half of the block.
  const DeformationStack stack = trilinear({-5, -5, -5}, {30, 45, 25}, {3, 0, 0});
  auto [category, text] =
      clay::test::error_of([&] { (void)clay::deform::deform_model(stack, block); });
  CHECK(category == clay::ErrorCategory::OutOfDomain);
  CHECK_THAT(text, Contains("face "));
  clay::deform::ModelDeformationOptions options;
  options.max_degree = 0;
  CHECK(clay::test::error_of([&] {
          (void)clay::deform::deform_model(stack, block, options);
        }).first == clay::ErrorCategory::InvalidArgument);
}

TEST_CASE("deform_model: a bend refits every face and edge, certified, and stays valid") {
  const Model block = read(TestModel::FilletedBlock, "block-bend.step");
  clay::deform::Bend bend;
  bend.frame.origin = {30, 20, 10};
  bend.frame.axis = {1, 0, 0};  // bend along the block's length
  bend.frame.reference = {0, 0, 1};
  bend.y_min = -40;  // the whole block inside the bent region, where the bend is smooth
  bend.y_max = 40;
  bend.center = 0;
  bend.rate = 0.01;  // radius 100 mm
  DeformationStack stack;
  stack.steps.push_back({bend, "arch", true});
  clay::deform::ModelDeformationOptions options;
  clay::deform::RefitOptions refit;
  refit.relative_tolerance = 0;
  refit.tolerance_mm = 1e-3;  // 1 micrometre
  options.surface.refit = refit;
  const auto result = clay::deform::deform_model(stack, block, options);
  const auto& r = result.report;
  INFO(r.brief());
  CHECK(r.faces_refit == 17);
  CHECK(r.max_certified_bound_mm > 0);
  CHECK(r.max_certified_bound_mm <= 1e-3);
  // Every edge gap within its tolerance, and the tolerances within what the bounds allow.
  for (const auto& g : clay::brep::edge_gaps(result.model)) {
    const auto& e = result.model.edges[static_cast<size_t>(g.edge)];
    CHECK(g.gap_mm <= e.tolerance_mm);
    CHECK(e.tolerance_mm <= block.edges[static_cast<size_t>(g.edge)].tolerance_mm +
                                2 * r.max_certified_bound_mm + 1e-9 * 75);
  }
  // Each face within the certified bound of the pointwise bend inside its trims.
  int samples = 0;
  CHECK(max_pointwise_deviation(stack, block, result.model, 200, samples) <=
        r.max_certified_bound_mm);
  CHECK(clay::brep::check_model(result.model).valid);
  // Without a refit tolerance the bend is refused, naming the face.
  auto [category, text] =
      clay::test::error_of([&] { (void)clay::deform::deform_model(stack, block); });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(text, Contains("face 0"));
}

TEST_CASE("deform_model: an open shell in a solid is refused, naming the shell") {
  Model block = read(TestModel::FilletedBlock, "block-open.step");
  block.bodies[0].shells[0].faces.pop_back();  // a hole in the solid
  const DeformationStack stack = trilinear({-5, -5, -5}, {65, 45, 25}, {6, 4, 5});
  auto [category, text] =
      clay::test::error_of([&] { (void)clay::deform::deform_model(stack, block); });
  CHECK(category == clay::ErrorCategory::InvalidGeometry);
  CHECK_THAT(text, Contains("shell 0"));
}

TEST_CASE("deform_model: max_degree refits exact results above it, certified") {
  const Model block = read(TestModel::FilletedBlock, "block-degree.step");
  const DeformationStack stack = trilinear({-5, -5, -5}, {65, 45, 25}, {6, 4, 5});
  clay::deform::ModelDeformationOptions options;
  options.max_degree = 2;  // the trilinear lattice (total degree 3) gives degree 3 and more
  auto [category, text] =
      clay::test::error_of([&] { (void)clay::deform::deform_model(stack, block, options); });
  CHECK(category == clay::ErrorCategory::DegreeLimit);
  CHECK_THAT(text, Contains("above max_degree 2"));
  clay::deform::RefitOptions refit;
  refit.relative_tolerance = 0;
  refit.tolerance_mm = 1e-3;
  options.surface.refit = refit;
  const auto result = clay::deform::deform_model(stack, block, options);
  INFO(result.report.brief());
  CHECK(result.report.faces_refit > 0);
  CHECK(result.report.max_certified_bound_mm <= 1e-3);
  for (const auto& face : result.model.faces) {
    CHECK(face.surface.u.degree <= 2);
    CHECK(face.surface.v.degree <= 2);
  }
  for (const auto& edge : result.model.edges)
    if (!edge.degenerate) CHECK(edge.curve.basis.degree <= 2);
  CHECK(clay::brep::check_model(result.model).valid);
}

TEST_CASE("deform_model: only the chosen faces deform, a shared edge that would tear is refused") {
  // The pair: a box [0, 20]^3 (faces 0-5) and a sphere at (50, 10, 10). A lattice over both,
  // with only the sphere chosen: the box stays bit for bit.
  const Model pair = read(TestModel::Separated, "pair-chosen.step");
  int sphere = -1;
  for (size_t f = 0; f < pair.faces.size(); ++f)
    if (pair.faces[f].elementary &&
        pair.faces[f].elementary->kind == clay::brep::ElementaryKind::Sphere)
      sphere = static_cast<int>(f);
  REQUIRE(sphere >= 0);
  const DeformationStack stack = trilinear({-5, -5, -5}, {60, 25, 25}, {3, 2, 4});
  clay::deform::ModelDeformationOptions options;
  options.faces = {sphere};
  const auto result = clay::deform::deform_model(stack, pair, options);
  INFO(result.report.brief());
  CHECK(result.report.faces_exact == 1);
  CHECK(result.report.faces_untouched == 6);
  for (size_t f = 0; f < pair.faces.size(); ++f)
    CHECK(clay::surface::identical(pair.faces[f].surface, result.model.faces[f].surface) ==
          (static_cast<int>(f) != sphere));
  // The sphere is the pointwise deformation of the original.
  const auto& before = pair.faces[static_cast<size_t>(sphere)].surface;
  const auto& after = result.model.faces[static_cast<size_t>(sphere)].surface;
  for (double u : {0.3, 2.0, 4.1})
    for (double v : {-1.0, 0.2, 1.2}) {
      const auto [u0, u1] = before.u.domain();
      const auto [v0, v1] = before.v.domain();
      const double a = u0 + (u1 - u0) * u / 6.3, b = v0 + (v1 - v0) * (v + 1.6) / 3.2;
      CHECK((clay::surface::evaluate(after, a, b) -
             clay::deform::deform_point(stack, clay::surface::evaluate(before, a, b)))
                .norm() <= 1e-12 * 60);
    }
  CHECK(clay::brep::check_model(result.model).valid);

  // The block's top alone under a lattice that lifts its rim: the rim is shared with the sides.
  const Model block = read(TestModel::FilletedBlock, "block-chosen.step");
  int top = -1;
  for (size_t f = 0; f < block.faces.size(); ++f)
    if (block.faces[f].name == "top") top = static_cast<int>(f);
  REQUIRE(top >= 0);
  clay::deform::ModelDeformationOptions only_top;
  only_top.faces = {top};
  const auto [category, message] = clay::test::error_of([&] {
    clay::deform::deform_model(trilinear({-5, -5, -5}, {65, 45, 25}, {6, 4, 5}), block, only_top);
  });
  CHECK(category == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("(\"top\") is deformed but face") &&
                          Contains("is not, and the stack moves their shared edge") &&
                          Contains("choose both faces"));
  only_top.faces = {99};
  const auto [c2, m2] =
      clay::test::error_of([&] { clay::deform::deform_model(stack, block, only_top); });
  CHECK(c2 == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(m2, Contains("names face 99, but the model has 17 faces"));
}
