#pragma once
/// Mass properties of solids (volume, centroid, inertia) and their exact gradients with respect to
/// the faces' control points and the vertices (issue #41).
///
/// Every property is a volume integral ∭_Ω φ(x) dV, φ = 1, x_i or x_i x_j (about a reference point
/// c near the solid), turned into ∯ Φ·n dA by the divergence theorem with div Φ = φ
/// (Φ = (x − c) / 3, e_i y_i² / 2, e_i y_i³ / 3, e_i y_i² y_j / 2, y = x − c), and each face's
/// integral over its trimmed domain into a loop integral by Green's theorem, as brep::volume_mm3
/// does: Gauss–Legendre per knot span along u (ceil(5p / 2) points: exact for the degree 5p − 1
/// of the second moments' integrand on a polynomial face of degree p; adaptive on rational
/// faces), adaptive along the pcurves until the 16- and 10-point rules agree to 1e-14 of the
/// size's power for every moment.
///
/// The gradient is the derivative of these figures as computed, not of an ideal solid: on a face
/// X(u, v) = Σ_k R_k(u, v) P_k (weights fixed) the flux ∬ Φ(X − c)·(X_u × X_v) du dv moves, for
/// P_k → P_k + e, by ∬ R_k e·(∇Φᵀ n) + R_k,u e·(X_v × Φ) + R_k,v e·(Φ × X_u) du dv, integrated
/// with the value's own nodes; c, the mean of the bodies' vertices, moves with them. On a closed
/// shell this is Hadamard's shape derivative ∯ φ(X) δX·n dA integrated by parts; on a real file's
/// shell with gaps (within its edge tolerances) it is still the exact derivative of the reported
/// figure, which Hadamard's form is not (a CATIA bolt with 5e-5 mm gaps: 2e-7 off). On a
/// polynomial model the volume is a cubic polynomial in the control points.
#include <clay/brep/export.hpp>
#include <clay/brep/model.hpp>

#include <Eigen/Core>

#include <array>
#include <optional>
#include <vector>

namespace clay::brep {

/// Volume, centroid and inertia of solids of unit density.
struct MassProperties {
  double volume_mm3 = 0;
  Eigen::Vector3d centroid_mm = Eigen::Vector3d::Zero();
  /// The inertia tensor about the centroid, ∭ (|r|² 1 − r rᵀ) dV with r = x − centroid (mm^5;
  /// times a density in kg/mm^3 it is in kg mm^2).
  Eigen::Matrix3d inertia_mm5 = Eigen::Matrix3d::Zero();
};

/// A property's derivative with respect to the model's points: row k of faces[f] is ∂q/∂P_k
/// (x, y, z) of face f's control point k (its weight held fixed), indexed like model.faces (a face
/// of no measured solid has no rows); row v of `vertices` is ∂q/∂(vertex v's point), through the
/// reference point c (zero on a closed shell but for the centroid's own c).
struct PointGradients {
  std::vector<Eigen::MatrixX3d> faces;
  Eigen::MatrixX3d vertices;
};

/// Mass properties and their gradients (see above).
struct MassPropertyGradients {
  MassProperties value;
  PointGradients volume;                   ///< mm^2 per mm
  std::array<PointGradients, 3> centroid;  ///< of centroid_mm x, y, z
  /// Of inertia_mm5's entries xx, yy, zz, xy, xz, yz (the tensor is symmetric).
  std::array<PointGradients, 6> inertia;
};

/// What mass_property_gradients measures and checks.
struct MassPropertyOptions {
  /// The body to measure (index into model.bodies; a solid for the mass properties, any body with
  /// faces for the area); none: every solid together (the area: every body's faces).
  std::optional<int> body;
  /// Check the model first (validate: its invariants, edge gaps within tolerance). false: the
  /// caller vouches for it, as an optimiser re-evaluating one topology at moved points does
  /// (the check costs as much as the integration on a 200-face plate); an invalid model then
  /// gives a meaningless figure, never a crash of a valid-topology model.
  bool validate = true;
};

/// Mass properties of every solid of the model together (its voids subtracted). Throws
/// clay::Error: InvalidGeometry when the model breaks an invariant (validate), InvalidArgument
/// for an assembly (flatten it first: brep::flattened) or a model without a solid,
/// ToleranceNotMet when a face's integration does not converge (naming it).
CLAY_BREP_API MassProperties mass_properties(const Model& model);
/// Mass properties of body `body` (a solid). Throws as above, and InvalidArgument for a body out
/// of range or one that is not a solid.
CLAY_BREP_API MassProperties mass_properties(const Model& model, int body);

/// Mass properties of every solid and their gradients with respect to the faces' control points.
/// Throws as mass_properties.
CLAY_BREP_API MassPropertyGradients mass_property_gradients(const Model& model);
/// Same for body `body`.
CLAY_BREP_API MassPropertyGradients mass_property_gradients(const Model& model, int body);
/// Same as options say.
CLAY_BREP_API MassPropertyGradients mass_property_gradients(const Model& model,
                                                            const MassPropertyOptions& options);

/// The area of faces. |n| = |X_u × X_v| is not a polynomial, even on a polynomial face, so each
/// face's ∬_D |n| du dv (turned into loop integrals by Green's theorem, as the volume) is
/// integrated adaptively along u and along the loops, and `bound_mm2` bounds the error: the sum,
/// over every accepted interval, of the gap between its 16- and 10-point Gauss–Legendre sums (the
/// error of the coarser rule; the area is the finer one's, typically many digits better), the
/// inner integrals' own bounds carried through the outer rule, and the rounding of the sums. The
/// bound is a posteriori, as QUADPACK's: rigorous for integrands the 10-point rule resolves to
/// its gap, which the adaptive refinement until the two agree to 1e-14 of the size² makes the
/// case on smooth faces (checked on spheres, cylinders, tori and real files' faces against their
/// closed forms and OCCT's BRepGProp).
struct SurfaceArea {
  double area_mm2 = 0;
  double bound_mm2 = 0;           ///< |area − area_mm2| <= bound_mm2 (see above)
  std::vector<double> faces_mm2;  ///< each face's area, indexed like model.faces (0 unmeasured)
};

/// The area and its gradient: row k of area.faces[f] is ∂A/∂P_k of face f's control point k
/// (weights held); the area does not depend on the vertices (area.vertices is zero). The
/// derivative of the figure as computed: ∬ R_k,u e·(X_v × ν) + R_k,v e·(ν × X_u) du dv with
/// ν = n / |n|, at the value's own nodes.
struct SurfaceAreaGradient {
  SurfaceArea value;
  PointGradients area;  ///< mm^2 per mm
};

/// The area of every face of every body (each face once): solids, shells and sheets. Throws
/// clay::Error: InvalidGeometry when the model breaks an invariant, InvalidArgument for an
/// assembly (flatten it first) or a model without faces, ToleranceNotMet when a face's
/// integration does not converge (naming it).
CLAY_BREP_API SurfaceArea surface_area(const Model& model);
/// The area of body `body`'s faces. Throws as above, and InvalidArgument for a body out of range
/// or one without faces (a wire body).
CLAY_BREP_API SurfaceArea surface_area(const Model& model, int body);
/// The area and its gradient, as options say (options.body: one body's faces). Throws as
/// surface_area.
CLAY_BREP_API SurfaceAreaGradient surface_area_gradient(const Model& model,
                                                        const MassPropertyOptions& options = {});

}  // namespace clay::brep
