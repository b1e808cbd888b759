#pragma once
/// Local deformations with continuity (Sederberg–Parry §3.1): a lattice whose control points next
/// to chosen faces stay at their undisplaced positions joins the undeformed space around it with
/// C^k continuity. For a Bézier lattice (and a clamped B-spline lattice) that is the face plane
/// and the k planes after it; for any knot vector the locked planes are those whose basis
/// functions have a non-zero derivative of order <= k on the face (for unclamped uniform knots of
/// degree p: p planes, whatever k < p).
#include <clay/deform/export.hpp>
#include <clay/deform/lattice.hpp>

#include <span>
#include <vector>

namespace clay::deform {

/// A face of the lattice: s = 0, s = 1, t = 0, t = 1, u = 0, u = 1.
enum class Face { SMin, SMax, TMin, TMax, UMin, UMax };

/// C^order continuity with the undeformed space across one face.
struct FaceContinuity {
  Face face = Face::SMin;  ///< the face across which the continuity holds
  int order = 1;           ///< k of C^k, 0 <= k <= degree in the face's normal direction
};

/// Which control points must stay undisplaced for the requested continuity: entry r is true when
/// row r of lattice.points is locked (same index as the points). Throws clay::Error
/// (InvalidArgument) for an order outside [0, degree] naming the face, (InvalidGeometry) for an
/// invalid lattice.
CLAY_DEFORM_API std::vector<bool> locked_control_points(const BezierLattice& lattice,
                                                        std::span<const FaceContinuity> faces);
/// Same for a B-spline lattice (derivatives of the basis at the face, The NURBS Book A2.3).
CLAY_DEFORM_API std::vector<bool> locked_control_points(const BSplineLattice& lattice,
                                                        std::span<const FaceContinuity> faces);

/// The lattice with its locked control points reset to their undisplaced positions, so that the
/// deformation is C^k with the space around the faces (Sederberg–Parry §3.1). Same throws.
CLAY_DEFORM_API BezierLattice with_continuity(BezierLattice lattice,
                                              std::span<const FaceContinuity> faces);
/// Same for a B-spline lattice.
CLAY_DEFORM_API BSplineLattice with_continuity(BSplineLattice lattice,
                                               std::span<const FaceContinuity> faces);

}  // namespace clay::deform
