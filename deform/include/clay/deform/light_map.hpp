#pragma once
/// The light form of a lattice step as an affine map of the lattice's control points (issue #38,
/// studio drags): one matrix product per drag update instead of a fit and its certificate.
///
/// Why it holds (docs/deform.md, "Light forms while dragging"): a lattice deforms a point by a
/// sum linear in its control points, D(X) = Σ_a B_a(ξ(X)) P_a (Sederberg–Parry eq. (2) for a
/// Bézier lattice, Hsu–Hughes–Kaufman eq. (1) for a B-spline lattice; X itself outside the
/// lattice), and the light form is the least-squares net of refit_deformed on fixed knots and
/// fixed Chebyshev–Lobatto parameters, C = A_u⁺ F A_vᵀ⁺, linear in the samples F = D(S(u_r, v_s)).
/// For a fixed input surface S, lattice frame, degrees and knots, and light knots,
///   C = Σ_a N_a P_a + C_out,   N_a = A_u⁺ [B_a(ξ(S(u_r, v_s)))] A_vᵀ⁺,
/// C_out the fit of the samples outside the lattice. With the points the light form was fitted
/// for, light_net gives that light form again (to rounding); with moved points, the net
/// refit_deformed would give on the same knots. It carries no certificate: the adaptive fit and
/// its certified bound are made again when the drag is let go.
#include <clay/deform/export.hpp>
#include <clay/deform/stack.hpp>
#include <clay/surface/bspline_surface.hpp>

#include <Eigen/Core>

namespace clay::deform {

/// The linear map from a lattice's control points to the light net of one input surface.
struct LatticeLightMap {
  surface::BSplineSurface input;  ///< the surface the lattice deforms (the step's input)
  Deformation lattice;            ///< the lattice it was made for (its points as they were then)
  surface::BSplineBasis u, v;     ///< the light form's bases (degree and knots)
  /// N: one row per light control point (row i * count_v + j, as BSplineSurface::index), one
  /// column per lattice control point (the lattice's row order).
  Eigen::MatrixXd weights;
  Points3 outside;  ///< C_out: the fit of the samples the lattice leaves where they are (mm)
};

/// The map for `lattice` (a Bézier or B-spline lattice) deforming `input`, on the bases of
/// `light` (a light form of that step: refit_deformed's result, or deform_surface's under a
/// budget). Throws clay::Error: InvalidArgument for another kind of deformation (taper, twist,
/// bend, extended lattices are not linear in points: refit them) or a rational `light`;
/// InvalidGeometry for an invalid lattice or surface.
CLAY_DEFORM_API LatticeLightMap lattice_light_map(const Deformation& lattice,
                                                  const surface::BSplineSurface& input,
                                                  const surface::BSplineSurface& light);

/// True when `map` holds for `lattice` deforming `input`: the same kind, frame, degrees and knots
/// (the points may differ) and the same input surface, bit for bit.
CLAY_DEFORM_API bool applies_to(const LatticeLightMap& map, const Deformation& lattice,
                                const surface::BSplineSurface& input) noexcept;

/// The light net of `input` deformed by `lattice` on the bases of `light`, fitted at once: what
/// light_net(lattice_light_map(lattice, input, light), lattice) gives (to rounding), for three
/// columns of samples instead of one per lattice point. For an input that changes at every call
/// (a drag upstream of the lattice: the style's target), where a map would serve once. Throws
/// clay::Error as lattice_light_map does.
CLAY_DEFORM_API surface::BSplineSurface light_fit(const Deformation& lattice,
                                                  const surface::BSplineSurface& input,
                                                  const surface::BSplineSurface& light);

/// The light net of map.input deformed by `lattice` (its points moved): Σ_a N_a P_a + C_out, then
/// closed sides kept closed and poles kept one point, as the light form's fit does. Throws
/// clay::Error(InvalidArgument) when the map does not apply to the lattice's structure (then make
/// a new map).
CLAY_DEFORM_API surface::BSplineSurface light_net(const LatticeLightMap& map,
                                                  const Deformation& lattice);

}  // namespace clay::deform
