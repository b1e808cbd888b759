// Software rendering of surfaces into an RGB picture and a PNG writer (clay/render/render.hpp).
#include <clay/brep/mesh.hpp>
#include <clay/error.hpp>
#include <clay/internal/checks.hpp>
#include <clay/internal/files.hpp>
#include <clay/render/render.hpp>
#include <clay/surface/basis.hpp>
#include <clay/surface/evaluate.hpp>
#include <clay/surface/tessellate.hpp>

#include <png.h>
#include <unistd.h>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <system_error>

namespace clay::render {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

std::string text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", x);
  return buf;
}

/// Orthonormal camera frame: `right` and `up` span the picture, `eye` points towards the viewer.
struct Camera {
  Vector3d right, up, eye;
};

Camera camera_for(const Vector3d& eye_direction) {
  const Vector3d w = eye_direction.normalized();
  const Vector3d world_up =
      Vector3d::UnitZ().cross(w).norm() < 1e-6 ? Vector3d::UnitY() : Vector3d::UnitZ();
  const Vector3d r = world_up.cross(w).normalized();
  return {r, w.cross(r), w};
}

constexpr int max_rows = 400;  // triangle rows per direction and surface

/// A tessellated surface: the kernel's one tessellator (surface::tessellate: the viewer's and the
/// glTF preview's grid and normal rules, poles included), samples_per_span per knot span, at most
/// max_rows intervals a direction.
struct Mesh {
  surface::GridMesh grid;
  std::vector<Vector3d> normals;
  int nu() const { return grid.rows; }
  int nv() const { return grid.cols; }
  Vector3d point(int i, int j) const {
    return grid.positions.row(static_cast<Eigen::Index>(i) * grid.cols + j).transpose();
  }
};

Mesh tessellate_for_render(const surface::BSplineSurface& s, int per_span) {
  Mesh m{surface::tessellate(s, per_span, max_rows + 1), {}};
  m.normals.reserve(static_cast<size_t>(m.grid.normals.rows()));
  for (Eigen::Index r = 0; r < m.grid.normals.rows(); ++r)
    m.normals.emplace_back(m.grid.normals.row(r).transpose());
  return m;
}

/// Base colour of surface k: golden-angle hue steps from blue, soft saturation (HSV -> RGB).
Rgb palette(size_t k) {
  const double h = std::fmod(0.58 + 0.381966 * static_cast<double>(k), 1.0) * 6.0, s = 0.45,
               v = 0.92;
  const double f = h - std::floor(h), p = v * (1 - s), q = v * (1 - s * f),
               t = v * (1 - s * (1 - f));
  const double rgb[6][3] = {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}};
  const auto* c = rgb[static_cast<int>(h) % 6];
  auto byte = [](double x) { return static_cast<std::uint8_t>(std::lround(255 * x)); };
  return {byte(c[0]), byte(c[1]), byte(c[2])};
}

/// The sample buffers (supersampled when asked) and the projection of world points onto them.
struct Canvas {
  int width, height;              // in samples
  std::vector<float> depth;       // towards the eye, normalized to [0, 1] over the model; -1 empty
  std::vector<std::uint8_t> rgb;  // shaded colour per sample
  Camera cam;
  double centre_x, centre_y, scale, depth_min, depth_scale;
  Vector3d light, half;  // unit key light and Blinn–Phong half vector

  Vector3d project(const Vector3d& p) const {
    return {0.5 * width + (p.dot(cam.right) - centre_x) * scale,
            0.5 * height - (p.dot(cam.up) - centre_y) * scale,
            (p.dot(cam.eye) - depth_min) * depth_scale};
  }

  void put(int x, int y, const Rgb& c) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    std::copy(c.begin(), c.end(), rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * width + x));
  }

  /// Two-sided Lambert: ambient 0.15, key light 0.6, head light 0.25 (no face seen is black); soft
  /// Blinn–Phong highlight of the key light.
  Rgb shade(Vector3d n, const Rgb& base) const {
    const double len = n.norm();
    n = len > 0 ? Vector3d(n / len) : cam.eye;
    if (n.dot(cam.eye) < 0) n = -n;
    const double diffuse = 0.15 + 0.6 * std::max(0.0, n.dot(light)) + 0.25 * n.dot(cam.eye);
    const double spec = 0.35 * 255 * std::pow(std::max(0.0, n.dot(half)), 50);
    Rgb c;
    for (int k = 0; k < 3; ++k)
      c[static_cast<size_t>(k)] = static_cast<std::uint8_t>(
          std::lround(std::min(255.0, base[static_cast<size_t>(k)] * diffuse + spec)));
    return c;
  }

  /// Z-buffered triangle a, b, c (screen points) with vertex normals na, nb, nc; samples at pixel
  /// centres, edges inclusive (no cracks between neighbouring triangles).
  void triangle(const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& na,
                const Vector3d& nb, const Vector3d& nc, const Rgb& base) {
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (!(std::abs(area) > 1e-12)) return;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}) - 0.5)));
    const int x1 =
        std::min(width - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}) - 0.5)));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}) - 0.5)));
    const int y1 =
        std::min(height - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}) - 0.5)));
    auto edge = [](const Vector3d& p, const Vector3d& q, double x, double y) {
      return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
    };
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double la = edge(b, c, px, py) / area, lb = edge(c, a, px, py) / area,
                     lc = edge(a, b, px, py) / area;
        if (la < 0 || lb < 0 || lc < 0) continue;
        const float z = static_cast<float>(la * a.z() + lb * b.z() + lc * c.z());
        float& stored =
            depth[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)];
        if (z <= stored) continue;
        stored = z;
        put(x, y, shade(la * na + lb * nb + lc * nc, base));
      }
  }

  /// A line `thick` samples wide, drawn over everything (a control net is seen through the
  /// surface), or, with a `hidden` depth margin, only where no surface lies nearer the eye by
  /// more than that margin.
  void line(const Vector3d& a, const Vector3d& b, int thick, const Rgb& c,
            double hidden = std::numeric_limits<double>::infinity()) {
    const int steps =
        static_cast<int>(std::ceil(std::max(std::abs(b.x() - a.x()), std::abs(b.y() - a.y())))) + 1;
    for (int k = 0; k <= steps; ++k) {
      const Vector3d p = a + (b - a) * (static_cast<double>(k) / steps);
      const int x = static_cast<int>(std::floor(p.x() - 0.5 * (thick - 1)));
      const int y = static_cast<int>(std::floor(p.y() - 0.5 * (thick - 1)));
      for (int dy = 0; dy < thick; ++dy)
        for (int dx = 0; dx < thick; ++dx) {
          const int px = x + dx, py = y + dy;
          if (px < 0 || py < 0 || px >= width || py >= height) continue;
          if (std::isfinite(hidden) && depth[static_cast<size_t>(py) * static_cast<size_t>(width) +
                                             static_cast<size_t>(px)] > p.z() + hidden)
            continue;
          put(px, py, c);
        }
    }
  }
};

}  // namespace

std::vector<std::string> RenderOptions::problems() const {
  std::vector<std::string> out;
  auto bad = [&out](const std::string& field, const std::string& value, const std::string& rule) {
    out.push_back("render: RenderOptions." + field + " = " + value + "; " + rule);
  };
  if (width < 16 || width > 4096)
    bad("width", std::to_string(width), "must be in [16, 4096] pixels");
  if (height < 16 || height > 4096)
    bad("height", std::to_string(height), "must be in [16, 4096] pixels");
  if (!internal::all_finite(eye_direction) || !(eye_direction.norm() > 0))
    bad("eye_direction",
        "[" + text(eye_direction.x()) + ", " + text(eye_direction.y()) + ", " +
            text(eye_direction.z()) + "]",
        "must be finite and non-zero (the direction from the model towards the eye)");
  if (samples_per_span < 1 || samples_per_span > 64)
    bad("samples_per_span", std::to_string(samples_per_span), "must be in [1, 64]");
  if (!(margin >= 0 && margin <= 0.4))
    bad("margin", text(margin), "must be in [0, 0.4] (fraction of the picture)");
  return out;
}

void RenderOptions::validate() const {
  internal::throw_if(ErrorCategory::InvalidArgument, problems());
}

Rgb Image::pixel(int x, int y) const noexcept {
  const size_t k =
      3 * (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x));
  return {rgb[k], rgb[k + 1], rgb[k + 2]};
}

namespace {

/// Triangles to draw: points, unit normals at them, and a base colour per triangle.
struct Batch {
  std::vector<Vector3d> points, normals;
  std::vector<std::array<int, 3>> triangles;
  std::vector<Rgb> colours;
};

/// The picture of `batches` (and of the control nets of `nets` when asked): the camera fitted to
/// everything drawn, z-buffered Phong shading, supersamples averaged.
Image draw(const std::vector<Batch>& batches, const std::vector<surface::BSplineSurface>& nets,
           const std::vector<std::vector<Vector3d>>& polylines, const RenderOptions& options) {
  const int f = options.supersample ? 2 : 1;
  Canvas cv{f * options.width,
            f * options.height,
            {},
            {},
            camera_for(options.eye_direction),
            0,
            0,
            1,
            0,
            1,
            {},
            {}};

  // Fit: the box of everything drawn, in camera coordinates.
  Vector3d lo = Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  auto grow = [&](const Vector3d& p) {
    const Vector3d q{p.dot(cv.cam.right), p.dot(cv.cam.up), p.dot(cv.cam.eye)};
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  };
  for (const Batch& b : batches)
    for (const Vector3d& p : b.points) grow(p);
  if (options.control_net)
    for (const auto& s : nets)
      for (Eigen::Index i = 0; i < s.points.rows(); ++i) grow(s.points.row(i).transpose());
  for (const auto& line : polylines)
    for (const Vector3d& p : line) grow(p);
  const Vector3d extent = hi - lo;
  const double room = 1 - 2 * options.margin;
  const double sx =
      extent.x() > 0 ? room * cv.width / extent.x() : std::numeric_limits<double>::infinity();
  const double sy =
      extent.y() > 0 ? room * cv.height / extent.y() : std::numeric_limits<double>::infinity();
  cv.scale = std::isfinite(std::min(sx, sy)) ? std::min(sx, sy) : 1.0;
  cv.centre_x = 0.5 * (lo.x() + hi.x());
  cv.centre_y = 0.5 * (lo.y() + hi.y());
  cv.depth_min = lo.z();
  cv.depth_scale = extent.z() > 0 ? 1 / extent.z() : 1.0;
  cv.light = (cv.cam.eye + 0.5 * cv.cam.up - 0.5 * cv.cam.right).normalized();
  cv.half = (cv.light + cv.cam.eye).normalized();

  const size_t samples = static_cast<size_t>(cv.width) * static_cast<size_t>(cv.height);
  cv.depth.assign(samples, -1.0f);
  cv.rgb.resize(3 * samples);
  for (size_t k = 0; k < samples; ++k)
    std::copy(options.background.begin(), options.background.end(),
              cv.rgb.begin() + 3 * static_cast<std::ptrdiff_t>(k));

  for (const Batch& b : batches) {
    std::vector<Vector3d> screen;
    screen.reserve(b.points.size());
    for (const Vector3d& p : b.points) screen.push_back(cv.project(p));
    for (size_t k = 0; k < b.triangles.size(); ++k) {
      const auto [i, j, l] = b.triangles[k];
      cv.triangle(screen[static_cast<size_t>(i)], screen[static_cast<size_t>(j)],
                  screen[static_cast<size_t>(l)], b.normals[static_cast<size_t>(i)],
                  b.normals[static_cast<size_t>(j)], b.normals[static_cast<size_t>(l)],
                  b.colours[k]);
    }
  }
  if (options.control_net)
    for (const auto& s : nets) {
      auto at = [&](int i, int j) { return cv.project(s.points.row(s.index(i, j)).transpose()); };
      for (int i = 0; i < s.count_u(); ++i)
        for (int j = 0; j < s.count_v(); ++j) {
          if (i + 1 < s.count_u()) cv.line(at(i, j), at(i + 1, j), f, options.net_colour);
          if (j + 1 < s.count_v()) cv.line(at(i, j), at(i, j + 1), f, options.net_colour);
          cv.line(at(i, j), at(i, j), 3 * f, options.net_colour);  // the control point
        }
    }
  for (const auto& line : polylines)
    for (size_t k = 0; k + 1 < line.size(); ++k)
      cv.line(cv.project(line[k]), cv.project(line[k + 1]), 3 * f, options.curve_colour, 0.01);

  // Average f x f samples per pixel.
  Image image{options.width, options.height,
              std::vector<std::uint8_t>(3 * static_cast<size_t>(options.width) *
                                        static_cast<size_t>(options.height))};
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        int sum = 0;
        for (int dy = 0; dy < f; ++dy)
          for (int dx = 0; dx < f; ++dx)
            sum += cv.rgb[3 * (static_cast<size_t>(f * y + dy) * static_cast<size_t>(cv.width) +
                               static_cast<size_t>(f * x + dx)) +
                          static_cast<size_t>(c)];
        image.rgb[3 * (static_cast<size_t>(y) * static_cast<size_t>(image.width) +
                       static_cast<size_t>(x)) +
                  static_cast<size_t>(c)] = static_cast<std::uint8_t>((sum + f * f / 2) / (f * f));
      }
  return image;
}

Rgb byte_colour(const brep::Colour& c) {
  auto byte = [](double x) {
    return static_cast<std::uint8_t>(std::lround(255 * std::clamp(x, 0.0, 1.0)));
  };
  return {byte(c.r), byte(c.g), byte(c.b)};
}

}  // namespace

/// Each curve as a polyline of 32 samples per knot span.
std::vector<std::vector<Vector3d>> polylines_of(const std::vector<surface::BSplineCurve>& curves) {
  std::vector<std::vector<Vector3d>> out;
  for (size_t k = 0; k < curves.size(); ++k) {
    surface::validate(curves[k], "render: curve #" + std::to_string(k));
    const surface::Points3 p =
        surface::evaluate_many(curves[k], surface::span_samples(curves[k].basis, 32));
    auto& line = out.emplace_back();
    for (Eigen::Index i = 0; i < p.rows(); ++i) line.push_back(p.row(i).transpose());
  }
  return out;
}

Image render(const std::vector<surface::BSplineSurface>& surfaces, const RenderOptions& options,
             const std::vector<surface::BSplineCurve>& curves) {
  options.validate();
  if (surfaces.empty())
    throw Error(ErrorCategory::InvalidArgument, "render: no surfaces; give at least one");
  for (size_t k = 0; k < surfaces.size(); ++k)
    surface::validate(surfaces[k], "render: surface #" + std::to_string(k));
  std::vector<Batch> batches;
  for (size_t k = 0; k < surfaces.size(); ++k) {
    const Mesh m = tessellate_for_render(surfaces[k], options.samples_per_span);
    const Rgb base =
        options.colours.empty() ? palette(k) : options.colours[k % options.colours.size()];
    Batch& b = batches.emplace_back();
    for (int i = 0; i < m.nu(); ++i)
      for (int j = 0; j < m.nv(); ++j) b.points.push_back(m.point(i, j));
    b.normals = m.normals;
    for (int i = 0; i + 1 < m.nu(); ++i)
      for (int j = 0; j + 1 < m.nv(); ++j) {
        const int a = i * m.nv() + j, c = a + m.nv() + 1, d = a + 1;
        b.triangles.push_back({a, a + m.nv(), c});
        b.triangles.push_back({a, c, d});
      }
    b.colours.assign(b.triangles.size(), base);
  }
  return draw(batches, surfaces, polylines_of(curves), options);
}

Vector3d facing_eye(const brep::ModelMesh& mesh, const Vector3d& eye) {
  if (!internal::all_finite(eye) || !(eye.norm() > 0))
    throw Error(ErrorCategory::InvalidArgument,
                "facing_eye: the eye direction must be finite and non-zero");
  Vector3d e = eye.normalized();
  Vector3d sum = Vector3d::Zero();  // twice the area-weighted mean normal
  double area = 0;                  // twice the area
  for (const auto& t : mesh.triangles) {
    const auto at = [&](int k) {
      return mesh.positions[static_cast<size_t>(t[static_cast<size_t>(k)])];
    };
    const Vector3d n = (at(1) - at(0)).cross(at(2) - at(0));
    sum += n;
    area += n.norm();
  }
  if (!(area > 0) || sum.norm() < 0.2 * area) return e;  // closed: every side is a front
  const Vector3d n = sum.normalized();
  if (e.dot(n) < 0) e -= 2 * e.dot(n) * n;  // the back faces the eye: mirror it to the front
  // At least 25 degrees above the sheet (the default eye is 30 degrees above the xy plane).
  const double min_sine = std::sin(25.0 * 3.14159265358979323846 / 180.0);
  if (e.dot(n) < min_sine) {
    const Vector3d along = e - e.dot(n) * n;
    e = along.norm() > 0
            ? Vector3d(std::sqrt(1 - min_sine * min_sine) * along.normalized() + min_sine * n)
            : n;
  }
  return e.normalized();
}

Image render_mesh(const brep::ModelMesh& mesh, const RenderOptions& options,
                  const std::vector<surface::BSplineSurface>& control_nets,
                  const std::vector<surface::BSplineCurve>& curves) {
  options.validate();
  if (mesh.triangles.empty())
    throw Error(ErrorCategory::InvalidArgument, "render_mesh: the mesh has no triangles");
  const size_t nodes = mesh.positions.size();
  if (mesh.normals.size() != nodes || mesh.triangle_face.size() != mesh.triangles.size() ||
      mesh.face_body.size() != mesh.face_colours.size())
    throw Error(ErrorCategory::InvalidArgument,
                "render_mesh: the mesh's arrays disagree in size (" + std::to_string(nodes) +
                    " positions, " + std::to_string(mesh.normals.size()) + " normals, " +
                    std::to_string(mesh.triangles.size()) + " triangles, " +
                    std::to_string(mesh.triangle_face.size()) + " triangle faces, " +
                    std::to_string(mesh.face_body.size()) + " face bodies, " +
                    std::to_string(mesh.face_colours.size()) +
                    " face colours); give a mesh from brep::tessellate");
  Batch b;
  b.points = mesh.positions;
  b.normals = mesh.normals;
  b.triangles = mesh.triangles;
  for (size_t k = 0; k < mesh.triangles.size(); ++k) {
    for (int corner : mesh.triangles[k])
      if (corner < 0 || static_cast<size_t>(corner) >= nodes)
        throw Error(ErrorCategory::InvalidArgument,
                    "render_mesh: triangle " + std::to_string(k) + " refers to node " +
                        std::to_string(corner) + " of " + std::to_string(nodes));
    const int f = mesh.triangle_face[k];
    if (f < 0 || static_cast<size_t>(f) >= mesh.face_colours.size())
      throw Error(ErrorCategory::InvalidArgument, "render_mesh: triangle " + std::to_string(k) +
                                                      " lies on face " + std::to_string(f) +
                                                      ", which the mesh has no colour entry for");
    const auto& own = mesh.face_colours[static_cast<size_t>(f)];
    const size_t body = static_cast<size_t>(std::max(0, mesh.face_body[static_cast<size_t>(f)]));
    b.colours.push_back(!options.colours.empty() ? options.colours[body % options.colours.size()]
                        : own                    ? byte_colour(*own)
                                                 : palette(body));
  }
  return draw({b}, control_nets, polylines_of(curves), options);
}

namespace {

void check_image(const Image& image, const char* function) {
  const size_t expected = 3 * static_cast<size_t>(std::max(image.width, 0)) *
                          static_cast<size_t>(std::max(image.height, 0));
  if (image.width <= 0 || image.height <= 0 || image.rgb.size() != expected)
    throw Error(ErrorCategory::InvalidArgument,
                std::string(function) + ": an image of " + std::to_string(image.width) + " x " +
                    std::to_string(image.height) + " pixels needs " + std::to_string(expected) +
                    " bytes (3 per pixel, both sizes > 0), it has " +
                    std::to_string(image.rgb.size()));
}

png_image png_header(const Image& image) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  return png;
}

}  // namespace

std::vector<unsigned char> encode_png(const Image& image) {
  check_image(image, "encode_png");
  // libpng's simplified API: ask for the size first, then write into a buffer of that size.
  png_image png = png_header(image);
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&png, nullptr, &size, 0, image.rgb.data(), 0, nullptr)) {
    const std::string why = png.message;
    png_image_free(&png);
    throw Error(ErrorCategory::Internal, "encode_png: libpng refused the image: " + why);
  }
  std::vector<unsigned char> out(size);
  png = png_header(image);
  if (!png_image_write_to_memory(&png, out.data(), &size, 0, image.rgb.data(), 0, nullptr)) {
    const std::string why = png.message;
    png_image_free(&png);
    throw Error(ErrorCategory::Internal, "encode_png: libpng refused the image: " + why);
  }
  out.resize(size);
  return out;
}

void write_png(const Image& image, const fs::path& file) {
  check_image(image, "write_png");
  if (!file.has_filename())
    throw Error(ErrorCategory::InvalidArgument,
                "write_png: \"" + file.string() + "\" names no file; give e.g. picture.png");
  // Encoded in memory, then written as every library writes a file (internal::write_atomically):
  // a temporary made by mkstemp beside it, flushed, renamed over it.
  const std::vector<unsigned char> bytes = encode_png(image);
  try {
    internal::write_atomically(
        file, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
        "picture");
  } catch (const Error& e) {
    throw Error(e.category(), "write_png: " + e.message());
  }
}

}  // namespace clay::render
