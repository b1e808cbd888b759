#pragma once
/// The one tessellator of the kernel (DESIGN.md: surface/ owns it): a surface on a parameter grid
/// that follows its knots, with exact unit normals, for the glTF preview and the browser viewer;
/// and the surface area from the NURBS itself, by Gauss–Legendre quadrature, to check a mesh.
#include <clay/surface/bspline_surface.hpp>
#include <clay/surface/export.hpp>

#include <Eigen/Core>

#include <array>
#include <vector>

namespace clay::surface {

/// A grid mesh: rows x cols vertices, vertex (i, j) at row i * cols + j of `positions`, at the
/// parameters (us[i], vs[j]); two triangles per grid cell.
struct GridMesh {
  int rows = 0, cols = 0;
  std::vector<double> us, vs;
  Points3 positions;  ///< S(u, v), mm
  Points3 normals;    ///< unit S_u x S_v; at a pole (S_u or S_v vanishing, exactly or nearly,
                      ///< as after a refit) the limit normal S_u x S_uv (or S_uv x S_v) turned to
                      ///< the side of the cells around it, else those cells' normal
};

/// The grid parameters of one direction: `per_span` samples per knot span following the knots
/// (8 by default), at least 17 and at most `max_samples` in all (161 by default), ends included.
/// Throws clay::Error(InvalidArgument) for per_span outside [1, 4096] or max_samples outside
/// [17, 4097].
CLAY_SURFACE_API std::vector<double> tessellation_parameters(const BSplineBasis& basis,
                                                             int per_span = 8,
                                                             int max_samples = 161);

/// The surface on the grid tessellation_parameters(u) x tessellation_parameters(v) (with the
/// same per_span and max_samples). Throws clay::Error(InvalidGeometry) for an invalid surface.
CLAY_SURFACE_API GridMesh tessellate(const BSplineSurface& surface, int per_span = 8,
                                     int max_samples = 161);

/// Sum of the areas of the mesh's triangles (mm^2); each cell is split along its shorter diagonal.
CLAY_SURFACE_API double mesh_area(const GridMesh& mesh);

/// The triangles of a grid cell (i, j) as vertex indices, split along the shorter diagonal
/// (mesh_area and every writer use this split).
CLAY_SURFACE_API std::array<std::array<int, 3>, 2> cell_triangles(const GridMesh& mesh, int i,
                                                                  int j);

/// The area of the surface (mm^2): ∫∫ |S_u x S_v| du dv by 8 x 8-point Gauss–Legendre per knot
/// span, each span halved `refine` times in both directions (refine >= 0). Throws
/// clay::Error(InvalidGeometry) for an invalid surface, InvalidArgument for refine < 0.
CLAY_SURFACE_API double surface_area(const BSplineSurface& surface, int refine = 1);

/// A mesh whose area is within `relative_area` of surface_area (refine 2): the viewer's grid
/// (8 samples per span, at most 161), then 16, 32, ... samples per span, at most `max_samples` a
/// direction, until it is. Throws clay::Error(ToleranceNotMet) naming the grid and the areas when
/// even the finest grid allowed misses it, and InvalidArgument for relative_area outside
/// (0, 0.5) or max_samples outside [17, 4097].
CLAY_SURFACE_API GridMesh tessellate_to_area(const BSplineSurface& surface,
                                             double relative_area = 0.005, int max_samples = 1025);

}  // namespace clay::surface
