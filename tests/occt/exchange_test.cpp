// STEP / IGES / glTF exchange (clay/occt/surface_exchange.hpp): lossless round trips, face
// validity, file headers, atomic writes and error paths, concurrent use.
#include <catch2/catch.hpp>

#include <clay/error.hpp>
#include <clay/occt/surface_exchange.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/revolve.hpp>
#include <clay/surface/tessellate.hpp>

#include <gltf_reader.hpp>
#include <occt_reference.hpp>
#include <random_geometry.hpp>

#include <algorithm>
#include <cfenv>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace clay;
using namespace clay::surface;
namespace fs = std::filesystem;

namespace {

/// A fresh, empty folder under the test output folder.
fs::path fresh_folder(const std::string& name) {
  const fs::path folder = fs::path(CLAY_TEST_OUTPUT_DIR) / "exchange" / name;
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

std::vector<std::string> names_in(const fs::path& folder) {
  std::vector<std::string> out;
  for (const auto& entry : fs::directory_iterator(folder))
    out.push_back(entry.path().filename().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Surfaces for the round trips: polynomial and rational, clamped and unclamped, interior knots
/// of multiplicity > 1, degrees up to 25 in both directions. The degree-25 ones have many knot
/// spans, where OpenCASCADE's own evaluation is accurate (see the "Bezier-like" test below).
std::vector<BSplineSurface> mixed_surfaces(std::mt19937& rng) {
  std::vector<BSplineSurface> out;
  out.push_back(test::random_surface(rng, 3, 3, 6, 7, false));
  out.push_back(test::random_surface(rng, 2, 3, 5, 6, true, true, 2));
  out.push_back(test::random_surface(rng, 5, 4, 11, 9, true, true, 4));     // C0 knots
  out.push_back(test::random_surface(rng, 4, 6, 8, 9, true, false));        // unclamped
  out.push_back(test::random_surface(rng, 25, 25, 30, 30, true, false));    // degree (25, 25)
  out.push_back(test::random_surface(rng, 25, 3, 29, 8, false, false, 2));  // degree (25, 3)
  out.push_back(test::random_surface(rng, 1, 1, 2, 2, false));              // bilinear
  return out;
}

void require_identical(const std::vector<BSplineSurface>& read,
                       const std::vector<BSplineSurface>& written) {
  REQUIRE(read.size() == written.size());
  for (size_t k = 0; k < read.size(); ++k) {
    INFO("surface #" << k << " degree (" << written[k].u.degree << ", " << written[k].v.degree
                     << ")");
    REQUIRE(identical(read[k], written[k]));
  }
}

void require_report(const ExchangeReport& report, const std::vector<BSplineSurface>& surfaces) {
  long points = 0;
  int degree = 0;
  for (const auto& s : surfaces) {
    points += static_cast<long>(s.points.rows());
    degree = std::max({degree, s.u.degree, s.v.degree});
  }
  std::string found;
  for (const auto& p : report.problems) found += p + "\n";
  INFO(found);
  REQUIRE(report.faces == static_cast<int>(surfaces.size()));
  REQUIRE(report.control_points == points);
  REQUIRE(report.max_degree == degree);
  REQUIRE(report.tolerance_mm == 1e-7);
  REQUIRE(report.valid);
  REQUIRE(report.problems.empty());
  REQUIRE(report.evaluation_error == 0.0);
}

ErrorCategory category_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.category();
  }
  FAIL("no clay::Error thrown");
  return ErrorCategory::Internal;
}

}  // namespace

TEST_CASE("STEP AP214 round trip is bit-identical and faces are valid at 1e-7",
          "[exchange][step]") {
  std::mt19937 rng(214);
  const auto surfaces = mixed_surfaces(rng);
  const fs::path file = fresh_folder("step214") / "surfaces.step";
  const ExchangeReport report = write_step(surfaces, file);
  require_report(report, surfaces);
  REQUIRE(report.max_degree == 25);
  require_identical(read_step(file), surfaces);

  const std::string text = read_text(file);
  REQUIRE_THAT(text, Catch::Matchers::StartsWith("ISO-10303-21;"));
  REQUIRE_THAT(text, Catch::Matchers::Contains("FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214"));
  REQUIRE_THAT(text,
               Catch::Matchers::Contains("LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.)"));
  REQUIRE_THAT(text, Catch::Matchers::Contains("PRODUCT('clayform','clayform'"));
  REQUIRE_THAT(text, Catch::Matchers::Contains("RATIONAL_B_SPLINE_SURFACE"));
  REQUIRE(names_in(file.parent_path()) == std::vector<std::string>{"surfaces.step"});
}

TEST_CASE("exchange calls leave OpenCASCADE's settings as they found them (a host's own)",
          "[exchange]") {
  // OpenCASCADE's Interface_Static settings are the process's: an application embedding us
  // (FreeCAD) sets its own. Ours are set for each call and put back after it: our IGES reading
  // left read.iges.bspline.continuity at 0, and FreeCAD's own reading then kept curves whole
  // that it splits by default. The host's values here are unusual ones, read back after.
  namespace ref = clay::surface::occt_reference;
  REQUIRE(ref::set_exchange_setting("read.iges.bspline.continuity", 2));
  REQUIRE(ref::set_exchange_setting("write.iges.brep.mode", 1));
  REQUIRE(ref::set_exchange_setting("write.iges.unit", 1));  // inches
  REQUIRE(ref::set_exchange_setting("write.step.unit", 1));  // inches
  REQUIRE(ref::set_exchange_setting("write.step.product.name", "host part"));
  std::mt19937 rng(7);
  const auto surfaces = mixed_surfaces(rng);
  const fs::path folder = fresh_folder("host_settings");
  write_iges(surfaces, folder / "s.igs");
  write_step(surfaces, folder / "s.step");
  // ours were in force for the calls: millimetres, faces (144), the files read back
  require_identical(read_iges(folder / "s.igs"), surfaces);
  require_identical(read_step(folder / "s.step"), surfaces);
  CHECK(ref::exchange_setting_int("read.iges.bspline.continuity") == 2);
  CHECK(ref::exchange_setting_int("write.iges.brep.mode") == 1);
  CHECK(ref::exchange_setting_int("write.iges.unit") == 1);
  CHECK(ref::exchange_setting_int("write.step.unit") == 1);
  CHECK(ref::exchange_setting_text("write.step.product.name") == "host part");
  // OpenCASCADE's defaults again, for the tests after this one
  ref::set_exchange_setting("read.iges.bspline.continuity", 1);
  ref::set_exchange_setting("write.iges.brep.mode", 0);
  ref::set_exchange_setting("write.iges.unit", "MM");
  ref::set_exchange_setting("write.step.unit", "MM");
  ref::set_exchange_setting("write.step.product.name", "");
}

TEST_CASE("STEP AP242 round trip is bit-identical", "[exchange][step]") {
  std::mt19937 rng(242);
  auto surfaces = mixed_surfaces(rng);
  std::reverse(surfaces.begin(), surfaces.end());  // order is kept, whatever it is
  const fs::path file = fresh_folder("step242") / "surfaces.stp";
  StepWriteOptions options;
  options.schema = StepSchema::AP242;
  options.product_name = "hood panel";
  require_report(write_step(surfaces, file, options), surfaces);
  require_identical(read_step(file), surfaces);

  const std::string text = read_text(file);
  REQUIRE_THAT(text, Catch::Matchers::Contains("AP242_MANAGED_MODEL_BASED_3D_ENGINEERING_MIM_LF"));
  REQUIRE_THAT(text, !Catch::Matchers::Contains("AUTOMOTIVE_DESIGN"));
  REQUIRE_THAT(text, Catch::Matchers::Contains("SI_UNIT(.MILLI.,.METRE.)"));
  REQUIRE_THAT(text, Catch::Matchers::Contains("PRODUCT('hood panel','hood panel'"));

  // The schema is a per-call setting, not a sticky global: the next default write is AP214.
  const fs::path again = file.parent_path() / "again.step";
  write_step({surfaces.front()}, again);
  REQUIRE_THAT(read_text(again), Catch::Matchers::Contains("AUTOMOTIVE_DESIGN"));
}

TEST_CASE("IGES round trip is bit-identical", "[exchange][iges]") {
  std::mt19937 rng(128);
  const auto surfaces = mixed_surfaces(rng);
  const fs::path file = fresh_folder("iges") / "surfaces.igs";
  require_report(write_iges(surfaces, file), surfaces);
  require_identical(read_iges(file), surfaces);

  // Global section: unit flag 2 = millimetres, unit name "MM"; directory entries of types 144
  // (trimmed surface) and 128 (rational B-spline surface), one each per surface.
  const std::string text = read_text(file);
  REQUIRE_THAT(text, Catch::Matchers::Contains(",2,2HMM,"));
  std::istringstream lines(text);
  std::string line;
  int trimmed = 0, bsplines = 0, directory_line = 0;
  while (std::getline(lines, line)) {
    if (line.size() < 73 || line[72] != 'D') continue;
    if (directory_line++ % 2 != 0) continue;  // two lines per directory entry
    const int type = std::stoi(line.substr(0, 8));
    trimmed += type == 144;
    bsplines += type == 128;
  }
  REQUIRE(trimmed == static_cast<int>(surfaces.size()));
  REQUIRE(bsplines == static_cast<int>(surfaces.size()));
}

TEST_CASE("Closed surfaces come back as written although the readers make them periodic",
          "[exchange][step][iges]") {
  std::mt19937 rng(9);
  BSplineSurface closed_u = test::random_surface(rng, 3, 3, 7, 6, true);
  for (int j = 0; j < 6; ++j) {  // last row = first row: closed in u (a tube)
    closed_u.points.row(closed_u.index(6, j)) = closed_u.points.row(closed_u.index(0, j));
    closed_u.weights[closed_u.index(6, j)] = closed_u.weights[closed_u.index(0, j)];
  }
  BSplineSurface closed_both = test::random_surface(rng, 4, 2, 8, 5, false);
  for (int j = 0; j < 5; ++j)
    closed_both.points.row(closed_both.index(7, j)) =
        closed_both.points.row(closed_both.index(0, j));
  for (int i = 0; i < 8; ++i)
    closed_both.points.row(closed_both.index(i, 4)) =
        closed_both.points.row(closed_both.index(i, 0));
  BSplineSurface pole = test::random_surface(rng, 3, 3, 6, 6, true);  // degenerate side
  for (int i = 0; i < 6; ++i) pole.points.row(pole.index(i, 0)) = pole.points.row(pole.index(0, 0));
  const std::vector<BSplineSurface> surfaces{closed_u, closed_both, pole};

  const fs::path folder = fresh_folder("closed");
  require_report(write_step(surfaces, folder / "closed.step"), surfaces);
  require_identical(read_step(folder / "closed.step"), surfaces);
  require_report(write_iges(surfaces, folder / "closed.igs"), surfaces);
  require_identical(read_iges(folder / "closed.igs"), surfaces);
}

TEST_CASE("Bezier-like degree-25 patches: exact file, honest BRepCheck verdict",
          "[exchange][step][validity]") {
  // One span of degree 25 with a random net: OpenCASCADE's cached power-basis evaluation (what
  // BRepCheck uses) is off by far more than 1e-7 mm, although the edges are exact iso-curves.
  // The report must say so instead of claiming validity, and the file must still be exact.
  std::mt19937 rng(2525);
  const std::vector<BSplineSurface> surfaces{test::random_surface(rng, 25, 25, 26, 26, true)};
  const ExchangeReport report = check_faces(surfaces);
  REQUIRE(report.faces == 1);
  REQUIRE_FALSE(report.valid);
  REQUIRE(report.evaluation_error > 1e-7);
  REQUIRE(report.problems.size() == 1);
  REQUIRE_THAT(report.problems[0], Catch::Matchers::StartsWith("surface #0: BRepCheck") &&
                                       Catch::Matchers::Contains("exact iso-curves") &&
                                       Catch::Matchers::Contains("cached power-basis"));
  // brief() names the verdict and the first problem
  REQUIRE_THAT(report.brief(),
               Catch::Matchers::Equals("1 face, max degree 25, 676 control points, NOT valid "
                                       "(BRepCheck at 1e-07 mm): 1 problem: " +
                                       report.problems[0]));
  const fs::path file = fresh_folder("bezier25") / "patch.igs";
  const ExchangeReport written = write_iges(surfaces, file);
  REQUIRE_FALSE(written.valid);
  require_identical(read_iges(file), surfaces);
}

TEST_CASE("check_faces reports sizes and validity without writing", "[exchange][validity]") {
  std::mt19937 rng(3);
  const std::vector<BSplineSurface> surfaces{test::random_surface(rng, 20, 22, 40, 41, true, false),
                                             test::random_surface(rng, 24, 2, 45, 3, false, false),
                                             test::random_surface(rng, 3, 3, 4, 4, true)};
  const ExchangeReport report = check_faces(surfaces);
  require_report(report, surfaces);
  // 40 x 41 + 45 x 3 + 4 x 4 control points, the largest degree 24
  CHECK(report.brief() ==
        "3 faces, max degree 24, 1791 control points, valid (BRepCheck at 1e-07 mm)");
}

TEST_CASE("Failed writes throw clay::Error and leave no file behind", "[exchange][errors]") {
  std::mt19937 rng(404);
  const std::vector<BSplineSurface> good{test::random_surface(rng, 3, 3, 5, 5, true)};
  const fs::path folder = fresh_folder("failures");

  SECTION("missing output folder") {
    const fs::path file = folder / "no-such-folder" / "out.step";
    try {
      write_step(good, file);
      FAIL("no exception");
    } catch (const Error& e) {
      REQUIRE(e.category() == ErrorCategory::Io);
      REQUIRE_THAT(e.message(), Catch::Matchers::Contains("no-such-folder"));
    }
    REQUIRE(category_of([&] { write_iges(good, file); }) == ErrorCategory::Io);
    REQUIRE(category_of([&] { write_gltf(good, folder / "missing" / "x.glb"); }) ==
            ErrorCategory::Io);
    REQUIRE_FALSE(fs::exists(folder / "no-such-folder"));
  }
  SECTION("NaN control point") {
    std::vector<BSplineSurface> bad = good;
    bad.push_back(good[0]);
    bad[1].points(3, 2) = std::numeric_limits<double>::quiet_NaN();
    try {
      write_step(bad, folder / "nan.step");
      FAIL("no exception");
    } catch (const Error& e) {
      REQUIRE(e.category() == ErrorCategory::InvalidGeometry);
      REQUIRE_THAT(e.message(), Catch::Matchers::Contains("surface #1"));
    }
    REQUIRE(category_of([&] { write_iges(bad, folder / "nan.igs"); }) ==
            ErrorCategory::InvalidGeometry);
    REQUIRE(category_of([&] { write_gltf(bad, folder / "nan.glb"); }) ==
            ErrorCategory::InvalidGeometry);
  }
  SECTION("degree above 25") {
    const std::vector<BSplineSurface> high{good[0], test::random_surface(rng, 3, 26, 4, 27, false)};
    try {
      write_iges(high, folder / "high.igs");
      FAIL("no exception");
    } catch (const Error& e) {
      REQUIRE(e.category() == ErrorCategory::DegreeLimit);
      REQUIRE_THAT(e.message(),
                   Catch::Matchers::Contains("surface #1") && Catch::Matchers::Contains("26"));
    }
    REQUIRE(category_of([&] { write_step(high, folder / "high.step"); }) ==
            ErrorCategory::DegreeLimit);
    REQUIRE(category_of([&] { (void)check_faces(high); }) == ErrorCategory::DegreeLimit);
  }
  SECTION("empty list and bad options") {
    REQUIRE(category_of([&] { write_step({}, folder / "empty.step"); }) ==
            ErrorCategory::InvalidArgument);
    REQUIRE(category_of([&] { write_iges({}, folder / "empty.igs"); }) ==
            ErrorCategory::InvalidArgument);
    REQUIRE(category_of([&] { (void)check_faces({}); }) == ErrorCategory::InvalidArgument);
    StepWriteOptions unnamed;
    unnamed.product_name.clear();
    REQUIRE(category_of([&] { write_step(good, folder / "unnamed.step", unnamed); }) ==
            ErrorCategory::InvalidArgument);
    for (double bad : {0.0, -1.0, 0.5, std::numeric_limits<double>::quiet_NaN()}) {
      GltfWriteOptions options;
      options.relative_area = bad;
      try {
        write_gltf(good, folder / "bad.glb", options);
        FAIL("no exception");
      } catch (const Error& e) {
        REQUIRE(e.category() == ErrorCategory::InvalidArgument);
        REQUIRE_THAT(e.message(), Catch::Matchers::Contains("relative_area"));
      }
    }
  }
  SECTION("target is an existing folder: the rename fails, the temporary file is removed") {
    fs::create_directories(folder / "taken.step");
    REQUIRE(category_of([&] { write_step(good, folder / "taken.step"); }) == ErrorCategory::Io);
    REQUIRE(category_of([&] { write_iges(good, folder / "taken.step"); }) == ErrorCategory::Io);
    REQUIRE(category_of([&] { write_gltf(good, folder / "taken.step"); }) == ErrorCategory::Io);
    REQUIRE(names_in(folder) == std::vector<std::string>{"taken.step"});
    REQUIRE(fs::is_empty(folder / "taken.step"));
    fs::remove(folder / "taken.step");
  }
  // Whatever failed: neither the target nor a temporary file is left.
  REQUIRE(names_in(folder).empty());
}

TEST_CASE("Reading missing, unparsable or empty files throws", "[exchange][errors]") {
  const fs::path folder = fresh_folder("reading");
  REQUIRE(category_of([&] { (void)read_step(folder / "missing.step"); }) == ErrorCategory::Io);
  REQUIRE(category_of([&] { (void)read_iges(folder / "missing.igs"); }) == ErrorCategory::Io);
  REQUIRE(category_of([&] { (void)read_step(folder); }) == ErrorCategory::Io);

  std::ofstream(folder / "garbage.step") << "this is not a STEP file\n";
  REQUIRE(category_of([&] { (void)read_step(folder / "garbage.step"); }) ==
          ErrorCategory::Exchange);

  // A well-formed STEP file without any geometry.
  std::ofstream(folder / "empty.step")
      << "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('empty'),'2;1');\n"
         "FILE_NAME('empty.step','2024-01-01T00:00:00',(''),(''),'','','');\n"
         "FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n"
         "#1 = CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;\nEND-ISO-10303-21;\n";
  try {
    (void)read_step(folder / "empty.step");
    FAIL("no exception");
  } catch (const Error& e) {
    REQUIRE(e.category() == ErrorCategory::Exchange);
    REQUIRE_THAT(e.message(), Catch::Matchers::Contains("empty.step"));
  }
}

TEST_CASE("Concurrent STEP and IGES round trips from 4 threads", "[exchange][threads]") {
  const fs::path folder = fresh_folder("threads");
  constexpr int threads = 4, rounds = 3;
  std::vector<std::vector<std::vector<BSplineSurface>>> written(threads);
  std::vector<std::vector<std::vector<BSplineSurface>>> read_back(threads);
  std::vector<std::string> failures(threads);
  std::vector<std::thread> workers;
  for (int t = 0; t < threads; ++t)
    workers.emplace_back([&, t] {
      try {
        std::mt19937 rng(1000 + static_cast<unsigned>(t));
        for (int r = 0; r < rounds; ++r) {
          std::vector<BSplineSurface> surfaces{
              test::random_surface(rng, 3 + r, 2 + t, 6 + r, 5 + t, (r + t) % 2 == 0, r != 1, 2),
              test::random_surface(rng, 12 + t, 5, 30, 9, true, false)};
          const fs::path stem = folder / ("t" + std::to_string(t) + "r" + std::to_string(r));
          write_step(surfaces, stem.string() + ".step");
          written[t].push_back(surfaces);
          read_back[t].push_back(read_step(stem.string() + ".step"));
          write_iges(surfaces, stem.string() + ".igs");
          written[t].push_back(surfaces);
          read_back[t].push_back(read_iges(stem.string() + ".igs"));
        }
      } catch (const std::exception& e) {
        failures[t] = e.what();
      }
    });
  for (auto& w : workers) w.join();
  for (int t = 0; t < threads; ++t) {
    INFO("thread " << t);
    REQUIRE(failures[t].empty());
    REQUIRE(read_back[t].size() == 2 * rounds);
    for (size_t r = 0; r < read_back[t].size(); ++r)
      require_identical(read_back[t][r], written[t][r]);
  }
  REQUIRE(names_in(folder).size() == 2 * threads * rounds);
}

TEST_CASE("glTF preview is a binary glTF file", "[exchange][gltf]") {
  std::mt19937 rng(77);
  const std::vector<BSplineSurface> surfaces{test::random_surface(rng, 3, 3, 5, 5, true),
                                             test::random_surface(rng, 2, 4, 4, 6, false)};
  const fs::path folder = fresh_folder("gltf");
  const fs::path file = folder / "preview.glb";
  write_gltf(surfaces, file);
  const std::string bytes = read_text(file);
  REQUIRE(bytes.size() > 100);
  REQUIRE(bytes.substr(0, 4) == "glTF");
  // Binary glTF header: version 2, then the total length, little-endian.
  auto u32 = [&](size_t at) {
    return static_cast<unsigned>(static_cast<unsigned char>(bytes[at])) |
           static_cast<unsigned>(static_cast<unsigned char>(bytes[at + 1])) << 8 |
           static_cast<unsigned>(static_cast<unsigned char>(bytes[at + 2])) << 16 |
           static_cast<unsigned>(static_cast<unsigned char>(bytes[at + 3])) << 24;
  };
  REQUIRE(u32(4) == 2u);
  REQUIRE(u32(8) == bytes.size());
  REQUIRE(names_in(folder) == std::vector<std::string>{"preview.glb"});
  // Read back independently: the triangles cover the surfaces (area within 1 % of the NURBS
  // area by quadrature) and span their bounding box (of a dense sample of the NURBS).
  const test::GltfTriangles back = test::read_glb(file.string());
  double area = 0;
  Eigen::AlignedBox3d box;
  for (const BSplineSurface& s : surfaces) {
    area += surface_area(s, 3);
    const auto [u0, u1] = s.u.domain();
    const auto [v0, v1] = s.v.domain();
    const Points3 dense = evaluate_grid(s, linspace(u0, u1, 401), linspace(v0, v1, 401));
    for (Eigen::Index r = 0; r < dense.rows(); ++r)
      box.extend(Eigen::Vector3d(dense.row(r).transpose()));
  }
  CHECK(back.triangles.size() > 1000);
  CHECK(std::abs(back.area() - area) <= 0.01 * area);
  const double size = box.diagonal().norm();
  CHECK((back.box().min() - box.min()).norm() <= 1e-3 * size);
  CHECK((back.box().max() - box.max()).norm() <= 1e-3 * size);
}

TEST_CASE("glTF previews of surfaces with poles and collapsed edges are not empty",
          "[exchange][gltf]") {
  // A sphere of revolution (a pole at each end of every meridian) and a cone with its apex
  // collapsed: OpenCASCADE's mesher once gave such faces zero-area meshes.
  // The half circle x^2 + z^2 = 100, x >= 0, as two rational quadratic quarter circles.
  const BSplineCurve meridian =
      make_curve(2, {0, 0, 0, 0.5, 0.5, 1, 1, 1},
                 (Points3(5, 3) << 0, 0, -10, 10, 0, -10, 10, 0, 0, 10, 0, 10, 0, 0, 10).finished(),
                 (Eigen::VectorXd(5) << 1, std::sqrt(0.5), 1, std::sqrt(0.5), 1).finished());
  const BSplineSurface sphere = revolve(meridian, Axis{}).surface;
  const fs::path folder = fresh_folder("gltf_poles");
  write_gltf({sphere}, folder / "sphere.glb");
  const test::GltfTriangles back = test::read_glb((folder / "sphere.glb").string());
  const double exact = 4 * std::numbers::pi * 100;  // closed form, mm^2
  CHECK(std::abs(back.area() - exact) <= 0.01 * exact);
  CHECK((back.box().min() - Eigen::Vector3d(-10, -10, -10)).norm() <= 1e-2);
  CHECK((back.box().max() - Eigen::Vector3d(10, 10, 10)).norm() <= 1e-2);
  CHECK_THAT(surface_area(sphere, 2), Catch::Matchers::WithinRel(exact, 1e-9));
  // A budget too small for the tolerance: the error names the writer, the surface and the way out.
  GltfWriteOptions starved;
  starved.relative_area = 1e-9;
  starved.max_vertices = 289;
  try {
    write_gltf({sphere}, folder / "starved.glb", starved);
    FAIL("no exception");
  } catch (const Error& e) {
    CHECK(e.category() == ErrorCategory::ToleranceNotMet);
    CHECK_THAT(e.message(), Catch::Matchers::Contains("write_gltf: the preview of") &&
                                Catch::Matchers::Contains("max_vertices"));
  }
  CHECK_FALSE(fs::exists(folder / "starved.glb"));
}

// ---- malformed files (issue #18: mutated files crashed or hung OpenCASCADE) ---------------------

namespace {

/// `text` with its first `from` replaced by `to`; fails the test when `from` is missing.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  REQUIRE(at != std::string::npos);
  return text.replace(at, from.size(), to);
}

/// An IGES file's lines with the data columns 1-64 of the line starting with `prefix` (offset
/// `down` lines below it) edited, padded back to 64 columns so the fixed format stays intact.
std::string iges_edited(const std::string& text, const std::string& prefix, int down,
                        const std::string& from, const std::string& to) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::size_t at = 0;
  while (at < lines.size() && lines[at].rfind(prefix, 0) != 0) ++at;
  at += static_cast<std::size_t>(down);
  REQUIRE(at < lines.size());
  std::string data = lines[at].substr(0, 64);
  data.erase(data.find_last_not_of(' ') + 1);
  data = replaced(data, from, to);
  REQUIRE(data.size() <= 64);
  lines[at] = data + std::string(64 - data.size(), ' ') + lines[at].substr(64);
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

/// The mutated files of tests/fuzz/corpus/exchange/ (README there), made from a bicubic and a
/// rational surface written by write_step and write_iges into `folder`: name -> what the
/// pre-check must say.
std::vector<std::pair<std::string, std::string>> write_mutated_files(const fs::path& folder) {
  std::mt19937 rng(1818);
  const std::vector<BSplineSurface> surfaces{test::random_surface(rng, 3, 3, 8, 6, false),
                                             test::random_surface(rng, 2, 2, 3, 3, true)};
  write_step(surfaces, folder / "valid.step");
  write_iges(surfaces, folder / "valid.igs");
  const std::string step = read_text(folder / "valid.step"), iges = read_text(folder / "valid.igs");
  // The first B-spline surface's entity, the first point of its control net and a placement.
  const std::string bspline = step.substr(step.find("B_SPLINE_SURFACE_WITH_KNOTS('',3,3,("), 36);
  const auto placement = step.find("AXIS2_PLACEMENT_3D('',#");
  REQUIRE(placement != std::string::npos);
  const std::string axis = step.substr(placement, step.find(';', placement) - placement);
  const auto comma = axis.find(',', axis.find("#"));
  const std::string first_ref = axis.substr(axis.find('#'), comma - axis.find('#'));
  const std::string second_ref = axis.substr(comma + 1, axis.find(',', comma + 1) - comma - 1);
  const auto net = step.find("(#", step.find(bspline));
  const std::string point_ref = step.substr(net + 1, step.find(',', net) - net - 1);
  const auto point_at = step.find(point_ref + " = CARTESIAN_POINT('',(");
  REQUIRE(point_at != std::string::npos);
  const std::string point = step.substr(point_at, step.find(';', point_at) - point_at);
  const auto x_at = point.find("'',(") + 4;
  const std::string x = point.substr(x_at, point.find(',', x_at) - x_at);
  auto coordinate = [&](const std::string& value) {
    return replaced(step, point, replaced(point, "'',(" + x, "'',(" + value));
  };
  const std::string record = "128,7,5,3,3,";  // the bicubic's surface record: K1, K2, M1, M2
  std::vector<std::pair<std::string, std::string>> files{
      {"step-dangling-point.step", "which the file does not define (a dangling reference)"},
      {"step-dangling-direction.step", "which the file does not define (a dangling reference)"},
      {"step-nan-coordinate.step", "'NaN' is not a STEP value"},
      {"step-infinite-coordinate.step", "'1.0E999' is beyond the range of a double"},
      {"step-denormal-coordinate.step", ""},  // read: see below
      {"step-absurd-coordinate.step", "larger in magnitude than 1e100"},
      {"step-degree-99.step", "B_SPLINE_SURFACE_WITH_KNOTS has degree 99"},
      {"step-rational-degree-99.step", "B_SPLINE_SURFACE has degree 99"},
      {"iges-degree-99.igs", "degree M1 99 is outside [1, 25]"},
      {"iges-counts-inconsistent.igs", "upper index K1 7000 is inconsistent"},
      {"iges-nan-coordinate.igs", "'NaN' is not a number"},
      {"iges-infinite-coordinate.igs", "'1.0D999' is beyond the range of a double"},
      {"iges-denormal-coordinate.igs", ""},
      {"step-duplicate-id.step", "is defined twice, on line "},
      {"step-huge-list.step", "a list has more than 50000 entries"},
  };
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(folder / name, std::ios::binary) << text;
  };
  write(files[0].first, replaced(step, axis, replaced(axis, first_ref + ",", "#999999,")));
  write(files[1].first, replaced(step, axis, replaced(axis, "," + second_ref + ",", ",#999998,")));
  write(files[2].first, coordinate("NaN"));
  write(files[3].first, coordinate("1.0E999"));
  write(files[4].first, coordinate("4.9E-324"));
  write(files[5].first, coordinate("1.0E+150"));
  write(files[6].first, replaced(step, bspline, "B_SPLINE_SURFACE_WITH_KNOTS('',99,3,("));
  write(files[7].first, replaced(step, "B_SPLINE_SURFACE(2,2,(", "B_SPLINE_SURFACE(99,2,("));
  write(files[8].first, iges_edited(iges, record, 0, record, "128,7,5,99,3,"));
  write(files[9].first, iges_edited(iges, record, 0, record, "128,7000,5,3,3,"));
  // the 14th line of the record (after 10 + 8 + 6 ... parameters): its first number, a weight
  const std::string line = [&] {
    std::istringstream in(iges);
    std::string l;
    for (int k = 0; std::getline(in, l);)
      if (l.rfind(record, 0) == 0 || k > 0)
        if (++k == 14) return l;
    return std::string();
  }();
  const std::string value = line.substr(0, line.find(','));
  write(files[10].first, iges_edited(iges, record, 13, value, "NaN"));
  write(files[11].first, iges_edited(iges, record, 13, value, "1.0D999"));
  write(files[12].first, iges_edited(iges, record, 13, value, "4.9D-324"));
  // The first control point defined a second time, elsewhere (issue #36: OpenCASCADE took one of
  // the two silently), and a list of 50,001 coordinates.
  const std::string moved = replaced(point, "'',(" + x, "'',(" + x + "1");
  write(files[13].first, replaced(step, point + ";", point + ";\n" + moved + ";"));
  std::string many;
  for (int k = 0; k < 50000; ++k) many += "0.,";
  write(files[14].first, coordinate(many + x));
  return files;
}

std::string message_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const Error& e) {
    CHECK(e.category() == ErrorCategory::Exchange);
    return e.message();
  }
  FAIL("no clay::Error thrown");
  return {};
}

std::vector<BSplineSurface> read_any(const fs::path& file, const ReadOptions& options) {
  return file.extension() == ".igs" ? read_iges(file, options) : read_step(file, options);
}

}  // namespace

TEST_CASE("The pre-check refuses malformed STEP and IGES files, naming the entity and line",
          "[exchange][malformed]") {
  const fs::path folder = fresh_folder("malformed");
  const auto files = write_mutated_files(folder);
  REQUIRE(read_step(folder / "valid.step").size() == 2);  // the originals pass
  REQUIRE(read_iges(folder / "valid.igs").size() == 2);
  for (const auto& [name, why] : files) {
    INFO(name);
    const auto start = std::chrono::steady_clock::now();
    const fs::path file = folder / name;  // the lambda captures this, not the binding (Clang 14)
    if (why.empty()) {
      // A denormal number (Alibre writes one in a centroid) is read as it is, as OpenCASCADE and
      // FreeCAD read it (issue #39: the pre-check refused such files). The changed control
      // coordinate is the file's 4.9e-324, the rest of the net as in the original.
      const auto read = read_any(file, {});
      const auto valid =
          read_any(folder / (name.rfind("step", 0) == 0 ? "valid.step" : "valid.igs"), {});
      REQUIRE(read.size() == valid.size());
      int changed = 0;
      for (std::size_t k = 0; k < read.size(); ++k) {
        REQUIRE(read[k].points.rows() == valid[k].points.rows());
        for (Eigen::Index r = 0; r < read[k].points.rows(); ++r)
          for (Eigen::Index c = 0; c < read[k].points.cols(); ++c)
            if (read[k].points(r, c) != valid[k].points(r, c)) {
              ++changed;
              CHECK(std::abs(read[k].points(r, c)) <= 1e-300);
            }
      }
      // STEP: the first control point's x. IGES: the 14th line of the record holds a weight of
      // the polynomial bicubic (PROP3 = 1), which its reading does not use: nothing changes.
      CHECK(changed == (name.rfind("step", 0) == 0 ? 1 : 0));
      continue;
    }
    const std::string m = message_of([&] { (void)read_any(file, {}); });
    CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < 5.0);
    CHECK_THAT(m, Catch::Matchers::Contains(why));
    CHECK_THAT(m, Catch::Matchers::Contains(name + "' line "));
    CHECK_THAT(m, Catch::Matchers::Contains(name.rfind("step", 0) == 0
                                                ? ", entity #"
                                                : ", entity 128 (directory entry "));
  }
  // A copy for the fuzzers' corpus (tests/fuzz/corpus/exchange/) is made from these files.
}

TEST_CASE(
    "The pre-check's refusal of 1.0E999 leaves the caller's floating-point environment as it was",
    "[exchange][malformed]") {
  // strtod reports 1.0E999 by raising overflow; a host trapping overflow (the Debug tests do) died
  // of it in the pre-check (issue #19). The scan runs with the traps held, the flags restored.
  const fs::path folder = fresh_folder("malformed-fenv");
  (void)write_mutated_files(folder);
  for (const char* name : {"step-infinite-coordinate.step", "iges-infinite-coordinate.igs"}) {
    INFO(name);
    std::feclearexcept(FE_ALL_EXCEPT);
#if defined(__GLIBC__)
    const int traps = fegetexcept();
#endif
    const fs::path file = folder / name;
    CHECK_THAT(message_of([&] { (void)read_any(file, {}); }),
               Catch::Matchers::Contains("is beyond the range of a double"));
    CHECK(std::fetestexcept(FE_OVERFLOW | FE_INVALID | FE_DIVBYZERO) == 0);
#if defined(__GLIBC__)
    CHECK(fegetexcept() == traps);
#endif
  }
}

TEST_CASE("An isolated read survives what crashes OpenCASCADE, and stops at its limits",
          "[exchange][malformed]") {
  const fs::path folder = fresh_folder("isolated");
  (void)write_mutated_files(folder);
  ReadOptions isolated;
  isolated.isolate = true;
  // Same surfaces as a direct read.
  require_identical(read_step(folder / "valid.step", isolated), read_step(folder / "valid.step"));
  require_identical(read_iges(folder / "valid.igs", isolated), read_iges(folder / "valid.igs"));
  // Without the pre-check, OpenCASCADE crashes on a dangling point reference and on a B-spline
  // record whose counts overrun it: the child dies, this process reports it.
  ReadOptions unchecked = isolated;
  unchecked.precheck = false;
  for (const char* name : {"step-dangling-point.step", "iges-counts-inconsistent.igs"}) {
    INFO(name);
    const std::string m = message_of([&] { (void)read_any(folder / name, unchecked); });
    CHECK_THAT(m, Catch::Matchers::Contains("OpenCASCADE crashed (SIGSEGV) while reading '"));
    CHECK_THAT(m, Catch::Matchers::Contains(name));
  }
  // The time and memory limits, on a valid file.
  ReadOptions hurried = isolated;
  hurried.time_limit_seconds = 1e-4;
  CHECK_THAT(message_of([&] { (void)read_step(folder / "valid.step", hurried); }),
             Catch::Matchers::Contains("took longer than 0.0001 s"));
  // 40,000 control points: OpenCASCADE's model of the file takes tens of MB, more than the 1 MB
  // the child may add to what this process maps.
  std::mt19937 rng(40000);
  write_step({test::random_surface(rng, 3, 3, 200, 200, false)}, folder / "large.step");
  ReadOptions starved = isolated;
  starved.memory_limit_mb = 1;
  CHECK_THAT(message_of([&] { (void)read_step(folder / "large.step", starved); }),
             Catch::Matchers::Contains("needed more than 1 MB"));
  // An error raised in the child comes back with its category and message.
  std::ofstream(folder / "garbage.step") << "this is not a STEP file\n";
  CHECK_THAT(message_of([&] { (void)read_step(folder / "garbage.step", isolated); }),
             Catch::Matchers::Contains("could not be parsed as a STEP file"));
  // The exchange lock was released: this process goes on reading.
  REQUIRE(read_step(folder / "valid.step").size() == 2);
  // Bad options.
  ReadOptions bad;
  bad.time_limit_seconds = 0;
  REQUIRE(category_of([&] { (void)read_step(folder / "valid.step", bad); }) ==
          ErrorCategory::InvalidArgument);
  bad = {};
  bad.memory_limit_mb = 0;
  REQUIRE(category_of([&] { (void)read_iges(folder / "valid.igs", bad); }) ==
          ErrorCategory::InvalidArgument);
}
