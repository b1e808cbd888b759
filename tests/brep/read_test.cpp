// Reading whole models (clay/brep/exchange.hpp): models built by OpenCASCADE (boxes with fillets,
// holes and a pocket, a sphere, a torus, a cone, a revolved bottle, an assembly with colours,
// loose IGES faces) are written as STEP or IGES, read into brep::Model, and compared with
// OpenCASCADE's own reading of the same file: the same topology counts, every face on the
// original surface, every edge on its faces (brep::problems, sampled independently), and names,
// colours and placements as written.
#include <catch2/catch.hpp>

#include <clay/brep/exchange.hpp>
#include <clay/surface/evaluate.hpp>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "error_of.hpp"
#include "occt/test_models.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using clay::brep::BodyKind;
using clay::brep::Model;
using clay::brep::read_model;
using clay::surface::occt_reference::TestModel;

namespace {

fs::path output(const std::string& name) {
  const fs::path folder = fs::path(CLAY_TEST_OUTPUT_DIR) / "brep";
  fs::create_directories(folder);
  return folder / name;
}

fs::path written(TestModel model, const std::string& name) {
  const fs::path file = output(name);
  clay::surface::occt_reference::write_test_model(model, file);
  return file;
}

/// Random points on each face's (untrimmed) surface, face by face.
std::vector<std::vector<Eigen::Vector3d>> surface_samples(const Model& m, int per_face) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<std::vector<Eigen::Vector3d>> out;
  for (const auto& face : m.faces) {
    const auto [u0, u1] = face.surface.u.domain();
    const auto [v0, v1] = face.surface.v.domain();
    auto& points = out.emplace_back();
    for (int k = 0; k < per_face; ++k)
      points.push_back(clay::surface::evaluate(face.surface, u0 + (u1 - u0) * unit(rng),
                                               v0 + (v1 - v0) * unit(rng)));
  }
  return out;
}

/// The checks every clean model passes: OpenCASCADE's counts, no broken invariant, every face
/// on the original surface to 1e-12 of the size, re-derived pcurves within 1e-9 of the size.
void check_against_occt(const fs::path& file, const clay::brep::ImportedModel& read) {
  const auto facts = clay::surface::occt_reference::facts_of_file(file);
  const auto c = clay::brep::counts(read.model);
  INFO(read.report.brief());
  CHECK(facts.valid);
  CHECK(c.solids == facts.solids);
  CHECK(c.faces == facts.faces);
  CHECK(c.edges == facts.edges);
  CHECK(c.vertices == facts.vertices);
  CHECK(read.report.counts == c);
  for (const auto& problem : read.report.problems) UNSCOPED_INFO(problem);
  CHECK(read.report.problems.empty());
  CHECK(read.report.size_mm > 0);
  CHECK(read.report.max_rederivation_error_mm <= 1e-9 * read.report.size_mm);
  CHECK(read.report.max_edge_gap_mm <= read.report.max_edge_tolerance_mm);
  const double distance = clay::surface::occt_reference::max_distance_to_surfaces(
      file, surface_samples(read.model, 200));
  CHECK(distance <= 1e-12 * read.report.size_mm);
}

bool near(const std::optional<clay::brep::Colour>& c, double r, double g, double b) {
  return c && std::abs(c->r - r) < 1e-6 && std::abs(c->g - g) < 1e-6 && std::abs(c->b - b) < 1e-6;
}

}  // namespace

TEST_CASE("read_model: a filleted block with holes and a pocket is one valid solid") {
  const fs::path file = written(TestModel::FilletedBlock, "block.step");
  const auto read = read_model(file);
  check_against_occt(file, read);
  const auto c = clay::brep::counts(read.model);
  CHECK(c.bodies == 1);
  CHECK(c.inner_loops >= 2);              // the hole rims on the bottom and top faces
  CHECK(read.report.faces_angular >= 6);  // 4 fillets, 2 holes
  REQUIRE(read.model.bodies.size() == 1);
  CHECK(read.model.bodies[0].kind == BodyKind::Solid);
  CHECK(read.model.bodies[0].name == "block");
  CHECK(near(read.model.bodies[0].colour, 0.8, 0.5, 0.2));
  int named = 0;
  for (const auto& face : read.model.faces)
    if (face.name == "top") {
      ++named;
      CHECK(near(face.colour, 0.1, 0.3, 0.9));
    }
  CHECK(named == 1);
}

TEST_CASE("read_model: a sphere keeps its seam and its two poles") {
  const fs::path file = written(TestModel::Sphere, "sphere.step");
  const auto read = read_model(file);
  check_against_occt(file, read);
  const auto c = clay::brep::counts(read.model);
  CHECK(c.faces == 1);
  CHECK(c.degenerate_edges == 2);
  CHECK(c.coedges == 4);  // the seam twice, the two poles
}

TEST_CASE("read_model: a torus, a cone and a revolved bottle") {
  for (const auto& [model, name] :
       {std::pair{TestModel::Torus, "torus.step"}, std::pair{TestModel::Cone, "cone.step"},
        std::pair{TestModel::Bottle, "bottle.step"}}) {
    INFO(name);
    const fs::path file = written(model, name);
    const auto read = read_model(file);
    check_against_occt(file, read);
    CHECK(clay::brep::counts(read.model).solids == 1);
  }
}

TEST_CASE("read_model: STEP and IGES of the same solid give the same topology") {
  const fs::path step = written(TestModel::FilletedBlock, "block-same.step");
  const fs::path iges = written(TestModel::FilletedBlock, "block-same.igs");
  const auto a = read_model(step);
  const auto b = read_model(iges);
  check_against_occt(iges, b);
  CHECK(clay::brep::counts(a.model).faces == clay::brep::counts(b.model).faces);
  CHECK(clay::brep::counts(a.model).edges == clay::brep::counts(b.model).edges);
}

TEST_CASE("read_model: an assembly keeps its tree, names, colours and placements") {
  const fs::path file = written(TestModel::Assembly, "assembly.step");
  const auto read = read_model(file);
  const Model& m = read.model;
  INFO(read.report.brief());
  CHECK(read.report.problems.empty());
  REQUIRE(m.is_assembly());
  REQUIRE(m.roots.size() == 1);
  const auto& top = m.parts[static_cast<size_t>(m.roots[0].part)];
  CHECK(top.name == "bracket assembly");
  REQUIRE(top.components.size() == 3);
  int pins = 0, plates = 0;
  for (const auto& instance : top.components) {
    const auto& part = m.parts[static_cast<size_t>(instance.part)];
    if (part.name == "pin") {
      ++pins;
      CHECK(near(part.colour, 0.1, 0.1, 0.8));
      const Eigen::Vector3d t = instance.placement.translation();
      CHECK((std::abs(t.x() - 10) < 1e-12 || std::abs(t.x() - 40) < 1e-12));
      CHECK(std::abs(t.y() - 15) < 1e-12);
      CHECK(std::abs(t.z() - 5) < 1e-12);
      CHECK(instance.placement.linear().isIdentity(1e-15));
    } else if (part.name == "plate") {
      ++plates;
      CHECK(near(part.colour, 0.8, 0.1, 0.1));
    }
  }
  CHECK(pins == 2);
  CHECK(plates == 1);
  // The pin is stored once and placed twice.
  CHECK(clay::brep::counts(m).solids == 2);
}

TEST_CASE("read_model: loose IGES faces stay loose, or are sewn into a solid on request") {
  const fs::path file = written(TestModel::LooseFaces, "faces.igs");
  const auto loose = read_model(file);
  CHECK(loose.report.problems.empty());
  REQUIRE(loose.model.bodies.size() == 1);
  CHECK(loose.model.bodies[0].kind == BodyKind::Sheet);
  CHECK(clay::brep::counts(loose.model).faces == 6);

  clay::brep::ModelReadOptions options;
  options.sew = true;
  const auto sewn = read_model(file, options);
  INFO(sewn.report.brief());
  CHECK(sewn.report.problems.empty());
  const auto c = clay::brep::counts(sewn.model);
  CHECK(c.solids == 1);
  CHECK(c.faces == 6);
  CHECK(c.edges == 12);
  CHECK(c.vertices == 8);
  REQUIRE(!sewn.report.healing.empty());
  CHECK_THAT(sewn.report.healing.front(), Contains("sewed 6 loose faces"));
}

TEST_CASE("read_model: bad files and options raise clay::Error naming the file") {
  using clay::ErrorCategory;
  using clay::test::error_of;
  auto [missing, missing_text] = error_of([] { read_model(output("nowhere.step")); });
  CHECK(missing == ErrorCategory::Io);
  CHECK_THAT(missing_text, Contains("nowhere.step"));

  const fs::path text = output("model.txt");
  std::ofstream(text) << "solid\n";
  auto [unknown, unknown_text] = error_of([&] { read_model(text); });
  CHECK(unknown == ErrorCategory::InvalidArgument);
  CHECK_THAT(unknown_text, Contains("extension"));

  const fs::path garbage = output("garbage.step");
  std::ofstream(garbage) << "this is not a STEP file\n";
  CHECK(error_of([&] { read_model(garbage); }).first == ErrorCategory::Exchange);

  // A truncated file: the first half of a valid one.
  const fs::path whole = written(TestModel::FilletedBlock, "whole.step");
  std::string bytes;
  {
    std::ifstream in(whole, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const fs::path truncated = output("truncated.step");
  std::ofstream(truncated, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  auto [cut, cut_text] = error_of([&] { read_model(truncated); });
  CHECK(cut == ErrorCategory::Exchange);
  CHECK_THAT(cut_text, Contains("truncated.step"));

  clay::brep::ModelReadOptions options;
  options.sewing_tolerance_mm = 0;
  auto [bad, bad_text] = error_of([&] { read_model(whole, options); });
  CHECK(bad == ErrorCategory::InvalidArgument);
  CHECK_THAT(bad_text, Contains("sewing_tolerance_mm"));
}
