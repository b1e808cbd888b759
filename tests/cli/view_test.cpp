// The view data of a run (issue #9): curvatures against closed forms (sphere, cylinder, plane),
// the .bin files read back and compared with the surfaces evaluated here, the manifest's fields,
// the refit deviation against the deformation applied pointwise; and the HTTP server of
// `clayform view` exercised in raw HTTP (tests/cli/raw_http.hpp).
#include <catch2/catch.hpp>

#include <clay/deform/regular.hpp>
#include <clay/occt/model_exchange.hpp>
#include <clay/recipe/recipe.hpp>
#include <clay/recipe/view.hpp>
#include <clay/serve.hpp>
#include <clay/surface/arc.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/tessellate.hpp>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "error_of.hpp"
#include "raw_http.hpp"

using namespace clay::recipe;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;
using clay::ErrorCategory;
using clay::test::error_of;
namespace surface = clay::surface;
namespace deform = clay::deform;
namespace fs = std::filesystem;
using Eigen::Vector3d;

namespace {

const double pi = std::acos(-1.0);

fs::path output_dir(const std::string& name) {
  const fs::path dir = fs::path(CLAY_TEST_OUTPUT_DIR) / name;
  fs::remove_all(dir);
  return dir;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void write_text(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary) << text;
}

std::vector<float> read_floats(const fs::path& file) {
  const std::string bytes = read_text(file);
  std::vector<float> f(bytes.size() / 4);
  for (std::size_t k = 0; k < f.size(); ++k) {  // little-endian float32, whatever the host
    std::uint32_t b = 0;
    for (int c = 3; c >= 0; --c)
      b = (b << 8) | static_cast<unsigned char>(bytes[4 * k + static_cast<std::size_t>(c)]);
    std::memcpy(&f[k], &b, 4);
  }
  return f;
}

/// A full sphere of radius r about c: an exact rational revolve of a half circle (poles at v = 0,
/// 1).
surface::BSplineSurface sphere(const Vector3d& c, double r) {
  const auto half =
      surface::circular_arc(c, Vector3d::UnitX(), Vector3d::UnitZ(), r, -pi / 2, pi / 2);
  surface::Axis axis;
  axis.point = c;
  return surface::revolve(half, axis, 360.0).surface;
}

std::string num(double x) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

/// The bicubic dome of recipe_test.cpp as inline recipe JSON (uneven knots, full-precision points).
std::string dome_json() {
  surface::BSplineBasis b{3, {0, 0, 0, 0, 0.3, 0.55, 1, 1, 1, 1}};
  const auto xi = surface::greville_abscissae(b);
  std::string pts;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      const double x = 100 * xi[static_cast<size_t>(i)], y = 100 * xi[static_cast<size_t>(j)];
      pts += std::string(pts.empty() ? "" : ",") + "[" + num(x) + "," + num(y) + "," +
             num(20 * std::sin(0.031 * x) * std::sin(0.029 * y) + 1.0 / 3.0) + "]";
    }
  return R"({"bspline": {"degrees": [3, 3], "knots_u": [0, 0, 0, 0, 0.3, 0.55, 1, 1, 1, 1],
            "knots_v": [0, 0, 0, 0, 0.3, 0.55, 1, 1, 1, 1], "points": [)" +
         pts + "]}}";
}

/// dome, a Bezier-lattice bulge (exact), a twist (refit within 0.01 mm), a style step (curves).
std::string stages_recipe() {
  return R"({"format": "clayform.recipe", "version": 1, "name": "viewtest",
    "curves": {
      "bound": {"arc": {"center": [50, 50, 25], "x_axis": [1, 0, 0], "y_axis": [0, 1, 0], "radius": 30, "start": 0, "end": 360}},
      "target": {"line": {"from": [35, 50, 30], "to": [65, 50, 30]}}},
    "surfaces": {
      "dome": )" +
         dome_json() + R"(,
      "bulged": {"deform": {"surface": "dome", "deformation": "shape"}},
      "spun": {"deform": {"surface": "dome", "deformation": "spin", "composition": {"mode": "refit", "tolerance_mm": 0.01}}},
      "styled": {"deform": {"surface": "dome", "deformation": "crease"}}},
    "deformations": {
      "shape": [{"kind": "bezier_lattice", "name": "bulge",
        "frame": {"origin": [-10, -10, -20], "s": [120, 0, 0], "t": [0, 120, 0], "u": [0, 0, 60]},
        "degrees": [2, 2, 1], "moves": [{"index": [1, 1, 1], "by": [3, -2, 15]}]}],
      "spin": [{"kind": "twist", "frame": {"origin": [50, 50, 0], "axis": [0, 0, 1], "reference": [1, 0, 0]}, "angle": [0, 0.01]}],
      "crease": [{"kind": "style", "name": "draft", "bound": "bound", "target": "target", "mode": "paper"}]},
    "exports": {"part": {"surfaces": ["bulged", "spun"], "formats": ["step"]},
                "other": {"surfaces": ["styled", "dome"], "formats": ["step"]}}})";
}

const RunResult& stages_run() {
  static const RunResult result = run_recipe(parse_recipe(stages_recipe()));
  return result;
}

}  // namespace

TEST_CASE("view parameters follow the knots, 8 per span, 17 to 161 in all", "[view]") {
  const surface::BSplineBasis cubic{3, {0, 0, 0, 0, 0.3, 0.55, 1, 1, 1, 1}};
  const auto t = view_parameters(cubic);
  REQUIRE(t.size() == 25);  // 3 spans x 8 + the end
  CHECK(t[8] == 0.3);
  CHECK(t[16] == 0.55);
  CHECK(t.front() == 0.0);
  CHECK(t.back() == 1.0);
  CHECK(view_parameters(surface::BSplineBasis{1, {0, 0, 1, 1}}).size() ==
        17);  // one span: at least 17
  CHECK(view_parameters(surface::clamped_uniform_basis(3, 43)).size() == 161);  // 40 spans x 4 + 1
  CHECK(view_parameters(surface::clamped_uniform_basis(3, 400)).size() == 161);
}

TEST_CASE("a sphere's mesh has K = 1 over r squared and a mean curvature of size 1 over r",
          "[view]") {
  const Vector3d c(3, -2, 5);
  const double r = 40;
  const auto s = sphere(c, r);
  const ViewMesh m = view_mesh(s);
  REQUIRE(m.rows == 33);  // around the axis: 4 quarter segments x 8 + 1
  REQUIRE(m.cols == 17);  // the half circle: 2 segments x 8 + 1
  int degenerate = 0;
  double worst_k = 0, worst_h = 0, worst_n = 0, worst_pole = 0;
  for (std::size_t k = 0; k < m.position.size(); ++k) {
    const Vector3d radial = (m.position[k] - c) / r;
    CHECK_THAT(radial.norm(), WithinAbs(1.0, 1e-13));
    // the revolve's S_u x S_v points outwards here: H is then negative (it bends away from the
    // normal)
    worst_k = std::max(worst_k, std::abs(m.gaussian[k] - 1 / (r * r)) * r * r);
    worst_h = std::max(worst_h, std::abs(m.mean[k] + 1 / r) * r);
    CHECK_THAT(m.normal[k].norm(), WithinAbs(1.0, 1e-14));
    if (m.degenerate[k]) {
      ++degenerate;
      // at a pole the limit normal, S_u x S_uv: the sphere's own normal there, along the axis
      const std::size_t j = k % static_cast<std::size_t>(m.cols);
      REQUIRE((j == 0 || j + 1 == static_cast<std::size_t>(m.cols)));
      worst_pole = std::max(worst_pole, (m.normal[k] - radial).norm());
    } else {
      worst_n = std::max(worst_n, (m.normal[k] - radial).norm());
    }
  }
  CHECK(degenerate == 2 * m.rows);  // both poles, every u sample
  CHECK(worst_k < 1e-10);
  CHECK(worst_h < 1e-10);
  CHECK(worst_n < 1e-13);
  CHECK(worst_pole < 1e-12);
}

TEST_CASE(
    "the view mesh is the kernel tessellator's: same grid, positions and normals, poles included",
    "[view]") {
  // One tessellator (issue #19): the viewer, the PNG renderer and the glTF preview shade alike.
  for (const auto& s : {sphere(Vector3d(3, -2, 5), 40), sphere(Vector3d(0, 0, 0), 0.5)}) {
    const ViewMesh m = view_mesh(s);
    const surface::GridMesh g = surface::tessellate(s);
    REQUIRE(m.rows == g.rows);
    REQUIRE(m.cols == g.cols);
    CHECK(m.us == g.us);
    CHECK(m.vs == g.vs);
    int poles = 0;
    for (std::size_t k = 0; k < m.position.size(); ++k) {
      const auto r = static_cast<Eigen::Index>(k);
      CHECK(m.position[k] == Vector3d(g.positions.row(r).transpose()));
      CHECK(m.normal[k] == Vector3d(g.normals.row(r).transpose()));
      poles += m.degenerate[k];
    }
    CHECK(poles == 2 * m.rows);
  }
}

TEST_CASE("a pole opened into a tiny ring, as a refit leaves it, is treated as degenerate",
          "[view]") {
  const Vector3d c(0, 0, 0);
  const double r = 40;
  auto s = sphere(c, r);
  // move the south pole's copies onto a ring of radius 1e-4 mm: the surface's K and H there are
  // of the order of 1/(1e-4 r) and 1e-4 / r^2 is the ring's share of S_u
  for (int i = 0; i < s.count_u(); ++i) {
    const double a = 2 * pi * i / (s.count_u() - 1);
    s.points.row(s.index(i, 0)) += 1e-4 * Eigen::RowVector3d(std::cos(a), std::sin(a), 0);
  }
  const ViewMesh m = view_mesh(s);
  double worst = 0;
  for (std::size_t k = 0; k < m.position.size(); ++k) {
    worst = std::max(worst, std::abs(m.gaussian[k] * r * r - 1));
    if (k % static_cast<std::size_t>(m.cols) == 0) CHECK(m.degenerate[k] == 1);
  }
  CHECK(worst < 1e-3);  // the neighbours' K, within the ring's disturbance of the next row
}

TEST_CASE("a cylinder's mesh has K = 0 and a mean curvature of size 1 over 2r", "[view]") {
  const double r = 30;
  surface::Points3 ends(2, 3);
  ends << r, 0, 0, r, 0, 80;
  const auto line = surface::make_curve(1, {0, 0, 1, 1}, ends);
  const auto can = surface::revolve(line, surface::Axis{}, 270.0).surface;
  const ViewMesh m = view_mesh(can);
  CHECK(m.rows == 25);
  CHECK(m.cols == 17);
  for (std::size_t k = 0; k < m.position.size(); ++k) {
    CHECK(m.degenerate[k] == 0);
    CHECK(std::abs(m.gaussian[k]) < 1e-15);
    CHECK_THAT(std::abs(m.mean[k]), WithinAbs(1 / (2 * r), 1e-14));
    const Vector3d radial = Vector3d(m.position[k].x(), m.position[k].y(), 0) / r;
    CHECK(std::abs(std::abs(m.normal[k].dot(radial)) - 1) < 1e-14);
    // sign: positive exactly when the normal points towards the axis
    CHECK(m.mean[k] * m.normal[k].dot(-radial) > 0);
  }
}

TEST_CASE("a plane's mesh has K = H = 0 and the plane's normal", "[view]") {
  // a bicubic patch in the plane through o spanned by a, b, with a wavy in-plane parametrization
  const Vector3d o(10, 20, 30), a = Vector3d(1, 2, 0.5).normalized(),
                                b = Vector3d(-2, 1, 0).normalized();
  const Vector3d n = a.cross(b).normalized();
  const auto basis = surface::clamped_uniform_basis(3, 6);
  surface::Points3 p(36, 3);
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) {
      const double x = 20.0 * i + 3 * std::sin(j), y = 15.0 * j + 4 * std::cos(1.7 * i);
      p.row(i * 6 + j) = (o + x * a + y * b).transpose();
    }
  const auto s = surface::make_surface(basis, basis, p);
  const ViewMesh m = view_mesh(s);
  for (std::size_t k = 0; k < m.position.size(); ++k) {
    CHECK(std::abs(m.gaussian[k]) < 1e-15);
    CHECK(std::abs(m.mean[k]) < 1e-12);
    CHECK((m.normal[k] - n).norm() < 1e-12);
  }
}

TEST_CASE("a whole model's view mesh: trimmed triangles, the cylinder's and the plane's curvature",
          "[view]") {
  // The label bottle: a cylinder r 15 for z in [0, 13] and [31, 40], a band r 16 for z in
  // [14, 30], a flat bottom at z = 0. With the outward normal, H = -1 / (2 r) on a cylinder.
  const clay::brep::Model bottle =
      clay::brep::read_model(fs::path(CLAY_EXAMPLES_DIR) / "models" / "label_bottle.step").model;
  const ViewMesh m = view_mesh(bottle);
  REQUIRE(m.rows == 0);
  REQUIRE(!m.triangles.empty());
  REQUIRE(m.gaussian.size() == m.position.size());
  REQUIRE(m.normal.size() == m.position.size());
  // Which face each node lies on, from the same (deterministic) mesh, and what that face is:
  // OpenCASCADE's mesher puts a cylinder's nodes on its rims, so nodes are told by their face.
  const clay::brep::Model flat = clay::brep::flattened(bottle);
  const clay::brep::ModelMesh mesh = clay::brep::tessellate(flat);
  REQUIRE(mesh.positions.size() == m.position.size());
  int cylinders = 0, planes = 0;
  for (std::size_t k = 0; k < m.position.size(); ++k) {
    CHECK(mesh.positions[k] == m.position[k]);
    const auto& e = flat.faces[static_cast<std::size_t>(mesh.node_face[k])].elementary;
    if (!e) continue;
    if (e->kind == clay::brep::ElementaryKind::Cylinder) {
      ++cylinders;
      CHECK(std::abs(m.gaussian[k]) <= 1e-9);
      CHECK(m.mean[k] == Approx(-1.0 / (2 * e->radius)).epsilon(1e-9));
      CHECK(std::abs(std::hypot(m.position[k].x(), m.position[k].y()) - e->radius) <= 1e-9);
    } else if (e->kind == clay::brep::ElementaryKind::Plane) {
      ++planes;
      CHECK(m.gaussian[k] == 0);
      CHECK(m.mean[k] == 0);
      CHECK(std::abs(m.normal[k].z()) == Approx(1));
    }
  }
  CHECK(cylinders > 40);
  CHECK(planes > 10);
  // view_floats then the triangles: what write_view_data writes for a model.
  CHECK(view_floats(m).size() == 9 * m.position.size());
}

TEST_CASE("write_outputs writes the view folder: manifest, meshes read back equal the surfaces",
          "[view]") {
  RunResult result = stages_run();
  const fs::path out = output_dir("view");
  write_outputs(result, out);
  const auto j = nlohmann::json::parse(read_text(out / "view" / "manifest.json"));
  CHECK(j["format"] == "clayform.view");
  CHECK(j["version"] == 1);
  CHECK(j["recipe"] == "viewtest");
  CHECK(j["report"] == "../report.json");
  CHECK(fs::is_regular_file(out / "view" / j["report"].get<std::string>()));
  REQUIRE(j["surfaces"].size() == 4);
  const std::vector<std::pair<std::string, std::string>> order{
      {"bulged", "part"}, {"spun", "part"}, {"styled", "other"}, {"dome", "other"}};
  for (std::size_t k = 0; k < 4; ++k) {
    CHECK(j["surfaces"][k]["name"] == order[k].first);
    CHECK(j["surfaces"][k]["export"] == order[k].second);
  }
  std::set<std::string> referenced;
  Vector3d lo = Vector3d::Constant(1e300), hi = -lo;
  // Every mesh: 36 R C bytes, positions equal to the surface evaluated at the view parameters,
  // unit normals.
  const auto check_mesh = [&](const nlohmann::json& mesh, const surface::BSplineSurface& s,
                              bool box) {
    const auto file = mesh["file"].get<std::string>();
    referenced.insert(file);
    const int rows = mesh["rows"], cols = mesh["cols"];
    const auto us = view_parameters(s.u), vs = view_parameters(s.v);
    REQUIRE(rows == static_cast<int>(us.size()));
    REQUIRE(cols == static_cast<int>(vs.size()));
    const std::size_t n = static_cast<std::size_t>(rows * cols);
    CHECK(fs::file_size(out / "view" / file) == 36 * n);
    const auto f = read_floats(out / "view" / file);
    REQUIRE(f.size() == 9 * n);
    double worst = 0, unit = 0;
    for (int i = 0; i < rows; ++i)
      for (int jj = 0; jj < cols; ++jj) {
        const std::size_t k = static_cast<std::size_t>(i * cols + jj);
        const Vector3d x =
            surface::evaluate(s, us[static_cast<std::size_t>(i)], vs[static_cast<std::size_t>(jj)]);
        const Vector3d p(f[3 * k], f[3 * k + 1], f[3 * k + 2]);
        const Vector3d nn(f[3 * n + 3 * k], f[3 * n + 3 * k + 1], f[3 * n + 3 * k + 2]);
        worst = std::max(worst, (p - x).norm());
        unit = std::max(unit, std::abs(nn.norm() - 1));
        if (box) {
          lo = lo.cwiseMin(x);
          hi = hi.cwiseMax(x);
        }
      }
    CHECK(worst < 2e-5);  // float32 of coordinates up to ~120 mm
    CHECK(unit < 1e-6);
    return f;
  };
  const auto deviation_of = [](const std::vector<float>& f) {
    const std::size_t n = f.size() / 9;
    return std::vector<float>(f.begin() + static_cast<std::ptrdiff_t>(8 * n), f.end());
  };
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& x = j["surfaces"][k];
    const auto& s = result.surface(order[k].first);
    check_mesh(x["mesh"], s, true);
    REQUIRE(x["net"]["rows"] == s.count_u());
    REQUIRE(x["net"]["cols"] == s.count_v());
    for (Eigen::Index r = 0; r < s.points.rows(); ++r)
      for (int c = 0; c < 3; ++c)
        CHECK(x["net"]["points"][static_cast<std::size_t>(r)][static_cast<std::size_t>(c)] ==
              s.points(r, c));
  }
  // dome: a parent, no stages, its build step's figures
  CHECK(j["surfaces"][3]["stages"].empty());
  CHECK(j["surfaces"][3]["figures"]["degree_u"] == 3);

  // bulged: one exact lattice step, deviation 0 everywhere
  const auto& bulged = j["surfaces"][0];
  REQUIRE(bulged["stages"].size() == 1);
  const auto& st0 = bulged["stages"][0];
  CHECK(st0["step"] == "surfaces.bulged.steps[0]");
  CHECK(st0["kind"] == "bezier_lattice");
  CHECK(st0["label"] == "bezier_lattice 'bulge'");
  CHECK(st0["figures"]["composition"] == "exact");
  CHECK(bulged["figures"] == st0["figures"]);
  CHECK(st0["curves"].empty());
  for (float d : deviation_of(check_mesh(st0["after"], result.surface("bulged"), false)))
    CHECK(d == 0.0f);
  for (float d : deviation_of(check_mesh(st0["before"], result.surface("dome"), false)))
    CHECK(d == 0.0f);
  CHECK(st0["net_before"]["points"].size() == 36);

  // spun: a refitted twist; the deviation is |fit - twist(dome)|, within the refit's tolerance and
  // > 0
  const auto& spun = j["surfaces"][1];
  REQUIRE(spun["stages"].size() == 1);
  const auto& st1 = spun["stages"][0];
  CHECK(st1["figures"]["composition"] == "refit");
  CHECK(spun["mesh"]["file"] == st1["after"]["file"]);  // the final mesh is the last stage's after
  const auto f = check_mesh(st1["after"], result.surface("spun"), false);
  const auto dev = deviation_of(f);
  deform::Twist twist;
  twist.frame.origin = {50, 50, 0};
  twist.angle = {0, 0.01};
  const auto& parent = result.surface("dome");
  const auto& fit = result.surface("spun");
  const auto us = view_parameters(fit.u), vs = view_parameters(fit.v);
  float most = 0;
  double worst = 0;
  for (std::size_t i = 0; i < us.size(); ++i)
    for (std::size_t jj = 0; jj < vs.size(); ++jj) {
      const std::size_t k = i * vs.size() + jj;
      const double expected =
          (surface::evaluate(fit, us[i], vs[jj]) -
           deform::deform_point(twist, surface::evaluate(parent, us[i], vs[jj])))
              .norm();
      worst = std::max(worst, std::abs(dev[k] - expected));
      most = std::max(most, dev[k]);
    }
  CHECK(worst < 1e-9);
  CHECK(most > 0.0f);
  CHECK(most <= 0.01f);
  CHECK(static_cast<double>(most) <= st1["figures"]["max_deviation_mm"].get<double>() * (1 + 1e-6));

  // styled: the style step's curves, 200 samples each, on the curves
  const auto& styled = j["surfaces"][2];
  REQUIRE(styled["stages"].size() == 1);
  const auto& st2 = styled["stages"][0];
  CHECK(st2["label"] == "style 'draft'");
  REQUIRE(st2["curves"].size() == 2);
  CHECK(st2["curves"][0]["name"] == "bound");
  CHECK(st2["curves"][1]["name"] == "target");
  for (const auto& c : st2["curves"]) {
    REQUIRE(c["points"].size() == 200);
    const auto& curve = result.curve(c["name"].get<std::string>());
    const auto [t0, t1] = curve.basis.domain();
    for (std::size_t k : {std::size_t{0}, std::size_t{77}, std::size_t{199}}) {
      const Vector3d x = surface::evaluate(curve, t0 + (t1 - t0) * static_cast<double>(k) / 199.0);
      const auto& p = c["points"][k];
      CHECK((Vector3d(p[0], p[1], p[2]) - x).norm() < 1e-12);
    }
  }
  for (float d : deviation_of(check_mesh(st2["after"], result.surface("styled"), false)))
    CHECK(d == 0.0f);

  // the box of every final mesh
  for (int c = 0; c < 3; ++c) {
    CHECK_THAT(j["box"]["min"][static_cast<std::size_t>(c)].get<double>(), WithinAbs(lo[c], 1e-9));
    CHECK_THAT(j["box"]["max"][static_cast<std::size_t>(c)].get<double>(), WithinAbs(hi[c], 1e-9));
  }
  // every .bin is referenced, none left over; a second run into the folder replaces them all
  std::set<std::string> files;
  for (const auto& e : fs::directory_iterator(out / "view"))
    if (e.path().extension() == ".bin") files.insert(e.path().filename().string());
  CHECK(files == referenced);
  RunResult parent_only = run_recipe(parse_recipe(
      R"({"format": "clayform.recipe", "version": 1, "name": "p",
      "surfaces": {"dome": )" +
      dome_json() + R"(}, "exports": {"d": {"surfaces": ["dome"], "formats": ["step"]}}})"));
  write_outputs(parent_only, out);
  int bins = 0;
  for (const auto& e : fs::directory_iterator(out / "view")) bins += e.path().extension() == ".bin";
  CHECK(bins == 1);
  CHECK(nlohmann::json::parse(read_text(out / "view" / "manifest.json"))["recipe"] == "p");
}

namespace {

/// A run folder with view data and a fake front end, for the server.
struct ServedFolders {
  fs::path run, dist;
  /// In a folder of the test's own (`name`): ctest runs the test cases in parallel, and two that
  /// shared one removed each other's files.
  explicit ServedFolders(const std::string& name) {
    const fs::path base = output_dir(name);
    run = base / "run";
    dist = base / "dist";
    write_text(run / "view" / "manifest.json", R"({"format": "clayform.view", "version": 1})"
                                               "\n");
    write_text(run / "view" / "000.bin", std::string("\x00\x01\x02\xff", 4));
    write_text(run / "part.glb", "glTF");
    write_text(base / "secret.txt", "not served");
    write_text(dist / "index.html", "<!doctype html><title>clayform viewer</title>\n");
    write_text(dist / "assets" / "app.js", "console.log(1);\n");
    write_text(dist / "assets" / "app.css", "body{}\n");
  }
};

}  // namespace

TEST_CASE("the view server serves the front end at the root and the run folder under run",
          "[view]") {
  using clay::test::body_of;
  using clay::test::header_of;
  using clay::test::status_of;
  const ServedFolders f("serve");
  ServeOptions o;
  o.port = 0;
  o.viewer = f.dist;
  ViewServer server(f.run, o);
  REQUIRE(server.port() > 0);
  CHECK(server.url() ==
        "http://127.0.0.1:" + std::to_string(server.port()) + "/?token=" + server.token());
  CHECK(server.token().size() == 32);
  server.start();
  const std::string host = "Host: 127.0.0.1:" + std::to_string(server.port()) + "\r\n";
  const std::string cookie =
      "Cookie: clayform_view_" + std::to_string(server.port()) + "=" + server.token() + "\r\n";
  const auto get = [&](const std::string& path, int status, const std::string& type,
                       const std::string& body) {
    INFO(path);
    const std::string answer = clay::test::get(server.port(), path, host + cookie);
    CHECK(status_of(answer) == status);
    if (!type.empty()) CHECK(header_of(answer, "Content-Type") == type);
    if (!body.empty()) CHECK(body_of(answer) == body);
    CHECK(header_of(answer, "Cache-Control") == "no-store");  // a run folder is rewritten
  };
  get("/run/view/manifest.json", 200, "application/json",
      read_text(f.run / "view" / "manifest.json"));
  get("/run/view/000.bin", 200, "application/octet-stream", std::string("\x00\x01\x02\xff", 4));
  get("/run/part.glb", 200, "model/gltf-binary", "glTF");
  get("/", 200, "text/html; charset=utf-8", read_text(f.dist / "index.html"));
  get("/index.html", 200, "text/html; charset=utf-8", read_text(f.dist / "index.html"));
  get("/assets/app.js", 200, "text/javascript; charset=utf-8", "console.log(1);\n");
  get("/assets/app.css", 200, "text/css; charset=utf-8", "body{}\n");
  get("/run/view/nothing.bin", 404, "", "");
  // Nothing outside the two folders, however the path is spelled.
  get("/run/../secret.txt", 404, "", "");
  get("/run/%2e%2e/secret.txt", 404, "", "");
  get("/run/view/..%2f..%2fsecret.txt", 404, "", "");
  get("/../secret.txt", 404, "", "");
  // The studio's boundary (issue #37 put the viewer on its HTTP stack): the token, opened once
  // with ?token= (which sets the cookie) and then carried by the cookie; the server's own Host;
  // the page's own Origin.
  const std::string no_token = clay::test::get(server.port(), "/run/view/manifest.json", host);
  CHECK(status_of(no_token) == 403);
  CHECK_THAT(body_of(no_token), Contains("clayform view") && Contains("?token="));
  CHECK(status_of(clay::test::get(server.port(), "/?token=" + std::string(32, '0'), host)) == 403);
  const std::string opened = clay::test::get(server.port(), "/?token=" + server.token(), host);
  CHECK(status_of(opened) == 200);
  CHECK(header_of(opened, "Set-Cookie") == "clayform_view_" + std::to_string(server.port()) + "=" +
                                               server.token() +
                                               "; Path=/; HttpOnly; SameSite=Strict");
  CHECK(status_of(clay::test::get(
            server.port(), "/",
            "Host: evil.example:" + std::to_string(server.port()) + "\r\n" + cookie)) == 403);
  CHECK(status_of(clay::test::get(server.port(), "/run/view/manifest.json",
                                  host + cookie + "Origin: http://evil.example\r\n")) == 403);
  CHECK(status_of(clay::test::raw_http(server.port(), "POST /run/view/manifest.json HTTP/1.1\r\n" +
                                                          host + cookie +
                                                          "Content-Length: 0\r\n\r\n")) == 405);
  server.stop();
  CHECK(!clay::test::can_connect(server.port()));  // stopped: nobody listens
}

TEST_CASE("the view server and snapshot name the fix for what is missing", "[view]") {
  const ServedFolders f("serve_missing");
  ServeOptions o;
  o.port = 0;
  o.viewer = f.dist;
  auto [category, message] = error_of([&] { ViewServer s(f.run / "view", o); });
  CHECK(category == ErrorCategory::Io);
  CHECK_THAT(message, Contains("view/manifest.json") && Contains("clayform run"));
  o.viewer = f.run;
  std::tie(category, message) = error_of([&] { ViewServer s(f.run, o); });
  CHECK(category == ErrorCategory::Io);
  CHECK_THAT(message, Contains("npm run build") && Contains("CLAYFORM_VIEWER_DIR"));
  ::setenv("CLAYFORM_VIEWER_DIR", f.dist.c_str(), 1);
  CHECK(viewer_dir() == f.dist);
  ::unsetenv("CLAYFORM_VIEWER_DIR");
  CHECK(viewer_dir().filename() == "dist");

  SnapshotOptions s;
  s.viewer = f.dist;
  s.chromium = f.run / "no-chromium-here";
  std::tie(category, message) = error_of([&] { snapshot(f.run, f.run / "x.png", s); });
  CHECK(category == ErrorCategory::Io);
  CHECK_THAT(message, Contains("apt-get install chromium"));
  s.mode = "wireframe";
  std::tie(category, message) = error_of([&] { snapshot(f.run, f.run / "x.png", s); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("zebra"));
  s.mode = "zebra";
  s.width = 4;
  CHECK(error_of([&] { snapshot(f.run, f.run / "x.png", s); }).first ==
        ErrorCategory::InvalidArgument);
  s.width = 640;
  // The camera, the stage and the surfaces to hide are checked before chromium is looked for.
  s.eye = {0, 0, 0};
  std::tie(category, message) = error_of([&] { snapshot(f.run, f.run / "x.png", s); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("--eye X Y Z"));
  s.eye = {0, 0, 1};
  s.stage = "middle";
  std::tie(category, message) = error_of([&] { snapshot(f.run, f.run / "x.png", s); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("after or before"));
  s.stage = "before";
  write_text(
      f.run / "view" / "manifest.json",
      R"({"format":"clayform.view","version":1,"surfaces":[{"name":"hood","export":"a",)"
      R"("stages":[{"curves":[{"name":"bound","points":[]}]}]},{"name":"lid","export":"b"}]})");
  s.hide = {"bound", "lid"};  // "bound" is a curve, not a surface
  std::tie(category, message) = error_of([&] { snapshot(f.run, f.run / "x.png", s); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("no surface 'bound'") && Contains("its surfaces are hood, lid"));
  s.hide = {"lid"};  // known: on to chromium, which is missing here
  CHECK(error_of([&] { snapshot(f.run, f.run / "x.png", s); }).first == ErrorCategory::Io);
}

TEST_CASE("the view leaves out a net too dense to draw: the sail's exact composition", "[view]") {
  // Without a budget the sail's lattice step composes exactly at degree 9 x 9 (104,610 control
  // points, more than the 20,000 a view draws); the style step's net is drawn, that one not.
  std::ifstream in(fs::path(CLAY_EXAMPLES_DIR) / "recipes" / "sail.json");
  nlohmann::json recipe = nlohmann::json::parse(in);
  recipe["composition"]["budget"] = "none";
  RunResult result = run_recipe(parse_recipe(recipe.dump()));
  const fs::path out = output_dir("view_sail");
  write_outputs(result, out);
  const auto j = nlohmann::json::parse(read_text(out / "view" / "manifest.json"));
  const auto& sail = j["surfaces"][0];
  REQUIRE(sail["name"] == "sail");
  REQUIRE(sail["stages"].size() == 2);
  const auto& style = sail["stages"][0];
  const auto& lattice = sail["stages"][1];
  CHECK(lattice["net_after"].is_null());
  CHECK(lattice["net_before"]["points"].size() ==
        static_cast<std::size_t>(style["net_after"]["rows"].get<int>() *
                                 style["net_after"]["cols"].get<int>()));
  CHECK(sail["net"].is_null());  // the final surface is that exact net
  CHECK(fs::file_size(out / "view" / "manifest.json") < 2'000'000);
}
