// Pictures of surfaces (clay/render/render.hpp): the orthographic fit against its closed form, the
// z-buffer, the shading of planes, the control net, the PNG read back with libpng, and every error.
#include <catch2/catch.hpp>

#include <clay/render/render.hpp>
#include <clay/surface/basis.hpp>

#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>

#include "error_of.hpp"

using namespace clay::render;
using Catch::Matchers::Contains;
using clay::ErrorCategory;
using clay::test::error_of;
namespace surface = clay::surface;
namespace fs = std::filesystem;

namespace {

/// The plane patch [x0, x1] x [y0, y1] at height z, degree p in both directions with its control
/// points at the Greville abscissae: by linear precision S(u, v) = (x0 + u (x1 - x0), y0 + v (y1 -
/// y0), z).
surface::BSplineSurface plate(double x0, double x1, double y0, double y1, double z, int p = 1) {
  const auto b = surface::clamped_uniform_basis(p, p + 1);
  const auto xi = surface::greville_abscissae(b);
  surface::Points3 pts((p + 1) * (p + 1), 3);
  for (int i = 0; i <= p; ++i)
    for (int j = 0; j <= p; ++j)
      pts.row(i * (p + 1) + j) << x0 + xi[static_cast<size_t>(i)] * (x1 - x0),
          y0 + xi[static_cast<size_t>(j)] * (y1 - y0), z;
  return surface::make_surface(b, b, pts);
}

/// 240 x 100 pixels, 10% margin, looking straight down (-z): a plate of 2 x 1 is scaled by
/// min(0.8 * 240 / 2, 0.8 * 100 / 1) = 80 pixels per unit and centred.
RenderOptions top_view() {
  RenderOptions o;
  o.width = 240;
  o.height = 100;
  o.margin = 0.1;
  o.eye_direction = {0, 0, 1};
  o.samples_per_span = 3;
  return o;
}

bool same(const Rgb& a, const Rgb& b) { return a == b; }

}  // namespace

TEST_CASE("render: a plate facing the camera covers the rectangle of the orthographic fit",
          "[render]") {
  for (const bool supersample : {false, true})
    for (const int degree : {1, 3}) {
      CAPTURE(supersample, degree);
      RenderOptions o = top_view();
      o.supersample = supersample;
      o.background = {10, 20, 30};
      o.colours = {{200, 100, 50}};
      const Image img = render({plate(0, 2, 0, 1, 0, degree)}, o);
      REQUIRE(img.width == 240);
      REQUIRE(img.height == 100);
      REQUIRE(img.rgb.size() == 3u * 240u * 100u);
      // x in [0, 2] maps to columns [120 - 80, 120 + 80), y in [0, 1] to rows [50 - 40, 50 + 40)
      // (y up); pixel centres never lie on these edges, so coverage is all or nothing.
      const Rgb inside = img.pixel(120, 50);
      for (int y = 0; y < 100; ++y)
        for (int x = 0; x < 240; ++x) {
          const bool covered = x >= 40 && x < 200 && y >= 10 && y < 90;
          const Rgb expected = covered ? inside : o.background;
          if (!same(img.pixel(x, y), expected))
            FAIL("pixel " << x << ", " << y << (covered ? " inside" : " outside"));
        }
      // A plane under a directional light, seen orthographically, is one colour: base * diffuse +
      // a grey highlight, so the channel differences keep the base's ratios 100 : 50.
      const double r = inside[0], g = inside[1], b = inside[2];
      CHECK(r > g);
      CHECK(g > b);
      CHECK_THAT(r - g, Catch::Matchers::WithinAbs(2 * (g - b), 2.0));
    }
}

TEST_CASE("render_mesh: a trimmed plate's hole shows the background, in the face's colour",
          "[render]") {
  // The plate [0, 2] x [0, 1] with the hole [0.5, 1.5] x [0.25, 0.75], as four trapezoids of two
  // triangles each; with top_view() x maps to columns 40 + 80 x and y to rows 90 - 80 y.
  clay::brep::ModelMesh mesh;
  const std::array<Eigen::Vector2d, 8> corners{
      Eigen::Vector2d(0, 0),      Eigen::Vector2d(2, 0),      Eigen::Vector2d(2, 1),
      Eigen::Vector2d(0, 1),      Eigen::Vector2d(0.5, 0.25), Eigen::Vector2d(1.5, 0.25),
      Eigen::Vector2d(1.5, 0.75), Eigen::Vector2d(0.5, 0.75)};
  for (const auto& c : corners) {
    mesh.positions.emplace_back(c.x(), c.y(), 0);
    mesh.normals.emplace_back(0, 0, 1);
  }
  for (int k = 0; k < 4; ++k) {
    const int a = k, b = (k + 1) % 4, c = 4 + (k + 1) % 4, d = 4 + k;
    mesh.triangles.push_back({a, b, c});
    mesh.triangles.push_back({a, c, d});
  }
  mesh.triangle_face.assign(8, 0);
  mesh.face_body = {0};
  mesh.face_colours = {clay::brep::Colour{0.9, 0.1, 0.1}};
  RenderOptions o = top_view();
  o.background = {10, 20, 30};
  const Image img = render_mesh(mesh, o);
  CHECK(same(img.pixel(120, 50), o.background));  // the hole's centre (1, 0.5)
  const Rgb frame = img.pixel(60, 50);            // (0.25, 0.5), on the plate
  CHECK(!same(frame, o.background));
  CHECK(frame[0] > 2 * frame[1]);  // red, the face's colour
  CHECK(frame[1] == frame[2]);
  for (int x = 82; x < 158; ++x)  // across the hole, away from its rims
    CHECK(same(img.pixel(x, 50), o.background));
  // Options' colours win over the model's.
  o.colours = {{20, 200, 20}};
  const Rgb green = render_mesh(mesh, o).pixel(60, 50);
  CHECK(green[1] > 2 * green[0]);
  // A mesh whose arrays disagree is refused.
  clay::brep::ModelMesh broken = mesh;
  broken.normals.pop_back();
  auto [c1, m1] = error_of([&] { render_mesh(broken, o); });
  CHECK(c1 == ErrorCategory::InvalidArgument);
  CHECK_THAT(m1, Contains("the mesh's arrays disagree in size"));
  broken = mesh;
  broken.triangles[3][1] = 99;
  auto [c2, m2] = error_of([&] { render_mesh(broken, o); });
  CHECK(c2 == ErrorCategory::InvalidArgument);
  CHECK_THAT(m2, Contains("triangle 3 refers to node 99 of 8"));
}

TEST_CASE("render: the whole model is visible, centred, and touches the margin on one axis",
          "[render]") {
  // A bicubic dome 4 x 4 control points, seen obliquely.
  const auto b = surface::clamped_uniform_basis(3, 4);
  surface::Points3 pts(16, 3);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      pts.row(i * 4 + j) << 30.0 * i, 20.0 * j,
          (i == 1 || i == 2) && (j == 1 || j == 2) ? 25.0 : 0.0;
  RenderOptions o;
  o.width = 300;
  o.height = 200;
  o.margin = 0.05;
  const Image img = render({surface::make_surface(b, b, pts)}, o);
  int left = o.width, right = -1, top = o.height, bottom = -1;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (!same(img.pixel(x, y), o.background)) {
        left = std::min(left, x), right = std::max(right, x);
        top = std::min(top, y), bottom = std::max(bottom, y);
      }
  // Free border: 15 pixels left and right, 10 above and below.
  CHECK(left >= 14);
  CHECK(right <= 285);
  CHECK(top >= 9);
  CHECK(bottom <= 190);
  CHECK_THAT(0.5 * (left + right + 1), Catch::Matchers::WithinAbs(150.0, 1.5));
  CHECK_THAT(0.5 * (top + bottom + 1), Catch::Matchers::WithinAbs(100.0, 1.5));
  CHECK((right - left + 1 >= 268 || bottom - top + 1 >= 178));
}

TEST_CASE("render: a surface behind another is hidden, whatever the drawing order", "[render]") {
  const auto far_plate = plate(0, 2, 0, 1, 0), near_plate = plate(0.5, 1.5, 0.25, 0.75, 1);
  const Rgb green{60, 200, 60}, red{220, 40, 40};
  for (const Eigen::Vector3d& eye : {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.2, -0.3, 1)}) {
    CAPTURE(eye.transpose());
    RenderOptions o = top_view();
    o.eye_direction = eye;
    o.colours = {green, red};
    const Image far_first = render({far_plate, near_plate}, o);
    o.colours = {red, green};
    const Image near_first = render({near_plate, far_plate}, o);
    CHECK(far_first.rgb == near_first.rgb);
    if (eye.x() == 0) {
      // Parallel planes facing the camera are shaded alike: the middle shows the near plate's
      // colour, a point of the far plate outside the near one shows the far plate's.
      o.colours = {red};
      const Rgb near_alone = render({near_plate}, o).pixel(120, 50);
      o.colours = {green};
      const Rgb far_alone = render({far_plate}, o).pixel(120, 50);
      CHECK(same(far_first.pixel(120, 50), near_alone));  // world (1, 0.5)
      CHECK(same(far_first.pixel(50, 50), far_alone));    // world (0.13, 0.5)
      CHECK_FALSE(same(near_alone, far_alone));
    }
  }
}

TEST_CASE("render: a collapsed or nearly collapsed edge is shaded like the rest of its plane",
          "[render]") {
  // S(u, v) = (u, u v, 0): S_u x S_v = (0, 0, u) vanishes on the edge u = 0 (a pole), where the
  // normal is the limit S_u x S_uv = (0, 0, 1). Then the same with the pole split by 1e-6 (as a
  // refit leaves it): S_u x S_v there is (3e-6 v, -3e-6, 1e-6), 70 degrees off, and must not be
  // used. Both surfaces are planar to 3e-6, so every fully covered pixel has the colour of the
  // plane.
  const auto b = surface::clamped_uniform_basis(1, 2);
  for (const double split : {0.0, 1e-6}) {
    CAPTURE(split);
    surface::Points3 pts(4, 3);
    pts << 0, 0, 0, 0, split, 3 * split, 1, 0, 0, 1, 1, 0;
    RenderOptions o = top_view();
    o.eye_direction = {0.1, 0.2, 1};
    o.supersample = false;  // every pixel is either covered or not
    const Image img = render({surface::make_surface(b, b, pts)}, o);
    auto covered = [&](int x, int y) { return !same(img.pixel(x, y), o.background); };
    std::vector<Rgb> colours;
    for (int y = 1; y + 1 < img.height; ++y)
      for (int x = 1; x + 1 < img.width; ++x)
        if (covered(x, y) && covered(x - 1, y) && covered(x + 1, y) && covered(x, y - 1) &&
            covered(x, y + 1))
          colours.push_back(img.pixel(x, y));
    REQUIRE(colours.size() > 1200);  // of the triangle's 80 x 80 / 2 pixels, foreshortened
    int off = 0;
    for (const Rgb& c : colours)
      for (size_t k = 0; k < 3; ++k) off += std::abs(int(c[k]) - int(colours[0][k])) > 1;
    CHECK(off == 0);
  }
}

TEST_CASE("render: the control net is drawn along its lines only", "[render]") {
  // Degree 1, 3 x 3 control points on [0, 2] x [0, 1]: net lines at x = 0, 1, 2 (columns 40, 120,
  // 200) and y = 0, 0.5, 1 (rows 90, 50, 10).
  const auto b = surface::clamped_uniform_basis(1, 3);
  surface::Points3 pts(9, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) pts.row(i * 3 + j) << i, 0.5 * j, 0;
  const auto s = surface::make_surface(b, b, pts);
  RenderOptions o = top_view();
  const Image plain = render({s}, o);
  o.control_net = true;
  const Image net = render({s}, o);
  auto near_line = [](int x, int y) {
    auto close = [](int a, int line) {
      return std::abs(2 * a + 1 - 2 * line) <= 4;
    };  // centre within 2 px
    return close(x, 40) || close(x, 120) || close(x, 200) || close(y, 10) || close(y, 50) ||
           close(y, 90);
  };
  int changed = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 240; ++x)
      if (!same(plain.pixel(x, y), net.pixel(x, y))) {
        ++changed;
        if (!near_line(x, y)) FAIL("pixel " << x << ", " << y << " changed away from the net");
      }
  CHECK(changed > 2 * (160 + 80));
  // Across the line x = 1 (column 120), at row 30, the darkest pixel is net-dark.
  int darkest = 255;
  for (int x = 117; x <= 122; ++x) darkest = std::min<int>(darkest, net.pixel(x, 30)[1]);
  CHECK(darkest < 150);
}

TEST_CASE("render: curves are drawn over the surface along their projection, hidden behind it",
          "[render]") {
  // The plate [0, 2] x [0, 1] at z = 0 from above (80 px per unit, centred at column 120, row
  // 50). A line on the plate at y = 0.5 from x = 0.25 to 1.75 (row 50, columns 60 to 180), and
  // one under it at z = -0.2 along x = 1 (column 120): hidden by the plate.
  RenderOptions o = top_view();
  o.supersample = false;
  surface::Points3 on(2, 3), under(2, 3);
  on << 0.25, 0.5, 0, 1.75, 0.5, 0;
  under << 1, 0.1, -0.2, 1, 0.9, -0.2;
  const auto line = [](const surface::Points3& p) {
    return surface::make_curve(1, {0, 0, 1, 1}, p);
  };
  const Image plain = render({plate(0, 2, 0, 1, 0)}, o);
  const Image drawn = render({plate(0, 2, 0, 1, 0)}, o, {line(on), line(under)});
  int changed = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 240; ++x)
      if (!same(plain.pixel(x, y), drawn.pixel(x, y))) {
        ++changed;
        CHECK(same(drawn.pixel(x, y), o.curve_colour));
        // Only along the visible line: rows 49..51, columns 59..181.
        if (!(y >= 48 && y <= 52 && x >= 58 && x <= 182))
          FAIL("pixel " << x << ", " << y << " changed away from the visible curve");
      }
  CHECK(changed >= 3 * 118);
  CHECK(same(drawn.pixel(120, 50), o.curve_colour));
  CHECK(same(drawn.pixel(120, 20), plain.pixel(120, 20)));  // the hidden line's column
}

TEST_CASE("render: write_png writes the pixels that libpng reads back, and no temporary file",
          "[render]") {
  const fs::path dir = fs::path(CLAY_TEST_OUTPUT_DIR) / "render";
  fs::remove_all(dir);
  fs::create_directories(dir);
  RenderOptions o;
  o.width = 64;
  o.height = 48;
  o.control_net = true;
  const Image img = render({plate(0, 2, 0, 1, 0, 3), plate(0.5, 1.5, 0.25, 0.75, 0.5, 2)}, o);
  const fs::path file = dir / "plates.png";
  write_png(img, file);
  write_png(img, file);  // over an existing picture
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  REQUIRE(png_image_begin_read_from_file(&png, file.c_str()) != 0);
  CHECK(png.width == 64u);
  CHECK(png.height == 48u);
  png.format = PNG_FORMAT_RGB;
  std::vector<std::uint8_t> back(PNG_IMAGE_SIZE(png));
  REQUIRE(png_image_finish_read(&png, nullptr, back.data(), 0, nullptr) != 0);
  CHECK(back == img.rgb);
  CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);
  // In memory: libpng decodes encode_png's bytes to the same pixels.
  const std::vector<unsigned char> bytes = encode_png(img);
  png_image mem{};
  mem.version = PNG_IMAGE_VERSION;
  REQUIRE(png_image_begin_read_from_memory(&mem, bytes.data(), bytes.size()) != 0);
  CHECK(mem.width == 64u);
  mem.format = PNG_FORMAT_RGB;
  std::vector<std::uint8_t> decoded(PNG_IMAGE_SIZE(mem));
  REQUIRE(png_image_finish_read(&mem, nullptr, decoded.data(), 0, nullptr) != 0);
  CHECK(decoded == img.rgb);
  Image bad = img;
  bad.rgb.pop_back();
  CHECK_THAT(error_of([&] { encode_png(bad); }).second,
             Contains("encode_png") && Contains("9216 bytes"));
}

TEST_CASE("render: bad options, no surfaces, bad images and unwritable files are named",
          "[render]") {
  const std::vector<surface::BSplineSurface> one{plate(0, 1, 0, 1, 0)};
  auto with = [&](auto change) {
    RenderOptions o;
    change(o);
    return error_of([&] { render(one, o); });
  };
  auto [c1, m1] = with([](RenderOptions& o) { o.width = 8; });
  CHECK(c1 == ErrorCategory::InvalidArgument);
  CHECK_THAT(m1, Contains("RenderOptions.width = 8") && Contains("[16, 4096]"));
  auto [c2, m2] = with([](RenderOptions& o) { o.eye_direction = Eigen::Vector3d::Zero(); });
  CHECK(c2 == ErrorCategory::InvalidArgument);
  CHECK_THAT(m2, Contains("RenderOptions.eye_direction = [0, 0, 0]") && Contains("non-zero"));
  auto [c3, m3] = with([](RenderOptions& o) { o.samples_per_span = 0; });
  CHECK_THAT(m3, Contains("RenderOptions.samples_per_span = 0") && Contains("[1, 64]"));
  auto [c4, m4] = with([](RenderOptions& o) { o.margin = 0.5; });
  CHECK_THAT(m4, Contains("RenderOptions.margin = 0.5"));
  auto [c5, m5] = with([](RenderOptions& o) { o.height = 5000; });
  CHECK_THAT(m5, Contains("RenderOptions.height = 5000"));
  CHECK((c3 == ErrorCategory::InvalidArgument && c4 == c3 && c5 == c3));

  auto [c6, m6] = error_of([] { render({}); });
  CHECK(c6 == ErrorCategory::InvalidArgument);
  CHECK_THAT(m6, Contains("no surfaces"));
  auto broken = one;
  broken.push_back(one[0]);
  broken[1].weights[2] = -1;
  auto [c7, m7] = error_of([&] { render(broken); });
  CHECK(c7 == ErrorCategory::InvalidGeometry);
  CHECK_THAT(m7, Contains("surface #1"));

  const fs::path missing = fs::path(CLAY_TEST_OUTPUT_DIR) / "no such folder" / "p.png";
  auto [c8, m8] = error_of([&] {
    write_png(Image{16, 16, std::vector<std::uint8_t>(3 * 16 * 16)}, missing);
  });
  CHECK(c8 == ErrorCategory::Io);
  CHECK_THAT(m8, Contains(missing.string()));
  auto [c9, m9] = error_of([&] {
    write_png(Image{16, 16, std::vector<std::uint8_t>(10)}, "x.png");
  });
  CHECK(c9 == ErrorCategory::InvalidArgument);
  CHECK_THAT(m9, Contains("16 x 16") && Contains("768 bytes") && Contains("it has 10"));
}

TEST_CASE("facing_eye: an open panel is pictured from its front, a closed model as asked",
          "[render]") {
  const Eigen::Vector3d eye(-1, -1.2, 0.9);
  // A square panel in z = 0 whose outward normal points down (-z): the default eye sees its back.
  clay::brep::ModelMesh panel;
  for (const auto& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 1, 0),
                        Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(1, 0, 0)}) {
    panel.positions.push_back(p);
    panel.normals.emplace_back(0, 0, -1);
  }
  panel.triangles = {{0, 1, 2}, {0, 2, 3}};  // counter-clockwise seen from -z
  const Eigen::Vector3d front = facing_eye(panel, eye);
  CHECK_THAT(front.norm(), Catch::Matchers::WithinAbs(1.0, 1e-15));
  CHECK(front.z() < 0);  // from below, where the normal points
  // The mirror image of the default: same x and y, z flipped.
  CHECK_THAT(front.x(), Catch::Matchers::WithinAbs(eye.normalized().x(), 1e-15));
  CHECK_THAT(front.z(), Catch::Matchers::WithinAbs(-eye.normalized().z(), 1e-15));
  // Seen nearly edge on, the eye is raised to 25 degrees above the panel.
  const Eigen::Vector3d low = facing_eye(panel, Eigen::Vector3d(1, 0, 0.01));
  CHECK_THAT(-low.z(),
             Catch::Matchers::WithinAbs(std::sin(25 * 3.14159265358979323846 / 180), 1e-12));
  // A closed tetrahedron (outward normals): every side is a front, the eye stays.
  clay::brep::ModelMesh solid;
  for (const auto& p : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                        Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)}) {
    solid.positions.push_back(p);
    solid.normals.push_back(p);
  }
  solid.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  CHECK((facing_eye(solid, eye) - eye.normalized()).norm() <= 1e-15);
  auto [category, message] = error_of([&] { facing_eye(panel, Eigen::Vector3d::Zero()); });
  CHECK(category == ErrorCategory::InvalidArgument);
  CHECK_THAT(message, Contains("non-zero"));
}
