#pragma once
/// Exact derivatives of a deformed B-rep model with respect to a lattice's points (issue #41):
/// the model's Jacobian in a fixed form, mass properties and their gradients, and moves that keep
/// chosen properties.
///
/// Every face the lattice reaches composes exactly (composition_jacobian: control points
/// P = C L, C fixed by the face, the frame and the degrees), every edge as its ruled strip's row 0
/// and every vertex by the FFD (influence_matrix), so the whole model is linear in the lattice
/// points L and its form does not depend on them: the same counts at the identity as after any
/// move (deform_model's lightest form keeps an undisplaced face as it is). The pcurves do not
/// change (composition keeps (u, v)). A model's mass properties are then polynomials (the volume
/// is cubic) in L on polynomial faces, and their gradients are
/// ∂q/∂L_J = Σ_faces Σ_k C_kJ ∂q/∂P_k + Σ_v V_vJ ∂q/∂V_v (brep::mass_property_gradients: with
/// respect to the faces' control points and the vertices).
#include <clay/brep/mass_properties.hpp>
#include <clay/brep/model.hpp>
#include <clay/deform/export.hpp>
#include <clay/deform/lattice.hpp>

#include <Eigen/SparseCore>

#include <array>
#include <optional>
#include <vector>

namespace clay::deform {

/// Row-major sparse matrix: geometry rows × lattice points.
using SparseRows = Eigen::SparseMatrix<double, Eigen::RowMajor>;

/// A model in the fixed form of its derivatives, and the linear maps from the lattice points to
/// its geometry. An entity whose matrix has no entries lies outside the lattice's box (the FFD is
/// the identity there) and keeps its points; inside, a row's entries sum to 1.
struct ModelJacobian {
  /// brep::flattened(model) composed at the lattice's points: each face the lattice reaches as
  /// composition_jacobian's surface (on the box of its trims when its surface leaves the lattice
  /// though its trims do not), each edge as the composition of its curve, each vertex moved by
  /// the FFD; edge and vertex tolerances widened as deform_model widens them.
  brep::Model model;
  /// Per face, indexed like model.faces: its control points = faces[f] × lattice points.
  std::vector<SparseRows> faces;
  /// Per edge: its curve's control points = edges[e] × lattice points.
  std::vector<SparseRows> edges;
  /// One row per vertex: its point = row × lattice points.
  SparseRows vertices;
  /// The lattice's point count (the matrices' columns).
  Eigen::Index lattice_points = 0;
  /// The lattice points `model` is composed at (lattice_points × 3).
  Points3 points;
};

/// The Jacobian of `model` deformed by `lattice` (see above). Throws clay::Error: InvalidGeometry
/// for an invalid lattice or model; OutOfDomain naming the face (or edge) and its name when one
/// crosses the lattice's boundary (the FFD is the identity outside, so no single polynomial is
/// exact: enlarge the frame, frame_around); InvalidArgument when a face crosses a B-spline
/// lattice's knot plane obliquely (no single patch is exact there: deform_model refits it, which
/// is not linear in the points) or the model has no face.
CLAY_DEFORM_API ModelJacobian model_jacobian(const BezierLattice& lattice,
                                             const brep::Model& model);
/// Same for a B-spline lattice.
CLAY_DEFORM_API ModelJacobian model_jacobian(const BSplineLattice& lattice,
                                             const brep::Model& model);

/// The model at other lattice points, in the same form: every matrix times `points` (a moved
/// lattice of the same shape), the entities outside the lattice as they are, tolerances widened
/// as model_jacobian's. A sparse product per face: much cheaper than composing again. Throws
/// InvalidArgument when points.rows() is not jacobian.lattice_points or a point is not finite.
CLAY_DEFORM_API brep::Model deformed_model(const ModelJacobian& jacobian, const Points3& points);

/// The Jacobian at given (u, v) of face `face`: row i is the derivative of the face's point at
/// uv[i] with respect to the lattice points (Σ_k R_k(u, v) C_k, R_k the face's rational basis).
/// Throws InvalidArgument for a face out of range or a (u, v) outside its surface's domain.
CLAY_DEFORM_API SparseRows face_point_jacobian(const ModelJacobian& jacobian, int face,
                                               const std::vector<Eigen::Vector2d>& uv);

/// Mass properties of the model's solids at the jacobian's lattice points and their gradients
/// with respect to the lattice points (lattice_points × 3 each).
struct LatticeMassGradients {
  brep::MassProperties value;
  Points3 volume;                   ///< ∂V/∂L_J (mm^2)
  std::array<Points3, 3> centroid;  ///< ∂g_i/∂L_J
  std::array<Points3, 6> inertia;   ///< of xx, yy, zz, xy, xz, yz (mm^4)
};

/// Mass properties of every solid of jacobian.model and their gradients with respect to the
/// lattice points: C_fᵀ times each face's gradient and Vᵀ times the vertices'
/// (brep::mass_property_gradients), summed.
/// Throws as brep::mass_property_gradients.
CLAY_DEFORM_API LatticeMassGradients mass_property_gradients(const ModelJacobian& jacobian);
/// Same at other lattice points (of deformed_model(jacobian, points)): an optimiser's evaluation.
/// Throws as deformed_model and brep::mass_property_gradients.
CLAY_DEFORM_API LatticeMassGradients mass_property_gradients(const ModelJacobian& jacobian,
                                                             const Points3& points);

/// The area of the model's faces at the jacobian's lattice points (with its error bound,
/// brep::surface_area) and its gradient with respect to the lattice points.
struct LatticeAreaGradient {
  brep::SurfaceArea value;
  Points3 area;  ///< ∂A/∂L_J (mm)
};

/// The area of every face of jacobian.model and its gradient with respect to the lattice points:
/// C_fᵀ times each face's gradient (brep::surface_area_gradient), summed. Throws as
/// brep::surface_area_gradient.
CLAY_DEFORM_API LatticeAreaGradient surface_area_gradient(const ModelJacobian& jacobian);
/// Same at other lattice points (of deformed_model(jacobian, points)). Throws as deformed_model
/// and brep::surface_area_gradient.
CLAY_DEFORM_API LatticeAreaGradient surface_area_gradient(const ModelJacobian& jacobian,
                                                          const Points3& points);

/// A plane the lattice's displacement mirrors across: a part symmetric about it stays symmetric.
struct SymmetryPlane {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();  ///< any length but 0
};

/// What keep_properties holds while the lattice moves.
struct KeptProperties {
  std::optional<double> volume_mm3;            ///< the solids' total volume
  std::optional<Eigen::Vector3d> centroid_mm;  ///< their centroid
  std::optional<double> area_mm2;              ///< the faces' total area (brep::surface_area)
  /// Faces (indices into jacobian.model.faces) that stay exactly where jacobian.model has them:
  /// C_f L = P_f, linear in the lattice points L (a mounting face, a flange).
  std::vector<int> fixed_faces;
  /// Planes the displacement L − jacobian.points mirrors across (L_m(J) − rest_m(J) =
  /// S (L_J − rest_J), S the reflection; the lattice's rest points must be symmetric about each).
  std::vector<SymmetryPlane> symmetry_planes;
  /// Lattice points (indices) the correction leaves where `moved` has them: the dragged point,
  /// or the points that hold a face fixed.
  std::vector<int> held;
  /// Relative tolerance on the volume (and on the centroid, relative to the model's size).
  double tolerance = 1e-13;
};

/// A move corrected to keep properties, and how it went.
struct KeptMove {
  Points3 points;                   ///< the corrected lattice points
  brep::MassProperties properties;  ///< at them (when the volume or centroid is kept)
  double area_mm2 = 0;              ///< the area at them (when the area is kept)
  int iterations = 0;               ///< Newton steps taken
  double volume_error = 0;          ///< |V − target| / target (0 when the volume is not kept)
  double centroid_error_mm = 0;     ///< |g − target| (0 when the centroid is not kept)
  double area_error = 0;            ///< |A − target| / target (0 when the area is not kept)
  /// The largest residual of the linear constraints (fixed faces' control points, mirrored
  /// displacements), mm; 0 when there are none.
  double linear_error_mm = 0;
};

/// `moved` corrected so that the kept properties hold. The linear ones first (fixed faces,
/// symmetry planes): the free points (not held) moved least, in the least-squares sense, onto
/// the affine set K L = b they define (an orthonormal basis Z of K's null space on the free
/// coordinates, by a column-pivoting QR). Then the nonlinear ones: + G λ, G the kept properties'
/// gradients with respect to the free points projected onto that null space (Z Zᵀ), λ by Newton
/// (V is cubic along the correction: two or three steps reach 1e-13), so every step keeps the
/// linear ones. The smallest correction in the span of the gradients (Sederberg–Parry §4's
/// volume constraint, on exact geometry). Throws InvalidArgument when nothing is kept, an index
/// is out of range, a plane's normal is zero or the lattice's rest points are not symmetric about
/// it, the held points break a linear constraint that the free ones cannot restore (a dragged
/// point that moves a fixed face), or the free points cannot change a kept property (every
/// point held); ToleranceNotMet when 20 steps do not reach the tolerance (the move folds the
/// lattice or is too large to correct: smaller steps).
CLAY_DEFORM_API KeptMove keep_properties(const ModelJacobian& jacobian, const Points3& moved,
                                         const KeptProperties& keep);

}  // namespace clay::deform
