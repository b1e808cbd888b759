#pragma once
/// Pictures of surfaces: a small software renderer (orthographic camera, z-buffer, Lambert and a
/// soft specular highlight) and a PNG writer, for README figures and `clayform render`. No GPU,
/// no window, no OpenCASCADE: the surfaces are tessellated with surface::evaluate_grid, whole
/// models by brep::tessellate.
#include <clay/brep/mesh.hpp>
#include <clay/render/export.hpp>
#include <clay/surface/bspline_curve.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace clay::render {

/// An 8-bit colour {red, green, blue}.
using Rgb = std::array<std::uint8_t, 3>;

/// How a picture is made. Every field is checked by validate().
struct CLAY_RENDER_API RenderOptions {
  int width = 960;   ///< picture width in pixels, in [16, 8192]
  int height = 640;  ///< picture height in pixels, in [16, 8192]
  /// Direction from the model towards the eye (any length > 0, finite): the camera sits far along
  /// it and looks back along -eye_direction. The default looks down on the model from -x, -y, +z.
  /// World +z is up on the picture (world +y when eye_direction is along z).
  Eigen::Vector3d eye_direction{-1.0, -1.2, 0.9};
  /// Tessellation density: parameters per non-empty knot span and direction, in [1, 64]. At most
  /// 400 triangle rows per direction: fewer per span when a surface has many spans, and evenly
  /// spaced parameters when it has more than 400 spans.
  int samples_per_span = 8;
  double margin = 0.05;      ///< free border on each side, fraction of width/height, in [0, 0.4]
  bool control_net = false;  ///< draw each control net (lines and points) over the surfaces
  bool supersample = true;   ///< 2 x 2 samples per pixel, averaged (anti-aliasing)
  Rgb background{255, 255, 255};
  Rgb net_colour{40, 40, 40};     ///< colour of the control net
  Rgb curve_colour{200, 30, 30};  ///< colour of the curves drawn over the surfaces
  /// Base colour of surface k is colours[k % colours.size()]; empty: a palette with a distinct hue
  /// per surface (golden-angle hue steps from blue).
  std::vector<Rgb> colours;

  /// Every bad field, each naming the field, its value and the rule broken; empty when valid.
  std::vector<std::string> problems() const;
  /// Throws clay::Error(InvalidArgument) listing problems(), if any.
  void validate() const;
};

/// An 8-bit RGB picture: pixel (x, y), x to the right and y down from the top-left corner, is
/// rgb[3 * (y * width + x) + c] for channel c (red, green, blue).
struct CLAY_RENDER_API Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  /// Pixel (x, y). Precondition: 0 <= x < width, 0 <= y < height.
  Rgb pixel(int x, int y) const noexcept;
};

/// Pictures `surfaces` with an orthographic camera along options.eye_direction, fitted to the
/// bounding box of the tessellated surfaces (and of the control nets when drawn) so that the
/// whole model is visible with options.margin free on each side and its centre at the picture's
/// centre; the scale is uniform (squares stay squares).
///
/// Each surface is tessellated on the grid of its knot spans (samples_per_span), split into
/// triangles and z-buffered. The unit normal at each grid point is S_u x S_v from
/// surface::derivatives; at a pole, where S_v vanishes along an edge (S_u along an edge of v), it
/// is the limit S_u x S_uv (S_uv x S_v), oriented like the neighbouring grid cells, and where that
/// vanishes too the average of the normals of the neighbouring cells (cross product of the cell
/// diagonals). Normals are
/// interpolated across each triangle and shaded per sample (Phong shading): two-sided Lambert
/// under a key light above-left of the eye (weight 0.6) and a head light (0.25), ambient 0.15,
/// plus a soft Blinn–Phong highlight of the key light (exponent 50, strength 0.35) so that the
/// highlight bands show curvature and its breaks.
///
/// `curves` are drawn over the surfaces in options.curve_colour, 3 pixels wide, as polylines of
/// 32 samples per knot span; a curve point is hidden where a surface lies in front of it by more
/// than 1 % of the model's depth (a curve on the surface shows, one behind it does not). They
/// count in the fit.
///
/// Throws clay::Error: InvalidArgument for bad options or no surfaces, InvalidGeometry for an
/// invalid surface (surface::validate) or curve.
CLAY_RENDER_API Image render(const std::vector<surface::BSplineSurface>& surfaces,
                             const RenderOptions& options = {},
                             const std::vector<surface::BSplineCurve>& curves = {});

/// Pictures a whole model's mesh (brep::tessellate: trimmed faces, holes are holes) with the
/// same camera, fit and shading as render(). Each triangle's base colour is
/// options.colours[body % size] when colours are given, else its face's colour from the model
/// (its own or its body's), else the palette's colour of its body. The control nets of
/// `control_nets` are drawn over it when options.control_net is set. Throws clay::Error
/// (InvalidArgument) for bad options or a mesh whose arrays disagree.
/// `curves` are drawn as by render().
CLAY_RENDER_API Image render_mesh(const brep::ModelMesh& mesh, const RenderOptions& options = {},
                                  const std::vector<surface::BSplineSurface>& control_nets = {},
                                  const std::vector<surface::BSplineCurve>& curves = {});

/// The direction to picture `mesh` from so that an open sheet shows its front: `eye` itself for a
/// closed or nearly closed model (the area-weighted sum of its triangles' outward normals below a
/// fifth of its area), else `eye` mirrored in the sheet's mean plane when it looks at the back
/// (a stylist's panel exported with its normal away from the default view), and raised to at
/// least 25° above that plane so the sheet is not seen edge on. Unit length. Throws
/// clay::Error(InvalidArgument) for a zero or non-finite `eye`.
CLAY_RENDER_API Eigen::Vector3d facing_eye(const brep::ModelMesh& mesh, const Eigen::Vector3d& eye);

/// Writes `image` as an 8-bit RGB PNG (libpng), atomically: into a temporary file next to `file`,
/// then renamed over it. Throws clay::Error: InvalidArgument when the image's size and pixel count
/// disagree, Io naming the file when it cannot be written.
CLAY_RENDER_API void write_png(const Image& image, const std::filesystem::path& file);

/// `image` encoded as an 8-bit RGB PNG in memory (libpng): a notebook's picture, a network
/// frame. Throws clay::Error(InvalidArgument) for an image whose pixels do not match its size.
CLAY_RENDER_API std::vector<unsigned char> encode_png(const Image& image);

}  // namespace clay::render
