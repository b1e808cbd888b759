// Meshes of whole models: tessellate() and write_model's .glb preview. Checked against closed
// forms (volumes by the divergence theorem on the triangles), the analytic surfaces the faces
// were read from (no triangle inside a hole), and an independent glTF reader.
#include <catch2/catch.hpp>

#include <clay/brep/volume.hpp>
#include <clay/occt/model_exchange.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <string>
#include <tuple>

#include "error_of.hpp"
#include "gltf_reader.hpp"
#include "occt_test_models.hpp"
#include "test_files.hpp"

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using clay::brep::ElementaryKind;
using clay::brep::Model;
using clay::brep::ModelMesh;
using clay::surface::occt_reference::TestModel;
using Eigen::Vector3d;

namespace {

fs::path output(const std::string& name) { return clay::test::test_output("brep-mesh", name); }

Model read(TestModel model, const std::string& name) {
  return clay::test::read_test_model(model, output(name));
}

/// The volume the triangles enclose (divergence theorem: each triangle's tetrahedron with the
/// origin), and their area.
std::pair<double, double> volume_and_area(const ModelMesh& mesh) {
  double volume = 0, area = 0;
  for (const auto& t : mesh.triangles) {
    const Vector3d& a = mesh.positions[static_cast<std::size_t>(t[0])];
    const Vector3d& b = mesh.positions[static_cast<std::size_t>(t[1])];
    const Vector3d& c = mesh.positions[static_cast<std::size_t>(t[2])];
    volume += a.dot(b.cross(c)) / 6;
    area += (b - a).cross(c - a).norm() / 2;
  }
  return {volume, area};
}

/// The block's volume in closed form (as in read_test.cpp): 60 x 40 x 20, four vertical fillets
/// r 5, two holes r 4 through, a pocket 12 x 16 x 8 deep.
double block_volume() {
  const double pi = std::numbers::pi;
  return 48000 - 4 * (25 - 25 * pi / 4) * 20 - 2 * pi * 16 * 20 - 12 * 16 * 8;
}

/// How many triangle edges are not matched by the same edge, run the other way, in another
/// triangle (positions compared bit for bit): 0 for a closed, consistently oriented mesh.
int unmatched_edges(const ModelMesh& mesh) {
  using Key = std::tuple<double, double, double, double, double, double>;
  std::map<Key, int> count;
  auto key = [&](int a, int b) {
    const Vector3d& p = mesh.positions[static_cast<std::size_t>(a)];
    const Vector3d& q = mesh.positions[static_cast<std::size_t>(b)];
    return Key{p.x(), p.y(), p.z(), q.x(), q.y(), q.z()};
  };
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++count[key(t[static_cast<std::size_t>(k)], t[(k + 1) % 3])];
  int unmatched = 0;
  for (const auto& [edge, n] : count) {
    const auto& [x0, y0, z0, x1, y1, z1] = edge;
    const auto other = count.find(Key{x1, y1, z1, x0, y0, z0});
    unmatched += other == count.end() || other->second != n;
  }
  return unmatched;
}

}  // namespace

TEST_CASE("tessellate: the filleted block's mesh has its holes and encloses its volume") {
  const Model block = read(TestModel::FilletedBlock, "block.step");
  const ModelMesh mesh = clay::brep::tessellate(block);
  INFO(mesh.triangles.size() << " triangles, deflection " << mesh.max_deflection_mm << " mm");
  REQUIRE(mesh.triangles.size() == mesh.triangle_face.size());
  REQUIRE(mesh.positions.size() == mesh.normals.size());
  REQUIRE(mesh.face_colours.size() == block.faces.size());
  CHECK(mesh.triangles.size() > 100);
  // The mesher's target is 5e-4 of the size (the block's box diagonal, 74.8 mm): 0.037 mm.
  const double target = 5e-4 * std::sqrt(60.0 * 60 + 40 * 40 + 20 * 20);
  CHECK(mesh.max_deflection_mm <= 2 * target);
  // Closed and consistently oriented: every edge of a triangle is run the other way by another.
  CHECK(unmatched_edges(mesh) == 0);
  // The volume: within the area times the largest deflection of the closed form. The holes alone
  // are 2011 mm^3, so a mesh that covered them would miss by far more.
  const auto [volume, area] = volume_and_area(mesh);
  CHECK(std::abs(volume - block_volume()) <= area * mesh.max_deflection_mm);
  CHECK(std::abs(volume - block_volume()) <= 1e-3 * block_volume());
  // No triangle of a plane lies inside a hole: its centroid is at least the radius (less the
  // mesher's chord error) from each hole's axis, taken from the cylinders the faces were read as.
  std::vector<clay::brep::Elementary> holes;
  for (const auto& face : block.faces)
    if (face.elementary && face.elementary->kind == ElementaryKind::Cylinder &&
        face.elementary->radius == 4)
      holes.push_back(*face.elementary);
  REQUIRE(holes.size() == 2);
  double nearest = INFINITY;
  int on_planes = 0;
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k) {
    const auto& face = block.faces[static_cast<std::size_t>(mesh.triangle_face[k])];
    if (!face.elementary || face.elementary->kind != ElementaryKind::Plane) continue;
    ++on_planes;
    Vector3d centroid = Vector3d::Zero();
    for (int corner : mesh.triangles[k])
      centroid += mesh.positions[static_cast<std::size_t>(corner)] / 3;
    for (const auto& hole : holes) {
      const Vector3d d = centroid - hole.origin;
      nearest = std::min(nearest, (d - d.dot(hole.z_axis) * hole.z_axis).norm());
    }
  }
  CHECK(on_planes > 0);
  CHECK(nearest >= 4 - target);
  // Normals: unit, and on the outer side: along the triangle's own normal.
  int along = 0;
  for (const auto& t : mesh.triangles) {
    const Vector3d& a = mesh.positions[static_cast<std::size_t>(t[0])];
    const Vector3d n = (mesh.positions[static_cast<std::size_t>(t[1])] - a)
                           .cross(mesh.positions[static_cast<std::size_t>(t[2])] - a);
    along += n.dot(mesh.normals[static_cast<std::size_t>(t[0])]) > 0;
  }
  CHECK(along == static_cast<int>(mesh.triangles.size()));
  for (const Vector3d& n : mesh.normals) CHECK(std::abs(n.norm() - 1) <= 1e-12);
  // The colours: the top face's own, the others the body's.
  for (std::size_t f = 0; f < block.faces.size(); ++f)
    CHECK(mesh.face_colours[f] ==
          (block.faces[f].colour ? block.faces[f].colour : block.bodies[0].colour));
}

TEST_CASE("tessellate: a sphere's poles get unit normals, and finer options give a finer mesh") {
  const Model sphere = read(TestModel::Sphere, "sphere.step");
  const ModelMesh coarse = clay::brep::tessellate(sphere);
  clay::brep::MeshOptions fine_options;
  fine_options.relative_deflection = 5e-5;
  const ModelMesh fine = clay::brep::tessellate(sphere, fine_options);
  CHECK(fine.triangles.size() > 2 * coarse.triangles.size());
  CHECK(fine.max_deflection_mm < coarse.max_deflection_mm);
  for (const ModelMesh* mesh : {&coarse, &fine}) {
    CHECK(unmatched_edges(*mesh) == 0);
    for (const Vector3d& n : mesh->normals) CHECK(std::abs(n.norm() - 1) <= 1e-12);
    const auto [volume, area] = volume_and_area(*mesh);
    const double exact = 4 * std::numbers::pi * 1000 / 3;
    CHECK(std::abs(volume - exact) <= area * mesh->max_deflection_mm);
    // Outward: at every node the normal points away from the centre.
    for (std::size_t i = 0; i < mesh->positions.size(); ++i)
      CHECK(mesh->normals[i].dot(mesh->positions[i].normalized()) >= 1 - 1e-3);
  }
}

TEST_CASE("tessellate: an assembly is meshed instance by instance, in world coordinates") {
  const Model assembly = read(TestModel::Assembly, "assembly.step");
  const Model flat = clay::brep::flattened(assembly);
  const ModelMesh mesh = clay::brep::tessellate(assembly);
  REQUIRE(mesh.face_body.size() == flat.faces.size());
  CHECK(unmatched_edges(mesh) == 0);
  const auto [volume, area] = volume_and_area(mesh);
  const double exact = clay::brep::volume_mm3(assembly);
  CHECK(std::abs(volume - exact) <= area * mesh.max_deflection_mm);
  int coloured = 0;
  for (std::size_t f = 0; f < flat.faces.size(); ++f) {
    const int b = mesh.face_body[f];
    REQUIRE(b >= 0);
    CHECK(mesh.face_colours[f] == (flat.faces[f].colour
                                       ? flat.faces[f].colour
                                       : flat.bodies[static_cast<std::size_t>(b)].colour));
    coloured += mesh.face_colours[f].has_value();
  }
  CHECK(coloured > 0);
}

TEST_CASE("write_model: a .glb preview holds the trimmed mesh, instances placed") {
  for (const auto& [model, name] :
       {std::pair{TestModel::FilletedBlock, "block"}, std::pair{TestModel::Assembly, "assembly"}}) {
    INFO(name);
    const Model m = read(model, std::string(name) + ".step");
    const fs::path glb = output(std::string(name) + ".glb");
    fs::remove(glb);
    const auto check = clay::brep::write_model(m, glb);
    CHECK(check.valid);
    const ModelMesh mesh = clay::brep::tessellate(m);
    const auto triangles = clay::test::read_glb(glb.string());
    CHECK(triangles.triangles.size() == mesh.triangles.size());
    double volume = 0;
    for (const auto& t : triangles.triangles) volume += t[0].dot(t[1].cross(t[2])) / 6;
    const auto [mesh_volume, area] = volume_and_area(mesh);
    // glTF stores single precision: the same mesh to float rounding.
    CHECK(std::abs(volume - mesh_volume) <= 1e-5 * std::abs(mesh_volume));
    CHECK(std::abs(triangles.area() - area) <= 1e-5 * area);
  }
}

TEST_CASE("tessellate and the .glb preview refuse bad options, naming the field") {
  const Model sphere = read(TestModel::Sphere, "sphere-bad.step");
  clay::brep::MeshOptions options;
  options.relative_deflection = 0;
  const auto e = clay::test::error_of([&] { clay::brep::tessellate(sphere, options); });
  CHECK(e.first == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(e.second, Contains("MeshOptions::relative_deflection = 0 must be in [1e-6, 0.1]"));
  clay::brep::ModelWriteOptions write;
  write.mesh.angular_deflection_rad = 2;
  const fs::path glb = output("bad.glb");
  fs::remove(glb);
  const auto w = clay::test::error_of([&] { clay::brep::write_model(sphere, glb, write); });
  CHECK(w.first == clay::ErrorCategory::InvalidArgument);
  CHECK_THAT(w.second, Contains("MeshOptions::angular_deflection_rad = 2 must be in [0.01, 1]"));
  CHECK(!fs::exists(glb));
}
